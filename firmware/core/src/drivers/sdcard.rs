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
//! [`MIN_DATA_CLOCK_HZ`]. Only a CRC failure counts ([`classify`]): a
//! pulled card's write error (its data response reads 0xFF) does not. The
//! clock goes back up: doubled (to the nominal clock at most) after
//! [`CLEAN_TRANSFERS_BEFORE_RAISING`] block transfers in a row without an
//! error, and straight to the nominal clock when a card that was gone is
//! identified again (another card, or the same one seated anew).

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

/// Error-free block transfers in a row after which a lowered data clock is
/// doubled (at 100 blocks a second of logging: about 10 s).
pub const CLEAN_TRANSFERS_BEFORE_RAISING: u32 = 1000;

/// Mask of the status bits of a data response token (SD spec 7.3.3.1).
const DATA_RESPONSE_MASK: u8 = 0x1F;
/// Data response token: the data was rejected for a CRC error.
const DATA_RESPONSE_CRC_ERROR: u8 = 0x0B;

/// What a card error says about the card and its line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ErrorClass {
    /// The signal was corrupted: a read block's CRC mismatch, or a written
    /// block the card rejected for its CRC.
    Crc,
    /// Nobody answered: the bus read idle-high (a missing card pulled up),
    /// a command or a data token never came.
    Gone,
    /// Anything else (the card refused a command, a bus or timing fault).
    Other,
}

/// Classifies `error`; `last_byte` is the last byte received in the failed
/// operation. embedded-sdmmc 0.10 reports every data response but
/// "accepted" as the same [`SdCardError::WriteError`]: the token itself
/// (0x0B a CRC error; 0xFF nothing on the line) tells them apart.
pub fn classify(error: &SdCardError, last_byte: Option<u8>) -> ErrorClass {
    match error {
        SdCardError::CrcError(..) => ErrorClass::Crc,
        SdCardError::WriteError => match last_byte {
            Some(0xFF) => ErrorClass::Gone,
            Some(b) if b & DATA_RESPONSE_MASK == DATA_RESPONSE_CRC_ERROR => ErrorClass::Crc,
            _ => ErrorClass::Other,
        },
        SdCardError::CardNotFound
        | SdCardError::TimeoutCommand(_)
        | SdCardError::TimeoutACommand(_)
        | SdCardError::TimeoutReadBuffer => ErrorClass::Gone,
        _ => ErrorClass::Other,
    }
}

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
    nominal_clock_hz: u32,
    data_clock_hz: Cell<u32>,
    crc_errors_in_row: Cell<u32>,
    clean_transfers: Cell<u32>,
    identified: Cell<bool>,
    /// The last error said the card was gone.
    gone: Cell<bool>,
}

impl<B: SpiBus, CS: OutputPin, D: DelayNs> Card<B, CS, D> {
    /// The card on `bus` with chip select `cs`, run at `data_clock_hz` once
    /// identified.
    pub fn new(bus: B, cs: CS, delay: D, hooks: CardHooks<B>, data_clock_hz: u32) -> Self {
        Self {
            card: sd_card(OperationSpi::new(bus, cs, hooks.now_us), delay),
            hooks,
            nominal_clock_hz: data_clock_hz,
            data_clock_hz: Cell::new(data_clock_hz),
            crc_errors_in_row: Cell::new(0),
            clean_transfers: Cell::new(0),
            identified: Cell::new(false),
            gone: Cell::new(false),
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
        if self.gone.replace(false) {
            // A card was pulled: this one starts afresh.
            self.data_clock_hz.set(self.nominal_clock_hz);
            self.crc_errors_in_row.set(0);
            self.clean_transfers.set(0);
        }
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
        let last_byte = self.card.spi(|s| s.last_byte());
        let ended = self.card.spi(OperationSpi::end);
        (self.hooks.after_operation)();
        self.settle(
            result.and_then(|v| ended.map(|()| v).map_err(|_| SdCardError::Transport)),
            last_byte,
        )
    }

    /// Passes `result` on; after an error the card is identified again
    /// before the next access, and CRC failures are counted ([`classify`]:
    /// a written block's rejected CRC as much as a read one's mismatch, a
    /// pulled card's silence not at all).
    fn settle<T>(
        &self,
        result: Result<T, SdCardError>,
        last_byte: Option<u8>,
    ) -> Result<T, SdCardError> {
        if let Err(e) = &result {
            self.identified.set(false);
            self.clean_transfers.set(0);
            match classify(e, last_byte) {
                ErrorClass::Crc => self.count_crc_error(),
                ErrorClass::Gone => self.gone.set(true),
                ErrorClass::Other => {}
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
            self.count_clean_transfer();
        }
        result
    }

    /// A lowered clock is doubled after enough clean transfers in a row.
    fn count_clean_transfer(&self) {
        let hz = self.data_clock_hz.get();
        if hz >= self.nominal_clock_hz {
            return;
        }
        let n = self.clean_transfers.get() + 1;
        if n < CLEAN_TRANSFERS_BEFORE_RAISING {
            self.clean_transfers.set(n);
            return;
        }
        self.clean_transfers.set(0);
        let faster = hz.saturating_mul(2).min(self.nominal_clock_hz);
        self.data_clock_hz.set(faster);
        self.set_clock(faster);
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
