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

/// A block device that counts the operations made on it (see the module
/// docs). Failed operations count too: the card was asked.
#[derive(Debug)]
pub struct CountingDevice<D> {
    inner: D,
    reads: Cell<u32>,
    writes: Cell<u32>,
    other: Cell<u32>,
}

impl<D> CountingDevice<D> {
    /// Wraps `inner`, counting from zero.
    pub const fn new(inner: D) -> Self {
        Self {
            inner,
            reads: Cell::new(0),
            writes: Cell::new(0),
            other: Cell::new(0),
        }
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
        self.inner.write(blocks, start)
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
