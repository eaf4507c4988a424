//! The CRC of a block's checked bytes at every offset of a stretch, each
//! from the one before in constant time.
//!
//! Resynchronising tries every sync marker whose length field passes as a
//! block start; markers a few bytes apart (a flood of `WBLK` with plausible
//! fields) would cost a full CRC of 508 bytes each. The CRC-32 register is
//! linear over GF(2), so the CRC of the window one byte further on is the
//! last one stepped by the new byte, with the leaving byte's contribution
//! (a table of 256 entries for the fixed window length) taken out: the
//! search then costs a table step per byte of input however dense the
//! markers are. No published crate rolls a fixed-window CRC-32 (the `crc`
//! and `crc32fast` crates compute and combine, but cannot drop a byte), so
//! it is written here; a property test checks it against [`super::crc32`]
//! at every offset.

use super::block::{crc32, BLOCK_LEN, CRC_LEN};

/// Bytes a block's CRC covers.
const WINDOW: usize = BLOCK_LEN - CRC_LEN;
/// CRC-32/ISO-HDLC's polynomial, reflected.
const POLY: u32 = 0xEDB8_8320;
/// The register before the first byte (and the final XOR).
const INIT: u32 = 0xFFFF_FFFF;

/// One step of the register of the byte-wise CRC, without a table.
const fn step_bits(reg: u32, byte: u8) -> u32 {
    let mut reg = reg ^ byte as u32;
    let mut bit = 0;
    while bit < 8 {
        reg = if reg & 1 == 1 {
            (reg >> 1) ^ POLY
        } else {
            reg >> 1
        };
        bit += 1;
    }
    reg
}

/// The byte table of the register's step.
const STEP: [u32; 256] = {
    let mut table = [0; 256];
    let mut i = 0;
    while i < 256 {
        table[i] = step_bits(0, i as u8);
        i += 1;
    }
    table
};

const fn step(reg: u32, byte: u8) -> u32 {
    STEP[((reg ^ byte as u32) & 0xff) as usize] ^ (reg >> 8)
}

/// `reg` carried through `WINDOW` zero bytes.
const fn through_zeros(mut reg: u32) -> u32 {
    let mut i = 0;
    while i < WINDOW {
        reg = step(reg, 0);
        i += 1;
    }
    reg
}

/// What the byte a window leaves contributes to the register once the
/// window has moved one byte past it: for the register `R` over bytes
/// `b0..bn` (length `WINDOW + 1`) from `INIT`, the register over
/// `b1..bn` from `INIT` is `R ^ LEAVE[b0]`.
///
/// `LEAVE[b]` is `INIT` and the one-byte register of `b` from `INIT`,
/// carried through `WINDOW` zero bytes; it is affine in `b`, so nine runs
/// through the zeros build the whole table.
const LEAVE: [u32; 256] = {
    let base = through_zeros(step(INIT, 0) ^ INIT);
    let mut bits = [0; 8];
    let mut k = 0;
    while k < 8 {
        bits[k] = through_zeros(step(INIT, 1 << k) ^ INIT) ^ base;
        k += 1;
    }
    let mut table = [0; 256];
    let mut b = 0;
    while b < 256 {
        let mut v = base;
        let mut k = 0;
        while k < 8 {
            if b & (1 << k) != 0 {
                v ^= bits[k];
            }
            k += 1;
        }
        table[b] = v;
        b += 1;
    }
    table
};

/// Moving a window further than this many bytes computes its CRC afresh
/// (the table-driven full CRC is cheaper than that many single steps).
const ROLL_MAX: usize = 128;

/// The CRC of the `WINDOW` bytes at some offset of one stretch of bytes,
/// moved forward to later offsets.
#[derive(Clone, Copy, Debug, Default)]
pub struct CrcWindow {
    /// Offset of the window in the stretch, and its register (the CRC
    /// before the final XOR), if one was computed.
    at: Option<(usize, u32)>,
}

impl CrcWindow {
    /// The CRC-32 of `bytes[at..at + 508]`, rolled from the last window
    /// computed over the same `bytes` when that is a little before `at`.
    ///
    /// # Panics
    /// When `bytes` ends before `at + 508` (callers check a block is there).
    pub fn crc_at(&mut self, bytes: &[u8], at: usize) -> u32 {
        let reg = match self.at {
            Some((from, mut reg)) if from <= at && at - from <= ROLL_MAX => {
                for i in from..at {
                    reg = step(reg, bytes[i + WINDOW]) ^ LEAVE[usize::from(bytes[i])];
                }
                reg
            }
            _ => !crc32(&bytes[at..at + WINDOW]),
        };
        self.at = Some((at, reg));
        !reg
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn rolled_crcs_are_the_crcs_of_their_windows(
            bytes in proptest::collection::vec(any::<u8>(), WINDOW..WINDOW + 700),
            steps in proptest::collection::vec(0usize..200, 1..40),
        ) {
            let mut window = CrcWindow::default();
            let mut at = 0;
            for s in steps {
                if at + WINDOW > bytes.len() {
                    break;
                }
                prop_assert_eq!(window.crc_at(&bytes, at), crc32(&bytes[at..at + WINDOW]));
                at += s;
            }
        }
    }

    #[test]
    fn a_window_rolled_over_every_offset_matches() {
        let bytes: Vec<u8> = (0..3 * WINDOW as u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 24) as u8)
            .collect();
        let mut window = CrcWindow::default();
        for at in 0..=bytes.len() - WINDOW {
            assert_eq!(
                window.crc_at(&bytes, at),
                crc32(&bytes[at..at + WINDOW]),
                "offset {at}"
            );
        }
    }
}
