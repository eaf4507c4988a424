//! The SD card: a FAT32 image file on the host, reached through ARM
//! semihosting, with the scenario's faults injected on the way.

use core::cell::{Cell, RefCell};

use embassy_time::{Duration, Instant};
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};
use semihosting::fs::File;
use semihosting::io::{Read, Seek, SeekFrom, Write};

use crate::report;
use crate::scenario::{within, Scenario};

/// Why the emulated card refused an operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CardError {
    /// Not inserted (the scenario's absence window).
    Absent,
    /// The host file could not be read or written.
    Io,
}

impl core::fmt::Display for CardError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(match self {
            Self::Absent => "card absent",
            Self::Io => "image file I/O failed",
        })
    }
}

impl core::error::Error for CardError {}

/// The image file and the fault injection state.
pub struct SemihostingCard {
    file: RefCell<Option<File>>,
    blocks: u32,
    scenario: &'static Scenario,
    writes: Cell<u32>,
}

impl SemihostingCard {
    /// Opens `card.img` for reading and writing (absent if it cannot).
    pub fn open(scenario: &'static Scenario) -> Self {
        let file = File::options()
            .read(true)
            .write(true)
            .open(c"card.img")
            .ok();
        let blocks = file
            .as_ref()
            .and_then(|f| f.metadata().ok())
            .map_or(0, |m| {
                u32::try_from(m.len() / Block::LEN as u64).unwrap_or(u32::MAX)
            });
        Self {
            file: RefCell::new(file),
            blocks,
            scenario,
            writes: Cell::new(0),
        }
    }

    fn present(&self) -> Result<(), CardError> {
        let t_ms = Instant::now().as_millis();
        if within(self.scenario.card_absent_ms, t_ms) {
            return Err(CardError::Absent);
        }
        Ok(())
    }

    fn seek(file: &mut File, idx: BlockIdx) -> Result<(), CardError> {
        file.seek(SeekFrom::Start(idx.into_bytes()))
            .map_err(|_| CardError::Io)?;
        Ok(())
    }

    /// The scenario's injections for one block write: a power cut ends the
    /// run here; a stall busy-waits in thread mode, as a card holding the
    /// bus would, while the sampler keeps preempting.
    fn before_write(&self) {
        let n = self.writes.get() + 1;
        self.writes.set(n);
        if self.scenario.cut_at_write == Some(n) {
            report::power_cut(n);
        }
        if let Some(&(_, ms)) = self.scenario.stalls.iter().find(|(w, _)| *w == n) {
            let until = Instant::now() + Duration::from_millis(u64::from(ms));
            report::stall(n, ms);
            while Instant::now() < until {}
        }
    }
}

impl BlockDevice for SemihostingCard {
    type Error = CardError;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), CardError> {
        self.present()?;
        let mut file = self.file.borrow_mut();
        let file = file.as_mut().ok_or(CardError::Absent)?;
        Self::seek(file, start)?;
        for block in blocks {
            file.read_exact(&mut block.contents)
                .map_err(|_| CardError::Io)?;
        }
        Ok(())
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), CardError> {
        self.present()?;
        let mut file = self.file.borrow_mut();
        let file = file.as_mut().ok_or(CardError::Absent)?;
        Self::seek(file, start)?;
        for block in blocks {
            self.before_write();
            file.write_all(&block.contents).map_err(|_| CardError::Io)?;
        }
        Ok(())
    }

    fn num_blocks(&self) -> Result<BlockCount, CardError> {
        self.present()?;
        Ok(BlockCount(self.blocks))
    }
}
