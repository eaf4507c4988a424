//! The microSD card on SPI2, blocking, as the core's [`Card`] block device:
//! chip select held for each card operation, wake-up clocks before each
//! identification, each operation bounded and followed by a watchdog
//! liveness proof (all in the core's `drivers::sd_spi` and
//! `drivers::sdcard`).

use embassy_stm32::gpio::Output;
use embassy_stm32::mode::Blocking;
use embassy_stm32::spi::{self, mode::Master, Spi};
use embassy_stm32::time::Hertz;
use embassy_time::{Delay, Instant};
use wobble_core::drivers::sdcard::{Card, CardHooks};

use crate::clocks::CARD_SPI_HZ;

/// The card's bus.
pub type CardBus = Spi<'static, Blocking, Master>;
/// The card as the logger's block device.
pub type SdCard = Card<CardBus, Output<'static>, Delay>;

/// SPI mode 0 at `hz` (rounded down by the prescaler).
pub fn spi_config(hz: u32) -> spi::Config {
    let mut config = spi::Config::default();
    config.frequency = Hertz(hz);
    // MISO floats while no card drives it: read 0xFF, "nothing".
    config.miso_pull = embassy_stm32::gpio::Pull::Up;
    config
}

fn set_clock(bus: &mut CardBus, hz: u32) {
    if bus.set_config(&spi_config(hz)).is_err() {
        defmt::warn!("card SPI: clock {} Hz refused", hz);
    } else if hz < CARD_SPI_HZ && hz > wobble_core::drivers::sdcard::IDENTIFICATION_CLOCK_HZ {
        // Lowered after repeated CRC errors, raised again step by step
        // after clean transfers (logged at each identification and change).
        defmt::warn!(
            "card SPI: data clock {} Hz (nominal {} Hz)",
            hz,
            CARD_SPI_HZ
        );
    }
}

fn now_us() -> u64 {
    Instant::now().as_micros()
}

/// Wraps the card (nothing is sent until the first access).
pub fn card(bus: CardBus, cs: Output<'static>) -> SdCard {
    let hooks = CardHooks {
        set_clock,
        now_us,
        after_operation: crate::watchdog::prove_alive,
    };
    Card::new(bus, cs, Delay, hooks, CARD_SPI_HZ)
}
