//! The 100 Hz sampling task: reads the sensor ports, has the frame built by
//! [`FrameAssembler`], runs the wobble detector on it, drives the alert
//! output and queues the records.
//!
//! The frame itself (held values, status bits, quantisation) is the
//! assembler's; what is the sampler's own: fault records for failed reads,
//! the detector with its alert records and pattern, marker records, and the
//! timing statistics.
//!
//! The work of one tick is [`Sampler::step`], a plain function of the inputs
//! and the time, so it is tested without an executor; [`run`] is the loop
//! the firmware spawns in its high-priority executor.

use embassy_time::{Duration, Instant, Ticker};

use super::ports::{
    AlertOutput, ImuPort, ImuSample, LoggerHealth, MarkerInput, SensorError, StatusLed,
    SteeringPort, SteeringSample, WheelPort,
};
use crate::channels::{CardHealth, RecordQueue, SharedStatus};
use crate::config::AlertConfig;
use crate::detector::{AlertEvent, AlertPattern, Detector, MarginEvent, MarginWarning};
use crate::faults::FaultCounter;
use crate::format::{FaultSource, FrameStatus, MarginRecord, MarginState, Marker, Record};
use crate::frame_assembly::{FrameAssembler, FrameConfig, TickInputs};
use crate::wheel::WheelSpeed;

/// Frame period: 100 Hz.
pub const FRAME_PERIOD_US: u64 = 10_000;
/// Each sensor fault code is recorded at most once per second, with a count.
pub const FAULT_INTERVAL_US: u64 = 1_000_000;

/// IMU fault 1: the IMU did not answer.
pub const FAULT_IMU_NO_RESPONSE: u8 = 1;
/// IMU fault 2: the IMU answered with a stale, impossible or stuck sample.
pub const FAULT_IMU_BAD_SAMPLE: u8 = 2;
/// IMU fault 3: a sample the sensor made reached no frame (a gap in its
/// data-ready times, a FIFO overflow or flush, an invalid FIFO packet:
/// [`crate::imu_clock`]); one count per sample.
pub const FAULT_IMU_SKIPPED: u8 = 3;
/// Steering fault 1: the steering sensor could not be read.
pub const FAULT_STEER_READ: u8 = 1;
/// Steering fault 2: the steering ADC overran and was restarted.
pub const FAULT_STEER_OVERRUN: u8 = 2;

/// Status bits that make the status LED show [`LoggerHealth::Degraded`]: a
/// sensor not delivering live values, or no recent GPS fix.
const DEGRADED: u8 = FrameStatus::IMU_STALE
    | FrameStatus::IMU_FAULT
    | FrameStatus::STEER_STALE
    | FrameStatus::STEER_SATURATED
    | FrameStatus::GPS_STALE;

/// What one tick read from the ports.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Inputs {
    /// The IMU's answer.
    pub imu: Result<ImuSample, SensorError>,
    /// The steering sensor's answer.
    pub steering: Result<SteeringSample, SensorError>,
    /// Whether the marker button is held.
    pub marker: bool,
    /// Local time of the last GPS fix with a position, µs since boot
    /// ([`SharedStatus::last_fix_us`]).
    pub last_gps_fix_us: Option<u64>,
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
    assembler: FrameAssembler,
    detector: Detector,
    margin: MarginWarning,
    pattern: AlertPattern,
    imu_faults: FaultCounter<3>,
    steer_faults: FaultCounter<2>,
    marker_held: bool,
    markers: u16,
    status: FrameStatus,
    stats: SamplerStats,
}

impl Sampler {
    /// A sampler with the configured wheel estimator, frame assembly,
    /// detector, margin warning and rider patterns.
    #[must_use]
    pub fn new(
        wheel: WheelSpeed,
        frame: FrameConfig,
        detector: Detector,
        alert: AlertConfig,
    ) -> Self {
        Self {
            wheel,
            assembler: FrameAssembler::new(frame),
            detector,
            margin: MarginWarning::new(alert.margin_mps),
            pattern: AlertPattern::new(alert.pattern, alert.approach),
            imu_faults: FaultCounter::new(FaultSource::Imu, FAULT_INTERVAL_US),
            steer_faults: FaultCounter::new(FaultSource::Steering, FAULT_INTERVAL_US),
            marker_held: false,
            markers: 0,
            status: FrameStatus(0),
            stats: SamplerStats::default(),
        }
    }

    /// Counters so far.
    #[must_use]
    pub fn stats(&self) -> SamplerStats {
        self.stats
    }

    /// Status bits of the last frame built (the status LED shows them).
    #[must_use]
    pub fn last_status(&self) -> FrameStatus {
        self.status
    }

    /// Counts a wheel edge captured at `t_us`.
    pub fn wheel_edge(&mut self, t_us: u64) {
        self.wheel.on_edge(t_us);
    }

    /// One tick at `now_us`: hands the records it makes to `out` (faults,
    /// alert and marker first, the frame last, so a reader sees an event
    /// before the frame that shows it) and returns the alert switching, if
    /// any.
    pub fn step(
        &mut self,
        now_us: u64,
        inputs: &Inputs,
        alert_out: &mut impl AlertOutput,
        out: &mut impl FnMut(Record<'static>),
    ) -> Option<AlertEvent> {
        let mut emit_fault = |f| out(Record::Fault(f));
        let imu_fault = match inputs.imu {
            Ok(sample) if sample.stuck => Some(FAULT_IMU_BAD_SAMPLE),
            Ok(_) => None,
            Err(SensorError::NoResponse) => Some(FAULT_IMU_NO_RESPONSE),
            Err(_) => Some(FAULT_IMU_BAD_SAMPLE),
        };
        if let Some(code) = imu_fault {
            self.imu_faults.count(code, now_us, &mut emit_fault);
        }
        if let Ok(sample) = inputs.imu {
            for _ in 0..sample.skipped {
                self.imu_faults
                    .count(FAULT_IMU_SKIPPED, now_us, &mut emit_fault);
            }
        }
        if let Err(e) = inputs.steering {
            let code = if e == SensorError::Overrun {
                FAULT_STEER_OVERRUN
            } else {
                FAULT_STEER_READ
            };
            self.steer_faults.count(code, now_us, &mut emit_fault);
        }
        self.imu_faults.poll(now_us, &mut emit_fault);
        self.steer_faults.poll(now_us, &mut emit_fault);

        let mut frame = self.assembler.tick(
            now_us,
            &TickInputs {
                imu: inputs.imu,
                steering: inputs.steering,
                wheel: self.wheel.sample(now_us),
                last_gps_fix_us: inputs.last_gps_fix_us,
                marker: inputs.marker,
            },
        );
        // The detector sees the frame's values as the card stores them, so
        // the host's `wobblog detect` over a decoded log sees the same input.
        let event = self
            .detector
            .push(frame.steer_deg(), Some(frame.speed_mps()));
        if let Some(ev) = event {
            out(Record::Alert(ev.to_record(now_us)));
            self.pattern
                .set_alert(now_us, matches!(ev, AlertEvent::On { .. }));
        }
        let speed = Some(frame.speed_mps());
        if let Some(kick) = self.detector.take_kick() {
            let rate_hz = self.detector.config().sample_rate_hz;
            out(Record::Kick(kick.to_record(now_us, rate_hz)));
            if let Some(estimate) = self.margin.add_kick(&kick) {
                let state = MarginState::Estimate;
                out(Record::Margin(MarginRecord::new(
                    now_us,
                    state,
                    speed,
                    Some(&estimate),
                )));
            }
        }
        if let Some(ev) = self.margin.update(now_us, speed) {
            let approaching = ev == MarginEvent::Approaching;
            let state = if approaching {
                MarginState::Approaching
            } else {
                MarginState::Clear
            };
            let estimate = self.margin.estimate();
            out(Record::Margin(MarginRecord::new(
                now_us,
                state,
                speed,
                estimate.as_ref(),
            )));
            self.pattern.set_approaching(now_us, approaching);
        }
        self.pattern.update(now_us, alert_out);
        if self.detector.alert_active() {
            frame.status.0 |= FrameStatus::ALERT;
        }
        if inputs.marker && !self.marker_held {
            self.markers = self.markers.wrapping_add(1);
            out(Record::Marker(Marker {
                t_us: now_us,
                id: self.markers,
            }));
        }
        self.marker_held = inputs.marker;

        self.status = frame.status;
        self.stats.frames = self.stats.frames.wrapping_add(1);
        out(Record::Frame(frame));
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
        let imu = ports.imu.read(scheduled_us).await;
        // The IMU read may have taken a while (a re-initialisation): the
        // steering samples are owed up to the schedule, not up to now.
        let steer_late_us = Instant::now().as_micros().saturating_sub(scheduled_us);
        let inputs = Inputs {
            imu,
            steering: ports.steering.read(steer_late_us).await,
            marker: ports.marker.is_pressed(),
            last_gps_fix_us: shared.last_fix_us(),
        };
        // Stamped on its own tick, also in a catch-up burst after a stall
        // (the ticker then fires the missed ticks back to back): the frame
        // holds the samples owed up to that tick, so the card's frames stay
        // 10 ms apart instead of bunching microseconds apart.
        let event = sampler.step(scheduled_us, &inputs, &mut ports.alert, &mut |rec| {
            queue.push(rec);
        });
        if let Some(ev) = event {
            on_alert(scheduled_us, ev);
        }
        let degraded = sampler.status.0 & DEGRADED != 0;
        ports.status_led.show(match (shared.card(), degraded) {
            (CardHealth::Absent, _) => LoggerHealth::NoCard,
            (CardHealth::Unusable, _) => LoggerHealth::UnusableCard,
            (CardHealth::Full, _) => LoggerHealth::CardFull,
            (CardHealth::Logging, true) => LoggerHealth::Degraded,
            (CardHealth::Logging, false) => LoggerHealth::Ok,
        });
    }
}
