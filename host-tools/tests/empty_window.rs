//! One rule for every command with `--from/--to`: a window that selects
//! nothing (reversed, outside the log, a UTC bound on a log without UTC) is
//! an error naming the log and the window, and no output appears.

mod analysis_support;

use std::path::{Path, PathBuf};

use analysis_support::{wobblog, write_log, Extras, Ride, UTC_AT_BOOT_MS};
use wobblog::time::iso8601_unix_ms;

/// The commands with a window, each writing to `out` (its extension names
/// the format for `decode`).
fn commands(log: &Path, out: &Path) -> Vec<(String, assert_cmd::Command)> {
    let mut list = Vec::new();
    for ext in ["csv", "jsonl", "parquet", "mcap"] {
        let mut cmd = wobblog();
        cmd.arg("decode")
            .arg(log)
            .arg("-o")
            .arg(out.with_extension(ext));
        list.push((format!("decode .{ext}"), cmd));
    }
    let mut gpx = wobblog();
    gpx.arg("gpx")
        .arg(log)
        .arg("-o")
        .arg(out.with_extension("gpx"));
    list.push(("gpx".into(), gpx));
    let mut plot = wobblog();
    plot.arg("plot")
        .arg(log)
        .arg("-o")
        .arg(out.with_extension("png"));
    list.push(("plot".into(), plot));
    list
}

/// Runs every command with the window `from`..`to` on `log`; each must
/// exit with `code`, name the log and the window, and write nothing.
fn refused_everywhere(log: &Path, from: &str, to: &str, code: i32, why: &str) {
    let dir = log.parent().unwrap();
    let out = dir.join("out");
    for (name, mut cmd) in commands(log, &out) {
        let result = cmd.args(["--from", from, "--to", to]).output().unwrap();
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(result.status.code(), Some(code), "{name}: {stderr}");
        assert!(
            stderr.contains(&log.display().to_string())
                && stderr.contains(&format!("--from {from} --to {to}"))
                && stderr.contains(why),
            "{name}: {stderr}"
        );
        let left: Vec<_> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(left.len(), 1, "{name} left {left:?}");
    }
}

/// A 10 s ride at 5 m/s in its own folder, with or without GPS (and so UTC).
fn ride_log(gps: bool) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let extras = Extras {
        gps,
        ..Extras::default()
    };
    write_log(&log, &Ride::new(10.0, 5.0, 0.0, 0.0, 0.0), &extras);
    (dir, log)
}

fn utc(t_s: f64) -> String {
    iso8601_unix_ms(UTC_AT_BOOT_MS + (t_s * 1000.0) as i64).unwrap()
}

#[test]
fn a_reversed_window_is_a_usage_error_in_every_command() {
    let (_dir, log) = ride_log(true);
    refused_everywhere(&log, "8", "3", 2, "ends before it starts");
    refused_everywhere(&log, &utc(8.0), &utc(3.0), 2, "ends before it starts");
}

#[test]
fn a_window_outside_the_log_selects_nothing_in_every_command() {
    let (_dir, log) = ride_log(true);
    refused_everywhere(&log, "100", "200", 1, "selects no");
    refused_everywhere(&log, &utc(100.0), &utc(200.0), 1, "selects no");
}

#[test]
fn a_utc_bound_on_a_log_without_utc_says_so_in_every_command() {
    let (_dir, log) = ride_log(false);
    refused_everywhere(&log, "2", &utc(5.0), 1, "no UTC time");
}

#[test]
fn a_window_inside_the_log_still_writes() {
    let (dir, log) = ride_log(true);
    let out = dir.path().join("out");
    for (name, mut cmd) in commands(&log, &out) {
        let result = cmd.args(["--from", "3", "--to", "4"]).output().unwrap();
        assert!(
            result.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&result.stderr)
        );
    }
}
