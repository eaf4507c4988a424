//! No command writes into one of its inputs: standard output or `-o` that
//! is an input (`>>`, `1<>`, `/dev/stdout`, a link) is refused by device
//! and inode with exit code 2, and the input stays byte for byte as it was.

mod analysis_support;

use std::path::{Path, PathBuf};
use std::process::Command as Shell;

use analysis_support::{standard_log, wobblog};

fn bin() -> PathBuf {
    PathBuf::from(wobblog().get_program())
}

fn params() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/test-bicycle.toml")
}

/// Runs `script` in `sh` in `dir` with `$W` the program.
fn sh(dir: &Path, script: &str) -> std::process::Output {
    Shell::new("sh")
        .arg("-c")
        .arg(script)
        .current_dir(dir)
        .env("W", bin())
        .output()
        .unwrap()
}

/// Runs `script`, which must be refused as a usage error that says why,
/// leaving `file` as it was.
fn refused(dir: &Path, script: &str, file: &Path) {
    let before = std::fs::read(file).unwrap();
    let out = sh(dir, script);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{script}: {stderr}");
    assert!(
        stderr.contains("is the input") || stderr.contains("reading only"),
        "{script}: {stderr}"
    );
    assert!(
        std::fs::read(file).unwrap() == before,
        "{script} changed {}",
        file.display()
    );
}

#[test]
fn every_command_refuses_standard_output_that_is_its_log() {
    let dir = tempfile::tempdir().unwrap();
    let card = dir.path().join("CARD");
    std::fs::create_dir(&card).unwrap();
    standard_log(&card.join("RUN00001.WBL"));
    let log = "CARD/RUN00001.WBL";
    for command in [
        "info",
        "info --json",
        "events",
        "events --json",
        "config",
        "detect",
        "detect --json",
        "wobble",
        "wobble --json",
        "margin",
        "margin --json",
        "decode",
        "gpx",
    ] {
        for redirect in [">>", "1<>"] {
            refused(
                dir.path(),
                &format!("\"$W\" {command} {log} {redirect} {log}"),
                &card.join("RUN00001.WBL"),
            );
        }
    }
    // A log inside a folder named on the command line.
    for command in ["summary", "summary --json", "margin", "margin --json"] {
        refused(
            dir.path(),
            &format!("\"$W\" {command} CARD >> {log}"),
            &card.join("RUN00001.WBL"),
        );
    }
    // Through another name of the same file.
    std::fs::hard_link(card.join("RUN00001.WBL"), dir.path().join("linked.WBL")).unwrap();
    refused(
        dir.path(),
        &format!("\"$W\" info {log} >> linked.WBL"),
        &card.join("RUN00001.WBL"),
    );
}

#[test]
fn model_commands_refuse_standard_output_that_is_the_parameter_file() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("P.toml");
    std::fs::copy(params(), &p).unwrap();
    standard_log(&dir.path().join("RUN00001.WBL"));
    for command in [
        "model sweep P.toml --param geometry.trail --speeds 1:3:1",
        "model compare P.toml RUN00001.WBL --speeds 1:3:1",
    ] {
        refused(dir.path(), &format!("\"$W\" {command} >> P.toml"), &p);
    }
}

#[test]
fn an_output_named_for_standard_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    standard_log(&dir.path().join("RUN00001.WBL"));
    standard_log(&dir.path().join("other.WBL"));
    let other = dir.path().join("other.WBL");
    for target in ["/dev/stdin", "/dev/fd/0", "/proc/self/fd/0"] {
        refused(
            dir.path(),
            &format!("\"$W\" decode RUN00001.WBL -o {target} < other.WBL"),
            &other,
        );
    }
    // A descriptor opened for reading only, other than standard input.
    refused(
        dir.path(),
        "\"$W\" decode RUN00001.WBL -o /dev/fd/3 3< other.WBL",
        &other,
    );
}

#[test]
fn an_output_that_is_an_input_under_another_name_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    standard_log(&dir.path().join("RUN00001.WBL"));
    std::os::unix::fs::symlink("RUN00001.WBL", dir.path().join("alias.WBL")).unwrap();
    let log = dir.path().join("RUN00001.WBL");
    refused(
        dir.path(),
        "\"$W\" decode RUN00001.WBL --format csv -o alias.WBL",
        &log,
    );
    refused(
        dir.path(),
        "\"$W\" decode alias.WBL -o /dev/stdout >> RUN00001.WBL",
        &log,
    );
}

#[test]
fn a_terminal_or_pipe_that_is_also_read_is_still_written() {
    // The rule is for files that can be written into: a pipe on both
    // sides is the user's to choose, as with `cat`.
    let dir = tempfile::tempdir().unwrap();
    standard_log(&dir.path().join("RUN00001.WBL"));
    let out = sh(dir.path(), "\"$W\" info RUN00001.WBL | cat");
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("RUN00001.WBL"));
}
