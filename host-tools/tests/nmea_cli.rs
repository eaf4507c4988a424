//! `wobblog nmea`: the firmware's GPS path over raw captures, as JSON lines.

use std::path::PathBuf;

use assert_cmd::Command;
use serde_json::Value;

fn wobblog() -> Command {
    Command::cargo_bin("wobblog").unwrap()
}

fn capture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../hil-tests/fixtures/gps")
        .join(name)
}

/// Runs `wobblog nmea FILE`; returns (exit code, stdout lines, stderr).
fn nmea(path: &std::path::Path) -> (Option<i32>, Vec<String>, String) {
    let out = wobblog().arg("nmea").arg(path).output().unwrap();
    let stdout = String::from_utf8(out.stdout).expect("UTF-8 output");
    let lines = stdout.lines().map(str::to_owned).collect();
    (
        out.status.code(),
        lines,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn fixes_as_json_lines_in_the_documented_format() {
    let (code, lines, stderr) = nmea(&capture("nmea-fuzzy-cases.log"));
    assert_eq!(code, Some(0), "{stderr}");
    // 14 epochs, one GGA + one RMC each.
    assert_eq!(lines.len(), 14);
    assert_eq!(
        lines[0],
        r#"{"time":"2020-03-18T13:28:20.600Z","lat":41.5749702,"lon":-93.7505586,"speed_mps":1.67,"course_deg":92.31,"alt_m":278.02,"fix":"3d","sats":9,"hdop":1.0}"#
    );
    assert!(stderr.is_empty(), "{stderr}");
}

#[test]
fn every_capture_replays_and_every_line_is_a_fix() {
    for (name, fixes) in [
        ("bu353s4.log", 25),
        ("garmin15x.log", 7),
        // Its power-up placeholder position 8960.000000 (minutes 60) is a
        // counted out-of-range fault, not six fixes without a mode.
        ("mtk-3301.log", 5),
        ("nmea-fuzzy-cases.log", 14),
        ("quectel-l76k-nmea.log", 151),
        ("skytraq-err.log", 0),
    ] {
        let (code, lines, stderr) = nmea(&capture(name));
        assert_eq!(code, Some(0), "{name}: {stderr}");
        assert_eq!(lines.len(), fixes, "{name}");
        for line in &lines {
            let v: Value = serde_json::from_str(line).unwrap();
            let mode = v["fix"].as_str().unwrap();
            assert!(["none", "2d", "3d"].contains(&mode), "{line}");
            // A fix without a mode carries no position, time or motion.
            if mode == "none" {
                for key in ["time", "lat", "lon", "speed_mps", "course_deg", "alt_m"] {
                    assert!(v.get(key).is_none(), "{name}: {line}");
                }
            }
        }
    }
}

#[test]
fn faults_are_summarised_on_stderr() {
    let (code, lines, stderr) = nmea(&capture("skytraq-err.log"));
    assert_eq!(code, Some(0));
    assert!(lines.is_empty());
    assert!(stderr.contains("skytraq-err.log"), "{stderr}");
    assert!(stderr.contains("lines without checksum: 6"), "{stderr}");
}

#[test]
fn comment_lines_are_skipped() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.log");
    let rmc = "$GPRMC,113258,A,3238.9148,N,10822.4466,W,005.3,247.1,181022,009.3,E*6B";
    std::fs::write(&path, format!("# {rmc}\n#{rmc}\n")).unwrap();
    let (code, lines, _) = nmea(&path);
    assert_eq!((code, lines.len()), (Some(0), 0));
    std::fs::write(&path, format!("# a comment\n{rmc}\r\n")).unwrap();
    let (code, lines, _) = nmea(&path);
    assert_eq!((code, lines.len()), (Some(0), 1));
    assert!(lines[0].contains(r#""fix":"2d""#), "{}", lines[0]);
}

#[test]
fn binary_garbage_is_not_a_crash() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("noise.bin");
    let mut x = 0x2545_f491_u32;
    let bytes: Vec<u8> = (0..200_000)
        .map(|_| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            // Plenty of `$`, `*`, `,` and line ends among the noise.
            match x % 16 {
                0 => b'$',
                1 => b'*',
                2 => b',',
                3 => b'\n',
                _ => (x >> 8) as u8,
            }
        })
        .collect();
    std::fs::write(&path, bytes).unwrap();
    let (code, lines, _) = nmea(&path);
    assert_eq!(code, Some(0));
    assert!(lines.is_empty());
}

#[test]
fn unreadable_input_exits_1_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.log");
    let (code, lines, stderr) = nmea(&missing);
    assert_eq!(code, Some(1));
    assert!(lines.is_empty());
    assert!(stderr.contains("nope.log"), "{stderr}");
    let (code, _, stderr) = nmea(dir.path());
    assert_eq!(code, Some(1));
    assert!(stderr.contains(&*dir.path().to_string_lossy()), "{stderr}");
}

#[test]
fn usage_errors_exit_2() {
    let out = wobblog().arg("nmea").output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let out = wobblog()
        .args(["nmea", "--baud", "0"])
        .arg(capture("garmin15x.log"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let out = wobblog()
        .args(["nmea", "--bogus"])
        .arg(capture("garmin15x.log"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}
