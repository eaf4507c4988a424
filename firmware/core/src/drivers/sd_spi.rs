//! The SD card's SPI device, with chip select held low for a whole card
//! operation.
//!
//! embedded-sdmmc 0.10 talks to the card one byte at a time, each byte its
//! own `SpiDevice` transaction: over an ordinary device (embedded-hal-bus's
//! `ExclusiveDevice`) chip select rises between a command, its response
//! polls and its data block. The SD specification keeps CS low from a
//! command to the end of its response and data; some cards (Samsung EVO
//! among them) abort otherwise. [`OperationSpi`] holds CS low from
//! [`OperationSpi::begin`] to [`OperationSpi::end`], which the card wrapper
//! ([`super::sdcard::Card`]) calls around each block operation, and passes
//! the driver's transactions straight to the bus in between.
//!
//! It also bounds each operation: embedded-sdmmc's busy waits are retry
//! loops (up to 50 000 polls for a write, 10 000 per command, with loops
//! around them during acquisition), which a damaged card can stretch to
//! minutes. After [`CARD_OPERATION_BUDGET_US`] every transfer fails, so the
//! driver returns an error at its next byte and the logger's retry takes
//! over; the watchdog's timeout is sized on this bound.

use embedded_hal::digital::OutputPin;
use embedded_hal::spi::{ErrorKind, ErrorType, Operation, SpiBus, SpiDevice};

/// Longest card operation allowed, µs: a block write may keep the card busy
/// for 500 ms (SDXC; 250 ms SDHC), an identification 1 s (ACMD41).
pub const CARD_OPERATION_BUDGET_US: u64 = 1_500_000;

/// Bytes of 0xFF with CS high that wake a card: at least 74 clocks (SD
/// physical layer spec 6.4.1.1).
pub const WAKE_UP_BYTES: usize = 10;
const _: () = assert!(WAKE_UP_BYTES * 8 >= 74);

/// What went wrong.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum Error<B> {
    /// The bus failed.
    Bus(B),
    /// The chip-select pin could not be driven.
    ChipSelect,
    /// The operation ran past [`CARD_OPERATION_BUDGET_US`].
    Overtime,
    /// A delay inside a transaction, which the card driver never asks for.
    Unsupported,
}

impl<B: embedded_hal::spi::Error> embedded_hal::spi::Error for Error<B> {
    fn kind(&self) -> ErrorKind {
        match self {
            Self::Bus(e) => e.kind(),
            Self::ChipSelect => ErrorKind::ChipSelectFault,
            Self::Overtime | Self::Unsupported => ErrorKind::Other,
        }
    }
}

/// Microseconds since boot, from the board's clock.
pub type Clock = fn() -> u64;

/// The card's bus and chip select (see the module docs).
pub struct OperationSpi<B, CS> {
    bus: B,
    cs: CS,
    clock: Clock,
    /// While an operation runs: when its budget ends.
    deadline_us: Option<u64>,
    /// The last single byte received in the current (or last) operation:
    /// after a failed write, the card's data response token.
    last_byte: Option<u8>,
}

impl<B: SpiBus, CS: OutputPin> OperationSpi<B, CS> {
    /// The device on `bus` with chip select `cs` (driven high by the caller
    /// until the first operation), timed by `clock`.
    pub const fn new(bus: B, cs: CS, clock: Clock) -> Self {
        Self {
            bus,
            cs,
            clock,
            deadline_us: None,
            last_byte: None,
        }
    }

    /// The bus, to change its clock between operations.
    pub fn bus_mut(&mut self) -> &mut B {
        &mut self.bus
    }

    /// Selects the card until [`Self::end`] and starts the budget.
    ///
    /// # Errors
    /// [`Error::ChipSelect`].
    pub fn begin(&mut self) -> Result<(), Error<B::Error>> {
        self.last_byte = None;
        self.deadline_us = Some((self.clock)().saturating_add(CARD_OPERATION_BUDGET_US));
        self.cs.set_low().map_err(|_| Error::ChipSelect)
    }

    /// The last single byte received since [`Self::begin`] (embedded-sdmmc
    /// reads each response and token one byte at a time), if any.
    pub fn last_byte(&self) -> Option<u8> {
        self.last_byte
    }

    /// Deselects the card, then clocks one byte so that it releases MISO
    /// (SD spec 7.2: the card drives DO until the next clock edge).
    ///
    /// # Errors
    /// The bus's error or [`Error::ChipSelect`]; CS is raised in any case.
    pub fn end(&mut self) -> Result<(), Error<B::Error>> {
        self.deadline_us = None;
        let flushed = self.bus.flush().map_err(Error::Bus);
        self.cs.set_high().map_err(|_| Error::ChipSelect)?;
        flushed?;
        self.bus.write(&[0xFF]).map_err(Error::Bus)?;
        self.bus.flush().map_err(Error::Bus)
    }

    /// [`WAKE_UP_BYTES`] of 0xFF with the card deselected: before every
    /// identification, since a card pushed back in needs them as much as
    /// one at power-up.
    ///
    /// # Errors
    /// The bus's error or [`Error::ChipSelect`].
    pub fn wake_up(&mut self) -> Result<(), Error<B::Error>> {
        self.deadline_us = None;
        self.cs.set_high().map_err(|_| Error::ChipSelect)?;
        self.bus.write(&[0xFF; WAKE_UP_BYTES]).map_err(Error::Bus)?;
        self.bus.flush().map_err(Error::Bus)
    }

    fn run(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Error<B::Error>> {
        for op in operations {
            match op {
                Operation::Read(buf) => self.bus.read(buf),
                Operation::Write(buf) => self.bus.write(buf),
                Operation::Transfer(read, write) => self.bus.transfer(read, write),
                Operation::TransferInPlace(buf) => self.bus.transfer_in_place(buf),
                Operation::DelayNs(_) => return Err(Error::Unsupported),
            }
            .map_err(Error::Bus)?;
            match op {
                Operation::Read(buf) | Operation::TransferInPlace(buf) if buf.len() == 1 => {
                    self.last_byte = Some(buf[0]);
                }
                Operation::Transfer(read, _) if read.len() == 1 => {
                    self.last_byte = Some(read[0]);
                }
                _ => {}
            }
        }
        Ok(())
    }
}

impl<B: SpiBus, CS: OutputPin> ErrorType for OperationSpi<B, CS> {
    type Error = Error<B::Error>;
}

impl<B: SpiBus, CS: OutputPin> SpiDevice for OperationSpi<B, CS> {
    fn transaction(&mut self, operations: &mut [Operation<'_, u8>]) -> Result<(), Self::Error> {
        match self.deadline_us {
            Some(deadline) if (self.clock)() > deadline => Err(Error::Overtime),
            Some(_) => self.run(operations),
            // Outside an operation: an ordinary device, CS around the
            // transaction.
            None => {
                self.cs.set_low().map_err(|_| Error::ChipSelect)?;
                let result = self.run(operations);
                let flushed = self.bus.flush().map_err(Error::Bus);
                self.cs.set_high().map_err(|_| Error::ChipSelect)?;
                result.and(flushed)
            }
        }
    }
}
