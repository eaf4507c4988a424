//! The ICM-42688-P on SPI1 as the sampler's [`ImuPort`].

use embassy_stm32::gpio::Output;
use embassy_stm32::mode::Async;
use embassy_stm32::spi::{mode::Master, Spi};
use embassy_time::{Delay, Duration, Instant};
use embedded_hal_bus::spi::ExclusiveDevice;
use wobble_core::app::ports::{ImuPort, ImuSample, SensorError};
use wobble_core::drivers::icm42688::{Error, Icm42688};
use wobble_core::imu::Imu;

/// The sensor's SPI device: SPI1 with its chip select.
pub type ImuSpi = ExclusiveDevice<Spi<'static, Async, Master>, Output<'static>, Delay>;

/// A sensor that failed is set up again at most this often: its start-up
/// wait (45 ms) delays the sampler's tick once per attempt.
const RETRY: Duration = Duration::from_secs(1);

/// Driver plus the core's IMU channel (scaling, mounting, stuck check).
pub struct ImuAdapter {
    driver: Icm42688<ImuSpi>,
    channel: Imu,
    ready: bool,
    next_attempt: Instant,
}

impl ImuAdapter {
    /// Wraps a driver whose `init` has not run yet (the first read runs it).
    pub fn new(driver: Icm42688<ImuSpi>, channel: Imu) -> Self {
        Self {
            driver,
            channel,
            ready: false,
            next_attempt: Instant::MIN,
        }
    }

    async fn ensure_ready(&mut self) -> Result<(), SensorError> {
        if self.ready {
            return Ok(());
        }
        let now = Instant::now();
        if now < self.next_attempt {
            return Err(SensorError::NoResponse);
        }
        self.next_attempt = now + RETRY;
        match self.driver.init(&mut Delay).await {
            Ok(()) => {
                defmt::info!("IMU ready");
                self.ready = true;
                Ok(())
            }
            Err(e) => Err(self.failed(e)),
        }
    }

    /// The sensor's `WHO_AM_I` as read, `None` when the bus fails.
    pub async fn identity(&mut self) -> Option<u8> {
        self.driver.who_am_i().await.ok()
    }

    fn failed<E>(&mut self, e: Error<E>) -> SensorError {
        defmt::warn!("IMU: {}", e.sensor_error());
        self.ready = false;
        e.sensor_error()
    }
}

impl ImuPort for ImuAdapter {
    async fn read(&mut self) -> Result<ImuSample, SensorError> {
        self.ensure_ready().await?;
        let raw = match self.driver.read().await {
            Ok(raw) => raw,
            Err(e) => return Err(self.failed(e)),
        };
        self.channel.push(raw);
        let sample = self.channel.take().ok_or(SensorError::Stale)?;
        if sample.stuck {
            // Frozen output: the frame flags it; reset the sensor on the
            // next attempt.
            self.ready = false;
        }
        Ok(sample)
    }
}
