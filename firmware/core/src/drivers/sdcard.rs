//! The SD card on SPI: embedded-sdmmc's [`SdCard`] with this logger's
//! acquisition options, chip select held for each card operation
//! ([`super::sd_spi`]), and identification again after any error.
//!
//! Acquisition blocks the thread-mode executor, so its worst case matters
//! more than its patience: a card that never answers costs, per attempt, one
//! CMD0 polled 10 001 times plus 255 flush bytes (about 0.36 s at the
//! 400 kHz identification clock, with embedded-sdmmc's 10 µs poll delay).
//! Two attempts bound a missing card to about 0.7 s; the logger retries on
//! its own schedule anyway, so nothing is lost by giving up early.
//!
//! embedded-sdmmc identifies a card once and then trusts it. A card pulled
//! and pushed back (or swapped) must be identified again, after the wake-up
//! clocks and at the slow clock: [`Card`] forgets the card after any error
//! and does both before the next access. A card whose blocks keep failing
//! their CRC, read or written (long wires, a marginal socket), runs at half
//! the clock after [`CRC_ERRORS_BEFORE_SLOWING`] in a row, down to
//! [`MIN_DATA_CLOCK_HZ`].

use core::cell::Cell;

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::OutputPin;
use embedded_hal::spi::{SpiBus, SpiDevice};
use embedded_sdmmc::sdcard::spi::AcquireOpts;
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx, SdCard, SdCardError};

use super::sd_spi::{Clock, OperationSpi};

/// Acquisition attempts after the first before the card counts as absent.
pub const ACQUIRE_RETRIES: u32 = 1;

/// Highest SPI clock while the card is identified (SD physical layer spec).
pub const IDENTIFICATION_CLOCK_HZ: u32 = 400_000;

/// CRC failures in a row after which the data clock is halved.
pub const CRC_ERRORS_BEFORE_SLOWING: u32 = 3;
/// The data clock is never lowered below this (8 × the identification
/// clock: a 512-byte block still moves in under 2 ms).
pub const MIN_DATA_CLOCK_HZ: u32 = 2_600_000;

/// The card driver with CRC checking on and [`ACQUIRE_RETRIES`]. Nothing is
/// sent until the first block access (or `get_card_type`).
pub fn sd_card<S: SpiDevice, D: DelayNs>(spi: S, delay: D) -> SdCard<S, D> {
    SdCard::new_with_options(
        spi,
        delay,
        AcquireOpts {
            use_crc: true,
            acquire_retries: ACQUIRE_RETRIES,
        },
    )
}

/// What the board supplies besides the bus.
pub struct CardHooks<B> {
    /// Sets the bus clock, Hz (rounded down by the board).
    pub set_clock: fn(&mut B, u32),
    /// µs since boot: times each operation's budget.
    pub now_us: Clock,
    /// Called after every card operation, whatever its result: the writer
    /// is alive (the watchdog's proof of progress between operations).
    pub after_operation: fn(),
}

/// The card as a [`BlockDevice`] that survives removal (see the module
/// docs).
pub struct Card<B: SpiBus, CS: OutputPin, D: DelayNs> {
    card: SdCard<OperationSpi<B, CS>, D>,
    hooks: CardHooks<B>,
    data_clock_hz: Cell<u32>,
    crc_errors_in_row: Cell<u32>,
    identified: Cell<bool>,
}

impl<B: SpiBus, CS: OutputPin, D: DelayNs> Card<B, CS, D> {
    /// The card on `bus` with chip select `cs`, run at `data_clock_hz` once
    /// identified.
    pub fn new(bus: B, cs: CS, delay: D, hooks: CardHooks<B>, data_clock_hz: u32) -> Self {
        Self {
            card: sd_card(OperationSpi::new(bus, cs, hooks.now_us), delay),
            hooks,
            data_clock_hz: Cell::new(data_clock_hz),
            crc_errors_in_row: Cell::new(0),
            identified: Cell::new(false),
        }
    }

    /// The data clock in force, Hz (lower after repeated CRC errors).
    pub fn data_clock_hz(&self) -> u32 {
        self.data_clock_hz.get()
    }

    fn set_clock(&self, hz: u32) {
        self.card.spi(|s| (self.hooks.set_clock)(s.bus_mut(), hz));
    }

    fn identify(&self) -> Result<(), SdCardError> {
        if self.identified.get() {
            return Ok(());
        }
        self.card.mark_card_uninit();
        self.set_clock(IDENTIFICATION_CLOCK_HZ);
        self.card
            .spi(OperationSpi::wake_up)
            .map_err(|_| SdCardError::Transport)?;
        // Reading the size identifies the card and proves it answers.
        self.operation(|card| card.num_blocks())?;
        self.set_clock(self.data_clock_hz.get());
        self.identified.set(true);
        Ok(())
    }

    /// Runs `op` with the card selected throughout, then settles its result.
    fn operation<T>(
        &self,
        op: impl FnOnce(&SdCard<OperationSpi<B, CS>, D>) -> Result<T, SdCardError>,
    ) -> Result<T, SdCardError> {
        let result = self
            .card
            .spi(OperationSpi::begin)
            .map_err(|_| SdCardError::Transport)
            .and_then(|()| op(&self.card));
        let ended = self.card.spi(OperationSpi::end);
        (self.hooks.after_operation)();
        self.settle(result.and_then(|v| ended.map(|()| v).map_err(|_| SdCardError::Transport)))
    }

    /// Passes `result` on; after an error the card is identified again
    /// before the next access, and CRC failures are counted.
    fn settle<T>(&self, result: Result<T, SdCardError>) -> Result<T, SdCardError> {
        if let Err(e) = &result {
            self.identified.set(false);
            // embedded-sdmmc 0.10 reports a written block's rejected CRC
            // (data response 0x0B) as a write error: the line is as bad
            // going out as a read CRC mismatch shows it coming in.
            if matches!(e, SdCardError::CrcError(..) | SdCardError::WriteError) {
                self.count_crc_error();
            }
        }
        result
    }

    /// A block transfer: only its success ends a run of CRC errors (the
    /// identification between two failed transfers succeeds either way).
    fn transfer(
        &self,
        op: impl FnOnce(&SdCard<OperationSpi<B, CS>, D>) -> Result<(), SdCardError>,
    ) -> Result<(), SdCardError> {
        self.identify()?;
        let result = self.operation(op);
        if result.is_ok() {
            self.crc_errors_in_row.set(0);
        }
        result
    }

    fn count_crc_error(&self) {
        let n = self.crc_errors_in_row.get() + 1;
        if n < CRC_ERRORS_BEFORE_SLOWING {
            self.crc_errors_in_row.set(n);
            return;
        }
        self.crc_errors_in_row.set(0);
        let slower = (self.data_clock_hz.get() / 2).max(MIN_DATA_CLOCK_HZ);
        self.data_clock_hz.set(slower);
    }
}

impl<B: SpiBus, CS: OutputPin, D: DelayNs> BlockDevice for Card<B, CS, D> {
    type Error = SdCardError;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), Self::Error> {
        self.transfer(|card| card.read(blocks, start))
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), Self::Error> {
        self.transfer(|card| card.write(blocks, start))
    }

    fn num_blocks(&self) -> Result<BlockCount, Self::Error> {
        self.identify()?;
        self.operation(|card| card.num_blocks())
    }
}
