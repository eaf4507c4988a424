//! Outputs appear whole or not at all, and no command writes over its input.

mod analysis_support;

use analysis_support::{steady_ride_log, wobblog};
use assert_cmd::Command;
use std::path::{Path, PathBuf};

/// A 10 s ride CSV with GPS and the log `wobblog encode` makes of it.
fn sample(dir: &Path) -> (PathBuf, PathBuf) {
    steady_ride_log(dir, 1000, "ride.csv", "RUN00001.WBL")
}

/// The names in `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Every writing command, given its input and an output path.
fn writers(csv: &Path, log: &Path, out: &Path) -> Vec<Command> {
    let mut cmds = Vec::new();
    for format in ["csv", "jsonl", "parquet"] {
        let mut c = wobblog();
        c.arg("decode").arg(log).args(["--format", format, "-o"]);
        c.arg(out);
        cmds.push(c);
    }
    let mut c = wobblog();
    c.args(["encode", "--csv"]).arg(csv).arg("-o").arg(out);
    cmds.push(c);
    let mut c = wobblog();
    c.arg("gpx").arg(log).arg("-o").arg(out);
    cmds.push(c);
    cmds
}

/// Runs `cmd` where its output is the same file as its input, and checks
/// it is refused with the input untouched.
fn assert_refused(mut cmd: Command, input: &Path) {
    let before = std::fs::read(input).unwrap();
    let out = cmd.output().unwrap();
    assert_eq!(out.status.code(), Some(2), "{cmd:?}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("refusing to overwrite"), "{stderr}");
    assert_eq!(
        std::fs::read(input).unwrap(),
        before,
        "{cmd:?} changed its input"
    );
}

#[test]
fn an_output_that_is_the_input_is_refused_by_path_hard_link_and_symlink() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, log) = sample(dir.path());
    let hard = dir.path().join("hard.wbl");
    std::fs::hard_link(&log, &hard).unwrap();
    let soft = dir.path().join("soft.wbl");
    std::os::unix::fs::symlink(&log, &soft).unwrap();
    let csv_hard = dir.path().join("hard.csv");
    std::fs::hard_link(&csv, &csv_hard).unwrap();
    let csv_soft = dir.path().join("soft.csv");
    std::os::unix::fs::symlink(&csv, &csv_soft).unwrap();
    let before = listing(dir.path());
    for same_as_log in [&log, &hard, &soft] {
        for format in ["csv", "jsonl", "parquet"] {
            let mut c = wobblog();
            c.arg("decode").arg(&log).args(["--format", format, "-o"]);
            c.arg(same_as_log);
            assert_refused(c, &log);
        }
        let mut c = wobblog();
        c.arg("gpx").arg(&log).arg("-o").arg(same_as_log);
        assert_refused(c, &log);
    }
    for same_as_csv in [&csv, &csv_hard, &csv_soft] {
        let mut c = wobblog();
        c.args(["encode", "--csv"])
            .arg(&csv)
            .arg("-o")
            .arg(same_as_csv);
        assert_refused(c, &csv);
    }
    // Image outputs are refused before the extension matters.
    let png_link = dir.path().join("log.png");
    std::os::unix::fs::symlink(&log, &png_link).unwrap();
    let mut c = wobblog();
    c.arg("plot").arg(&log).arg("-o").arg(&png_link);
    assert_refused(c, &log);
    let mut c = wobblog();
    c.arg("wobble").arg(&log).arg("--plot").arg(&png_link);
    assert_refused(c, &log);
    std::fs::remove_file(&png_link).unwrap();
    assert_eq!(listing(dir.path()), before, "nothing left behind");
}

#[test]
fn a_failed_write_leaves_the_old_file_and_nothing_else() {
    let dir = tempfile::tempdir().unwrap();
    let (_, _) = sample(dir.path());
    let junk = dir.path().join("junk.wbl");
    std::fs::write(&junk, vec![0x5a; 5000]).unwrap();
    let bad_csv = dir.path().join("bad.csv");
    std::fs::write(&bad_csv, "t_s,steer_deg\n0.00,1\n0.01,abc\n").unwrap();
    let old = dir.path().join("old.out");
    std::fs::write(&old, b"a result worth keeping\n").unwrap();
    let before = listing(dir.path());
    for mut cmd in writers(&bad_csv, &junk, &old) {
        let out = cmd.output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{cmd:?}");
        assert_eq!(
            std::fs::read(&old).unwrap(),
            b"a result worth keeping\n",
            "{cmd:?}"
        );
        assert_eq!(listing(dir.path()), before, "{cmd:?} left a file behind");
    }
}

#[test]
fn a_failed_plot_leaves_the_old_image() {
    let dir = tempfile::tempdir().unwrap();
    let (_, log) = sample(dir.path());
    let png = dir.path().join("run.png");
    std::fs::write(&png, b"old image").unwrap();
    let before = listing(dir.path());
    wobblog()
        .arg("plot")
        .arg(&log)
        .arg("-o")
        .arg(&png)
        .args(["--from", "500", "--to", "600"])
        .assert()
        .code(1);
    assert_eq!(std::fs::read(&png).unwrap(), b"old image");
    assert_eq!(listing(dir.path()), before);
}

#[test]
fn a_successful_write_replaces_the_target_whole_and_keeps_a_symlink() {
    let dir = tempfile::tempdir().unwrap();
    let (_, log) = sample(dir.path());
    let real = dir.path().join("real.csv");
    std::fs::write(&real, b"stale").unwrap();
    let link = dir.path().join("link.csv");
    std::os::unix::fs::symlink(&real, &link).unwrap();
    let before = listing(dir.path());
    wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&link)
        .assert()
        .success();
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let text = std::fs::read_to_string(&real).unwrap();
    assert!(text.starts_with("t_s,ax_g"), "{text:.40}");
    assert_eq!(text.lines().count(), 1001);
    assert_eq!(listing(dir.path()), before, "no temporary file left");
}

#[test]
fn an_unwritable_output_is_reported_plainly() {
    let dir = tempfile::tempdir().unwrap();
    let (csv, log) = sample(dir.path());
    let nowhere = dir.path().join("no such dir").join("x.png");
    let mut cmds = writers(&csv, &log, &nowhere);
    let mut c = wobblog();
    c.arg("plot").arg(&log).arg("-o").arg(&nowhere);
    cmds.push(c);
    let mut c = wobblog();
    c.arg("wobble").arg(&log).arg("--plot").arg(&nowhere);
    cmds.push(c);
    for mut cmd in cmds {
        let out = cmd.output().unwrap();
        assert_eq!(out.status.code(), Some(1), "{cmd:?}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(stderr.contains("no such dir/x.png"), "{stderr}");
        assert!(stderr.contains("No such file or directory"), "{stderr}");
        assert!(
            !stderr.contains("Os {") && !stderr.contains("Error("),
            "{stderr}"
        );
    }
}

#[test]
fn a_command_that_fails_commits_no_figure() {
    let dir = tempfile::tempdir().unwrap();
    let (_, log) = sample(dir.path());
    let missing = dir.path().join("MISSING.WBL");
    let params =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/test-bicycle.toml");
    for (name, mut cmd) in [("modes.png", wobblog()), ("fig8.svg", wobblog())] {
        let fig = dir.path().join(name);
        std::fs::write(&fig, b"good old figure").unwrap();
        if name == "modes.png" {
            cmd.arg("wobble")
                .arg(&log)
                .arg(&missing)
                .arg("--plot")
                .arg(&fig);
        } else {
            cmd.args(["model", "compare"])
                .arg(&params)
                .arg(&log)
                .arg(&missing);
            cmd.arg("-o").arg(&fig);
        }
        let before = listing(dir.path());
        cmd.assert().code(1);
        assert_eq!(std::fs::read(&fig).unwrap(), b"good old figure", "{name}");
        assert_eq!(listing(dir.path()), before, "{name}");
    }
}
