//! Packs records into sealed 512-byte blocks, without allocation.

use super::block::{Block, BlockHeader, BLOCK_LEN, HEADER_LEN, PAYLOAD_LEN, VERSION_MINOR};
use super::codec::{self, EncodeError, MAX_RECORD_LEN};
use super::record::Record;

/// Builds a log file block by block.
///
/// Block `seq` belongs at byte offset `seq * 512` of the file. Records go into
/// an open block; when one does not fit, the open block is sealed and handed
/// out and the record opens the next. [`Self::snapshot`] seals a copy of the
/// open block without closing it, for a periodic flush: the writer puts it at
/// the same offset and overwrites it later with the fuller version.
pub struct BlockEncoder {
    open: Block,
    sealed: Block,
    payload_len: usize,
    seq: u32,
    frames_before_block: u32,
    frames_total: u32,
    t0_us: u64,
    cursor_us: u64,
}

impl Default for BlockEncoder {
    fn default() -> Self {
        Self::new()
    }
}

impl BlockEncoder {
    /// An encoder for a new file.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            open: [0; BLOCK_LEN],
            sealed: [0; BLOCK_LEN],
            payload_len: 0,
            seq: 0,
            frames_before_block: 0,
            frames_total: 0,
            t0_us: 0,
            cursor_us: 0,
        }
    }

    /// Sequence number of the open block (its file offset is `seq * 512`).
    #[must_use]
    pub fn open_seq(&self) -> u32 {
        self.seq
    }

    /// Frames encoded so far.
    #[must_use]
    pub fn frames_total(&self) -> u32 {
        self.frames_total
    }

    /// Whether the open block holds no record.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.payload_len == 0
    }

    /// Adds a record. Returns the block this closed, if any, to be written at
    /// offset `seq * 512` (its seq is one less than [`Self::open_seq`]).
    ///
    /// A frame earlier than the previous frame of the open block starts a new
    /// block, so any sequence of records can be encoded; the decoder reports
    /// the time jump.
    pub fn push(&mut self, rec: &Record<'_>) -> Result<Option<&Block>, EncodeError> {
        let t_us = rec.t_us();
        if self.payload_len == 0 {
            self.t0_us = t_us;
            self.cursor_us = t_us;
        }
        let goes_back = matches!(rec, Record::Frame(_)) && t_us < self.cursor_us;
        let mut closed = false;
        if !goes_back {
            if let Some(n) = self.try_append(rec)? {
                self.commit(rec, n);
                return Ok(None);
            }
        }
        // Does not fit (or must not follow): close this block, open the next.
        if self.payload_len > 0 {
            self.close();
            closed = true;
        }
        self.t0_us = t_us;
        self.cursor_us = t_us;
        // Every record is at most MAX_RECORD_LEN, which fits an empty block.
        let n = self.try_append(rec)?.ok_or(EncodeError::TooLong)?;
        self.commit(rec, n);
        Ok(closed.then_some(&self.sealed))
    }

    /// Seals a copy of the open block without closing it; `None` if it is empty.
    pub fn snapshot(&mut self) -> Option<&Block> {
        if self.payload_len == 0 {
            return None;
        }
        self.seal_open();
        Some(&self.sealed)
    }

    /// Closes the open block and returns it; `None` if it is empty.
    pub fn finish(&mut self) -> Option<&Block> {
        if self.payload_len == 0 {
            return None;
        }
        self.close();
        Some(&self.sealed)
    }

    fn header(&self) -> BlockHeader {
        BlockHeader {
            version_minor: VERSION_MINOR,
            // PAYLOAD_LEN < 2^16.
            payload_len: self.payload_len as u16,
            seq: self.seq,
            first_frame: self.frames_before_block,
            t0_us: self.t0_us,
        }
    }

    fn try_append(&mut self, rec: &Record<'_>) -> Result<Option<usize>, EncodeError> {
        let start = HEADER_LEN + self.payload_len;
        let room = &mut self.open[start..HEADER_LEN + PAYLOAD_LEN];
        codec::encode(rec, self.cursor_us, room)
    }

    fn commit(&mut self, rec: &Record<'_>, len: usize) {
        self.payload_len += len;
        if let Record::Frame(f) = rec {
            self.cursor_us = f.t_us;
            self.frames_total = self.frames_total.wrapping_add(1);
        }
    }

    /// Copies the open block, zero-padded, into `sealed` and seals it.
    fn seal_open(&mut self) {
        self.open[HEADER_LEN + self.payload_len..].fill(0);
        self.sealed = self.open;
        self.header().seal(&mut self.sealed);
    }

    fn close(&mut self) {
        self.seal_open();
        self.payload_len = 0;
        self.seq = self.seq.wrapping_add(1);
        self.frames_before_block = self.frames_total;
    }
}

const _: () = assert!(MAX_RECORD_LEN <= PAYLOAD_LEN);
