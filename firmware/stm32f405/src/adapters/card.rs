//! The microSD card on SPI2, blocking, as the core's [`Card`] block device.

use embassy_stm32::gpio::Output;
use embassy_stm32::mode::Blocking;
use embassy_stm32::spi::{self, mode::Master, Spi};
use embassy_stm32::time::Hertz;
use embassy_time::Delay;
use embedded_hal_bus::spi::ExclusiveDevice;
use wobble_core::drivers::sdcard::{wake_up, Card, IDENTIFICATION_CLOCK_HZ};

use crate::clocks::CARD_SPI_HZ;

/// The card's SPI device: SPI2 with its chip select.
pub type CardSpi = ExclusiveDevice<Spi<'static, Blocking, Master>, Output<'static>, Delay>;
/// The card as the logger's block device.
pub type SdCard = Card<CardSpi, Delay>;

/// SPI mode 0 at `hz` (rounded down by the prescaler).
pub fn spi_config(hz: u32) -> spi::Config {
    let mut config = spi::Config::default();
    config.frequency = Hertz(hz);
    // MISO floats while no card drives it: read 0xFF, "nothing".
    config.miso_pull = embassy_stm32::gpio::Pull::Up;
    config
}

fn set_clock(device: &mut CardSpi, hz: u32) {
    device
        .bus_mut()
        .set_config(&spi_config(hz))
        .unwrap_or_else(|()| {
            defmt::warn!("card SPI: clock {} Hz refused", hz);
        });
}

/// Wakes the card (clocks with chip select high) and wraps it.
pub fn card(mut bus: Spi<'static, Blocking, Master>, mut cs: Output<'static>) -> SdCard {
    bus.set_config(&spi_config(IDENTIFICATION_CLOCK_HZ))
        .unwrap_or_else(|()| defmt::warn!("card SPI: slow clock refused"));
    cs.set_high();
    if wake_up(&mut bus).is_err() {
        defmt::warn!("card SPI: wake-up clocks failed");
    }
    let device = ExclusiveDevice::new(bus, cs, Delay).unwrap_or_else(|e| match e {});
    Card::new(device, Delay, set_clock, CARD_SPI_HZ)
}
