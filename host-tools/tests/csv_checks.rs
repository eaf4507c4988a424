//! CSV input that is not what it claims is refused with the file, line and
//! column, never stored clamped (unless `--clip` asks, and then said),
//! zeroed or at the wrong rate.

use assert_cmd::Command;
use std::path::Path;

fn wobblog() -> Command {
    Command::cargo_bin("wobblog").unwrap()
}

/// `n` rows of `t_s,steer_deg,speed_mps` at `rate_hz`.
fn rows(n: usize, rate_hz: f64) -> Vec<String> {
    (0..n)
        .map(|i| format!("{},{:.2},4.0", i as f64 / rate_hz, (i as f64 * 0.4).sin()))
        .collect()
}

fn csv_text(rows: &[String]) -> String {
    let mut s = String::from("t_s,steer_deg,speed_mps\n");
    for r in rows {
        s.push_str(r);
        s.push('\n');
    }
    s
}

/// Runs `encode` and `detect` on `text`; both must fail with exit 1 and a
/// message holding `expected`; no log may appear.
fn assert_both_refuse(dir: &Path, text: &str, expected: &str) {
    for command in ["encode", "detect"] {
        assert_refuses(dir, &[command], text, expected);
    }
}

/// Runs `wobblog COMMAND... --csv` on `text`: it must fail with exit 1 and
/// one line naming the file, the line and `expected`; no log may appear.
fn assert_refuses(dir: &Path, command: &[&str], text: &str, expected: &str) {
    let csv = dir.join("in.csv");
    std::fs::write(&csv, text).unwrap();
    let log = dir.join("out.wbl");
    let mut cmd = wobblog();
    cmd.args(command).arg("--csv").arg(&csv);
    if command[0] == "encode" {
        cmd.arg("-o").arg(&log);
    }
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{command:?}: {stderr}");
    assert!(stderr.contains(expected), "{command:?}: {stderr}");
    assert!(stderr.contains("in.csv: line "), "{command:?}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{command:?}: {stderr}");
    assert!(!log.exists());
}

/// A `utc` column `encode` cannot turn into sync pairs.
#[test]
fn utc_that_cannot_be_stored_names_the_cell() {
    let dir = tempfile::tempdir().unwrap();
    for (rows, expected) in [
        (
            "0.01,1,2020-03-18T10:00:01Z\n0.02,1,yesterday\n",
            "line 3, column 3: `utc` is not a UTC time",
        ),
        (
            "0.01,1,2020-03-18T10:00:01Z\n0.02,1,\n",
            "line 3, column 3: `utc` is empty after a row with a UTC",
        ),
        (
            "0.01,1,2150-01-01T00:00:00Z\n",
            "line 2, column 3: `utc` is outside the years",
        ),
    ] {
        let text = format!("t_s,steer_deg,utc\n{rows}");
        assert_refuses(dir.path(), &["encode"], &text, expected);
    }
}

#[test]
fn a_csv_at_another_rate_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    assert_both_refuse(
        dir.path(),
        &csv_text(&rows(100, 200.0)),
        "line 3, column 1: `t_s` steps by 0.005 s, about 200 Hz, but a log is sampled at 100 Hz",
    );
    assert_both_refuse(dir.path(), &csv_text(&rows(100, 50.0)), "about 50 Hz");
    assert_both_refuse(dir.path(), &csv_text(&rows(100, 50.0)), "line 5, column 1");
}

#[test]
fn time_going_backwards_or_repeating_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut r = rows(20, 100.0);
    r[10] = "0.05,0.0,4.0".into();
    assert_both_refuse(
        dir.path(),
        &csv_text(&r),
        "line 12, column 1: `t_s` 0.05 does not come after 0.09 (line 11): time goes backwards",
    );
    let mut r = rows(20, 100.0);
    r[10] = "0.09,0.0,4.0".into();
    assert_both_refuse(dir.path(), &csv_text(&r), "time repeats");
}

#[test]
fn values_the_log_cannot_store_are_refused_not_clamped() {
    let dir = tempfile::tempdir().unwrap();
    for (row, expected) in [
        ("0.05,NaN,4.0", "line 7, column 2: `steer_deg` is NaN"),
        ("0.05,inf,4.0", "line 7, column 2: `steer_deg` is inf"),
        ("0.05,-inf,4.0", "`steer_deg` is -inf"),
        (
            "0.05,1e9,4.0",
            "`steer_deg` is 1000000000, outside what the log stores",
        ),
        (
            "0.05,1.0,-3",
            "line 7, column 3: `speed_mps` is -3, outside what the log stores",
        ),
        ("0.05,1.0,70", "`speed_mps` is 70, outside"),
    ] {
        let mut r = rows(20, 100.0);
        r[5] = row.into();
        let csv = dir.path().join("in.csv");
        std::fs::write(&csv, csv_text(&r)).unwrap();
        let out = wobblog()
            .args(["encode", "--csv"])
            .arg(&csv)
            .arg("-o")
            .arg(dir.path().join("x.wbl"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{row}: {stderr}");
        assert!(stderr.contains(expected), "{row}: {stderr}");
    }
    // The detector takes any finite steering angle, but never NaN.
    let mut r = rows(20, 100.0);
    r[5] = "0.05,NaN,4.0".into();
    let csv = dir.path().join("nan.csv");
    std::fs::write(&csv, csv_text(&r)).unwrap();
    let out = wobblog()
        .args(["detect", "--csv"])
        .arg(&csv)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("line 7, column 2: `steer_deg` is NaN"));
}

#[test]
fn gps_positions_outside_the_globe_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    for (cells, expected) in [
        ("91,6.88,3d", "column 4: `gps_lat_deg` is 91, outside"),
        ("52.2,-181,3d", "column 5: `gps_lon_deg` is -181, outside"),
        ("52.2,6.88,4d", "column 6: `gps_fix` must be 2d, 3d or none"),
    ] {
        let mut csv = String::from("t_s,steer_deg,speed_mps,gps_lat_deg,gps_lon_deg,gps_fix\n");
        for i in 0..10 {
            csv.push_str(&format!("{},0,4,{cells}\n", f64::from(i) / 100.0));
        }
        let path = dir.path().join("gps.csv");
        std::fs::write(&path, csv).unwrap();
        let out = wobblog()
            .args(["encode", "--csv"])
            .arg(&path)
            .arg("-o")
            .arg(dir.path().join("x.wbl"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{stderr}");
        assert!(
            stderr.contains(&format!("gps.csv: line 2, {expected}")),
            "{stderr}"
        );
    }
}

#[test]
fn a_gap_between_frames_is_kept_not_refused() {
    let dir = tempfile::tempdir().unwrap();
    let mut r = rows(10, 100.0);
    r.extend((0..10).map(|i| format!("{},0.0,4.0", 5.0 + f64::from(i) / 100.0)));
    let csv = dir.path().join("gap.csv");
    std::fs::write(&csv, csv_text(&r)).unwrap();
    let log = dir.path().join("gap.wbl");
    wobblog()
        .args(["encode", "--csv"])
        .arg(&csv)
        .arg("-o")
        .arg(&log)
        .assert()
        .success();
    let out = wobblog()
        .args(["detect", "--csv"])
        .arg(&csv)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("line 12: time gap; detector restarted"),
        "{stderr}"
    );
}

/// `t_s,steer_deg` rows of the decoded log `encode --resample` makes of
/// `text`.
fn resampled(dir: &Path, text: &str) -> Vec<(f64, f64)> {
    let csv = dir.join("fast.csv");
    std::fs::write(&csv, text).unwrap();
    let log = dir.join("fast.wbl");
    wobblog()
        .args(["encode", "--resample", "--csv"])
        .arg(&csv)
        .arg("-o")
        .arg(&log)
        .assert()
        .success();
    let out = wobblog()
        .arg("decode")
        .arg(&log)
        .args(["--columns", "t_s,steer_deg"])
        .output()
        .unwrap();
    assert!(out.status.success());
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let (t, s) = l.split_once(',').unwrap();
            (t.parse().unwrap(), s.parse().unwrap())
        })
        .collect()
}

/// A 7 Hz steering sine of 1 degree at `rate_hz` from 0 to `end_s`.
fn sine_rows(rate_hz: f64, end_s: f64) -> Vec<String> {
    let n = (end_s * rate_hz).round() as usize;
    (0..=n)
        .map(|i| {
            let t = i as f64 / rate_hz;
            format!("{t},{:.2},4.0", (std::f64::consts::TAU * 7.0 * t).sin())
        })
        .collect()
}

/// With `--resample`, a CSV at 200 Hz or 50 Hz becomes 100 Hz frames on the
/// grid of its first row, each within quantisation and interpolation error
/// of the signal.
#[test]
fn resample_takes_other_rates_onto_the_log_rate() {
    let dir = tempfile::tempdir().unwrap();
    // Linear interpolation of a 7 Hz sine misses by at most
    // (dt^2 / 8) (2 pi 7)^2: 0.006 deg at 200 Hz, 0.1 deg at 50 Hz.
    for (rate_hz, tolerance) in [(200.0, 0.015), (50.0, 0.11)] {
        let frames = resampled(dir.path(), &csv_text(&sine_rows(rate_hz, 3.0)));
        assert_eq!(frames.len(), 301, "{rate_hz} Hz");
        for (k, &(t, steer)) in frames.iter().enumerate() {
            assert!((t - k as f64 / 100.0).abs() < 1e-9, "{rate_hz} Hz: {t}");
            let truth = (std::f64::consts::TAU * 7.0 * t).sin();
            assert!(
                (steer - truth).abs() <= tolerance,
                "{rate_hz} Hz at {t}: {steer}"
            );
        }
    }
}

/// Rows more than 0.1 s apart are a gap: `--resample` makes no frame in it.
#[test]
fn resample_leaves_gaps_empty() {
    let dir = tempfile::tempdir().unwrap();
    let mut rows = sine_rows(200.0, 1.0);
    rows.extend(sine_rows(200.0, 1.0).iter().map(|r| {
        let (t, rest) = r.split_once(',').unwrap();
        format!("{},{rest}", 3.0 + t.parse::<f64>().unwrap())
    }));
    let frames = resampled(dir.path(), &csv_text(&rows));
    assert_eq!(frames.len(), 2 * 101);
    assert!(frames.iter().all(|&(t, _)| !(1.001..2.999).contains(&t)));
    assert!(frames.iter().any(|&(t, _)| (t - 3.0).abs() < 1e-9));
}

/// `--resample` takes any rate, never time that stands still or goes back,
/// nor values the log cannot store.
#[test]
fn resample_still_refuses_what_cannot_be_a_log() {
    let dir = tempfile::tempdir().unwrap();
    for (text, expected) in [
        (
            "t_s,steer_deg\n0,0\n0.005,1\n0.004,2\n",
            "line 4, column 1: `t_s` 0.004 does not come after 0.005 (line 3): time goes backwards",
        ),
        ("t_s,steer_deg\n0,0\n0.005,NaN\n", "line 3, column 2"),
    ] {
        assert_refuses(dir.path(), &["encode", "--resample"], text, expected);
    }
}

#[test]
fn a_time_jump_the_encoder_cannot_hold_names_its_line() {
    // 1e13 s is inside what a log's times may be, but no block can hold a
    // step of more than 2^63 us from its time base.
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("jump.csv");
    std::fs::write(
        &csv,
        "t_s,steer_deg\n0,1\n0.01,1\n0.02,1\n10000000000000,1\n",
    )
    .unwrap();
    let out = wobblog()
        .args(["encode", "--csv"])
        .arg(&csv)
        .arg("-o")
        .arg(dir.path().join("jump.WBL"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("jump.csv: line 5: "), "{err}");
}

/// With `--clip`, a foreign CSV's out-of-range numbers (a GPS speed of
/// -0.01 m/s, a speed beyond the log's range) are clamped, each column's
/// count and largest change said on stderr, and the decoded log holds the
/// clamped values; NaN and text are still refused.
#[test]
fn clip_clamps_out_of_range_numbers_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let mut text =
        String::from("t_s,steer_deg,speed_mps,gps_lat_deg,gps_lon_deg,gps_speed_mps,gps_fix\n");
    for i in 0..20 {
        let t = f64::from(i) / 100.0;
        let (speed, gps_speed) = match i {
            5 => ("70", "-0.01"),
            6 => ("4.0", "-0.004"),
            _ => ("4.0", "1.0"),
        };
        text.push_str(&format!("{t},0.5,{speed},52.0,4.3,{gps_speed},3d\n"));
    }
    let csv = dir.path().join("foreign.csv");
    std::fs::write(&csv, &text).unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let encode = |extra: &[&str]| {
        wobblog()
            .args(["encode", "--csv"])
            .arg(&csv)
            .arg("-o")
            .arg(&log)
            .args(extra)
            .output()
            .unwrap()
    };
    let refused = encode(&[]);
    assert_eq!(refused.status.code(), Some(1));
    assert!(!log.exists());
    let out = encode(&["--clip"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(
        stderr.contains("foreign.csv: --clip: 1 cell of `speed_mps` outside what the log stores, clamped (by 4.465 at most)"),
        "{stderr}"
    );
    assert!(
        stderr.contains("--clip: 2 cells of `gps_speed_mps` outside what the log stores, clamped (by 0.01 at most)"),
        "{stderr}"
    );
    let decoded = dir.path().join("out.csv");
    let out = wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&decoded)
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = std::fs::read_to_string(&decoded).unwrap();
    let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let row: Vec<&str> = text.lines().nth(6).unwrap().split(',').collect();
    assert_eq!(
        row[col("speed_mps")].parse::<f64>().unwrap(),
        65.535,
        "{text}"
    );
    assert_eq!(
        row[col("gps_speed_mps")].parse::<f64>().unwrap(),
        0.0,
        "{text}"
    );
    // NaN is no number to clamp.
    std::fs::remove_file(&log).unwrap();
    std::fs::write(&csv, text_with_nan()).unwrap();
    let out = encode(&["--clip"]);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("`steer_deg` is NaN"));
    assert!(!log.exists());
}

fn text_with_nan() -> String {
    let mut r = rows(20, 100.0);
    r[5] = "0.05,NaN,4.0".into();
    csv_text(&r)
}

/// `--run` states the run number in the log's header.
#[test]
fn run_sets_the_headers_run_number() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("in.csv");
    std::fs::write(&csv, csv_text(&rows(50, 100.0))).unwrap();
    let log = dir.path().join("RUN00042.WBL");
    let out = wobblog()
        .args(["encode", "--run", "42", "--csv"])
        .arg(&csv)
        .arg("-o")
        .arg(&log)
        .output()
        .unwrap();
    assert!(out.status.success());
    let out = wobblog()
        .args(["info", "--json"])
        .arg(&log)
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["run"], 42, "{v}");
}
