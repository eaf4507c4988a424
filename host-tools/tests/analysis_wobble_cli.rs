//! `wobblog wobble`: episodes of a synthetic ride with a known wobble, and
//! what happens with damaged and unreadable logs.

mod analysis_support;

use analysis_support::{stdout_of, wobble, wobblog};
use serde_json::Value;

fn unstable(report: &Value) -> Vec<&Value> {
    report["episodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|e| e["stability"] == "unstable")
        .collect()
}

fn check_known_wobble(report: &Value) {
    let found = unstable(report);
    assert_eq!(found.len(), 1, "{report:#}");
    let e = found[0];
    let f = |k: &str| e[k].as_f64().unwrap();
    assert!((f("freq_hz") - wobble::FREQ_HZ).abs() < 0.1, "{e}");
    assert!(
        (f("sigma_per_s") / wobble::SIGMA_PER_S - 1.0).abs() < 0.2,
        "{e}"
    );
    assert!((f("onset_s") - wobble::ONSET_S).abs() < 0.2, "{e}");
    assert!((f("speed_at_onset_mps") - 5.0).abs() < 0.1, "{e}");
    assert!((f("peak_s") - wobble::peak_s()).abs() < 0.3, "{e}");
    assert_eq!(
        report["wobble_speed_mps"].as_f64(),
        Some(f("speed_at_onset_mps"))
    );
}

#[test]
fn known_wobble_is_measured() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let json = stdout_of(wobblog().arg("wobble").arg(&log).arg("--json"));
    let report: Value = serde_json::from_str(&json).unwrap();
    check_known_wobble(&report);

    let text = stdout_of(wobblog().arg("wobble").arg(&log));
    assert!(text.contains("wobble speed 5.00 m/s"), "{text}");
    assert!(text.contains(": 1 episode, "), "{text}");
    // The table's names and values are the JSON's.
    assert!(
        text.contains("peak_amp_deg  speed_at_onset_mps  stability"),
        "{text}"
    );
    assert!(text.trim_end().ends_with("unstable   episode"), "{text}");
}

#[test]
fn damaged_log_is_analysed_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let mut bytes = std::fs::read(&log).unwrap();
    // A block a few seconds into the ride, well before the wobble.
    bytes[20 * 512 + 77] ^= 0x10;
    std::fs::write(&log, &bytes).unwrap();
    let out = wobblog()
        .arg("wobble")
        .arg(&log)
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("RUN00003.WBL") && stderr.contains("warning"),
        "{stderr}"
    );
    check_known_wobble(&serde_json::from_slice(&out.stdout).unwrap());
}

#[test]
fn unreadable_log_is_named_and_the_others_still_reported() {
    let dir = tempfile::tempdir().unwrap();
    let good = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&good);
    let junk = dir.path().join("JUNK.WBL");
    std::fs::write(&junk, vec![0x55u8; 4096]).unwrap();
    let missing = dir.path().join("MISSING.WBL");
    let out = wobblog()
        .args(["wobble", "--json"])
        .arg(&junk)
        .arg(&good)
        .arg(&missing)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("JUNK.WBL") && stderr.contains("MISSING.WBL"),
        "{stderr}"
    );
    assert!(stderr.contains("2 of 3 logs"), "{stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1);
    check_known_wobble(&serde_json::from_str(stdout.trim()).unwrap());
}

#[test]
fn no_logs_is_a_usage_error() {
    wobblog().arg("wobble").assert().code(2);
}
