//! An in-memory SD card for host tests of the logger, with fault injection:
//! a power-cut countdown ("fuel": block writes left before the power goes),
//! card removal and stalls (reported, so a test clock can let them pass).

use core::cell::{Cell, RefCell};
use std::vec::Vec;

use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};

/// Why the mock card refused an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub enum MockError {
    /// The power-cut countdown reached zero: nothing is written any more.
    PowerCut,
    /// The card was pulled out.
    Removed,
    /// A block index past the end of the card.
    OutOfRange,
    /// A block marked unreadable ([`MockCard::set_unreadable`]).
    ReadFailed,
}

impl core::fmt::Display for MockError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::PowerCut => "power cut",
            Self::Removed => "card removed",
            Self::OutOfRange => "block index out of range",
            Self::ReadFailed => "block unreadable",
        })
    }
}

impl core::error::Error for MockError {}

/// The mock card (see the module docs). Block operations take `&self`, as
/// embedded-sdmmc's trait demands, so the state lives in cells.
#[derive(Debug)]
pub struct MockCard {
    image: RefCell<Vec<u8>>,
    fuel: Cell<Option<u32>>,
    removed: Cell<bool>,
    stall_every_write_ms: Cell<u32>,
    stalled_ms: Cell<u64>,
    writes: Cell<u32>,
    reads: Cell<u32>,
    unreadable: Cell<Option<u32>>,
}

impl MockCard {
    /// A card holding `image` (its length is rounded down to whole blocks).
    #[must_use]
    pub fn new(image: Vec<u8>) -> Self {
        Self {
            image: RefCell::new(image),
            fuel: Cell::new(None),
            removed: Cell::new(false),
            stall_every_write_ms: Cell::new(0),
            stalled_ms: Cell::new(0),
            writes: Cell::new(0),
            reads: Cell::new(0),
            unreadable: Cell::new(None),
        }
    }

    /// The power goes after `writes` more block writes: the next write after
    /// those fails and nothing is written from then on. `None`: never.
    pub fn set_fuel(&self, writes: Option<u32>) {
        self.fuel.set(writes);
    }

    /// Every read of a range holding block `block` fails (a block whose
    /// CRC never matches); `None`: every block reads.
    pub fn set_unreadable(&self, block: Option<u32>) {
        self.unreadable.set(block);
    }

    /// Pulls the card out (`true`) or puts it back.
    pub fn set_removed(&self, removed: bool) {
        self.removed.set(removed);
    }

    /// Every block write from now on takes `ms` (0: none).
    pub fn set_write_stall_ms(&self, ms: u32) {
        self.stall_every_write_ms.set(ms);
    }

    /// Stall time accumulated since the last call, for a test clock.
    pub fn take_stalled_ms(&self) -> u64 {
        self.stalled_ms.replace(0)
    }

    /// Block writes done so far.
    pub fn writes(&self) -> u32 {
        self.writes.get()
    }

    /// Block reads done so far.
    pub fn reads(&self) -> u32 {
        self.reads.get()
    }

    /// Replaces the card's contents (the rider formats it elsewhere and
    /// puts it back).
    pub fn set_image(&self, image: Vec<u8>) {
        *self.image.borrow_mut() = image;
    }

    /// A copy of the card's contents.
    pub fn image(&self) -> Vec<u8> {
        self.image.borrow().clone()
    }

    fn range(&self, start: BlockIdx, blocks: usize) -> Result<core::ops::Range<usize>, MockError> {
        if self.removed.get() {
            return Err(MockError::Removed);
        }
        let begin = start.0 as usize * Block::LEN;
        let end = begin + blocks * Block::LEN;
        if end > self.image.borrow().len() {
            return Err(MockError::OutOfRange);
        }
        Ok(begin..end)
    }
}

impl BlockDevice for MockCard {
    type Error = MockError;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), MockError> {
        if self.fuel.get() == Some(0) {
            return Err(MockError::PowerCut);
        }
        let range = self.range(start, blocks.len())?;
        let bad = self.unreadable.get().map(|b| b as usize * Block::LEN);
        if bad.is_some_and(|b| range.contains(&b)) {
            return Err(MockError::ReadFailed);
        }
        let image = self.image.borrow();
        for (block, src) in blocks.iter_mut().zip(image[range].chunks_exact(Block::LEN)) {
            block.contents.copy_from_slice(src);
            self.reads.set(self.reads.get() + 1);
        }
        Ok(())
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), MockError> {
        let range = self.range(start, blocks.len())?;
        let mut image = self.image.borrow_mut();
        for (block, dst) in blocks.iter().zip(image[range].chunks_exact_mut(Block::LEN)) {
            match self.fuel.get() {
                Some(0) => return Err(MockError::PowerCut),
                Some(n) => self.fuel.set(Some(n - 1)),
                None => {}
            }
            dst.copy_from_slice(&block.contents);
            self.writes.set(self.writes.get() + 1);
            self.stalled_ms
                .set(self.stalled_ms.get() + u64::from(self.stall_every_write_ms.get()));
        }
        Ok(())
    }

    fn num_blocks(&self) -> Result<BlockCount, MockError> {
        if self.removed.get() {
            return Err(MockError::Removed);
        }
        let blocks = self.image.borrow().len() / Block::LEN;
        Ok(BlockCount(u32::try_from(blocks).unwrap_or(u32::MAX)))
    }
}
