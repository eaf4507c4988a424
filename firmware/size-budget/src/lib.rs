//! Flash and static RAM of a Cortex-M firmware image, read from the ELF
//! section headers, the way `size` reports them in Berkeley format:
//!
//! - **flash** = every allocated section with contents (`.vector_table`,
//!   `.text`, `.rodata`, and `.data`, whose initial values live in flash);
//! - **static RAM** = every allocated section placed in SRAM (`.data`,
//!   `.bss`, `.uninit`). The stack is what is left of SRAM above that;
//! - **CCM** = every allocated section placed in the core-coupled RAM
//!   (`.ccmram`: CPU-only state, never a DMA buffer).
//!
//! The memory plan (`firmware/docs/board.md`): flash at most
//! [`FLASH_BUDGET`], the active slot of a two-image layout for field
//! updates; CCM at most its 64 KiB. Static SRAM plus the worst-case stack
//! bound at most 120 KiB is checked where the bound is computed
//! (`stack_bound.py --check`).
//!
//! Sections that are not loaded (`.defmt` strings, debug information) do
//! not count. Only 32-bit little-endian ELF files are read (the ARM
//! targets); anything else is an error, never a panic.
#![warn(missing_docs)]

use std::fmt;

/// STM32F405 SRAM (SRAM1 + SRAM2): `[start, end)`.
pub const SRAM_RANGE: (u32, u32) = (0x2000_0000, 0x2002_0000);
/// STM32F405 core-coupled RAM: `[start, end)`.
pub const CCM_RANGE: (u32, u32) = (0x1000_0000, 0x1001_0000);

/// Flash, bytes: 384 KiB, the active slot of the flash layout for field
/// updates (sectors 5-7 of the STM32F405's 16, 16, 16, 16, 64 and 7 × 128
/// KiB; a second image needs sectors 8-11, one 128 KiB sector more than the
/// slot, to swap into; the bootloader and its state take sectors 0-3).
pub const FLASH_BUDGET: u64 = 384 * 1024;
/// CCM, bytes: all of it (64 KiB).
pub const CCM_BUDGET: u64 = (CCM_RANGE.1 - CCM_RANGE.0) as u64;

const SHF_ALLOC: u32 = 0x2;
const SHT_NOBITS: u32 = 8;
const SECTION_HEADER_LEN: usize = 40;

/// What the image occupies.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Footprint {
    /// Bytes programmed into flash.
    pub flash: u64,
    /// Bytes of SRAM reserved before the stack.
    pub ram: u64,
    /// Bytes of CCM reserved.
    pub ccm: u64,
}

/// Why a file could not be measured.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ElfError {
    /// Not an ELF file.
    NotElf,
    /// Not 32-bit little-endian.
    Unsupported,
    /// A header points outside the file.
    Truncated,
}

impl fmt::Display for ElfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::NotElf => "not an ELF file",
            Self::Unsupported => "not a 32-bit little-endian ELF file",
            Self::Truncated => "truncated ELF file",
        })
    }
}

impl std::error::Error for ElfError {}

fn u16_at(data: &[u8], at: usize) -> Result<u16, ElfError> {
    let bytes = data.get(at..at + 2).ok_or(ElfError::Truncated)?;
    Ok(u16::from_le_bytes([bytes[0], bytes[1]]))
}

fn u32_at(data: &[u8], at: usize) -> Result<u32, ElfError> {
    let bytes = data.get(at..at + 4).ok_or(ElfError::Truncated)?;
    Ok(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]))
}

/// Measures an ELF image.
///
/// # Errors
/// When the file is not a 32-bit little-endian ELF file or is cut short.
pub fn measure(elf: &[u8]) -> Result<Footprint, ElfError> {
    if elf.get(..4) != Some(b"\x7fELF".as_slice()) {
        return Err(ElfError::NotElf);
    }
    // EI_CLASS 1: 32-bit; EI_DATA 1: little-endian.
    if elf.get(4..6) != Some([1u8, 1].as_slice()) {
        return Err(ElfError::Unsupported);
    }
    let table = u32_at(elf, 0x20)? as usize;
    let entry_len = usize::from(u16_at(elf, 0x2E)?);
    let count = usize::from(u16_at(elf, 0x30)?);
    if count > 0 && entry_len < SECTION_HEADER_LEN {
        return Err(ElfError::Truncated);
    }
    let mut footprint = Footprint::default();
    for i in 0..count {
        let at = table + i * entry_len;
        let kind = u32_at(elf, at + 4)?;
        let flags = u32_at(elf, at + 8)?;
        let addr = u32_at(elf, at + 12)?;
        let size = u64::from(u32_at(elf, at + 20)?);
        if flags & SHF_ALLOC == 0 {
            continue;
        }
        if kind != SHT_NOBITS {
            footprint.flash += size;
        }
        if (SRAM_RANGE.0..SRAM_RANGE.1).contains(&addr) {
            footprint.ram += size;
        } else if (CCM_RANGE.0..CCM_RANGE.1).contains(&addr) {
            footprint.ccm += size;
        }
    }
    Ok(footprint)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A minimal ELF32 LE file with these sections (kind, flags, addr, size).
    fn elf(sections: &[(u32, u32, u32, u32)]) -> Vec<u8> {
        let mut data = vec![0u8; 52];
        data[..6].copy_from_slice(b"\x7fELF\x01\x01");
        data[0x20..0x24].copy_from_slice(&52u32.to_le_bytes());
        data[0x2E..0x30].copy_from_slice(&40u16.to_le_bytes());
        data[0x30..0x32].copy_from_slice(&(sections.len() as u16).to_le_bytes());
        for &(kind, flags, addr, size) in sections {
            let mut header = [0u8; 40];
            header[4..8].copy_from_slice(&kind.to_le_bytes());
            header[8..12].copy_from_slice(&flags.to_le_bytes());
            header[12..16].copy_from_slice(&addr.to_le_bytes());
            header[20..24].copy_from_slice(&size.to_le_bytes());
            data.extend_from_slice(&header);
        }
        data
    }

    const PROGBITS: u32 = 1;

    #[test]
    fn flash_counts_loaded_contents_and_ram_counts_what_lives_in_ram() {
        let image = elf(&[
            (PROGBITS, SHF_ALLOC | 0x4, 0x0800_0000, 1000), // .text
            (PROGBITS, SHF_ALLOC, 0x0800_1000, 200),        // .rodata
            (PROGBITS, SHF_ALLOC | 0x1, 0x2000_0000, 16),   // .data
            (SHT_NOBITS, SHF_ALLOC | 0x1, 0x2000_0010, 4000), // .bss
            (SHT_NOBITS, SHF_ALLOC | 0x3, 0x1000_0000, 64), // .ccmram
            (SHT_NOBITS, SHF_ALLOC | 0x1, 0x2000_0FB0, 8),  // .uninit
            (PROGBITS, 0, 0, 9999),                         // .defmt, debug
        ]);
        assert_eq!(
            measure(&image),
            Ok(Footprint {
                flash: 1216,
                ram: 4024,
                ccm: 64
            })
        );
    }

    /// Only addresses inside each range count for it: SRAM ends at
    /// 0x2002_0000 and CCM at 0x1001_0000 (QEMU's larger SRAM or the
    /// backup SRAM are neither).
    #[test]
    fn each_memory_counts_only_its_own_range() {
        let image = elf(&[
            (SHT_NOBITS, SHF_ALLOC | 0x1, 0x2001_FFFC, 4),
            (SHT_NOBITS, SHF_ALLOC | 0x1, 0x2002_0000, 100),
            (SHT_NOBITS, SHF_ALLOC | 0x1, 0x1000_FFF0, 16),
            (SHT_NOBITS, SHF_ALLOC | 0x1, 0x1001_0000, 200),
            (SHT_NOBITS, SHF_ALLOC | 0x1, 0x0FFF_FFF0, 300),
        ]);
        assert_eq!(
            measure(&image),
            Ok(Footprint {
                flash: 0,
                ram: 4,
                ccm: 16
            })
        );
        assert_eq!(CCM_BUDGET, 64 * 1024);
    }

    #[test]
    fn other_files_are_errors_not_panics() {
        assert_eq!(measure(b""), Err(ElfError::NotElf));
        assert_eq!(measure(b"\x7fELF\x02\x01"), Err(ElfError::Unsupported));
        let mut cut = elf(&[(PROGBITS, SHF_ALLOC, 0x0800_0000, 1)]);
        cut.truncate(60);
        assert_eq!(measure(&cut), Err(ElfError::Truncated));
        let mut bad_table = elf(&[]);
        bad_table[0x30] = 3;
        assert_eq!(measure(&bad_table), Err(ElfError::Truncated));
    }
}
