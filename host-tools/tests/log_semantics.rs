//! Logs whose blocks pass their CRC but whose content is impossible: what
//! `wobblog` reports of them, and what it refuses to show as data.

mod analysis_support;

use std::path::Path;

use analysis_support::{info_json, wobblog};
use wobble_core::format::header::header_records;
use wobble_core::format::{BlockEncoder, FixMode, Frame, GpsFix, LogInfo, Record, UtcTime};

fn frame(t_us: u64) -> Record<'static> {
    Record::Frame(Frame {
        t_us,
        ..Frame::default()
    })
}

fn info(firmware: &str, sample_rate_hz: u16) -> LogInfo<'_> {
    LogInfo {
        t_us: 0,
        firmware,
        device_id: [7; 12],
        sample_rate_hz,
        run: 1,
    }
}

/// Writes the header of `info` with `config`, then `records`, to `path`.
fn write_log<'a>(
    path: &Path,
    info: LogInfo<'a>,
    config: &'a [&'a str],
    records: impl IntoIterator<Item = Record<'a>>,
) {
    let mut enc = BlockEncoder::new();
    let mut file = Vec::new();
    for r in header_records(info, config.iter().copied()).chain(records) {
        if let Some(b) = enc.push(&r).unwrap() {
            file.extend_from_slice(b);
        }
    }
    if let Some(b) = enc.finish() {
        file.extend_from_slice(b);
    }
    std::fs::write(path, file).unwrap();
}

const DAY_US: u64 = 86_400_000_000;

#[test]
fn a_forward_jump_of_days_is_counted_and_left_out_of_the_duration() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("jump.wbl");
    let frames = (0..1500)
        .map(|i| frame(i * 10_000))
        .chain((0..1500).map(|i| frame(3 * DAY_US + i * 10_000)));
    write_log(&log, info("fw", 100), &[], frames);
    let j = info_json(&log);
    assert_eq!(j["samples"], 3000);
    assert_eq!(j["duration_s"], 30.0);
    assert_eq!(j["segments"], 2);
    assert_eq!(j["forward_time_jumps"], 1);
    assert_eq!(j["losses"]["time_jumps"][0][0], 14.99);
    assert_eq!(j["losses"]["time_jumps"][0][1], 259_200.0);

    let text = wobblog().arg("info").arg(&log).output().unwrap();
    let text = String::from_utf8(text.stdout).unwrap();
    assert!(text.contains("duration:     30.00 s (2 segments"), "{text}");
    assert!(text.contains("time jumps:   0 back, 1 forward"), "{text}");
    assert!(
        text.contains("time jumps forward from 14.990000 s to 259200.000000 s"),
        "{text}"
    );
}

/// `front.wbl` in `dir`: a block of 20 frames at 2^62 µs, then 30 s of
/// frames from 0 s.
fn front_log(dir: &std::path::Path) -> std::path::PathBuf {
    let log = dir.join("front.wbl");
    let far = 1u64 << 62;
    let frames = (0..20)
        .map(|i| frame(far + i * 10_000))
        .chain((0..3000).map(|i| frame(i * 10_000)));
    write_log(&log, info("fw", 100), &[], frames);
    log
}

#[test]
fn a_block_of_far_future_frames_in_front_holds_nothing_back() {
    let dir = tempfile::tempdir().unwrap();
    let log = front_log(dir.path());
    let j = info_json(&log);
    assert_eq!(j["time_jumps"], 1);
    assert_eq!(j["segments"], 2);
    assert!(
        (j["duration_s"].as_f64().unwrap() - 30.2).abs() < 1e-9,
        "{j}"
    );
    let out = wobblog().arg("decode").arg(&log).output().unwrap();
    assert!(out.status.success());
    assert_eq!(out.stdout.iter().filter(|&&b| b == b'\n').count(), 1 + 3020);
}

#[test]
fn a_clock_that_jumps_at_every_block_warns_in_a_few_lines() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("jumps.wbl");
    // A day forward every 50 frames.
    let frames = (0..5000u64).map(|i| frame((i / 50) * 86_400_000_000 + i * 10_000));
    write_log(&log, info("fw", 100), &[], frames);
    assert_eq!(info_json(&log)["forward_time_jumps"], 99);
    for (command, output) in [("plot", "jumps.png"), ("decode", "jumps.csv")] {
        let out = wobblog()
            .arg(command)
            .arg(&log)
            .arg("-o")
            .arg(dir.path().join(output))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{command}: {stderr}");
        assert_eq!(
            stderr.matches("time jumps forward").count(),
            10,
            "{command}: {stderr}"
        );
        assert!(
            stderr.contains("more losses not shown here"),
            "{command}: {stderr}"
        );
        assert!(stderr.lines().count() <= 12, "{command}: {stderr}");
    }
}

#[test]
fn a_run_behind_far_future_frames_is_plotted_over_its_own_stretch() {
    let dir = tempfile::tempdir().unwrap();
    let log = front_log(dir.path());
    let png = dir.path().join("front.png");
    let out = wobblog()
        .arg("plot")
        .arg(&log)
        .arg("-o")
        .arg(&png)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("plotting its longest stretch, 0.00 to 29.99 s (3000 of 3020 frames)"),
        "{stderr}"
    );
    assert!(std::fs::metadata(&png).unwrap().len() > 0);
    // One back jump: one warning of it, and nothing held back.
    assert_eq!(stderr.matches("time jumps back").count(), 1, "{stderr}");
    // A window asked for is plotted where it lies, without the warning.
    let window = dir.path().join("window.png");
    let out = wobblog()
        .arg("plot")
        .arg(&log)
        .args(["--from", "5", "--to", "10", "-o"])
        .arg(&window)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("longest stretch"), "{stderr}");
}

#[test]
fn an_impossible_sample_rate_is_reported_and_the_default_used() {
    let dir = tempfile::tempdir().unwrap();
    for rate in [0u16, 65_535] {
        let log = dir.path().join(format!("rate{rate}.wbl"));
        write_log(
            &log,
            info("fw", rate),
            &[],
            (0..500).map(|i| frame(i * 10_000)),
        );
        let j = info_json(&log);
        assert_eq!(j["sample_rate_hz"], 100);
        assert_eq!(j["out_of_range"], 1);
        assert_eq!(j["duration_s"], 5.0);
        let out = wobblog().arg("info").arg(&log).output().unwrap();
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(
            text.contains(&format!(
                "sample rate {rate} Hz is not one the logger runs at; 100 Hz used"
            )),
            "{text}"
        );
    }
}

#[test]
fn gps_values_off_the_globe_never_reach_gpx_or_info() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("gps.wbl");
    let fix = |t_us, lat_e7: i32, lon_e7: i32, ms_of_day| {
        Record::Gps(GpsFix {
            t_us,
            utc: Some(UtcTime {
                // 2016-12-31, a day that ended with a leap second.
                days_since_2000: 6_209,
                ms_of_day,
            }),
            lat_e7: Some(lat_e7),
            lon_e7: Some(lon_e7),
            fix: FixMode::Fix3d,
            ..GpsFix::default()
        })
    };
    let records = vec![
        fix(0, 2_147_000_000, 10_000_000, 4_294_000_000),
        fix(10_000, 910_000_000, 10_000_000, 1000),
        fix(20_000, 10_000_000, 1_810_000_000, 2000),
        frame(30_000),
        fix(40_000, 522_000_000, 68_800_000, 86_400_500),
        frame(50_000),
    ];
    write_log(&log, info("fw", 100), &[], records);
    let j = info_json(&log);
    assert_eq!(j["out_of_range"], 3);
    // No sync pair: the frames have no UTC, in `info` as in `decode`.
    assert!(j["first_utc"].is_null() && j["last_utc"].is_null(), "{j}");
    let gpx = wobblog().arg("gpx").arg(&log).output().unwrap();
    let gpx = String::from_utf8(gpx.stdout).unwrap();
    assert_eq!(gpx.matches("<trkpt").count(), 1, "{gpx}");
    assert!(gpx.contains(r#"lat="52.2000000""#), "{gpx}");
    // A leap second is written as one.
    assert!(gpx.contains("T23:59:60.500Z"), "{gpx}");
}

#[test]
fn control_characters_from_the_log_are_shown_escaped() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("esc.wbl");
    write_log(
        &log,
        info("fw\u{1b}]0;owned\u{7}\u{1b}[2J\u{9b}2J\u{202e}", 100),
        &["alert.enabled=true\u{1b}[31m"],
        (0..100).map(|i| frame(i * 10_000)),
    );
    for args in [&["info"][..], &["info", "--json"], &["config"]] {
        let out = wobblog().args(args).arg(&log).output().unwrap();
        assert!(
            !out.stdout.iter().any(|&b| b == 0x1b || b == 0x07),
            "{args:?}: raw control bytes reach the terminal"
        );
        let text = String::from_utf8_lossy(&out.stdout);
        assert!(
            !text.contains(['\u{9b}', '\u{202e}']),
            "{args:?}: a C1 control or a bidi override reaches the terminal: {text}"
        );
        if args == ["info", "--json"] {
            // The JSON value is still the log's exact string.
            let json: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert_eq!(
                json["firmware"], "fw\u{1b}]0;owned\u{7}\u{1b}[2J\u{9b}2J\u{202e}",
                "{text}"
            );
        } else {
            assert!(text.contains("fw\\u{1b}]0;owned\\u{7}"), "{args:?}: {text}");
        }
    }
}
