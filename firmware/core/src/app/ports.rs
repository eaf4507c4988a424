//! The traits through which the core's tasks reach the hardware. The board
//! crate implements them with real peripherals, the QEMU image with fixture
//! replay; the tasks never see which.
//!
//! Units are the card format's: accelerations in 1/2048 g, rates in 1/32
//! deg/s, steering in degrees, times in µs since boot (the `embassy-time`
//! clock).

pub use crate::detector::AlertOutput;

/// One IMU reading, already scaled to the frame's units.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ImuReading {
    /// Acceleration x, y, z, 1/2048 g.
    pub accel: [i16; 3],
    /// Angular rate x, y, z, 1/32 deg/s.
    pub gyro: [i16; 3],
}

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
}

/// The 6-DOF IMU, read once per frame.
#[allow(async_fn_in_trait)]
pub trait ImuPort {
    /// The latest filtered sample. Must return within a few ms: the
    /// sampler's period is 10 ms.
    async fn read(&mut self) -> Result<ImuReading, SensorError>;
}

/// The steering potentiometer, calibrated.
#[allow(async_fn_in_trait)]
pub trait SteeringPort {
    /// Steering angle now, degrees, left positive.
    async fn read_deg(&mut self) -> Result<f32, SensorError>;
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
}

/// The status LED (separate from the alert LED of [`AlertOutput`]).
pub trait StatusLed {
    /// Shows `health`; called once per frame, so it should only act on
    /// changes.
    fn show(&mut self, health: LoggerHealth);
}
