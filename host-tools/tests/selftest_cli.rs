//! `wobblog selftest`: a report the firmware's own writer made is printed
//! check by check with the failures named; anything else is a clear error.

use std::path::Path;

use assert_cmd::Command;
use wobble_core::boot::{BorCheck, ResetCause};
use wobble_core::selftest::{write_report, Measurements, PulseTrain};

fn run(path: &Path) -> (Option<i32>, String, String) {
    let out = Command::cargo_bin("wobblog")
        .unwrap()
        .arg("selftest")
        .arg(path)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8(out.stdout).unwrap(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn a_report_is_printed_with_its_failures_named() {
    let mut data_ready = PulseTrain::default();
    for k in 0..100u64 {
        data_ready.pulse(2_000_000 + k * 10_000);
    }
    let m = Measurements {
        imu_id: Some(0x47),
        accel_g: Some(0.99),
        steer_counts: Some((1500, 2500)),
        wheel_edges: 0,
        gps_baud: Some(38_400),
        gps_rate_hz: 20,
        card_kib_s: Some((700, 1500)),
        card_free_mib: 7_000,
        card_unusable: false,
        crystal: true,
        reset: Some(ResetCause::Watchdog),
        bor: Some(BorCheck::Level3),
        stack_bytes: Some((14_000, 86_000)),
        imu_data_ready: Some(data_ready),
    };
    let mut text = String::new();
    write_report(&m, &mut text).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("SELFTEST.TXT");
    std::fs::write(&path, &text).unwrap();
    let (code, stdout, stderr) = run(&path);
    // A failed check fails the command.
    assert_eq!(code, Some(1), "{stderr}");
    assert!(stderr.contains("SELFTEST.TXT: 2 checks failed"), "{stderr}");
    let lines: Vec<&str> = stdout.lines().collect();
    assert_eq!(lines.len(), 11, "{stdout}");
    assert!(
        lines[0].starts_with("imu       pass  who_am_i=0x47"),
        "{stdout}"
    );
    assert!(lines[2].starts_with("wheel     FAIL  edges=0"), "{stdout}");
    assert_eq!(lines[7], "bor       pass  level=3 (2.7 V)");
    assert_eq!(lines[8], "stack     pass  used=14000 of 86000 bytes");
    assert_eq!(
        lines[9],
        "imu_drdy  pass  pulses=100 period_us=10000 longest_gap_us=10000"
    );
    assert_eq!(
        lines[10],
        "failed: wheel, reset (see firmware/docs/board.md, bring-up)"
    );
    // The input is never touched.
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
}

#[test]
fn a_file_that_is_no_report_is_an_error_naming_it() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("CONFIG.TXT");
    std::fs::write(&path, "wheel.circumference_m=2.1\n").unwrap();
    let (code, stdout, stderr) = run(&path);
    assert_eq!(code, Some(1));
    assert!(stdout.is_empty());
    assert!(
        stderr.contains("CONFIG.TXT: not a self-test report"),
        "{stderr}"
    );
    let (code, _, stderr) = run(&dir.path().join("missing.txt"));
    assert_eq!(code, Some(1));
    assert!(stderr.contains("missing.txt"), "{stderr}");
}

/// The `text` blocks of `firmware/docs/board.md` after `marker`.
fn block_after(marker: &str) -> String {
    let doc = include_str!("../../firmware/docs/board.md");
    let from = doc.find(marker).expect("the marker is in board.md");
    let rest = &doc[from..];
    let start = rest.find("```text\n").unwrap() + "```text\n".len();
    rest[start..start + rest[start..].find("```").unwrap()].to_string()
}

#[test]
fn the_documented_report_reads_as_documented() {
    let file = block_after("`SELFTEST.TXT` itself is plain text");
    let printed = block_after("Read the report on a PC");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("SELFTEST.TXT");
    std::fs::write(&path, &file).unwrap();
    let (code, stdout, stderr) = run(&path);
    assert_eq!(code, Some(1), "{stderr}");
    assert_eq!(stdout, printed);
    let passing = file.replace("wheel FAIL edges=0", "wheel PASS edges=50");
    std::fs::write(&path, passing).unwrap();
    let (code, stdout, _) = run(&path);
    assert_eq!(code, Some(0));
    assert!(
        stdout.ends_with("all checks passed: ready to ride\n"),
        "{stdout}"
    );
}
