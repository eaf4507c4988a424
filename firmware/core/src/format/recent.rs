//! The blocks decoded last, kept whole so a copy of one, or a fuller
//! rewrite of a flushed one, is recognised by its content, not by its
//! sequence number alone.
//!
//! Two valid blocks are the same block when they carry the same sequence
//! number, frame counter and time base and one payload is a prefix of the
//! other: a flush writes the open block and a later write at the same
//! offset carries it fuller (FORMAT.md, "Flushing"). Any other pair of
//! valid blocks, whatever their numbers, holds different data.

use super::block::{BlockHeader, PAYLOAD_LEN};

/// Blocks remembered (about 32 KiB): a copy of a block met within this
/// many other blocks of it is recognised. The host decodes a seekable file
/// in sequence order, which puts every copy right after its original.
pub const RECENT_BLOCKS: usize = 64;

#[derive(Clone, Copy, Debug)]
struct Entry {
    seq: u32,
    first_frame: u32,
    t0_us: u64,
    len: usize,
    payload: [u8; PAYLOAD_LEN],
}

impl Entry {
    const EMPTY: Self = Self {
        seq: 0,
        first_frame: 0,
        t0_us: 0,
        len: 0,
        payload: [0; PAYLOAD_LEN],
    };

    fn same_block(&self, h: &BlockHeader) -> bool {
        self.seq == h.seq && self.first_frame == h.first_frame && self.t0_us == h.t0_us
    }

    fn bytes(&self) -> &[u8] {
        &self.payload[..self.len]
    }
}

/// How a valid block relates to the blocks decoded before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Seen {
    /// Data not decoded yet.
    New,
    /// A copy of a decoded block, or an earlier flush of one.
    Repeat,
    /// A fuller version of a decoded block: its first `decoded_len` payload
    /// bytes were decoded already.
    Fuller {
        /// Payload bytes already decoded.
        decoded_len: usize,
    },
}

/// The last [`RECENT_BLOCKS`] blocks decoded.
#[derive(Clone, Debug)]
pub struct Recent {
    entries: [Entry; RECENT_BLOCKS],
    /// Entries in use.
    len: usize,
    /// The entry the next new block replaces once all are in use.
    next: usize,
    /// The highest sequence number of any block remembered so far (ones
    /// since replaced too): a block numbered above it (each block of a log
    /// read in order) matches no entry.
    highest: Option<u32>,
}

impl Default for Recent {
    fn default() -> Self {
        Self {
            entries: [Entry::EMPTY; RECENT_BLOCKS],
            len: 0,
            next: 0,
            highest: None,
        }
    }
}

impl Recent {
    /// What a valid block with `header` and `payload` is to the blocks
    /// decoded, and remembers it (a fuller version replaces the shorter).
    pub fn see(&mut self, header: &BlockHeader, payload: &[u8]) -> Seen {
        let mut fuller: Option<usize> = None;
        let known = self.highest.is_some_and(|seq| header.seq <= seq);
        let candidates = if known {
            &self.entries[..self.len]
        } else {
            &[]
        };
        for (i, e) in candidates.iter().enumerate() {
            if !e.same_block(header) {
                continue;
            }
            if payload.len() <= e.len && e.bytes().starts_with(payload) {
                return Seen::Repeat;
            }
            if payload.starts_with(e.bytes()) && fuller.is_none_or(|f| self.entries[f].len < e.len)
            {
                fuller = Some(i);
            }
        }
        let slot = match fuller {
            Some(i) => i,
            None if self.len < RECENT_BLOCKS => {
                self.len += 1;
                self.len - 1
            }
            None => {
                let i = self.next;
                self.next = (self.next + 1) % RECENT_BLOCKS;
                i
            }
        };
        let seen = fuller.map_or(Seen::New, |i| Seen::Fuller {
            decoded_len: self.entries[i].len,
        });
        self.highest = self.highest.max(Some(header.seq));
        let e = &mut self.entries[slot];
        e.seq = header.seq;
        e.first_frame = header.first_frame;
        e.t0_us = header.t0_us;
        e.len = payload.len().min(PAYLOAD_LEN);
        e.payload[..e.len].copy_from_slice(&payload[..e.len]);
        seen
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn header(seq: u32, first_frame: u32, t0_us: u64) -> BlockHeader {
        BlockHeader {
            version_minor: 0,
            payload_len: 0,
            seq,
            first_frame,
            t0_us,
        }
    }

    #[test]
    fn copies_flushes_and_rewrites_are_told_apart_by_content() {
        let mut r = Recent::default();
        let h = header(3, 40, 1000);
        assert_eq!(r.see(&h, b"abc"), Seen::New);
        assert_eq!(r.see(&h, b"abc"), Seen::Repeat);
        assert_eq!(r.see(&h, b"ab"), Seen::Repeat, "an earlier flush");
        assert_eq!(r.see(&h, b"abcde"), Seen::Fuller { decoded_len: 3 });
        assert_eq!(r.see(&h, b"abcd"), Seen::Repeat, "a flush of the fuller");
        assert_eq!(r.see(&h, b"abX"), Seen::New, "same number, other data");
        assert_eq!(r.see(&header(3, 41, 1000), b"abc"), Seen::New);
        assert_eq!(r.see(&header(3, 40, 1001), b"abc"), Seen::New);
        assert_eq!(r.see(&header(4, 40, 1000), b"abc"), Seen::New);
    }

    #[test]
    fn the_oldest_block_is_forgotten_first() {
        let mut r = Recent::default();
        for seq in 0..=RECENT_BLOCKS as u32 {
            assert_eq!(r.see(&header(seq, 0, 0), b"x"), Seen::New);
        }
        // Block 0 fell out; blocks 1..=64 are still known.
        assert_eq!(r.see(&header(1, 0, 0), b"x"), Seen::Repeat);
        assert_eq!(r.see(&header(0, 0, 0), b"x"), Seen::New);
    }
}
