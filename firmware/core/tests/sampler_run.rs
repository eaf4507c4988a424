//! The sampling loop (`app::sampler::run`) in virtual time through a stall:
//! a port read that holds the task for 66 ms (an IMU re-initialisation)
//! makes the ticker fire the missed ticks back to back. Each frame of that
//! catch-up burst is stamped on the tick it is owed, 10 ms after the one
//! before, not microseconds after it.

use core::future::Future;
use core::pin::pin;
use core::task::{Context, Poll, Waker};

use embassy_time::{Duration, Instant, MockDriver};
use wobble_core::app::ports::{
    AlertOutput, ImuPort, ImuSample, LoggerHealth, MarkerInput, SensorError, StatusLed,
    SteeringPort, SteeringSample, WheelPort,
};
use wobble_core::app::sampler::{self, Sampler, SamplerPorts, FRAME_PERIOD_US};
use wobble_core::channels::{RecordQueue, SharedStatus};
use wobble_core::config::{AlertConfig, Config};
use wobble_core::format::Record;
use wobble_core::frame_assembly::FrameConfig;
use wobble_core::stall::LONGEST_STALL_US;
use wobble_core::wheel::{WheelConfig, WheelSpeed};

static QUEUE: RecordQueue = RecordQueue::new();
static SHARED: SharedStatus = SharedStatus::new();

/// An IMU whose `stall_at`-th read holds the task for the longest stall.
struct StallingImu {
    reads: u32,
    stall_at: u32,
}

impl ImuPort for StallingImu {
    async fn read(&mut self, _scheduled_us: u64) -> Result<ImuSample, SensorError> {
        self.reads += 1;
        if self.reads == self.stall_at {
            // Busy in the port (the re-initialisation's waits): time goes
            // on without the loop getting back to its ticker.
            MockDriver::get().advance(Duration::from_micros(u64::from(LONGEST_STALL_US)));
        }
        Ok(ImuSample {
            accel_g: [0.0, 0.0, 1.0],
            gyro_dps: [f32::from(self.reads as u16 % 7), 0.0, 0.0],
            stuck: false,
            skipped: 0,
        })
    }
}

struct Quiet;

impl SteeringPort for Quiet {
    async fn read(&mut self, _late_us: u64) -> Result<SteeringSample, SensorError> {
        Ok(SteeringSample {
            deg: 0.0,
            saturated: false,
        })
    }
}
impl WheelPort for Quiet {
    fn drain_edges(&mut self, _edge: &mut dyn FnMut(u64)) {}
}
impl MarkerInput for Quiet {
    fn is_pressed(&mut self) -> bool {
        false
    }
}
impl AlertOutput for Quiet {
    fn set_buzzer(&mut self, _on: bool) {}
    fn set_led(&mut self, _on: bool) {}
}
impl StatusLed for Quiet {
    fn show(&mut self, _health: LoggerHealth) {}
}

/// Polls `future` to its end, advancing the mock clock by 100 µs whenever
/// it waits.
fn drive<F: Future>(future: F) -> F::Output {
    let mut future = pin!(future);
    let mut cx = Context::from_waker(Waker::noop());
    let start = Instant::now();
    loop {
        if let Poll::Ready(out) = future.as_mut().poll(&mut cx) {
            return out;
        }
        assert!(Instant::now().duration_since(start) < Duration::from_secs(10));
        MockDriver::get().advance(Duration::from_micros(100));
    }
}

#[test]
fn frames_of_a_catch_up_burst_are_stamped_on_their_own_ticks() {
    let mut s = Sampler::new(
        WheelSpeed::try_new(WheelConfig::DEFAULT).expect("default wheel"),
        FrameConfig::DEFAULT,
        Config::default().detector().expect("default detector"),
        AlertConfig::default(),
    );
    let mut ports = SamplerPorts {
        imu: StallingImu {
            reads: 0,
            stall_at: 5,
        },
        steering: Quiet,
        wheel: Quiet,
        marker: Quiet,
        alert: Quiet,
        status_led: Quiet,
    };
    let start_us = Instant::now().as_micros();
    let frames = 30;
    drive(sampler::run(
        &mut s,
        &mut ports,
        &QUEUE,
        &SHARED,
        frames,
        &mut |_, _| {},
    ));
    let mut times = Vec::new();
    while let Some(rec) = QUEUE.try_pop() {
        if let Record::Frame(f) = rec {
            times.push(f.t_us);
        }
    }
    assert_eq!(times.len(), frames as usize);
    let expected: Vec<u64> = (1..=u64::from(frames))
        .map(|k| start_us + k * FRAME_PERIOD_US)
        .collect();
    assert_eq!(times, expected);
    // The stall happened: the burst's frames were built late.
    assert!(
        s.stats().max_lateness_us >= LONGEST_STALL_US - FRAME_PERIOD_US as u32,
        "{:?}",
        s.stats()
    );
}
