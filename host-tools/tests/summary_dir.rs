//! `wobblog summary DIR`: one row per run, every readable run even when
//! some logs are not.

mod analysis_support;

use analysis_support::{wobblog, Extras, Ride};
use serde_json::Value;

/// The JSON rows of `summary DIR`, which must exit 1 naming the unreadable
/// log `bad` on stderr.
fn rows_failing_on(dir: &std::path::Path, bad: &str) -> Vec<Value> {
    let out = wobblog()
        .arg("summary")
        .arg(dir)
        .arg("--json")
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(bad), "{stderr}");
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn one_row_per_run_and_unreadable_logs_named() {
    let dir = tempfile::tempdir().unwrap();
    analysis_support::standard_log(&dir.path().join("RUN00003.WBL"));
    let mut calm = Ride::new(20.0, 3.0, 0.0, 0.0, 0.0);
    calm.steer_deg.fill(0.0);
    analysis_support::write_log(&dir.path().join("run00004.wbl"), &calm, &Extras::default());
    std::fs::write(dir.path().join("RUN00005.WBL"), b"not a log").unwrap();
    std::fs::write(dir.path().join("notes.txt"), b"ignored").unwrap();

    let rows = rows_failing_on(dir.path(), "RUN00005.WBL");
    assert_eq!(rows.len(), 2);

    let wobbly = &rows[0];
    assert_eq!(wobbly["log"], "RUN00003.WBL");
    assert_eq!(wobbly["duration_s"].as_f64(), Some(30.0));
    let distance = wobbly["distance_m"].as_f64().unwrap();
    assert!((distance - 5.0 * 29.99).abs() < 0.5, "{distance}");
    assert_eq!(wobbly["max_speed_mps"].as_f64(), Some(5.0));
    assert_eq!(wobbly["unstable_episodes"], 1);
    assert!((wobbly["wobble_speed_mps"].as_f64().unwrap() - 5.0).abs() < 0.1);
    assert_eq!(wobbly["frames_lost"], 0);

    let calm_row = &rows[1];
    assert_eq!(calm_row["log"], "run00004.wbl");
    assert_eq!(calm_row["episodes"], 0);
    assert_eq!(calm_row["wobble_speed_mps"], Value::Null);
}

#[test]
fn lost_blocks_are_counted_and_csv_has_a_header() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let mut bytes = std::fs::read(&log).unwrap();
    bytes[30 * 512 + 9] ^= 0x01;
    std::fs::write(&log, &bytes).unwrap();
    let out = wobblog()
        .arg("summary")
        .arg(dir.path())
        .args(["--format", "csv"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let mut csv = csv::Reader::from_reader(out.stdout.as_slice());
    let header = csv.headers().unwrap().clone();
    let row = csv.records().next().unwrap().unwrap();
    let col = |name: &str| row[header.iter().position(|h| h == name).unwrap()].to_string();
    assert_eq!(col("lost_blocks"), "1");
    assert!(col("frames_lost").parse::<u64>().unwrap() > 10);
}

#[test]
fn empty_or_missing_directory_fails_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let run = |path: &std::path::Path| wobblog().arg("summary").arg(path).output().unwrap();
    let out = run(dir.path());
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no *.WBL"));
    assert_eq!(run(&dir.path().join("absent")).status.code(), Some(1));
}

#[test]
fn a_folder_of_cards_gives_every_cards_runs() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("card-a"), dir.path().join("card-b"));
    std::fs::create_dir_all(&a).unwrap();
    std::fs::create_dir_all(&b).unwrap();
    std::fs::create_dir_all(dir.path().join("empty")).unwrap();
    analysis_support::standard_log(&a.join("RUN00001.WBL"));
    let mut calm = Ride::new(20.0, 3.0, 0.0, 0.0, 0.0);
    calm.steer_deg.fill(0.0);
    analysis_support::write_log(&b.join("RUN00001.WBL"), &calm, &Extras::default());
    std::fs::write(b.join("RUN00002.WBL"), b"").unwrap();

    // The empty log is named and left out; the other runs are there.
    let rows = rows_failing_on(dir.path(), "RUN00002.WBL");
    let logs: Vec<&str> = rows.iter().map(|r| r["log"].as_str().unwrap()).collect();
    assert_eq!(logs, ["card-a/RUN00001.WBL", "card-b/RUN00001.WBL"]);
    assert_eq!(rows[0]["unstable_episodes"], 1);
    assert_eq!(rows[1]["episodes"], 0);
    assert_eq!(rows[1]["duration_s"].as_f64(), Some(20.0));
}

#[test]
fn hostile_log_names_are_escaped_in_the_table_and_csv_and_exact_in_json() {
    let dir = tempfile::tempdir().unwrap();
    // ESC, BEL, a C1 CSI, a right-to-left override and a newline that
    // would forge a row.
    let names = [
        "a\u{1b}]0;owned\u{7}.WBL",
        "b\u{9b}2J\u{202e}LBW.WBL",
        "c\nRUN09999.WBL  99.00.WBL",
    ];
    // Three different rides (a byte-identical copy would be one input).
    for (i, name) in names.iter().enumerate() {
        analysis_support::write_log(
            &dir.path().join(name),
            &Ride::new(5.0 + i as f64, 3.0, 0.0, 0.0, 0.0),
            &Extras::default(),
        );
    }
    let raw = |c: char| c.is_control() && c != '\n' || ('\u{202a}'..='\u{202e}').contains(&c);
    for format in ["table", "csv", "jsonl"] {
        let out = wobblog()
            .arg("summary")
            .arg(dir.path())
            .args(["--format", format])
            .output()
            .unwrap();
        assert!(out.status.success(), "{format}");
        let text = String::from_utf8(out.stdout).unwrap();
        assert!(!text.chars().any(raw), "{format}: {text:?}");
        let lines: Vec<&str> = text.lines().collect();
        let header = usize::from(format != "jsonl");
        assert_eq!(lines.len(), header + names.len(), "{format}: {text}");
        if format == "jsonl" {
            for (line, name) in lines.iter().zip(names) {
                let row: Value = serde_json::from_str(line).unwrap();
                assert_eq!(row["log"], name, "the exact name");
            }
        } else {
            assert!(
                text.contains("a\\u{1b}]0;owned\\u{7}.WBL"),
                "{format}: {text}"
            );
            assert!(
                text.contains("b\\u{9b}2J\\u{202e}LBW.WBL"),
                "{format}: {text}"
            );
            assert!(text.contains("c\\nRUN09999.WBL"), "{format}: {text}");
        }
    }
}
