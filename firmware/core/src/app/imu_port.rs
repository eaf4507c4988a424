//! The ICM-42688-P as the sampler's [`ImuPort`]: the driver plus the core's
//! IMU channel (scaling, mounting, stuck check), with the recovery policy
//! the board and the QEMU image share. A sensor that fails or freezes is
//! set up again, at most once per [`RETRY`]: each attempt's start-up wait
//! (45 ms) delays one sampler tick.

use embassy_time::{Duration, Instant};
use embedded_hal_async::delay::DelayNs;
use embedded_hal_async::spi::SpiDevice;

use super::ports::{ImuPort, ImuSample, SensorError};
use crate::drivers::icm42688::{Error, Icm42688};
use crate::imu::Imu;

/// Shortest time between two set-up attempts of a failed sensor.
pub const RETRY: Duration = Duration::from_secs(1);

/// Driver, channel and recovery state.
pub struct Icm42688Port<SPI, D> {
    driver: Icm42688<SPI>,
    channel: Imu,
    delay: D,
    ready: bool,
    next_attempt: Instant,
}

impl<SPI: SpiDevice, D: DelayNs> Icm42688Port<SPI, D> {
    /// Wraps a driver whose `init` has not run yet (the first read runs it);
    /// `delay` times its waits.
    pub fn new(driver: Icm42688<SPI>, channel: Imu, delay: D) -> Self {
        Self {
            driver,
            channel,
            delay,
            ready: false,
            next_attempt: Instant::MIN,
        }
    }

    /// Sets the sensor up before sampling starts, so that its start-up
    /// wait delays no tick; a failure is left to the reads' retries.
    pub async fn start(&mut self) {
        let _ = self.ensure_ready().await;
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
        match self.driver.init(&mut self.delay).await {
            Ok(()) => {
                #[cfg(feature = "defmt")]
                defmt::info!("IMU ready");
                self.ready = true;
                Ok(())
            }
            Err(e) => Err(self.failed(&e)),
        }
    }

    /// The sensor's `WHO_AM_I` as read, `None` when the bus fails (the
    /// self-test's report).
    pub async fn identity(&mut self) -> Option<u8> {
        self.driver.who_am_i().await.ok()
    }

    fn failed<E>(&mut self, e: &Error<E>) -> SensorError {
        #[cfg(feature = "defmt")]
        defmt::warn!("IMU: {}", e.sensor_error());
        self.ready = false;
        e.sensor_error()
    }
}

impl<SPI: SpiDevice, D: DelayNs> ImuPort for Icm42688Port<SPI, D> {
    async fn read(&mut self) -> Result<ImuSample, SensorError> {
        self.ensure_ready().await?;
        let raw = match self.driver.read().await {
            Ok(raw) => raw,
            Err(e) => return Err(self.failed(&e)),
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
