//! The traits through which the core's tasks reach the hardware. The board
//! crate implements them with real peripherals, the QEMU image with fixture
//! replay; the tasks never see which.
//!
//! The sensor ports deliver the core's channel values ([`ImuSample`] in g
//! and deg/s in the bicycle frame, [`SteeringSample`] in degrees), which the
//! sampler hands to [`crate::frame_assembly`]; quantisation to the card's
//! units happens there, never in an adapter. Times are µs since boot (the
//! `embassy-time` clock).

pub use crate::detector::AlertOutput;
pub use crate::imu::ImuSample;
pub use crate::steering::SteeringSample;

/// Why a sensor read failed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
#[non_exhaustive]
pub enum SensorError {
    /// The sensor did not answer (bus timeout, NACK).
    NoResponse,
    /// It answered, but with no new sample since the last read.
    Stale,
    /// It answered with a value outside its range.
    OutOfRange,
    /// Its converter overran (samples lost) and has been restarted.
    Overrun,
}

/// The 6-DOF IMU, read once per frame.
#[allow(async_fn_in_trait)]
pub trait ImuPort {
    /// The value of the frame due at `scheduled_us` (µs since boot):
    /// with the sensor's data-ready times, its output at a fixed age
    /// before that time ([`crate::imu_clock`]); without them, the samples
    /// since the previous read (the [`crate::imu::Imu`] channel's `take`).
    /// `stuck` is set when the sensor repeats itself, `skipped` counts its
    /// samples that reach no frame; [`SensorError::NoResponse`] when it
    /// did not answer, [`SensorError::Stale`] when no sample is there for
    /// the frame. Must return within a few ms: the sampler's period is
    /// 10 ms.
    async fn read(&mut self, scheduled_us: u64) -> Result<ImuSample, SensorError>;
}

/// The IMU's data-ready line (INT1), its pulses timed by the hardware.
pub trait DataReadyPort {
    /// Whether the line is wired and timed: without it the IMU is read
    /// once per frame, its newest sample 0-10 ms old.
    const WIRED: bool;

    /// Hands the time of each pulse since the last call to `pulse`, oldest
    /// first, as µs since boot, until `pulse` returns `false` (it has taken
    /// that one and wants no more now): the rest wait in the adapter's
    /// queue, which holds a full FIFO's worth.
    fn drain_pulses(&mut self, pulse: &mut dyn FnMut(u64) -> bool);
}

/// No data-ready line (the QEMU machine's emulated sensor has none).
#[derive(Clone, Copy, Debug, Default)]
pub struct NoDataReady;

impl DataReadyPort for NoDataReady {
    const WIRED: bool = false;

    fn drain_pulses(&mut self, _pulse: &mut dyn FnMut(u64) -> bool) {}
}

/// The steering potentiometer, calibrated.
#[allow(async_fn_in_trait)]
pub trait SteeringPort {
    /// The frame's angle from the ADC samples it is owed (the
    /// [`crate::steering::Steering`] channel's `take`), degrees, left
    /// positive, `saturated` when a sample hit either end of the ADC range;
    /// [`SensorError::Stale`] when no sample came. The frame is read
    /// `late_us` after its scheduled time: samples converted since belong
    /// to the next frame ([`crate::adc_ring::SampleBacklog`]).
    async fn read(&mut self, late_us: u64) -> Result<SteeringSample, SensorError>;
}

/// The wheel's hall sensor, whose edges the hardware timestamps.
pub trait WheelPort {
    /// Hands every edge captured since the last call to `edge`, oldest
    /// first, as µs since boot.
    fn drain_edges(&mut self, edge: &mut dyn FnMut(u64));
}

/// The GPS receiver's UART.
#[allow(async_fn_in_trait)]
pub trait GpsPort {
    /// Waits for bytes and copies what arrived into `buf`; returns how many
    /// (0 only at the end of a replayed capture).
    async fn read(&mut self, buf: &mut [u8]) -> usize;

    /// Bytes that had arrived before the last `read` returned but did not
    /// fit its buffer: that chunk's last byte came this many character
    /// times before the read returned (the GPS task back-dates by it).
    fn pending(&self) -> usize {
        0
    }
}

/// The rider's marker button.
pub trait MarkerInput {
    /// Whether the button is held now (debounced by the caller's 10 ms
    /// sampling).
    fn is_pressed(&mut self) -> bool;
}

/// What the status LED shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum LoggerHealth {
    /// Logging to a card, sensors fine.
    Ok,
    /// Logging, but a sensor is failing or the GPS has no fix.
    Degraded,
    /// No card: sampling and alerting go on, nothing is recorded.
    NoCard,
    /// A card without a FAT16 or FAT32 volume (exFAT, say): as without a
    /// card, until it is formatted FAT32.
    UnusableCard,
    /// A full card: as without a card, until it is swapped or emptied.
    CardFull,
}

/// Frames per blink half-period: degraded blinks at 1 Hz, no card at 5 Hz.
const DEGRADED_HALF_FRAMES: u32 = 50;
const NO_CARD_HALF_FRAMES: u32 = 10;

impl LoggerHealth {
    /// Whether the status LED is lit at frame `frame` (100 per second):
    /// steady while logging with every sensor fine, a 1 Hz blink when a
    /// sensor fails or the GPS has no fix, 5 Hz without a card, with a
    /// card it cannot use two of the 5 Hz blinks, then dark to the
    /// second's end (exFAT: format it FAT32), and with a full card lit but
    /// for 0.1 s each second.
    #[must_use]
    pub fn led_on(self, frame: u32) -> bool {
        let blink = |half: u32| (frame / half) & 1 == 0;
        match self {
            Self::Ok => true,
            Self::Degraded => blink(DEGRADED_HALF_FRAMES),
            Self::NoCard => blink(NO_CARD_HALF_FRAMES),
            Self::UnusableCard => {
                frame % (10 * NO_CARD_HALF_FRAMES) < 4 * NO_CARD_HALF_FRAMES
                    && blink(NO_CARD_HALF_FRAMES)
            }
            Self::CardFull => frame % (10 * NO_CARD_HALF_FRAMES) >= NO_CARD_HALF_FRAMES,
        }
    }
}

/// The status LED (separate from the alert LED of [`AlertOutput`]).
pub trait StatusLed {
    /// Shows `health`; called once per frame, so it should only act on
    /// changes.
    fn show(&mut self, health: LoggerHealth);
}

#[cfg(test)]
mod tests {
    use super::LoggerHealth;

    /// Lit frames of one second (100 frames), as on/off runs.
    fn runs(health: LoggerHealth) -> std::vec::Vec<(bool, u32)> {
        let mut out: std::vec::Vec<(bool, u32)> = std::vec::Vec::new();
        for frame in 0..100 {
            let on = health.led_on(frame);
            match out.last_mut() {
                Some((last, n)) if *last == on => *n += 1,
                _ => out.push((on, 1)),
            }
        }
        out
    }

    /// Each state has its own pattern a rider can tell apart: steady, one
    /// 0.5 s flash a second, five 0.1 s flashes, two 0.1 s flashes, lit
    /// but for 0.1 s; and the pattern repeats every second.
    #[test]
    fn each_health_blinks_its_own_pattern() {
        assert_eq!(runs(LoggerHealth::Ok), [(true, 100)]);
        assert_eq!(runs(LoggerHealth::Degraded), [(true, 50), (false, 50)]);
        assert_eq!(
            runs(LoggerHealth::NoCard),
            [(true, 10), (false, 10)].repeat(5)
        );
        assert_eq!(
            runs(LoggerHealth::UnusableCard),
            [(true, 10), (false, 10), (true, 10), (false, 70)]
        );
        assert_eq!(runs(LoggerHealth::CardFull), [(false, 10), (true, 90)]);
        for health in [
            LoggerHealth::Degraded,
            LoggerHealth::NoCard,
            LoggerHealth::UnusableCard,
            LoggerHealth::CardFull,
        ] {
            for frame in 0..300 {
                assert_eq!(health.led_on(frame), health.led_on(frame + 100));
            }
        }
    }
}
