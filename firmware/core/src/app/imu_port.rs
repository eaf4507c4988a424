//! The ICM-42688-P as the sampler's [`ImuPort`]: the driver plus the core's
//! IMU channel (scaling, mounting, stuck check), with the recovery policy
//! the board and the QEMU image share. A sensor that fails or freezes is
//! set up again, at most once per [`RETRY`]: each attempt's start-up wait
//! (45 ms) delays one sampler tick.
//!
//! With the sensor's data-ready line timed by the hardware
//! ([`DataReadyPort::WIRED`], the board), every sample is read from the
//! sensor's FIFO and placed on the MCU clock by [`SampleClock`]: each frame
//! gets the sensor's output exactly [`crate::imu_clock::AGE_US`] before its
//! tick, and samples that reach no frame are counted. Without it (the QEMU
//! machine), the newest sample is read once per frame, 0-10 ms old.

use core::borrow::BorrowMut;

use embassy_time::{Duration, Instant};
use embedded_hal_async::delay::DelayNs;
use embedded_hal_async::spi::SpiDevice;

use super::ports::{DataReadyPort, ImuPort, ImuSample, NoDataReady, SensorError};
use crate::drivers::icm42688::{Error, Icm42688};
use crate::imu::Imu;
use crate::imu_clock::{self, ClockStats, SampleClock};

/// Shortest time between two set-up attempts of a failed sensor.
pub const RETRY: Duration = Duration::from_secs(1);

/// Driver, channel, data-ready line and recovery state.
///
/// The sample clock (`C`, about 1 KiB) is owned by default; the board
/// lends it a `&'static mut SampleClock` instead, so that it sits once in a
/// static and not in every task future the port is moved through.
pub struct Icm42688Port<SPI, D, R = NoDataReady, C = SampleClock> {
    driver: Icm42688<SPI>,
    channel: Imu,
    delay: D,
    data_ready: R,
    clock: C,
    /// Skipped samples not yet handed to a frame (a stale frame has none).
    skipped: u32,
    ready: bool,
    next_attempt: Instant,
}

impl<SPI: SpiDevice, D: DelayNs> Icm42688Port<SPI, D> {
    /// Wraps a driver whose `init` has not run yet (the first read runs it);
    /// `delay` times its waits. No data-ready line: one read per frame.
    pub fn new(driver: Icm42688<SPI>, channel: Imu, delay: D) -> Self {
        Self::with_data_ready(driver, channel, delay, NoDataReady)
    }
}

impl<SPI: SpiDevice, D: DelayNs, R: DataReadyPort> Icm42688Port<SPI, D, R> {
    /// As [`Icm42688Port::new`], with the sensor's data-ready pulses timed
    /// by `data_ready`.
    pub fn with_data_ready(driver: Icm42688<SPI>, channel: Imu, delay: D, data_ready: R) -> Self {
        Self::with_clock(driver, channel, delay, data_ready, SampleClock::new())
    }
}

impl<SPI: SpiDevice, D: DelayNs, R: DataReadyPort, C: BorrowMut<SampleClock>>
    Icm42688Port<SPI, D, R, C>
{
    /// As [`Icm42688Port::with_data_ready`], pairing samples and pulses in
    /// `clock` (which the first set-up restarts).
    pub fn with_clock(
        driver: Icm42688<SPI>,
        channel: Imu,
        delay: D,
        data_ready: R,
        clock: C,
    ) -> Self {
        Self {
            driver,
            channel,
            delay,
            data_ready,
            clock,
            skipped: 0,
            ready: false,
            next_attempt: Instant::MIN,
        }
    }

    /// Sets the sensor up before sampling starts, so that its start-up
    /// wait delays no tick; a failure is left to the reads' retries.
    pub async fn start(&mut self) {
        let _ = self.ensure_ready().await;
    }

    /// What the sample clock counted so far, and its period estimate.
    pub fn clock(&self) -> (ClockStats, f32) {
        let clock = self.clock.borrow();
        (clock.stats(), clock.period_us())
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
        let set_up = match self.driver.init(&mut self.delay).await {
            // The start-up wait's samples have no timed pulses: gone.
            Ok(()) if R::WIRED => self.driver.flush_fifo().await,
            other => other,
        };
        match set_up {
            Ok(()) => {
                #[cfg(feature = "defmt")]
                defmt::info!("IMU ready");
                self.data_ready.drain_pulses(&mut |_| true);
                self.clock.borrow_mut().restart();
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

    /// The wired read: pulses first, then the FIFO (the order
    /// [`SampleClock`] pairs them by), then the frame's value.
    async fn read_timed(&mut self, scheduled_us: u64) -> Result<ImuSample, SensorError> {
        // `drain_pulses` hands over a pulse it has already taken: ask only
        // while the clock has room.
        let clock = self.clock.borrow_mut();
        if clock.pulses_waiting() < imu_clock::PENDING {
            self.data_ready.drain_pulses(&mut |t| clock.data_ready(t));
        }
        let waiting = match self.driver.fifo_samples().await {
            Ok(n) => usize::from(n),
            Err(e) => return Err(self.failed(&e)),
        };
        // Only as far as this frame's time: after a stall the FIFO and the
        // pulse queue keep the rest for the catch-up frames that follow (up
        // to the FIFO's 128 samples, 1.28 s, nothing is lost).
        let mut read = 0;
        while read < waiting && self.clock.borrow_mut().wants_sample(scheduled_us) {
            // The pulses of the samples counted, as far as the clock has
            // room (a pulse drawn for a sample not counted would pass for
            // one whose sample was lost).
            let clock = self.clock.borrow_mut();
            if clock.pulses_waiting() < (waiting - read).min(imu_clock::PENDING) {
                self.data_ready.drain_pulses(&mut |t| {
                    clock.data_ready(t) && clock.pulses_waiting() < waiting - read
                });
            }
            read += 1;
            match self.driver.fifo_sample().await {
                Ok(raw) => {
                    if let Some(raw) = raw {
                        self.channel.watch(raw);
                    }
                    self.clock.borrow_mut().sample(raw);
                }
                Err(e) => return Err(self.failed(&e)),
            }
        }
        let value = self.clock.borrow_mut().frame_leaving(
            scheduled_us,
            Instant::now().as_micros(),
            waiting - read,
        );
        self.skipped = self.skipped.saturating_add(value.skipped);
        let counts = value.counts.ok_or(SensorError::Stale)?;
        let mut sample = self.channel.scale(counts);
        let reported = self.skipped.min(u32::from(u16::MAX));
        sample.skipped = reported as u16;
        self.skipped -= reported;
        Ok(sample)
    }

    /// The unwired read: the newest sample in the data registers.
    async fn read_polled(&mut self) -> Result<ImuSample, SensorError> {
        let raw = match self.driver.read().await {
            Ok(raw) => raw,
            Err(e) => return Err(self.failed(&e)),
        };
        self.channel.push(raw);
        self.channel.take().ok_or(SensorError::Stale)
    }
}

impl<SPI: SpiDevice, D: DelayNs, R: DataReadyPort, C: BorrowMut<SampleClock>> ImuPort
    for Icm42688Port<SPI, D, R, C>
{
    async fn read(&mut self, scheduled_us: u64) -> Result<ImuSample, SensorError> {
        self.ensure_ready().await?;
        let sample = if R::WIRED {
            self.read_timed(scheduled_us).await?
        } else {
            self.read_polled().await?
        };
        if sample.stuck {
            // Frozen output: the frame flags it; reset the sensor on the
            // next attempt.
            self.ready = false;
        }
        Ok(sample)
    }
}
