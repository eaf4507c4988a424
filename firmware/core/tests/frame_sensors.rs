//! All sensor channels through the 100 Hz frame assembly, on a simulated
//! clock: steering decimation, a silent IMU, wheel and GPS together.

use std::f64::consts::TAU;

use wobble_core::app::ports::SensorError;
use wobble_core::format::{FixMode, Frame, FrameStatus};
use wobble_core::frame_assembly::{FrameAssembler, FrameConfig, TickInputs};
use wobble_core::gps::{GpsConfig, GpsEvent, GpsReceiver};
use wobble_core::imu::{Imu, ImuConfig, RawImu};
use wobble_core::steering::{Steering, SteeringCalibration};
use wobble_core::wheel::{WheelConfig, WheelSpeed};

const TICK_US: u64 = 10_000;

/// Amplitude of the `freq_hz` component of `x`, sampled at 100 Hz.
fn amplitude(x: &[f64], freq_hz: f64) -> f64 {
    let (mut s, mut c) = (0.0, 0.0);
    for (i, v) in x.iter().enumerate() {
        let phase = TAU * freq_hz * i as f64 / 100.0;
        s += v * phase.sin();
        c += v * phase.cos();
    }
    2.0 * s.hypot(c) / x.len() as f64
}

/// Steering frames (degrees) for one second of a pure tone of `freq_hz` and
/// `amp_counts` on the ADC, sampled at 10 kHz.
fn steering_frames(freq_hz: f64, amp_counts: f64) -> Vec<f64> {
    let cal = SteeringCalibration {
        deg_per_count: 0.01,
        ..SteeringCalibration::DEFAULT
    };
    let mut steering = Steering::try_new(cal).unwrap();
    let mut frames = Vec::new();
    for i in 0..10_000u32 {
        let t = f64::from(i) / 10_000.0;
        let counts = 2048.0 + amp_counts * (TAU * freq_hz * t).sin();
        steering.push(counts.round() as u16);
        if (i + 1) % 100 == 0 {
            frames.push(f64::from(steering.take().unwrap().deg));
        }
    }
    frames
}

#[test]
fn steering_decimation_passes_wobble_and_rejects_aliases() {
    // 1000 counts at 0.01 deg/count: a 10° oscillation.
    for (f, gain) in [(6.0, 0.9941), (7.0, 0.9920), (9.0, 0.9867)] {
        let a = amplitude(&steering_frames(f, 1000.0), f);
        assert!((a / 10.0 - gain).abs() < 0.002, "{f} Hz: {a}");
    }
    // 93 Hz and 107 Hz alias to 7 Hz at 100 Hz: attenuated to under 8 %.
    for f in [93.0, 107.0] {
        let a = amplitude(&steering_frames(f, 1000.0), 7.0);
        assert!(a / 10.0 < 0.08, "{f} Hz: {a}");
    }
}

#[test]
fn a_silent_imu_never_blocks_the_frames() {
    let mut imu = Imu::try_new(ImuConfig::DEFAULT).unwrap();
    let mut assembler = FrameAssembler::new(FrameConfig::DEFAULT);
    let mut frames = Vec::new();
    // IMU at 200 Hz, silent from 0.5 s to 0.9 s.
    for tick in 1..=200u64 {
        let t_us = tick * TICK_US;
        for half in 0..2 {
            let t_sample = t_us - TICK_US / 2 * (1 - half);
            if !(500_000..900_000).contains(&t_sample) {
                let noise = (t_sample / 5000 % 7) as i16;
                imu.push(RawImu {
                    accel: [noise, 0, 2048],
                    gyro: [0, noise, 0],
                });
            }
        }
        frames.push(assembler.tick(
            t_us,
            &TickInputs {
                // An IMU that answers but has nothing new is stale.
                imu: imu.take().ok_or(SensorError::Stale),
                ..TickInputs::default()
            },
        ));
    }
    assert_eq!(frames.len(), 200);
    let status = |t_ms: u64| frames[(t_ms / 10 - 1) as usize].status;
    assert!(!status(400).has(FrameStatus::IMU_STALE));
    // Silent: stale at once, a fault after 10 ticks, the last value held.
    assert!(status(510).has(FrameStatus::IMU_STALE));
    assert!(!status(590).has(FrameStatus::IMU_FAULT));
    assert!(status(600).has(FrameStatus::IMU_FAULT));
    assert_eq!(frames[88].accel, frames[49].accel);
    // Back.
    assert!(!status(910).has(FrameStatus::IMU_STALE | FrameStatus::IMU_FAULT));
    assert_eq!(frames[99].accel[2], 2048);
}

#[test]
fn wheel_and_gps_in_the_frames() {
    let mut wheel = WheelSpeed::try_new(WheelConfig::DEFAULT).unwrap();
    let mut gps = GpsReceiver::new(GpsConfig::default());
    let mut assembler = FrameAssembler::new(FrameConfig::DEFAULT);
    // The Garmin capture's 1 Hz epochs (each begins with its RMC), each sent
    // at the start of a second on a 115200 baud UART: (arrival µs, byte).
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../hil-tests/fixtures/gps/garmin15x.log"),
    )
    .unwrap();
    let byte_us = 10_000_000 / 115_200;
    let mut uart: Vec<(u64, u8)> = Vec::new();
    let mut epoch = 0u64;
    let mut t_us = 0;
    for line in text.lines().filter(|l| !l.starts_with('#')) {
        if line.starts_with("$GPRMC") {
            epoch += 1;
            t_us = epoch * 1_000_000;
        }
        for b in format!("{line}\r\n").bytes() {
            t_us += byte_us;
            uart.push((t_us, b));
        }
    }
    let mut next_byte = 0;
    // The wheel at 4 m/s: an edge every 10.9 ms.
    let mut next_edge = 5_000u64;
    let mut frames: Vec<Frame> = Vec::new();
    let mut fixes = Vec::new();
    let mut last_fix_us = None;
    for tick in 1..=1500u64 {
        let t_us = tick * TICK_US;
        while next_edge <= t_us {
            wheel.on_edge(next_edge);
            next_edge += 10_900;
        }
        // What the UART DMA delivered during this tick, in one chunk.
        let start = next_byte;
        while next_byte < uart.len() && uart[next_byte].0 <= t_us {
            next_byte += 1;
        }
        // As the GPS task publishes it: the time of the last fix with a
        // position.
        let mut on_event = |e| {
            if let GpsEvent::Fix(f) = e {
                if f.lat_e7.is_some() {
                    last_fix_us = Some(f.t_us);
                }
                fixes.push(f);
            }
        };
        if next_byte > start {
            let chunk: Vec<u8> = uart[start..next_byte].iter().map(|&(_, b)| b).collect();
            gps.feed(&chunk, uart[next_byte - 1].0, &mut on_event);
        }
        gps.poll(t_us, &mut on_event);
        frames.push(assembler.tick(
            t_us,
            &TickInputs {
                wheel: wheel.sample(t_us),
                last_gps_fix_us: last_fix_us,
                ..TickInputs::default()
            },
        ));
    }
    // 7 one-second epochs, each merged into one 3D fix.
    assert_eq!(fixes.len(), 7);
    assert!(fixes.iter().all(|f| f.fix == FixMode::Fix3d));
    let at = |t_ms: u64| frames[(t_ms / 10 - 1) as usize];
    // GPS: stale before the first fix, fresh while epochs come (once the
    // merger has learned where an epoch ends, each fix is out within
    // milliseconds of its first sentence), stale a second after the last.
    assert!(at(500).status.has(FrameStatus::GPS_STALE));
    for t_ms in [3500, 5200, 7900] {
        assert!(!at(t_ms).status.has(FrameStatus::GPS_STALE), "{t_ms} ms");
    }
    assert!(at(9000).status.has(FrameStatus::GPS_STALE));
    // Wheel: exact speed after the first revolution, counts and edge age.
    for f in &frames[60..] {
        assert_eq!(f.speed_mm_s, 4000, "at {}", f.t_us);
        assert!(f.wheel_edge_age_us < 10_900);
        assert!(!f.status.has(FrameStatus::WHEEL_STOPPED));
    }
    let last = frames.last().unwrap();
    assert_eq!(u32::from(last.wheel_count), wheel.pulses() % 65_536);
    assert_eq!(wheel.pulses(), ((15_000_000 - 5_000) / 10_900 + 1) as u32);
}
