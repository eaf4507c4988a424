//! The sampler's tick ([`Sampler::step`]) on a simulated clock: frames come
//! from the frame assembly, failed reads become counted fault records, and
//! marker and alert records come before the frame that shows them.

use proptest::prelude::*;
use wobble_core::app::ports::{ImuSample, SensorError, SteeringSample};
use wobble_core::app::sampler::{
    Inputs, Sampler, FAULT_IMU_BAD_SAMPLE, FAULT_IMU_NO_RESPONSE, FAULT_IMU_SKIPPED,
    FAULT_INTERVAL_US, FAULT_STEER_OVERRUN, FAULT_STEER_READ, FRAME_PERIOD_US,
};
use wobble_core::config::{AlertConfig, Config};
use wobble_core::detector::{AlertEvent, AlertOutput};
use wobble_core::format::{Fault, FaultSource, Frame, FrameStatus, Record};
use wobble_core::frame_assembly::{FrameAssembler, FrameConfig, TickInputs};
use wobble_core::wheel::{WheelConfig, WheelSpeed};

/// The buzzer and LED, remembering whether they were ever switched on.
#[derive(Default)]
struct Outputs {
    buzzer_on: bool,
    led_on: bool,
    ever_on: bool,
}

impl AlertOutput for Outputs {
    fn set_buzzer(&mut self, on: bool) {
        self.buzzer_on = on;
        self.ever_on |= on;
    }
    fn set_led(&mut self, on: bool) {
        self.led_on = on;
        self.ever_on |= on;
    }
}

fn sampler() -> Sampler {
    Sampler::new(
        WheelSpeed::try_new(WheelConfig::DEFAULT).expect("default wheel"),
        FrameConfig::DEFAULT,
        Config::default().detector().expect("default detector"),
        AlertConfig::default(),
    )
}

/// A live IMU sample that changes with `tick` (as MEMS noise does).
fn imu(tick: u64) -> ImuSample {
    let noise = (tick % 7) as f32 / 2048.0;
    ImuSample {
        accel_g: [noise, -0.25, 1.0],
        gyro_dps: [0.5, noise * 32.0, -3.0],
        stuck: false,
        skipped: 0,
    }
}

fn steering(deg: f32) -> Result<SteeringSample, SensorError> {
    Ok(SteeringSample {
        deg,
        saturated: false,
    })
}

fn inputs(tick: u64) -> Inputs {
    Inputs {
        imu: Ok(imu(tick)),
        steering: steering(1.5),
        marker: false,
        last_gps_fix_us: Some(tick * FRAME_PERIOD_US),
    }
}

/// Runs one tick; returns its records in order.
fn step(
    s: &mut Sampler,
    tick: u64,
    inputs: &Inputs,
    outputs: &mut Outputs,
) -> Vec<Record<'static>> {
    let mut records = Vec::new();
    s.step(tick * FRAME_PERIOD_US, inputs, outputs, &mut |r| {
        records.push(r)
    });
    records
}

/// The tick's frame: always exactly one, always the last record.
fn frame_of(records: &[Record<'static>]) -> Frame {
    let frames = records
        .iter()
        .filter(|r| matches!(r, Record::Frame(_)))
        .count();
    assert_eq!(frames, 1, "{records:?}");
    match records.last() {
        Some(Record::Frame(f)) => *f,
        other => panic!("frame not last: {other:?}"),
    }
}

fn faults(records: &[Record<'static>]) -> Vec<Fault> {
    records
        .iter()
        .filter_map(|r| match r {
            Record::Fault(f) => Some(*f),
            _ => None,
        })
        .collect()
}

#[test]
fn an_imu_that_stops_answering_is_flagged_and_counted() {
    let mut s = sampler();
    let mut out = Outputs::default();
    // Live for 1 s, no answer from 1 s to 2.5 s, live again until 4 s.
    let dead = 100..250u64;
    let mut frames = Vec::new();
    let mut recorded = Vec::new();
    for tick in 1..=400u64 {
        let mut input = inputs(tick);
        if dead.contains(&tick) {
            input.imu = Err(SensorError::NoResponse);
        }
        let records = step(&mut s, tick, &input, &mut out);
        recorded.extend(faults(&records));
        frames.push(frame_of(&records));
    }
    let at = |tick: u64| frames[(tick - 1) as usize];
    let fault_bits = FrameStatus::IMU_STALE | FrameStatus::IMU_FAULT;
    for tick in 1..=400u64 {
        let status = at(tick).status;
        if dead.contains(&tick) {
            assert!(status.has(fault_bits), "tick {tick}: {status:?}");
            // The last live value is held.
            assert_eq!(at(tick).accel, at(99).accel, "tick {tick}");
        } else {
            assert_eq!(status.0 & fault_bits, 0, "tick {tick}: {status:?}");
        }
    }
    // The first failure at once, then at most one record a second, and the
    // remainder once a second has passed: every failure counted, once.
    assert!(recorded
        .iter()
        .all(|f| f.source == FaultSource::Imu && f.code == FAULT_IMU_NO_RESPONSE));
    assert_eq!(recorded[0].t_us, 100 * FRAME_PERIOD_US);
    assert_eq!(recorded[0].count, 1);
    for pair in recorded.windows(2) {
        assert!(pair[1].t_us - pair[0].t_us >= FAULT_INTERVAL_US, "{pair:?}");
    }
    let counted: u32 = recorded.iter().map(|f| u32::from(f.count)).sum();
    assert_eq!(counted, dead.end as u32 - dead.start as u32);
}

#[test]
fn imu_samples_that_reach_no_frame_are_each_counted() {
    let mut s = sampler();
    let mut out = Outputs::default();
    let mut recorded = Vec::new();
    // Three samples skipped before tick 5, two before tick 50, then 2 s of
    // frames for the counter to record the rest.
    for tick in 1..=300u64 {
        let mut input = inputs(tick);
        let skipped = match tick {
            5 => 3,
            50 => 2,
            _ => 0,
        };
        input.imu = Ok(ImuSample {
            skipped,
            ..imu(tick)
        });
        let records = step(&mut s, tick, &input, &mut out);
        // The frame itself is live: the skip is a fault, not a stale value.
        assert_eq!(frame_of(&records).status.0 & FrameStatus::IMU_STALE, 0);
        recorded.extend(faults(&records));
    }
    assert!(recorded
        .iter()
        .all(|f| f.source == FaultSource::Imu && f.code == FAULT_IMU_SKIPPED));
    assert_eq!(recorded[0].t_us, 5 * FRAME_PERIOD_US);
    let counted: u32 = recorded.iter().map(|f| u32::from(f.count)).sum();
    assert_eq!(counted, 5);
}

#[test]
fn stale_and_stuck_imu_samples_are_bad_samples() {
    let mut s = sampler();
    let mut out = Outputs::default();
    let mut recorded = Vec::new();
    let mut frames = Vec::new();
    // 1-9: live; 10-29: answers without a sample; 30-39: stuck.
    for tick in 1..40u64 {
        let mut input = inputs(tick);
        if (10..30).contains(&tick) {
            input.imu = Err(SensorError::Stale);
        } else if tick >= 30 {
            input.imu = Ok(ImuSample {
                stuck: true,
                ..imu(0)
            });
        }
        let records = step(&mut s, tick, &input, &mut out);
        recorded.extend(faults(&records));
        frames.push(frame_of(&records));
    }
    let status = |tick: usize| frames[tick - 1].status;
    // Late samples are only stale until `imu_missing_ticks` (10) in a row.
    assert!(status(10).has(FrameStatus::IMU_STALE));
    assert!(!status(18).has(FrameStatus::IMU_FAULT));
    assert!(status(19).has(FrameStatus::IMU_STALE | FrameStatus::IMU_FAULT));
    assert!(status(30).has(FrameStatus::IMU_FAULT));
    assert!(!status(30).has(FrameStatus::IMU_STALE));
    // One record at once; the other 29 bad samples wait for the interval.
    assert_eq!(recorded.len(), 1);
    assert_eq!(
        (recorded[0].code, recorded[0].t_us),
        (FAULT_IMU_BAD_SAMPLE, 10 * FRAME_PERIOD_US)
    );
}

#[test]
fn a_steering_read_failure_holds_the_angle_and_is_counted() {
    let mut s = sampler();
    let mut out = Outputs::default();
    let first = step(&mut s, 1, &inputs(1), &mut out);
    assert_eq!(frame_of(&first).steer_cdeg, 150);
    let input = Inputs {
        steering: Err(SensorError::Stale),
        ..inputs(2)
    };
    let records = step(&mut s, 2, &input, &mut out);
    let frame = frame_of(&records);
    assert_eq!(frame.steer_cdeg, 150);
    assert!(frame.status.has(FrameStatus::STEER_STALE));
    let recorded = faults(&records);
    assert_eq!(recorded.len(), 1);
    assert_eq!(
        (recorded[0].source, recorded[0].code),
        (FaultSource::Steering, FAULT_STEER_READ)
    );
    // A saturated pot is a flagged value, not a failed read.
    let input = Inputs {
        steering: Ok(SteeringSample {
            deg: 135.0,
            saturated: true,
        }),
        ..inputs(3)
    };
    let records = step(&mut s, 3, &input, &mut out);
    let frame = frame_of(&records);
    assert_eq!(frame.steer_cdeg, 13_500);
    assert!(frame.status.has(FrameStatus::STEER_SATURATED));
    assert!(faults(&records).is_empty());
}

#[test]
fn an_adc_overrun_is_its_own_counted_fault() {
    let mut s = sampler();
    let mut out = Outputs::default();
    step(&mut s, 1, &inputs(1), &mut out);
    let overrun = Inputs {
        steering: Err(SensorError::Overrun),
        ..inputs(2)
    };
    let records = step(&mut s, 2, &overrun, &mut out);
    assert!(frame_of(&records).status.has(FrameStatus::STEER_STALE));
    let codes: Vec<_> = faults(&records)
        .iter()
        .map(|f| (f.source, f.code))
        .collect();
    assert_eq!(codes, [(FaultSource::Steering, FAULT_STEER_OVERRUN)]);
    // A read failure right after is recorded under its own code at once.
    let stale = Inputs {
        steering: Err(SensorError::Stale),
        ..inputs(3)
    };
    let codes: Vec<_> = faults(&step(&mut s, 3, &stale, &mut out))
        .iter()
        .map(|f| f.code)
        .collect();
    assert_eq!(codes, [FAULT_STEER_READ]);
}

#[test]
fn each_marker_press_makes_one_record() {
    let mut s = sampler();
    let mut out = Outputs::default();
    let held = [
        false, true, true, true, false, false, true, false, true, true,
    ];
    let mut markers = Vec::new();
    for (tick, &marker) in (1u64..).zip(&held) {
        let input = Inputs {
            marker,
            ..inputs(tick)
        };
        let records = step(&mut s, tick, &input, &mut out);
        let frame = frame_of(&records);
        assert_eq!(frame.status.has(FrameStatus::MARKER), marker, "tick {tick}");
        for r in &records {
            if let Record::Marker(m) = r {
                assert_eq!(m.t_us, frame.t_us);
                markers.push((tick, m.id));
            }
        }
    }
    assert_eq!(markers, [(2, 1), (7, 2), (9, 3)]);
}

#[test]
fn alert_records_come_before_the_frame_that_shows_them() {
    const SPEED_MPS: f64 = 5.0;
    let edge_us = (WheelConfig::DEFAULT.pitch_m() as f64 / SPEED_MPS * 1e6) as u64;
    let mut next_edge_us = 0;
    let mut s = sampler();
    let mut out = Outputs::default();
    // An 8 Hz wobble (clear of the wheel's harmonics at 5 m/s) growing
    // from 4 s up to 3°, then gone at 9 s.
    let steer_deg = |t_s: f64| {
        let envelope = if t_s < 9.0 {
            (0.02 * (2.0 * (t_s - 4.0)).exp()).min(3.0)
        } else {
            0.0
        };
        (envelope * (std::f64::consts::TAU * 8.0 * t_s).sin()) as f32
    };
    let mut alert_on = false;
    let mut switches = Vec::new();
    for tick in 1..=1200u64 {
        let t_us = tick * FRAME_PERIOD_US;
        while next_edge_us <= t_us {
            s.wheel_edge(next_edge_us);
            next_edge_us += edge_us;
        }
        let input = Inputs {
            steering: steering(steer_deg(t_us as f64 / 1e6)),
            ..inputs(tick)
        };
        let mut records = Vec::new();
        let event = s.step(t_us, &input, &mut out, &mut |r| records.push(r));
        let frame = frame_of(&records);
        let alerts: Vec<_> = records
            .iter()
            .filter_map(|r| match r {
                Record::Alert(a) => Some(*a),
                _ => None,
            })
            .collect();
        assert_eq!(alerts.len(), usize::from(event.is_some()));
        if let (Some(ev), Some(a)) = (event, alerts.first()) {
            assert_eq!(*a, ev.to_record(t_us));
            alert_on = matches!(ev, AlertEvent::On { .. });
            switches.push((tick, alert_on));
        }
        assert_eq!(
            frame.status.has(FrameStatus::ALERT),
            alert_on,
            "tick {tick}"
        );
    }
    assert_eq!(switches.len(), 2, "{switches:?}");
    let (on_tick, off_tick) = (switches[0].0, switches[1].0);
    assert!(switches[0].1 && !switches[1].1);
    assert!((500..900).contains(&on_tick), "on at tick {on_tick}");
    assert!(off_tick > 900, "off at tick {off_tick}");
    assert!(out.ever_on);
    assert!(!out.buzzer_on && !out.led_on);
}

/// Adds the fault counts of `records` to `counted`: IMU no response, IMU
/// bad sample, steering read.
fn tally(records: &[Record<'static>], counted: &mut [u32; 3]) {
    for f in faults(records) {
        let i = match (f.source, f.code) {
            (FaultSource::Imu, FAULT_IMU_NO_RESPONSE) => 0,
            (FaultSource::Imu, FAULT_IMU_BAD_SAMPLE) => 1,
            (FaultSource::Steering, FAULT_STEER_READ) => 2,
            other => panic!("unexpected fault {other:?}"),
        };
        counted[i] += u32::from(f.count);
    }
}

/// One tick's port answers, for the property test.
fn arb_tick() -> impl Strategy<
    Value = (
        Result<ImuSample, SensorError>,
        Result<SteeringSample, SensorError>,
        bool,
        bool,
    ),
> {
    let sample =
        (prop::array::uniform6(-40.0f32..40.0), any::<bool>()).prop_map(|(v, stuck)| ImuSample {
            accel_g: [v[0], v[1], v[2]],
            gyro_dps: [v[3] * 40.0, v[4] * 40.0, v[5] * 40.0],
            stuck,
            skipped: 0,
        });
    let imu = prop_oneof![
        6 => sample.prop_map(Ok),
        1 => Just(Err(SensorError::NoResponse)),
        1 => Just(Err(SensorError::Stale)),
        1 => Just(Err(SensorError::OutOfRange)),
    ];
    let steer = prop_oneof![
        4 => (-400.0f32..400.0, any::<bool>())
            .prop_map(|(deg, saturated)| Ok(SteeringSample { deg, saturated })),
        1 => Just(Err(SensorError::Stale)),
    ];
    (imu, steer, any::<bool>(), prop::bool::weighted(0.05))
}

proptest! {
    /// Whatever the ports answer: the frame is the assembler's (the sampler
    /// adds only the alert bit, exactly while an alert is on), one marker
    /// record per press, and every failed or stuck read is counted once in
    /// the fault records by a second after the last one.
    #[test]
    fn frames_are_the_assemblers_and_faults_add_up(ticks in prop::collection::vec(arb_tick(), 1..300)) {
        let mut s = sampler();
        let mut reference = FrameAssembler::new(FrameConfig::DEFAULT);
        let mut wheel = WheelSpeed::try_new(WheelConfig::DEFAULT).expect("default wheel");
        let mut out = Outputs::default();
        let mut last_fix_us = None;
        let mut alert_on = false;
        let (mut presses, mut held, mut markers) = (0, false, 0);
        let mut failures = [0u32; 3];
        let mut counted = [0u32; 3];
        let n = ticks.len() as u64;
        // The wheel at 4 m/s, fed to both.
        let mut next_edge_us = 0;
        for (tick, &(imu, steering, marker, fix)) in (1u64..).zip(&ticks) {
            let t_us = tick * FRAME_PERIOD_US;
            while next_edge_us <= t_us {
                s.wheel_edge(next_edge_us);
                wheel.on_edge(next_edge_us);
                next_edge_us += 10_900;
            }
            if fix {
                last_fix_us = Some(t_us);
            }
            let input = Inputs { imu, steering, marker, last_gps_fix_us: last_fix_us };
            let records = step(&mut s, tick, &input, &mut out);
            let frame = frame_of(&records);
            let expected = reference.tick(t_us, &TickInputs {
                imu,
                steering,
                wheel: wheel.sample(t_us),
                last_gps_fix_us: last_fix_us,
                marker,
            });
            prop_assert_eq!(
                Frame { status: FrameStatus(frame.status.0 & !FrameStatus::ALERT), ..frame },
                expected
            );
            for r in &records {
                match r {
                    Record::Alert(a) => alert_on = a.on,
                    Record::Marker(_) => markers += 1,
                    _ => {}
                }
            }
            prop_assert_eq!(frame.status.has(FrameStatus::ALERT), alert_on);
            presses += u32::from(marker && !held);
            held = marker;
            match imu {
                Err(SensorError::NoResponse) => failures[0] += 1,
                Err(_) => failures[1] += 1,
                Ok(sample) if sample.stuck => failures[1] += 1,
                Ok(_) => {}
            }
            failures[2] += u32::from(steering.is_err());
            tally(&records, &mut counted);
            for i in 0..3 {
                prop_assert!(counted[i] <= failures[i]);
            }
        }
        prop_assert_eq!(markers, presses);
        // A second of good reads: the pending counts come out.
        for tick in n + 1..=n + 1 + FAULT_INTERVAL_US / FRAME_PERIOD_US {
            let records = step(&mut s, tick, &inputs(tick), &mut out);
            tally(&records, &mut counted);
        }
        prop_assert_eq!(counted, failures);
    }
}
