//! Every command that prints ends quietly and successfully when its reader
//! has gone away (`wobblog ... | head`), and a multi-log failure names no
//! single file.

mod analysis_support;

use std::path::PathBuf;
use std::process::Command;

fn fixture(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../hil-tests/fixtures")
        .join(path)
}

/// Runs `wobblog args` with standard output a pipe whose reader is already
/// closed, so its first write fails with a broken pipe; returns the
/// process output.
fn run_into_closed_pipe(args: &[&std::ffi::OsStr]) -> std::process::Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    let mut cmd = Command::new(assert_cmd::cargo::cargo_bin("wobblog"));
    cmd.args(args).stdout(writer);
    cmd.output().unwrap()
}

#[test]
fn every_printing_command_ends_quietly_on_a_closed_pipe() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    analysis_support::standard_log(&log);
    let logs = dir.path().to_path_buf();
    let steer = fixture("corpus/wobble_fig6.csv");
    let nmea = fixture("gps/nmea-fuzzy-cases.log");
    let l = log.as_os_str();
    let os = |s: &'static str| std::ffi::OsStr::new(s);
    let cases: Vec<Vec<&std::ffi::OsStr>> = vec![
        vec![os("info"), l],
        vec![os("info"), l, os("--json")],
        vec![os("decode"), l],
        vec![os("decode"), l, os("--format"), os("jsonl")],
        vec![os("decode"), l, os("--format"), os("parquet")],
        vec![os("gpx"), l],
        vec![os("wobble"), l],
        vec![os("wobble"), l, os("--json")],
        vec![os("summary"), logs.as_os_str()],
        vec![os("summary"), logs.as_os_str(), os("--format"), os("csv")],
        vec![os("summary"), logs.as_os_str(), os("--format"), os("jsonl")],
        vec![os("detect"), os("--csv"), steer.as_os_str()],
        vec![os("detect"), os("--json"), os("--csv"), steer.as_os_str()],
        vec![os("nmea"), nmea.as_os_str()],
    ];
    for args in cases {
        let out = run_into_closed_pipe(&args);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{args:?}: {stderr}");
        assert!(
            !stderr.contains("pipe") && !stderr.contains("panicked"),
            "{args:?}: {stderr}"
        );
    }
}

#[test]
fn a_figure_is_still_drawn_when_the_table_reader_went_away() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    analysis_support::standard_log(&log);
    let png = dir.path().join("modes.png");
    let out = run_into_closed_pipe(&[
        "wobble".as_ref(),
        log.as_os_str(),
        "--plot".as_ref(),
        png.as_os_str(),
    ]);
    assert_eq!(out.status.code(), Some(0));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
}

#[test]
fn multi_log_failures_close_naming_no_single_file() {
    let dir = tempfile::tempdir().unwrap();
    analysis_support::standard_log(&dir.path().join("RUN00001.WBL"));
    // Two different files (a byte-identical pair would be one input).
    for bad in ["RUN00002.WBL", "RUN00003.WBL"] {
        std::fs::write(dir.path().join(bad), format!("{bad} is not a log")).unwrap();
    }
    let logs: Vec<PathBuf> = ["RUN00001.WBL", "RUN00002.WBL", "RUN00003.WBL"]
        .iter()
        .map(|n| dir.path().join(n))
        .collect();
    let mut wobble = analysis_support::wobblog();
    wobble.arg("wobble").args(&logs);
    let mut summary = analysis_support::wobblog();
    summary.arg("summary").arg(dir.path());
    for mut cmd in [wobble, summary] {
        let out = cmd.output().unwrap();
        assert_eq!(out.status.code(), Some(1));
        let stderr = String::from_utf8_lossy(&out.stderr);
        let last = stderr.lines().last().unwrap_or_default();
        assert_eq!(
            last,
            "wobblog: 2 of 3 logs could not be read (see above); the others were processed"
        );
        for bad in ["RUN00002.WBL", "RUN00003.WBL"] {
            assert!(stderr.contains(bad), "{stderr}");
        }
    }
}
