//! The ICM-42688-P on SPI1 as the sampler's `ImuPort`: the core's
//! [`Icm42688Port`] (driver, FIFO, sample clock, recovery) on the board's
//! bus, with its data-ready pulses timed by TIM5 channel 2
//! ([`DataReadyAdapter`]).

use embassy_stm32::gpio::{Level, Output, Speed};
use embassy_stm32::mode::Async;
use embassy_stm32::spi::{mode::Master, Spi};
use embassy_stm32::time::Hertz;
use embassy_time::Delay;
use embedded_hal_bus::spi::ExclusiveDevice;
use static_cell::StaticCell;
use wobble_core::app::imu_port::Icm42688Port;
use wobble_core::drivers::icm42688::{self, Icm42688};
use wobble_core::imu::{Imu, ImuConfig};
use wobble_core::imu_clock::SampleClock;

pub use super::wheel::DataReadyAdapter;
use crate::clocks;
use crate::pins::{ImuPins, Irqs};

/// The sensor's SPI device: SPI1 with its chip select.
pub type ImuSpi = ExclusiveDevice<Spi<'static, Async, Master>, Output<'static>, Delay>;

/// The IMU port of the board.
pub type ImuAdapter = Icm42688Port<ImuSpi, Delay, DataReadyAdapter, &'static mut SampleClock>;

/// The port's sample clock (1 KiB): in a static, not in the futures of the
/// sampler or self-test task, which hold the port more than once.
static CLOCK: StaticCell<SampleClock> = StaticCell::new();

/// The board's IMU port on SPI1, timed by the sensor's data-ready pulses
/// (TIM5 channel 2, started by `wheel::start`), with the mounting and
/// checks of `config`. Once per boot: the sample clock is a static, and a
/// second call panics.
pub fn port(pins: ImuPins, config: ImuConfig) -> ImuAdapter {
    let mut spi_config = embassy_stm32::spi::Config::default();
    spi_config.frequency = Hertz(clocks::IMU_SPI_HZ);
    let bus = Spi::new(
        pins.spi,
        pins.sck,
        pins.mosi,
        pins.miso,
        pins.tx_dma,
        pins.rx_dma,
        Irqs,
        spi_config,
    );
    let cs = Output::new(pins.cs, Level::High, Speed::VeryHigh);
    let device = ExclusiveDevice::new(bus, cs, Delay).unwrap_or_else(|e| match e {});
    let driver_config = icm42688::Config::default();
    // `Config::parse` only lets through what the core's modules accept.
    let channel = defmt::unwrap!(Imu::try_new(driver_config.imu_config(config)).ok());
    let clock = CLOCK.init(SampleClock::new());
    Icm42688Port::with_clock(
        Icm42688::new(device, driver_config),
        channel,
        Delay,
        DataReadyAdapter::default(),
        clock,
    )
}
