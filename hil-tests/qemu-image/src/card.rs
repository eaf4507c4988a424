//! The SD card: a FAT32 image file on the host, reached through ARM
//! semihosting, taking the virtual time a card on the board's bus takes
//! (`sd_timing.rs`), with the scenario's faults injected on the way.

use core::cell::{Cell, RefCell};

use embassy_time::{Duration, Instant};
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx};
use semihosting::fs::File;
use semihosting::io::{Read, Seek, SeekFrom, Write};

use crate::report;
use crate::scenario::{within, Scenario};
use crate::sd_timing::{busy_until, CutPoint, SdTiming};

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
    timing: SdTiming,
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
            timing: SdTiming::new(scenario.card_seed),
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

    /// Writes one block as a card does: the transfer, then the busy time
    /// (the model's, plus a scenario stall: thread mode waits, as the
    /// board's writer holding the bus does, while the sampler and the GPS
    /// task keep preempting). A power cut before the block ends the run
    /// here; one inside it leaves the block torn.
    fn write_one(&self, file: &mut File, block: &Block) -> Result<(), CardError> {
        let n = self.writes.get() + 1;
        self.writes.set(n);
        if self.scenario.cut_at_write == Some(n) {
            report::power_cut(n, 0);
        }
        let (transfer, mut busy) = self.timing.write();
        if let Some(&(_, ms)) = self.scenario.stalls.iter().find(|(w, _)| *w == n) {
            report::stall(n, ms);
            busy += Duration::from_millis(u64::from(ms));
        }
        let start = Instant::now();
        if let Some((_, permille)) = self.scenario.cut_in_write.filter(|(w, _)| *w == n) {
            let cut = CutPoint::new(transfer, busy, permille);
            busy_until(start + cut.after);
            // The cells programmed before the cut hold the new bytes, the
            // rest the old ones: the block reads back torn.
            let torn = cut.programmed_bytes(Block::LEN);
            if torn > 0 {
                let _ = file.write_all(&block.contents[..torn]);
            }
            report::power_cut(n, torn)
        }
        busy_until(start + transfer + busy);
        file.write_all(&block.contents).map_err(|_| CardError::Io)
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
            busy_until(Instant::now() + self.timing.read());
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
            self.write_one(file, block)?;
        }
        Ok(())
    }

    fn num_blocks(&self) -> Result<BlockCount, CardError> {
        self.present()?;
        Ok(BlockCount(self.blocks))
    }
}
