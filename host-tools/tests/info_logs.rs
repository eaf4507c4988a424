//! `wobblog info` of several logs (or a card folder): each log's report in
//! turn, the same as `info` of that log alone; JSON as JSON lines naming
//! their log, as `wobble --json`.

mod analysis_support;

use std::path::{Path, PathBuf};

use analysis_support::{info_json, stdout_of, wobblog};
use serde_json::Value;

fn golden(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../firmware/core/tests/golden")
        .join(name)
}

/// A card folder holding copies of two golden logs.
fn card() -> (tempfile::TempDir, Vec<PathBuf>) {
    let dir = tempfile::tempdir().unwrap();
    let logs: Vec<PathBuf> = ["gps", "alert"]
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let log = dir.path().join(format!("RUN0000{}.WBL", i + 1));
            std::fs::copy(golden(&format!("{name}.WBL")), &log).unwrap();
            log
        })
        .collect();
    (dir, logs)
}

/// The JSON lines of `info --json` on `inputs`, each checked against
/// `info --json` of its log alone and returned with their `log`.
fn lines_as_alone(inputs: &[&Path]) -> Vec<String> {
    let text = stdout_of(wobblog().arg("info").args(inputs).arg("--json"));
    text.lines()
        .map(|line| {
            let mut value: Value = serde_json::from_str(line).unwrap();
            let log = value.as_object_mut().unwrap().remove("log").unwrap();
            let log = log.as_str().unwrap().to_string();
            assert_eq!(value, info_json(Path::new(&log)), "{log}");
            log
        })
        .collect()
}

#[test]
fn several_logs_are_each_reported_as_alone() {
    let (_dir, logs) = card();
    let alone: Vec<String> = logs
        .iter()
        .map(|log| stdout_of(wobblog().arg("info").arg(log)))
        .collect();
    let together = stdout_of(wobblog().arg("info").args(&logs));
    assert_eq!(together, alone.join("\n"));

    let named: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    let shown: Vec<String> = logs.iter().map(|l| l.display().to_string()).collect();
    assert_eq!(lines_as_alone(&named), shown);
}

#[test]
fn a_card_folder_is_its_logs_in_name_order() {
    let (dir, logs) = card();
    let shown: Vec<String> = logs.iter().map(|l| l.display().to_string()).collect();
    assert_eq!(lines_as_alone(&[dir.path()]), shown);
}

#[test]
fn an_unreadable_log_is_named_and_the_others_still_reported() {
    let (dir, logs) = card();
    let missing = dir.path().join("RUN00009.WBL");
    let out = wobblog()
        .arg("info")
        .arg(&logs[0])
        .arg(&missing)
        .arg("--json")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("RUN00009.WBL"), "{stderr}");
    assert!(stderr.contains("1 of 2 logs could not be read"), "{stderr}");
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert_eq!(stdout.lines().count(), 1, "{stdout}");
    assert!(stdout.contains("RUN00001.WBL"), "{stdout}");
}

/// Blocks of zeros after a log's data (space reserved ahead of it, or a
/// card image padded) are counted as unwritten, not as lost or skipped,
/// and no command warns of them; the frames are those of the log alone.
#[test]
fn zeros_after_the_data_are_unwritten_not_lost() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let mut bytes = std::fs::read(golden("clean.WBL")).unwrap();
    bytes.extend([0u8; 4 * 512]);
    std::fs::write(&log, &bytes).unwrap();
    let info = info_json(&log);
    assert_eq!(info["unwritten_blocks"], 4);
    assert_eq!(info["bytes_skipped"], 0);
    assert_eq!(info["lost_blocks"], 0);
    let alone = info_json(&golden("clean.WBL"));
    assert_eq!(info["samples"], alone["samples"]);
    let out = wobblog().arg("info").arg(&log).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.contains("unwritten:    4 blocks of zeros"), "{text}");
    assert!(
        out.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}
