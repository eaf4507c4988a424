//! `wobblog detect LOG`: the on-board detector replayed on a card log with
//! the settings in its header, re-tuned with `--set`.

mod analysis_support;

use std::path::Path;

use analysis_support::{stdout_of, wobblog, write_log, Extras, Ride};
use wobble_core::config::Config;

/// The standard ride with `config` (CONFIG.TXT lines) in its header.
fn log_with(path: &Path, config: &[&str]) {
    let ride = Ride::new(30.0, 5.0, 15.0, 2.0, 0.5);
    let mut text = String::new();
    let loaded = Config::parse(config.join("\n").as_bytes());
    assert!(loaded.faults.is_empty());
    loaded.config.write_lines(&mut text).unwrap();
    let extras = Extras {
        config: text.lines().map(String::from).collect(),
        ..Extras::default()
    };
    write_log(path, &ride, &extras);
}

fn alerts(cmd: &mut assert_cmd::Command) -> Vec<String> {
    stdout_of(cmd.arg("--json"))
        .lines()
        .map(String::from)
        .collect()
}

#[test]
fn a_log_replays_like_its_decoded_csv() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    log_with(&log, &[]);
    let csv = dir.path().join("run.csv");
    wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&csv)
        .assert()
        .success();
    let from_log = alerts(wobblog().arg("detect").arg(&log));
    let from_csv = alerts(wobblog().arg("detect").arg("--csv").arg(&csv));
    assert!(!from_log.is_empty() && from_log[0].contains("alert_on"));
    assert_eq!(from_log, from_csv);
}

#[test]
fn the_header_settings_are_used_and_set_retunes_them() {
    let dir = tempfile::tempdir().unwrap();
    let deaf = dir.path().join("RUN00002.WBL");
    log_with(
        &deaf,
        &["detector.amp_on_deg=20", "detector.amp_off_deg=10"],
    );
    assert!(alerts(wobblog().arg("detect").arg(&deaf)).is_empty());
    let retuned = alerts(wobblog().arg("detect").arg(&deaf).args([
        "--set",
        "detector.amp_on_deg=0.5",
        "--set",
        "detector.amp_off_deg=0.3",
    ]));
    assert!(
        retuned.first().is_some_and(|l| l.contains("alert_on")),
        "{retuned:?}"
    );

    let out = wobblog()
        .arg("detect")
        .arg(&deaf)
        .args(["--set", "detector.no_such_key=1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("detector.no_such_key") && err.contains("unknown key"),
        "{err}"
    );
    let out = wobblog().arg("detect").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn a_rejected_set_line_is_a_usage_error_whatever_the_header_holds() {
    // Nine header lines the parser skips: more than the faults it keeps
    // with their line numbers, which once hid the `--set` line's fault.
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let mut config: Vec<String> = (0..9).map(|i| format!("detector.bogus_{i}=1")).collect();
    config.push("detector.amp_on_deg=20".into());
    let extras = Extras {
        config,
        ..Extras::default()
    };
    write_log(&log, &Ride::new(30.0, 5.0, 15.0, 2.0, 0.5), &extras);
    for set in [
        "detector.amp_on_deg=NaN",
        "detector.amp_on_deg=5x",
        "detector.amp_on_dge=5",
    ] {
        let out = wobblog()
            .arg("detect")
            .arg(&log)
            .args(["--set", set])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{set}: {err}");
        assert!(err.contains(&format!("--set {set}")), "{set}: {err}");
    }
    // The header's own usable line still holds: 20 degrees hears nothing.
    assert!(alerts(wobblog().arg("detect").arg(&log)).is_empty());
}
