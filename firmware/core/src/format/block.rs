//! The 512-byte block: header, payload and CRC.
//!
//! ```text
//! offset size field
//!      0    4 magic "WBLK"
//!      4    1 format major version (readers reject other majors)
//!      5    1 format minor version (additive changes only)
//!      6    2 payload length in bytes (u16 LE, at most PAYLOAD_LEN)
//!      8    4 block sequence number (u32 LE, 0 for the first block of a file)
//!     12    4 frames written to the file before this block (u32 LE)
//!     16    8 time base t0, µs since boot (u64 LE)
//!     24  484 payload: records, zero padded
//!    508    4 CRC-32 (IEEE) of bytes 0..508 (u32 LE)
//! ```

/// Size of a block: one SD sector.
pub const BLOCK_LEN: usize = 512;
/// Size of the block header.
pub const HEADER_LEN: usize = 24;
/// Size of the CRC trailer.
pub const CRC_LEN: usize = 4;
/// Payload bytes available for records.
pub const PAYLOAD_LEN: usize = BLOCK_LEN - HEADER_LEN - CRC_LEN;
/// Sync marker at the start of every block.
pub const MAGIC: [u8; 4] = *b"WBLK";
/// Format major version written and read by this code.
pub const VERSION_MAJOR: u8 = 1;
/// Format minor version written by this code.
pub const VERSION_MINOR: u8 = 2;

/// One block's bytes.
pub type Block = [u8; BLOCK_LEN];

/// The decoded header of a valid block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct BlockHeader {
    /// Minor format version of the writer.
    pub version_minor: u8,
    /// Bytes of records in the payload.
    pub payload_len: u16,
    /// Block sequence number within the file.
    pub seq: u32,
    /// Frames written to the file before this block.
    pub first_frame: u32,
    /// Time base of the block's records, µs since boot.
    pub t0_us: u64,
}

/// Why 512 bytes are not a valid block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum BlockError {
    /// The sync marker is absent.
    BadMagic,
    /// The CRC does not match: the block is damaged.
    BadCrc,
    /// Written by an incompatible major version of the format.
    UnsupportedVersion(u8),
    /// The payload length exceeds the payload area (CRC matched: a writer bug).
    BadLength(u16),
}

impl core::fmt::Display for BlockError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Self::BadMagic => f.write_str("no block sync marker"),
            Self::BadCrc => f.write_str("CRC mismatch"),
            Self::UnsupportedVersion(v) => write!(f, "unsupported format major version {v}"),
            Self::BadLength(n) => write!(f, "payload length {n} exceeds the block"),
        }
    }
}

/// The MCU checks a block or two per second and has a flash budget, so it
/// computes bit by bit (about 0.1 ms per block at 168 MHz) without a table.
#[cfg(target_os = "none")]
static CRC32: crc::Crc<u32, crc::NoTable> =
    crc::Crc::<u32, crc::NoTable>::new(&crc::CRC_32_ISO_HDLC);

/// CRC-32 (IEEE 802.3, as zlib) of `bytes`.
#[cfg(target_os = "none")]
#[must_use]
pub fn crc32(bytes: &[u8]) -> u32 {
    CRC32.checksum(bytes)
}

/// CRC-32 (IEEE 802.3, as zlib) of `bytes`. The host checks every block of
/// every log it reads, twice for a file read in two passes: `crc32fast`
/// folds with the CPU's carry-less multiply where it has one (found at run
/// time), several times the speed of a table, and is the same CRC.
#[cfg(not(target_os = "none"))]
#[must_use]
pub fn crc32(bytes: &[u8]) -> u32 {
    crc32fast::hash(bytes)
}

impl BlockHeader {
    /// Writes this header and the CRC over `block` (whose payload is in place).
    pub fn seal(&self, block: &mut Block) {
        block[0..4].copy_from_slice(&MAGIC);
        block[4] = VERSION_MAJOR;
        block[5] = self.version_minor;
        block[6..8].copy_from_slice(&self.payload_len.to_le_bytes());
        block[8..12].copy_from_slice(&self.seq.to_le_bytes());
        block[12..16].copy_from_slice(&self.first_frame.to_le_bytes());
        block[16..24].copy_from_slice(&self.t0_us.to_le_bytes());
        let crc = crc32(&block[..BLOCK_LEN - CRC_LEN]);
        block[BLOCK_LEN - CRC_LEN..].copy_from_slice(&crc.to_le_bytes());
    }

    /// Checks and decodes a block's header; on success the payload is
    /// `block[HEADER_LEN..HEADER_LEN + payload_len]`.
    pub fn parse(block: &Block) -> Result<Self, BlockError> {
        if block[0..4] != MAGIC {
            return Err(BlockError::BadMagic);
        }
        Self::parse_with_crc(block, crc32(&block[..BLOCK_LEN - CRC_LEN]))
    }

    /// [`Self::parse`] with the CRC of the block's first 508 bytes computed
    /// by the caller (a rolling search computes it from a nearby window's).
    pub fn parse_with_crc(block: &Block, crc: u32) -> Result<Self, BlockError> {
        if block[0..4] != MAGIC {
            return Err(BlockError::BadMagic);
        }
        let stored = u32::from_le_bytes(le4(&block[BLOCK_LEN - CRC_LEN..]));
        if crc != stored {
            return Err(BlockError::BadCrc);
        }
        if block[4] != VERSION_MAJOR {
            return Err(BlockError::UnsupportedVersion(block[4]));
        }
        let payload_len = u16::from_le_bytes([block[6], block[7]]);
        if usize::from(payload_len) > PAYLOAD_LEN {
            return Err(BlockError::BadLength(payload_len));
        }
        Ok(Self {
            version_minor: block[5],
            payload_len,
            seq: u32::from_le_bytes(le4(&block[8..12])),
            first_frame: u32::from_le_bytes(le4(&block[12..16])),
            t0_us: u64::from_le_bytes(le8(&block[16..24])),
        })
    }

    /// The record bytes of a block this header was parsed from.
    #[must_use]
    pub fn payload<'a>(&self, block: &'a Block) -> &'a [u8] {
        &block[HEADER_LEN..HEADER_LEN + usize::from(self.payload_len)]
    }
}

fn le4(bytes: &[u8]) -> [u8; 4] {
    let mut out = [0; 4];
    out.copy_from_slice(&bytes[..4]);
    out
}

fn le8(bytes: &[u8]) -> [u8; 8] {
    let mut out = [0; 8];
    out.copy_from_slice(&bytes[..8]);
    out
}

#[cfg(test)]
mod tests {
    use super::crc32;

    #[test]
    fn crc_is_the_zlib_crc32() {
        // The standard check value of CRC-32/ISO-HDLC.
        assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    }

    proptest::proptest! {
        /// The MCU's bitwise CRC (the one that seals blocks on the card)
        /// and the host's folded one agree on any bytes.
        #[test]
        fn the_mcus_bitwise_crc_is_the_hosts(bytes in proptest::collection::vec(proptest::num::u8::ANY, 0..600)) {
            let bitwise = crc::Crc::<u32, crc::NoTable>::new(&crc::CRC_32_ISO_HDLC);
            proptest::prop_assert_eq!(bitwise.checksum(&bytes), crc32(&bytes));
        }
    }
}
