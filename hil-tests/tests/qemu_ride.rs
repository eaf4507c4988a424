//! The bundled ride end to end under QEMU: the firmware's tasks sample the
//! Figure-6 ride for 30 s of virtual time while replaying a real 5 Hz NMEA
//! capture; the card image must hold every frame on time, the capture's
//! fixes, the alert where the ground truth has the wobble, and a clean FAT.

use std::path::Path;

use wobble_core::format::FrameStatus;
use wobble_hil::qemu::{self, decode, fixture, Scenario};

const FRAMES: u32 = 3000;
/// Frame spacing tolerance: the sampler runs on 1 ms SysTick alarms with
/// 1 µs time stamps; a tick may be late by the card writes it preempts.
const SPACING_TOLERANCE_US: u64 = 1000;

#[test]
fn bundled_ride_logs_every_frame_fix_and_alert() {
    let bundle = qemu::bundle(FRAMES).expect("fixtures");
    let dir = qemu::work_dir(Path::new(env!("CARGO_TARGET_TMPDIR")), "ride").expect("dir");
    let setup = bundle.setup(dir.clone(), Scenario::ride(FRAMES));
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
    assert_eq!(in_force.config, wobble_core::config::Config::default());

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
    // The frames carry the replayed signals: steering exactly, speed once
    // the wheel estimator has a revolution of edges.
    for (k, f) in log.frames.iter().enumerate() {
        let row = bundle.ride.rows[k];
        assert_eq!(
            f.steer_cdeg,
            (f64::from(row.steer_deg) * 100.0).round() as i16,
            "frame {k}"
        );
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

    let virtual_s = f64::from(FRAMES) / 100.0;
    println!(
        "FIGURES ride: virtual {virtual_s:.1} s in {:.2} s wall ({:.1}x), worst frame spacing error {worst_us} µs, \
         max tick lateness {} µs, queue high water {}",
        out.wall.as_secs_f64(),
        virtual_s / out.wall.as_secs_f64(),
        out.number("END", "max_late_us").unwrap_or(0),
        out.number("END", "queue_high_water").unwrap_or(0),
    );
}
