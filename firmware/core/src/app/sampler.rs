//! The 100 Hz sampling task: reads the sensor ports, builds the frame, runs
//! the wobble detector, drives the alert output and queues the records.
//!
//! The work of one tick is [`Sampler::step`], a plain function of the inputs
//! and the time, so it is tested without an executor; [`run`] is the loop
//! the firmware spawns in its high-priority executor.

use embassy_time::{Duration, Instant, Ticker};

use super::ports::{
    AlertOutput, ImuPort, ImuReading, LoggerHealth, MarkerInput, SensorError, StatusLed,
    SteeringPort, WheelPort,
};
use crate::channels::{RecordQueue, SharedStatus};
use crate::detector::{AlertEvent, AlertPattern, Detector, PatternConfig};
use crate::faults::FaultCounter;
use crate::format::{
    quantise_i16, quantise_u16, FaultSource, Frame, FrameStatus, Marker, Record, EDGE_AGE_NONE,
    STEER_COUNTS_PER_DEG,
};
use crate::wheel::WheelSpeed;

/// Frame period: 100 Hz.
pub const FRAME_PERIOD_US: u64 = 10_000;
/// The GPS counts as stale (status bit) without a fix for this long.
pub const GPS_STALE_US: u64 = 1_000_000;
/// Each sensor fault code is recorded at most once per second, with a count.
pub const FAULT_INTERVAL_US: u64 = 1_000_000;

/// IMU fault 1: the IMU did not answer.
pub const FAULT_IMU_NO_RESPONSE: u8 = 1;
/// IMU fault 2: the IMU answered with a stale or impossible sample.
pub const FAULT_IMU_BAD_SAMPLE: u8 = 2;
/// Steering fault 1: the steering sensor could not be read.
pub const FAULT_STEER_READ: u8 = 1;

/// What one tick read from the sensors.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    /// The IMU's answer.
    pub imu: Result<ImuReading, SensorError>,
    /// The steering angle, degrees.
    pub steer_deg: Result<f32, SensorError>,
    /// Whether the marker button is held.
    pub marker: bool,
    /// Whether the GPS has had no fix for [`GPS_STALE_US`].
    pub gps_stale: bool,
}

/// Counters of the sampling task.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SamplerStats {
    /// Frames built.
    pub frames: u32,
    /// Largest delay of a tick after its scheduled time, µs.
    pub max_lateness_us: u32,
}

/// State of the sampling task (see the module docs).
pub struct Sampler {
    wheel: WheelSpeed,
    detector: Detector,
    pattern: AlertPattern,
    imu_faults: FaultCounter<2>,
    steer_faults: FaultCounter<1>,
    last_imu: ImuReading,
    last_steer_deg: f32,
    marker_held: bool,
    markers: u16,
    stats: SamplerStats,
}

impl Sampler {
    /// A sampler with the configured wheel estimator and detector.
    #[must_use]
    pub fn new(wheel: WheelSpeed, detector: Detector, pattern: PatternConfig) -> Self {
        Self {
            wheel,
            detector,
            pattern: AlertPattern::new(pattern),
            imu_faults: FaultCounter::new(FaultSource::Imu, FAULT_INTERVAL_US),
            steer_faults: FaultCounter::new(FaultSource::Steering, FAULT_INTERVAL_US),
            last_imu: ImuReading::default(),
            last_steer_deg: 0.0,
            marker_held: false,
            markers: 0,
            stats: SamplerStats::default(),
        }
    }

    /// Counters so far.
    #[must_use]
    pub fn stats(&self) -> SamplerStats {
        self.stats
    }

    /// Counts a wheel edge captured at `t_us`.
    pub fn wheel_edge(&mut self, t_us: u64) {
        self.wheel.on_edge(t_us);
    }

    /// One tick at `now_us`: hands the records it makes to `out` (frame
    /// last, so a reader sees an event before the frame that shows it) and
    /// returns the alert switching, if any.
    pub fn step(
        &mut self,
        now_us: u64,
        inputs: &Inputs,
        alert_out: &mut impl AlertOutput,
        out: &mut impl FnMut(Record<'static>),
    ) -> Option<AlertEvent> {
        let mut status = 0u8;
        let mut emit_fault = |f| out(Record::Fault(f));
        match inputs.imu {
            Ok(reading) => self.last_imu = reading,
            Err(e) => {
                status |= FrameStatus::IMU_STALE;
                let code = match e {
                    SensorError::NoResponse => {
                        status |= FrameStatus::IMU_FAULT;
                        FAULT_IMU_NO_RESPONSE
                    }
                    _ => FAULT_IMU_BAD_SAMPLE,
                };
                self.imu_faults.count(code, now_us, &mut emit_fault);
            }
        }
        match inputs.steer_deg {
            Ok(deg) => self.last_steer_deg = deg,
            Err(_) => {
                status |= FrameStatus::STEER_STALE;
                self.steer_faults
                    .count(FAULT_STEER_READ, now_us, &mut emit_fault);
            }
        }
        self.imu_faults.poll(now_us, &mut emit_fault);
        self.steer_faults.poll(now_us, &mut emit_fault);

        let steer_counts = f64::from(self.last_steer_deg) * f64::from(STEER_COUNTS_PER_DEG);
        if steer_counts.abs() >= f64::from(i16::MAX) {
            status |= FrameStatus::STEER_SATURATED;
        }
        let wheel = self.wheel.sample(now_us);
        if wheel.stopped {
            status |= FrameStatus::WHEEL_STOPPED;
        }
        if inputs.gps_stale {
            status |= FrameStatus::GPS_STALE;
        }
        let event = self
            .detector
            .push(self.last_steer_deg, Some(wheel.speed_mps));
        if let Some(ev) = event {
            out(Record::Alert(ev.to_record(now_us)));
            self.pattern
                .set_alert(now_us, matches!(ev, AlertEvent::On { .. }));
        }
        self.pattern.update(now_us, alert_out);
        if self.detector.alert_active() {
            status |= FrameStatus::ALERT;
        }
        if inputs.marker {
            status |= FrameStatus::MARKER;
            if !self.marker_held {
                self.markers = self.markers.wrapping_add(1);
                out(Record::Marker(Marker {
                    t_us: now_us,
                    id: self.markers,
                }));
            }
        }
        self.marker_held = inputs.marker;

        let edge_age_us = wheel
            .last_edge_us
            .map(|t| now_us.saturating_sub(t))
            .filter(|&age| age < u64::from(EDGE_AGE_NONE))
            .map_or(EDGE_AGE_NONE, |age| age as u16);
        self.stats.frames = self.stats.frames.wrapping_add(1);
        out(Record::Frame(Frame {
            t_us: now_us,
            accel: self.last_imu.accel,
            gyro: self.last_imu.gyro,
            steer_cdeg: quantise_i16(self.last_steer_deg, STEER_COUNTS_PER_DEG),
            // The card stores the cumulative count modulo 2^16.
            wheel_count: wheel.pulses as u16,
            wheel_edge_age_us: edge_age_us,
            speed_mm_s: quantise_u16(wheel.speed_mps, 1000.0),
            status: FrameStatus(status),
        }));
        event
    }
}

/// The sensor side of the board, as the sampling task uses it.
pub struct SamplerPorts<I, S, W, M, A, L> {
    /// The IMU.
    pub imu: I,
    /// The steering sensor.
    pub steering: S,
    /// The wheel sensor.
    pub wheel: W,
    /// The marker button.
    pub marker: M,
    /// Buzzer and alert LED.
    pub alert: A,
    /// Status LED.
    pub status_led: L,
}

/// The sampling loop: `frames` ticks at 100 Hz (`u32::MAX`: for ever, well,
/// 497 days), then returns. `on_alert` sees every alert switching as it
/// happens (the QEMU image reports it to the test harness).
#[allow(clippy::too_many_arguments)]
pub async fn run<I, S, W, M, A, L>(
    sampler: &mut Sampler,
    ports: &mut SamplerPorts<I, S, W, M, A, L>,
    queue: &RecordQueue,
    shared: &SharedStatus,
    frames: u32,
    on_alert: &mut impl FnMut(u64, AlertEvent),
) where
    I: ImuPort,
    S: SteeringPort,
    W: WheelPort,
    M: MarkerInput,
    A: AlertOutput,
    L: StatusLed,
{
    let mut ticker = Ticker::every(Duration::from_micros(FRAME_PERIOD_US));
    let start_us = Instant::now().as_micros();
    for k in 1..=u64::from(frames) {
        ticker.next().await;
        let now_us = Instant::now().as_micros();
        let scheduled_us = start_us + k * FRAME_PERIOD_US;
        let late_us = u32::try_from(now_us.saturating_sub(scheduled_us)).unwrap_or(u32::MAX);
        sampler.stats.max_lateness_us = sampler.stats.max_lateness_us.max(late_us);
        ports.wheel.drain_edges(&mut |t| sampler.wheel_edge(t));
        let inputs = Inputs {
            imu: ports.imu.read().await,
            steer_deg: ports.steering.read_deg().await,
            marker: ports.marker.is_pressed(),
            gps_stale: shared.gps_stale(now_us, GPS_STALE_US),
        };
        let event = sampler.step(now_us, &inputs, &mut ports.alert, &mut |rec| {
            queue.push(rec);
        });
        if let Some(ev) = event {
            on_alert(now_us, ev);
        }
        let degraded = inputs.imu.is_err() || inputs.steer_deg.is_err() || inputs.gps_stale;
        ports.status_led.show(match (shared.card_ok(), degraded) {
            (false, _) => LoggerHealth::NoCard,
            (true, true) => LoggerHealth::Degraded,
            (true, false) => LoggerHealth::Ok,
        });
    }
}
