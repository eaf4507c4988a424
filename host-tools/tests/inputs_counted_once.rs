//! A log reached twice (named twice, through its folder and its own path,
//! a hard link, a byte-identical copy on the card) is one log: `summary`,
//! `wobble` and `export` count it once and say so.

mod analysis_support;

use std::path::Path;

use analysis_support::{standard_log, stdout_of, wobblog};

/// A card with two different rides, a copy of the first and a hard link
/// to the second.
fn card_with_twins(card: &Path) {
    std::fs::create_dir_all(card).unwrap();
    standard_log(&card.join("RUN00001.WBL"));
    analysis_support::late_fix_log(&card.join("RUN00002.WBL"));
    std::fs::copy(card.join("RUN00001.WBL"), card.join("RUN00003.WBL")).unwrap();
    std::fs::hard_link(card.join("RUN00002.WBL"), card.join("RUN00004.WBL")).unwrap();
}

#[test]
fn summary_counts_a_copy_and_a_link_once() {
    let dir = tempfile::tempdir().unwrap();
    let card = dir.path().join("CARD");
    card_with_twins(&card);
    let out = wobblog()
        .arg("summary")
        .arg(&card)
        .arg("--json")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    let rows: Vec<serde_json::Value> = String::from_utf8_lossy(&out.stdout)
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let names: Vec<&str> = rows.iter().map(|r| r["log"].as_str().unwrap()).collect();
    assert_eq!(names, ["RUN00001.WBL", "RUN00002.WBL"], "{stderr}");
    assert!(stderr.contains("RUN00003.WBL is a copy of"), "{stderr}");
    assert!(
        stderr.contains("RUN00004.WBL is the same file as"),
        "{stderr}"
    );
}

#[test]
fn wobble_reports_a_log_named_twice_once() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    standard_log(&log);
    let once = stdout_of(wobblog().arg("wobble").arg(&log).arg("--json"));
    let out = wobblog()
        .arg("wobble")
        .args([&log, &dir.path().join(".").join("RUN00001.WBL"), &log])
        .arg("--json")
        .output()
        .unwrap();
    assert!(out.status.success());
    assert_eq!(String::from_utf8_lossy(&out.stdout), once);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(stderr.matches("counted once").count(), 2, "{stderr}");
}

#[test]
fn export_writes_a_copied_run_once() {
    let dir = tempfile::tempdir().unwrap();
    let cards = dir.path().join("cards");
    card_with_twins(&cards.join("anna"));
    std::fs::create_dir_all(cards.join("ben")).unwrap();
    std::fs::copy(
        cards.join("anna/RUN00001.WBL"),
        cards.join("ben/RUN00007.WBL"),
    )
    .unwrap();
    let dataset = dir.path().join("dataset");
    let out = wobblog()
        .arg("export")
        .arg(&cards)
        .arg("-o")
        .arg(&dataset)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(stderr.contains("2 runs written"), "{stderr}");
    let mut runs: Vec<String> = std::fs::read_dir(dataset.join("frames/card=anna"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    runs.sort();
    assert_eq!(runs, ["RUN00001.parquet", "RUN00002.parquet"]);
    assert!(!dataset.join("frames/card=ben").exists(), "{stderr}");
}
