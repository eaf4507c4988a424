//! `wobblog detect` end to end: the corpus's Figure 6 fixture, output formats,
//! exit codes and error messages.

use std::path::PathBuf;

use assert_cmd::Command;

fn corpus(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../hil-tests/fixtures/corpus")
        .join(name)
}

fn wobblog() -> Command {
    Command::cargo_bin("wobblog").expect("wobblog binary")
}

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
    let p = dir.path().join(name);
    std::fs::write(&p, text).expect("write temp file");
    p
}

#[test]
fn figure6_fixture_alerts_once_with_json() {
    let out = wobblog()
        .args(["detect", "--json", "--csv"])
        .arg(corpus("wobble_fig6.csv"))
        .output()
        .expect("runs");
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    assert_eq!(lines.len(), 2, "{text}");
    assert_eq!(lines[0]["event"], "alert_on");
    let t_on = lines[0]["t_s"].as_f64().expect("t_s");
    let f = lines[0]["freq_hz"].as_f64().expect("freq_hz");
    let a = lines[0]["amp_deg"].as_f64().expect("amp_deg");
    // Ground truth (manifest.json): 6.4 Hz, envelope reaches 0.5 deg at 13.84 s.
    assert!((f - 6.4).abs() <= 0.25, "{f}");
    assert!(t_on > 13.0 && t_on < 13.84 + 0.6, "{t_on}");
    assert!(a >= 0.4, "{a}");
    assert_eq!(lines[1]["event"], "alert_off");
    assert!(lines[1].get("freq_hz").is_none());
    assert!(lines[1]["t_s"].as_f64().expect("t_s") > t_on);
}

#[test]
fn same_events_as_the_corpus_metrics() {
    // The human table and the JSON lines report the same changes.
    let json = wobblog()
        .args(["detect", "--json", "--csv"])
        .arg(corpus("ride_two_wobbles.csv"))
        .output()
        .expect("runs");
    let table = wobblog()
        .args(["detect", "--csv"])
        .arg(corpus("ride_two_wobbles.csv"))
        .output()
        .expect("runs");
    let json = String::from_utf8(json.stdout).expect("utf-8");
    let table = String::from_utf8(table.stdout).expect("utf-8");
    assert_eq!(json.lines().count(), 4, "{json}");
    assert_eq!(json.lines().filter(|l| l.contains("alert_on")).count(), 2);
    assert!(table
        .lines()
        .next()
        .is_some_and(|h| h.contains("event") && h.contains("freq_hz")));
    assert_eq!(table.lines().filter(|l| l.contains("alert_on")).count(), 2);
    assert!(
        table.trim_end().ends_with("(9000 samples, with speed)"),
        "{table}"
    );
}

#[test]
fn non_wobble_ride_prints_no_alerts_and_its_kicks() {
    let out = wobblog()
        .args(["detect", "--csv"])
        .arg(corpus("ride_kicks.csv"))
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).expect("utf-8");
    let summary = text.lines().last().unwrap_or("");
    assert!(
        summary.starts_with("no alerts over 119.99 s (12000 samples, with speed), "),
        "{text}"
    );
    assert!(!text.contains("alert_on"), "{text}");
    let out = wobblog()
        .args(["detect", "--json", "--csv"])
        .arg(corpus("ride_kicks.csv"))
        .output()
        .expect("runs");
    let text = String::from_utf8(out.stdout).expect("utf-8");
    // Every line is a kick the fixture holds (manifest.json: its times).
    let manifest: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(corpus("manifest.json")).expect("manifest"))
            .expect("JSON");
    let fixture = manifest["fixtures"]
        .as_array()
        .and_then(|f| f.iter().find(|f| f["name"] == "ride_kicks"))
        .expect("ride_kicks in the manifest");
    let true_kicks: Vec<f64> = fixture["events"]
        .as_array()
        .expect("events")
        .iter()
        .filter(|e| e["kind"] == "kick")
        .map(|e| e["t_s"].as_f64().expect("t_s"))
        .collect();
    let lines: Vec<serde_json::Value> = text
        .lines()
        .map(|l| serde_json::from_str(l).expect("each line is JSON"))
        .collect();
    assert!(!lines.is_empty(), "no kick measured");
    assert_eq!(summary.matches("kick").count(), 1, "{summary}");
    for l in &lines {
        assert_eq!(l["event"], "kick", "{l}");
        let t = l["t_s"].as_f64().expect("t_s");
        assert!(true_kicks.iter().any(|k| (k - t).abs() < 0.5), "{l}");
        for key in [
            "speed_mps",
            "freq_hz",
            "sigma_per_s",
            "amp_deg",
            "sigma_se_per_s",
        ] {
            assert!(l[key].is_number(), "{key} in {l}");
        }
    }
}

#[test]
fn steering_only_csv_works() {
    let dir = tempfile::tempdir().expect("tempdir");
    let text = std::fs::read_to_string(corpus("wobble_fig6.csv")).expect("fixture");
    let stripped: String = text
        .lines()
        .map(|l| {
            let mut cols = l.split(',');
            format!(
                "{},{}\n",
                cols.next().unwrap_or(""),
                cols.next().unwrap_or("")
            )
        })
        .collect();
    let p = write(&dir, "steer.csv", &stripped);
    let out = wobblog()
        .args(["detect", "--csv"])
        .arg(&p)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).expect("utf-8");
    assert!(
        text.contains("alert_on") && text.contains("steering only"),
        "{text}"
    );
}

#[test]
fn missing_file_is_exit_1_naming_it() {
    let out = wobblog()
        .args(["detect", "--csv", "/nonexistent/ride.csv"])
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("/nonexistent/ride.csv"), "{err}");
}

#[test]
fn malformed_rows_are_exit_1_naming_file_and_line() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cases = [
        ("noheader.csv", "1,2\n3,4\n", "line 1"),
        ("badnum.csv", "t_s,steer_deg\n0.00,1.0\n0.01,x\n", "line 3"),
        (
            "backwards.csv",
            "t_s,steer_deg\n0.02,1.0\n0.01,1.0\n",
            "line 3",
        ),
        (
            "fast.csv",
            "t_s,steer_deg\n0.000,1.0\n0.001,1.0\n",
            "100 Hz",
        ),
        ("binary.csv", "t_s,steer_deg\n0.00,\u{0}\u{1}\n", "line 2"),
    ];
    for (name, text, want) in cases {
        let p = write(&dir, name, text);
        let out = wobblog()
            .args(["detect", "--csv"])
            .arg(&p)
            .output()
            .expect("runs");
        assert_eq!(out.status.code(), Some(1), "{name}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(name) && err.contains(want), "{name}: {err}");
    }
    let p = dir.path().join("latin1.csv");
    std::fs::write(&p, b"t_s,steer_deg\n0.00,\xff\n").expect("write");
    let out = wobblog()
        .args(["detect", "--csv"])
        .arg(&p)
        .output()
        .expect("runs");
    assert_eq!(out.status.code(), Some(1));
}

#[test]
fn usage_errors_are_exit_2() {
    for args in [
        vec!["detect"],
        vec!["detect", "--csv"],
        vec!["detect", "--csv", "a", "--bogus"],
    ] {
        let out = wobblog().args(&args).output().expect("runs");
        assert_eq!(out.status.code(), Some(2), "{args:?}");
    }
}

#[test]
fn help_documents_the_output() {
    let out = wobblog().args(["detect", "--help"]).output().expect("runs");
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("alert_on") && text.contains("--json") && text.contains("Exit codes"));
}
