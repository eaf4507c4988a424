//! A failing SPI bus comes back as `Error::Comm` wrapping the bus's error.

use embassy_futures::block_on;
use embedded_hal::spi::{ErrorKind, ErrorType};
use embedded_hal_async::spi::{Operation, SpiDevice};
use embedded_hal_mock::eh1::delay::NoopDelay;
use wobble_core::app::ports::SensorError;
use wobble_core::drivers::icm42688::{Config, Error, Icm42688};

/// A bus whose every transfer fails, counting the attempts.
struct BrokenBus {
    attempts: usize,
}

impl ErrorType for BrokenBus {
    type Error = ErrorKind;
}

impl SpiDevice for BrokenBus {
    async fn transaction(&mut self, _: &mut [Operation<'_, u8>]) -> Result<(), ErrorKind> {
        self.attempts += 1;
        Err(ErrorKind::ModeFault)
    }
}

#[test]
fn bus_errors_are_wrapped_and_stop_the_sequence() {
    let mut imu = Icm42688::new(BrokenBus { attempts: 0 }, Config::default());
    let err = block_on(imu.init(&mut NoopDelay::new())).expect_err("bus");
    assert_eq!(err, Error::Comm(ErrorKind::ModeFault));
    assert_eq!(err.sensor_error(), SensorError::NoResponse);
    assert_eq!(block_on(imu.read()), Err(Error::Comm(ErrorKind::ModeFault)));
    assert_eq!(imu.release().attempts, 2);
}
