//! Card operations counted: every call of the [`BlockDevice`] trait is one
//! operation on the card (the board's `drivers::sdcard::Card` holds chip
//! select and times its budget per call; the QEMU image's card models its
//! busy time per call), so the count is what the writer's time depends on.
//!
//! The logger, `CONFIG.TXT` and the self-test all reach the card through
//! [`super::Volumes`], over a [`CountingDevice`]: one copy of
//! embedded-sdmmc's code in the firmware, and every operation counted.

use core::cell::Cell;

use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};

/// Operations since the device was wrapped, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CardOps {
    /// Read commands (one or more blocks each).
    pub reads: u32,
    /// Write commands (one or more blocks each).
    pub writes: u32,
    /// Capacity queries.
    pub other: u32,
}

impl CardOps {
    /// Every operation.
    #[must_use]
    pub const fn total(self) -> u32 {
        self.reads
            .saturating_add(self.writes)
            .saturating_add(self.other)
    }

    /// The operations done between `earlier` and `self` (counts wrap).
    #[must_use]
    pub const fn since(self, earlier: Self) -> Self {
        Self {
            reads: self.reads.wrapping_sub(earlier.reads),
            writes: self.writes.wrapping_sub(earlier.writes),
            other: self.other.wrapping_sub(earlier.other),
        }
    }
}

/// How many leading bytes of the last block written [`CountingDevice`]
/// keeps, to tell which block it was.
pub const WRITTEN_HEAD_LEN: usize = 24;

/// A block device that counts the operations made on it (see the module
/// docs). Failed operations count too: the card was asked. It also keeps
/// where the last single block written went, and its first bytes: the
/// logger learns so where embedded-sdmmc put a block of its file.
#[derive(Debug)]
pub struct CountingDevice<D> {
    inner: D,
    reads: Cell<u32>,
    writes: Cell<u32>,
    other: Cell<u32>,
    last_write: Cell<Option<(BlockIdx, [u8; WRITTEN_HEAD_LEN])>>,
}

impl<D> CountingDevice<D> {
    /// Wraps `inner`, counting from zero.
    pub const fn new(inner: D) -> Self {
        Self {
            inner,
            reads: Cell::new(0),
            writes: Cell::new(0),
            other: Cell::new(0),
            last_write: Cell::new(None),
        }
    }

    /// The card block of the last successful one-block write and the
    /// block's first [`WRITTEN_HEAD_LEN`] bytes (`None` before any, or when
    /// the last write failed or was of several blocks).
    pub fn last_write(&self) -> Option<(BlockIdx, [u8; WRITTEN_HEAD_LEN])> {
        self.last_write.get()
    }

    /// Operations so far.
    pub fn ops(&self) -> CardOps {
        CardOps {
            reads: self.reads.get(),
            writes: self.writes.get(),
            other: self.other.get(),
        }
    }

    /// The device itself.
    pub fn inner(&self) -> &D {
        &self.inner
    }

    /// The device itself, mutably (fault injection in tests).
    pub fn inner_mut(&mut self) -> &mut D {
        &mut self.inner
    }

    /// The device back.
    pub fn into_inner(self) -> D {
        self.inner
    }
}

fn bump(count: &Cell<u32>) {
    count.set(count.get().wrapping_add(1));
}

impl<D: BlockDevice> BlockDevice for CountingDevice<D> {
    type Error = D::Error;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), Self::Error> {
        bump(&self.reads);
        self.inner.read(blocks, start)
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), Self::Error> {
        bump(&self.writes);
        self.last_write.set(None);
        self.inner.write(blocks, start)?;
        if let [one] = blocks {
            let mut head = [0; WRITTEN_HEAD_LEN];
            head.copy_from_slice(&one.contents[..WRITTEN_HEAD_LEN]);
            self.last_write.set(Some((start, head)));
        }
        Ok(())
    }

    fn num_blocks(&self) -> Result<BlockCount, Self::Error> {
        bump(&self.other);
        self.inner.num_blocks()
    }
}

#[cfg(all(test, feature = "mock"))]
mod tests {
    use super::*;
    use crate::logger::mock::MockCard;

    #[test]
    fn every_call_is_one_operation_of_its_kind_failed_or_not() {
        let dev = CountingDevice::new(MockCard::new(vec![0u8; 8 * 512]));
        let mut two = [Block::new(), Block::new()];
        dev.read(&mut two, BlockIdx(0)).expect("read");
        dev.write(&two[..1], BlockIdx(3)).expect("write");
        dev.write(&two, BlockIdx(4)).expect("write");
        dev.num_blocks().expect("size");
        // Past the end: refused, still asked.
        assert!(dev.read(&mut two, BlockIdx(7)).is_err());
        let ops = dev.ops();
        assert_eq!(
            ops,
            CardOps {
                reads: 2,
                writes: 2,
                other: 1
            }
        );
        assert_eq!(ops.total(), 5);
        // Blocks moved are the card's business: three written, one command each call.
        assert_eq!(dev.inner().writes(), 3);
        // Only a one-block write is remembered.
        assert_eq!(dev.last_write(), None);
        let mut one = Block::new();
        one.contents[..3].copy_from_slice(b"abc");
        dev.write(core::slice::from_ref(&one), BlockIdx(6))
            .expect("write");
        let (at, head) = dev.last_write().expect("remembered");
        assert_eq!((at, &head[..4]), (BlockIdx(6), &b"abc\0"[..]));
        assert!(dev.write(core::slice::from_ref(&one), BlockIdx(8)).is_err());
        assert_eq!(dev.last_write(), None);
        let later = CardOps {
            reads: 1,
            writes: 7,
            other: 1,
        };
        assert_eq!(
            later.since(ops),
            CardOps {
                reads: u32::MAX,
                writes: 5,
                other: 0
            }
        );
    }
}
