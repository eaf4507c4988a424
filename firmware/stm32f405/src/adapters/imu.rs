//! The ICM-42688-P on SPI1 as the sampler's `ImuPort`: the core's
//! [`Icm42688Port`] (driver, FIFO, sample clock, recovery) on the board's
//! bus, with its data-ready pulses timed by TIM5 channel 2
//! ([`DataReadyAdapter`]).

use embassy_stm32::gpio::Output;
use embassy_stm32::mode::Async;
use embassy_stm32::spi::{mode::Master, Spi};
use embassy_time::Delay;
use embedded_hal_bus::spi::ExclusiveDevice;
use wobble_core::app::imu_port::Icm42688Port;

pub use super::wheel::DataReadyAdapter;

/// The sensor's SPI device: SPI1 with its chip select.
pub type ImuSpi = ExclusiveDevice<Spi<'static, Async, Master>, Output<'static>, Delay>;

/// The IMU port of the board.
pub type ImuAdapter = Icm42688Port<ImuSpi, Delay, DataReadyAdapter>;
