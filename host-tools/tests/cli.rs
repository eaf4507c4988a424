//! The `wobblog` binary: exit codes, messages and damage reports.

mod analysis_support;

use analysis_support::{info_json, steady_ride_log, wobblog};
use std::path::{Path, PathBuf};

/// A 30 s log of a steady ride with GPS, from CSV through `wobblog encode`.
fn sample_log(dir: &Path) -> PathBuf {
    steady_ride_log(dir, 3000, "in.csv", "run.wbl").1
}

#[test]
fn info_reports_samples_duration_and_gps() {
    let dir = tempfile::tempdir().unwrap();
    let info = info_json(&sample_log(dir.path()));
    assert_eq!(info["samples"], 3000);
    assert_eq!(info["duration_s"], 30.0);
    assert_eq!(info["lost_blocks"], 0);
    assert_eq!(info["gps_coverage_pct"], 100.0);
}

/// Kick records (tag 0x83) are counted, in the text and in JSON.
#[test]
fn info_counts_kicks() {
    use analysis_support::{stdout_of, write_log, Extras, Ride};
    use wobble_core::format::{KickRingDown, Record};
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let kick = |t_s: f64| {
        Record::Kick(KickRingDown {
            t_us: (t_s * 1e6) as u64,
            speed_mm_s: Some(3100),
            freq_chz: 620,
            sigma_milli_per_s: -1800,
            sigma_se_milli_per_s: 40,
            amp_cdeg: 150,
            segments: 9,
        })
    };
    let extras = Extras {
        markers_s: vec![4.0],
        records: vec![kick(2.0), kick(6.0), kick(8.5)],
        ..Extras::default()
    };
    write_log(&log, &Ride::new(10.0, 3.0, 0.0, 0.0, 0.0), &extras);
    let info = info_json(&log);
    assert_eq!(info["kicks"], 3, "{info}");
    assert_eq!(info["records"]["kick"]["count"], 3, "{info}");
    let text = stdout_of(wobblog().arg("info").arg(&log));
    assert!(text.contains("kicks:        3 "), "{text}");
}

#[test]
fn info_lists_records_by_kind_with_their_rates() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    // 30 s at 100 Hz; a fix every 5th frame, none with a position in
    // 22-29 s (140 of the 600); a sync pair every 10 s; one alert; two
    // markers.
    analysis_support::standard_log(&log);
    let info = info_json(&log);
    let records = &info["records"];
    let count = |kind: &str| records[kind]["count"].as_u64();
    let rate = |kind: &str| records[kind]["rate_hz"].as_f64().unwrap();
    assert_eq!(count("frame"), Some(3000));
    assert_eq!(rate("frame"), 100.0);
    assert_eq!(count("gps_fix"), Some(460));
    assert_eq!(count("gps_no_position"), Some(140));
    assert!((rate("gps_fix") - 460.0 / 30.0).abs() < 1e-9);
    assert_eq!(count("utc_sync"), Some(3));
    assert_eq!((count("alert_on"), count("alert_off")), (Some(1), Some(1)));
    assert_eq!(count("marker"), Some(2));
    assert_eq!(count("kick"), None);
    let text = analysis_support::stdout_of(wobblog().arg("info").arg(&log));
    let frame_line = text
        .lines()
        .find(|l| l.trim_start().starts_with("frame "))
        .unwrap();
    let cells: Vec<&str> = frame_line.split_whitespace().collect();
    assert_eq!(cells, ["frame", "3000", "100.000"], "{text}");
}

#[test]
fn damaged_block_is_reported_with_its_frames_and_time() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample_log(dir.path());
    let mut bytes = std::fs::read(&log).unwrap();
    bytes[10 * 512 + 100] ^= 0x40;
    std::fs::write(&log, &bytes).unwrap();
    let info = info_json(&log);
    assert_eq!(info["lost_blocks"], 1);
    assert_eq!(info["damaged_blocks"], 1);
    let lost = &info["losses"]["lost_blocks"][0];
    assert_eq!(lost["first_block"], 10);
    let frames = lost["frames"].as_u64().unwrap();
    assert!(frames > 10, "{frames} frames in a block");
    assert_eq!(info["samples"].as_u64().unwrap() + frames, 3000);

    let out = wobblog().arg("decode").arg(&log).output().unwrap();
    assert!(out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("blocks 10-10 lost"), "{stderr}");
    assert_eq!(
        out.stdout.iter().filter(|&&b| b == b'\n').count() as u64,
        3000 - frames + 1
    );
}

#[test]
fn unreadable_inputs_exit_1_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.wbl");
    let out = wobblog().arg("info").arg(&missing).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nope.wbl"));

    let junk = dir.path().join("junk.wbl");
    std::fs::write(&junk, vec![0x5a; 5000]).unwrap();
    let out = wobblog().arg("decode").arg(&junk).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(out.stdout.is_empty());
    assert!(String::from_utf8_lossy(&out.stderr).contains("junk.wbl: no valid log block"));

    let bad_csv = dir.path().join("bad.csv");
    std::fs::write(&bad_csv, "t_s,steer_deg\n0.01,abc\n").unwrap();
    let out = wobblog()
        .args(["encode", "--csv"])
        .arg(&bad_csv)
        .arg("-o")
        .arg(dir.path().join("x.wbl"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("bad.csv: line 2, column 2: `steer_deg` is not a number"),
        "{stderr}"
    );
}

#[test]
fn usage_errors_exit_2() {
    wobblog().assert().code(2);
    wobblog().args(["decode"]).assert().code(2);
    wobblog()
        .args(["decode", "x.wbl", "--format", "xml"])
        .assert()
        .code(2);
}

#[test]
fn truncated_log_decodes_every_complete_block() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample_log(dir.path());
    let bytes = std::fs::read(&log).unwrap();
    std::fs::write(&log, &bytes[..bytes.len() - 700]).unwrap();
    let info = info_json(&log);
    let skipped = &info["losses"]["skipped"][0];
    assert_eq!(skipped["cause"], "truncated tail");
    assert_eq!(skipped["len"], 512 - 700 % 512);
}

#[test]
fn closing_the_output_pipe_early_is_not_an_error() {
    use std::io::Read;
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let log = sample_log(dir.path());
    let mut child = std::process::Command::new(wobblog().get_program())
        .arg("decode")
        .arg(&log)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 100];
    child.stdout.take().unwrap().read_exact(&mut first).unwrap();
    let out = child.wait_with_output().unwrap();
    assert!(first.starts_with(b"t_s,ax_g"));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stderr.is_empty());
}

#[test]
fn info_to_a_closed_pipe_does_not_panic() {
    use std::process::Stdio;
    let dir = tempfile::tempdir().unwrap();
    let log = sample_log(dir.path());
    let child = std::process::Command::new(wobblog().get_program())
        .arg("info")
        .arg(&log)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the read end before the command writes anything.
    let mut child = child;
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(!String::from_utf8_lossy(&out.stderr).contains("panicked"));
}

#[test]
fn decode_help_and_the_man_page_list_every_column_with_its_unit() {
    let help = wobblog().args(["decode", "--help"]).output().unwrap();
    let help = String::from_utf8(help.stdout).unwrap();
    let man = wobblog().arg("man").output().unwrap();
    let man = String::from_utf8(man.stdout).unwrap();
    for column in wobblog::export::columns::COLUMNS {
        assert!(help.contains(column.name), "{} not in --help", column.name);
        assert!(
            man.contains(column.name),
            "{} not in the man page",
            column.name
        );
    }
    for line in [
        "t_s            time since boot, s",
        "ax_g ay_g az_g acceleration, g",
        "angular rate, deg/s",
        "steer_deg      steering angle, deg",
        "speed_mps      wheel speed, m/s",
        "gps_speed_mps  GPS ground speed, m/s",
        "utc            UTC, ISO 8601",
    ] {
        assert!(help.contains(line), "{line:?} not in\n{help}");
    }
}

#[test]
fn json_and_format_jsonl_are_one_convention() {
    let dir = tempfile::tempdir().unwrap();
    let log = sample_log(dir.path());
    for command in ["info", "events", "wobble"] {
        let json = wobblog()
            .arg(command)
            .arg(&log)
            .arg("--json")
            .output()
            .unwrap();
        let jsonl = wobblog()
            .arg(command)
            .arg(&log)
            .args(["--format", "jsonl"])
            .output()
            .unwrap();
        assert!(json.status.success() && jsonl.status.success(), "{command}");
        assert_eq!(json.stdout, jsonl.stdout, "{command}");
        let contradiction = wobblog()
            .arg(command)
            .arg(&log)
            .args(["--json", "--format", "text"])
            .output()
            .unwrap();
        assert_eq!(contradiction.status.code(), Some(2), "{command}");
    }
    let json = wobblog()
        .arg("summary")
        .arg(dir.path())
        .arg("--json")
        .output()
        .unwrap();
    let jsonl = wobblog()
        .arg("summary")
        .arg(dir.path())
        .args(["--format", "jsonl"])
        .output()
        .unwrap();
    assert!(json.status.success());
    assert_eq!(json.stdout, jsonl.stdout);
}

#[test]
fn help_that_cannot_be_written_is_a_failure() {
    let full = std::fs::OpenOptions::new()
        .write(true)
        .open("/dev/full")
        .unwrap();
    for args in [&["--help"][..], &["info", "--help"], &["--version"]] {
        let out = std::process::Command::new(wobblog().get_program())
            .args(args)
            .stdout(full.try_clone().unwrap())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        assert!(
            String::from_utf8_lossy(&out.stderr).contains("No space left on device"),
            "{args:?}"
        );
    }
}

#[test]
fn a_log_of_another_major_version_says_so() {
    use wobble_core::format::BLOCK_LEN;
    let dir = tempfile::tempdir().unwrap();
    let mut bytes = std::fs::read(sample_log(dir.path())).unwrap();
    // Every block as a version-2 writer would seal it: its CRC is right.
    for block in bytes.chunks_mut(BLOCK_LEN) {
        block[4] = 2;
        let crc = crc32fast::hash(&block[..BLOCK_LEN - 4]);
        block[BLOCK_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
    }
    let log = dir.path().join("RUN00002.WBL");
    std::fs::write(&log, bytes).unwrap();
    let out = wobblog().arg("info").arg(&log).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("RUN00002.WBL") && err.contains("unsupported format version"),
        "{err}"
    );
    assert!(err.contains("major version 2"), "{err}");
}
