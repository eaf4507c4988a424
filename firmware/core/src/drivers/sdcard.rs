//! The SD card on SPI: embedded-sdmmc's [`SdCard`] with this logger's
//! acquisition options, and the wake-up clocks the card needs first.
//!
//! Acquisition blocks the thread-mode executor, so its worst case matters
//! more than its patience: a card that never answers costs, per attempt, one
//! CMD0 polled 10 001 times plus 255 flush bytes (about 0.36 s at the
//! 400 kHz identification clock, with embedded-sdmmc's 10 µs poll delay).
//! Two attempts bound a missing card to about 0.7 s; the logger retries on
//! its own schedule anyway, so nothing is lost by giving up early.
//!
//! embedded-sdmmc identifies a card once and then trusts it. A card pulled
//! and pushed back (or swapped) must be identified again, at the slow
//! clock: [`Card`] forgets the card after any error and does that before
//! the next access.

use embedded_hal::delay::DelayNs;
use embedded_hal::spi::{SpiBus, SpiDevice};
use embedded_sdmmc::sdcard::spi::AcquireOpts;
use embedded_sdmmc::{Block, BlockCount, BlockDevice, BlockIdx, SdCard, SdCardError};

use core::cell::Cell;

/// Acquisition attempts after the first before the card counts as absent.
pub const ACQUIRE_RETRIES: u32 = 1;

/// Highest SPI clock while the card is identified (SD physical layer spec).
pub const IDENTIFICATION_CLOCK_HZ: u32 = 400_000;

/// Bytes of 0xFF sent with the chip select released before the first
/// command: at least 74 clock cycles (SD spec 6.4.1.1) make 10 bytes.
pub const WAKE_UP_BYTES: usize = 10;
const _: () = assert!(WAKE_UP_BYTES * 8 >= 74);

/// Clocks the card into its native mode: [`WAKE_UP_BYTES`] of 0xFF on the
/// raw bus, with the card's chip select released by the caller.
///
/// # Errors
/// The bus's error.
pub fn wake_up<B: SpiBus>(bus: &mut B) -> Result<(), B::Error> {
    bus.write(&[0xFF; WAKE_UP_BYTES])?;
    bus.flush()
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

/// Sets the SPI clock of the card's device, Hz (rounded down by the board).
pub type SetClock<S> = fn(&mut S, u32);

/// The card as a [`BlockDevice`] that survives removal: identified at
/// [`IDENTIFICATION_CLOCK_HZ`] before first use and after any error, then
/// run at the board's data clock.
pub struct Card<S: SpiDevice, D: DelayNs> {
    card: SdCard<S, D>,
    set_clock: SetClock<S>,
    data_clock_hz: u32,
    identified: Cell<bool>,
}

impl<S: SpiDevice, D: DelayNs> Card<S, D> {
    /// The card on `spi`; `set_clock` switches the device's clock.
    pub fn new(spi: S, delay: D, set_clock: SetClock<S>, data_clock_hz: u32) -> Self {
        Self {
            card: sd_card(spi, delay),
            set_clock,
            data_clock_hz,
            identified: Cell::new(false),
        }
    }

    fn identify(&self) -> Result<(), SdCardError> {
        if self.identified.get() {
            return Ok(());
        }
        self.card.mark_card_uninit();
        self.card
            .spi(|s| (self.set_clock)(s, IDENTIFICATION_CLOCK_HZ));
        // Reading the size identifies the card and proves it answers.
        let size = self.card.num_blocks();
        self.settle(size)?;
        self.card.spi(|s| (self.set_clock)(s, self.data_clock_hz));
        self.identified.set(true);
        Ok(())
    }

    /// Passes `result` on; after an error the card is identified again
    /// before the next access.
    fn settle<T>(&self, result: Result<T, SdCardError>) -> Result<T, SdCardError> {
        if result.is_err() {
            self.identified.set(false);
        }
        result
    }
}

impl<S: SpiDevice, D: DelayNs> BlockDevice for Card<S, D> {
    type Error = SdCardError;

    fn read(&self, blocks: &mut [Block], start: BlockIdx) -> Result<(), Self::Error> {
        self.identify()?;
        self.settle(self.card.read(blocks, start))
    }

    fn write(&self, blocks: &[Block], start: BlockIdx) -> Result<(), Self::Error> {
        self.identify()?;
        self.settle(self.card.write(blocks, start))
    }

    fn num_blocks(&self) -> Result<BlockCount, Self::Error> {
        self.identify()?;
        self.settle(self.card.num_blocks())
    }
}
