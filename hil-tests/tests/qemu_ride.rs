//! The bundled ride end to end under QEMU: the firmware's tasks sample the
//! Figure-6 ride for 30 s of virtual time while replaying a real 5 Hz NMEA
//! capture; the card image must hold every frame on time, the capture's
//! fixes, the alert where the ground truth has the wobble, and a clean FAT.
//! The sensors are mounted and calibrated as the card's `CONFIG.TXT` says
//! (a rotated IMU, a three-point steering calibration turning the other
//! way): the raw register bytes and ADC counts become the ride's values
//! only through the core's driver, axis map, averaging and calibration.

use std::path::Path;

use wobble_core::drivers::icm42688;
use wobble_core::format::{FrameStatus, ACCEL_COUNTS_PER_G, GYRO_COUNTS_PER_DPS};
use wobble_hil::qemu::{self, decode, fixture, Scenario};

const FRAMES: u32 = 3000;
/// The card's configuration: the IMU's x to the left and its y backwards;
/// the potentiometer reading fewer counts to the left, not quite linear.
const CONFIG_TXT: &str = "imu.axis_map = -y, +x, +z
steering.three_point = 620:42, 2100:0, 3480:-38
";
/// Frame spacing tolerance: the sampler runs on 1 ms SysTick alarms with
/// 1 µs time stamps; a tick may be late by the card writes it preempts.
const SPACING_TOLERANCE_US: u64 = 1000;

#[test]
fn bundled_ride_logs_every_frame_fix_and_alert() {
    let bundle = qemu::bundle(FRAMES).expect("fixtures");
    let dir = qemu::work_dir(Path::new(env!("CARGO_TARGET_TMPDIR")), "ride").expect("dir");
    let setup = qemu::Setup {
        config: Some(CONFIG_TXT),
        ..bundle.setup(dir.clone(), Scenario::ride(FRAMES))
    };
    let config = setup.config().expect("configuration");
    assert_ne!(config, wobble_core::config::Config::default());
    let out = qemu::run(&setup, |_| Ok(()), |_| {}).expect("qemu run");
    assert_eq!(out.code, 0, "{:?}", out.lines);
    assert_eq!(
        out.fields("END")
            .and_then(|f| f.get("closed").cloned())
            .as_deref(),
        Some("true")
    );

    let logs = decode::logs(&out.card, &dir).expect("decode");
    assert_eq!(logs.len(), 1, "one file per power-on");
    let log = &logs[0];
    assert_eq!(log.name, "RUN00001.WBL");
    assert!(log.starts_with_header);
    // The header holds the configuration in force, complete and exact.
    let in_force = wobble_core::config::Config::parse(log.summary.config.join("\n").as_bytes());
    assert!(in_force.faults.is_empty(), "{:?}", in_force.faults);
    assert_eq!(in_force.config, config, "the card's CONFIG.TXT in force");

    // Exactly duration x 100 frames, 10 ms apart, no dropout.
    assert_eq!(log.frames.len(), FRAMES as usize);
    assert!(log.dropouts.is_empty() && log.stats.frames_lost == 0 && log.stats.damaged_blocks == 0);
    let worst_us = log
        .frames
        .windows(2)
        .map(|w| (w[1].t_us - w[0].t_us).abs_diff(fixture::FRAME_US))
        .max()
        .unwrap_or(0);
    assert!(
        worst_us <= SPACING_TOLERANCE_US,
        "spacing off by {worst_us} µs"
    );
    // The frames carry the ride's values: steering to the averaged ADC
    // resolution (the steepest calibration segment over half a count per
    // conversion) plus the card's 0.01 deg; the IMU to its noise and the
    // sensor's and the card's quantisation; speed once the wheel estimator
    // has a revolution of edges.
    let [a, b, c] = config.steering.three_point.expect("three points");
    let steepest = [(a, b), (b, c)]
        .map(|(p, q)| ((q.deg - p.deg) / (q.counts - p.counts)).abs())
        .into_iter()
        .fold(0.0f32, f32::max);
    let steer_tol = f64::from(steepest) * 0.5 / fixture::ADC_PER_FRAME as f64 + 0.005 + 1e-4;
    let sensor = icm42688::Config::default().imu_config(config.imu);
    let accel_tol = (fixture::IMU_NOISE_LSB + 0.5) * f64::from(sensor.accel_g_per_lsb)
        + 0.5 / f64::from(ACCEL_COUNTS_PER_G)
        + 1e-6;
    let gyro_tol = (fixture::IMU_NOISE_LSB + 0.5) * f64::from(sensor.gyro_dps_per_lsb)
        + 0.5 / f64::from(GYRO_COUNTS_PER_DPS)
        + 1e-6;
    let mut worst = [0.0f64; 3];
    for (k, f) in log.frames.iter().enumerate() {
        let row = bundle.ride.rows[k];
        let steer_err = (f64::from(f.steer_deg()) - f64::from(row.steer_deg)).abs();
        assert!(
            steer_err <= steer_tol,
            "frame {k}: steering off by {steer_err} deg"
        );
        let (accel_g, gyro_dps) = fixture::imu_truth(&row);
        for i in 0..3 {
            let accel_err = (f64::from(f.accel_g()[i]) - accel_g[i]).abs();
            let gyro_err = (f64::from(f.gyro_dps()[i]) - gyro_dps[i]).abs();
            assert!(
                accel_err <= accel_tol,
                "frame {k}: accel axis {i} off by {accel_err} g"
            );
            assert!(
                gyro_err <= gyro_tol,
                "frame {k}: gyro axis {i} off by {gyro_err} deg/s"
            );
            worst[1] = worst[1].max(accel_err);
            worst[2] = worst[2].max(gyro_err);
        }
        worst[0] = worst[0].max(steer_err);
        assert!(f.status.0 & (FrameStatus::IMU_FAULT | FrameStatus::STEER_SATURATED) == 0);
        if k >= 200 {
            assert!(
                (f.speed_mps() - row.speed_mps).abs() < 0.1,
                "frame {k}: {} m/s",
                f.speed_mps()
            );
        }
    }

    // GPS: the card's fixes against gpsd's own decoding of the capture, both
    // ways: every fix on the card is one gpsd reported (UTC to the ms,
    // position to 1e-7 deg), and every fix gpsd reported while the capture
    // was replayed is on the card.
    let gpsd = fixture::gpsd_fixes(qemu::GPS_CAPTURE).expect("gpsd output");
    let card: Vec<(String, f64, f64)> = log
        .fixes
        .iter()
        .filter_map(|f| {
            Some((
                wobblog::time::iso8601(f.utc?),
                f64::from(f.lat_e7?) / 1e7,
                f64::from(f.lon_e7?) / 1e7,
            ))
        })
        .collect();
    assert!(card.len() > 100, "{} fixes with a position", card.len());
    for (time, lat, lon) in &card {
        let theirs = gpsd
            .iter()
            .find(|g| &g.time == time)
            .unwrap_or_else(|| panic!("{time}: on the card, not in gpsd's output"));
        assert!(
            (theirs.lat_deg - lat).abs() <= 1e-7 && (theirs.lon_deg - lon).abs() <= 1e-7,
            "{time}: card {lat},{lon} gpsd {},{}",
            theirs.lat_deg,
            theirs.lon_deg
        );
    }
    let last = card.last().map(|c| c.0.clone()).unwrap_or_default();
    let replayed: Vec<&str> = gpsd
        .iter()
        .map(|g| g.time.as_str())
        .filter(|t| *t <= last.as_str())
        .collect();
    let on_card: Vec<&str> = card.iter().map(|c| c.0.as_str()).collect();
    assert_eq!(
        replayed, on_card,
        "gpsd's fixes up to {last} all on the card, in order"
    );
    let utc_ms: Vec<u64> = log
        .fixes
        .iter()
        .filter_map(|f| f.utc.map(|u| u.unix_ms()))
        .collect();
    assert!(
        utc_ms.windows(2).all(|w| w[1] - w[0] == 200),
        "fixes 200 ms apart"
    );
    assert!(log
        .frames
        .iter()
        .skip(200)
        .all(|f| !f.status.has(FrameStatus::GPS_STALE)));

    // Alerts: one per wobble episode, within the latency goal of the
    // ground truth and at its frequency, nowhere else; the card and the
    // live report agree.
    let ons: Vec<(u64, f64)> = log
        .alerts
        .iter()
        .filter(|a| a.on)
        .map(|a| (a.t_us, f64::from(a.freq_chz) / 100.0))
        .collect();
    bundle.check_alerts(&ons).expect("alerts meet the goals");
    assert_eq!(out.alert_ons().len(), ons.len());
    for (live, logged) in out.alert_ons().iter().zip(&ons) {
        assert_eq!(live.0, logged.0);
        assert!((live.1 - logged.1).abs() < 0.006, "{live:?} vs {logged:?}");
    }
    let live: Vec<(bool, u64)> = out.alerts();
    let logged: Vec<(bool, u64)> = log.alerts.iter().map(|a| (a.on, a.t_us)).collect();
    assert_eq!(live, logged);

    let fsck = qemu::card::fsck(&out.card).expect("fsck");
    assert_eq!(fsck.code, 0, "{}", fsck.text);
    assert!(fsck.problems().is_empty(), "{}", fsck.text);

    // The writer's card operations per iteration, counted by the core's
    // counting device on the semihosted card: within the queue's sizing,
    // and a flush with a block write happened.
    let writer_ops = out.number("WRITER", "ops_max").expect("WRITER line");
    assert!(
        (5..=u64::from(wobble_core::channels::WRITER_OPS_PER_ITERATION)).contains(&writer_ops),
        "{:?}",
        out.fields("WRITER")
    );
    // The card model's busy times and the semihosted transfers take
    // virtual time: the worst iteration took some.
    let busy_us = out.number("WRITER", "busy_max_us").expect("WRITER line");
    assert!(busy_us > 0);
    println!(
        "FIGURES writer: at most {writer_ops} card operations in an iteration while logging, {} \
         opening the card, longest iteration {} µs",
        out.number("WRITER", "open_ops_max").unwrap_or(0),
        busy_us,
    );
    let virtual_s = f64::from(FRAMES) / 100.0;
    println!(
        "FIGURES ride: virtual {virtual_s:.1} s in {:.2} s wall ({:.1}x), worst frame spacing error {worst_us} µs, \
         max tick lateness {} µs, queue high water {}; worst error against the ride: steering {:.4} deg, \
         accel {:.5} g, gyro {:.4} deg/s",
        out.wall.as_secs_f64(),
        virtual_s / out.wall.as_secs_f64(),
        out.number("END", "max_late_us").unwrap_or(0),
        out.number("END", "queue_high_water").unwrap_or(0),
        worst[0],
        worst[1],
        worst[2],
    );
}
