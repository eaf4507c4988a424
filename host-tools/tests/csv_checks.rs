//! CSV input that is not what it claims is refused with the file, line and
//! column, never stored clamped, zeroed or at the wrong rate.

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
        assert_refuses(dir, command, text, expected);
    }
}

/// Runs `wobblog COMMAND --csv` on `text`: it must fail with exit 1 and one
/// line naming the file, the line and `expected`; no log may appear.
fn assert_refuses(dir: &Path, command: &str, text: &str, expected: &str) {
    let csv = dir.join("in.csv");
    std::fs::write(&csv, text).unwrap();
    let log = dir.join("out.wbl");
    let mut cmd = wobblog();
    cmd.args([command, "--csv"]).arg(&csv);
    if command == "encode" {
        cmd.arg("-o").arg(&log);
    }
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{command}: {stderr}");
    assert!(stderr.contains(expected), "{command}: {stderr}");
    assert!(stderr.contains("in.csv: line "), "{command}: {stderr}");
    assert_eq!(stderr.lines().count(), 1, "{command}: {stderr}");
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
        assert_refuses(dir.path(), "encode", &text, expected);
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
