//! The UTC column, `--from/--to`, `--columns` and the format from the
//! output's extension, on `wobblog decode`.

mod analysis_support;

use analysis_support::{late_fix_log, stdout_of, wobblog, UTC_AT_BOOT_MS};
use wobblog::time::iso8601_unix_us;

fn csv_rows(text: &str) -> (Vec<String>, Vec<csv::StringRecord>) {
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    let header = reader.headers().unwrap().iter().map(String::from).collect();
    (header, reader.records().map(Result::unwrap).collect())
}

/// The UTC the synthetic GPS gives at `t_s` since boot.
fn utc_at(t_s: f64) -> String {
    iso8601_unix_us((UTC_AT_BOOT_MS + (t_s * 1000.0).round() as i64) * 1000).unwrap()
}

#[test]
fn utc_column_is_empty_before_the_first_sync_pair_and_exact_after() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    late_fix_log(&log);
    let (header, rows) = csv_rows(&stdout_of(wobblog().arg("decode").arg(&log)));
    assert_eq!(header.last().map(String::as_str), Some("utc"));
    assert_eq!(header.len(), 14);
    let utc = header.len() - 1;
    let mut with_utc = 0;
    for row in &rows {
        let t: f64 = row[0].parse().unwrap();
        if t < 5.0 {
            assert_eq!(&row[utc], "", "t {t}");
        } else {
            assert_eq!(row[utc], utc_at(t), "t {t}");
            with_utc += 1;
        }
    }
    assert_eq!(with_utc, 1600);

    let json = stdout_of(
        wobblog()
            .arg("decode")
            .arg(&log)
            .args(["--format", "jsonl"]),
    );
    let lines: Vec<serde_json::Value> = json
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    // Every key on every line: an absent value is null.
    assert!(lines[0]["utc"].is_null() && lines[0]["gps_lat_deg"].is_null());
    let at_6 = lines.iter().find(|l| l["t_s"] == 6.0).unwrap();
    assert_eq!(at_6["utc"], utc_at(6.0));
}

#[test]
fn from_and_to_take_seconds_since_boot_or_utc() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    late_fix_log(&log);
    let window = |from: &str, to: &str| {
        let text = stdout_of(wobblog().arg("decode").arg(&log).args([
            "--from",
            from,
            "--to",
            to,
            "--columns",
            "t_s,utc",
        ]));
        csv_rows(&text)
    };
    let (header, by_boot) = window("10", "12");
    assert_eq!(header, ["t_s", "utc"]);
    assert_eq!(by_boot.len(), 201);
    assert_eq!(&by_boot[0][0], "10.0");
    assert_eq!(&by_boot[200][0], "12.0");
    let (_, by_utc) = window(&utc_at(10.0), &utc_at(12.0));
    assert_eq!(by_utc, by_boot);
    // A UTC bound cannot hold rows without UTC.
    let (_, early) = window("0", &utc_at(6.0));
    assert_eq!(&early[0][0], "5.0");
}

#[test]
fn format_follows_the_extension_and_a_contradiction_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    late_fix_log(&log);
    let jsonl = dir.path().join("run.jsonl");
    wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&jsonl)
        .assert()
        .success();
    let text = std::fs::read_to_string(&jsonl).unwrap();
    let first: serde_json::Value = serde_json::from_str(text.lines().next().unwrap()).unwrap();
    assert_eq!(first["t_s"], 1.0);

    let parquet = dir.path().join("run.parquet");
    let out = wobblog()
        .arg("decode")
        .arg(&log)
        .args(["--format", "csv", "-o"])
        .arg(&parquet)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("contradicts"));
    assert!(!parquet.exists());

    let out = wobblog()
        .arg("decode")
        .arg(&log)
        .args(["--columns", "t_s,steer"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("steer_deg"));
    let out = wobblog()
        .arg("decode")
        .arg(&log)
        .args(["--from", "soon"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}
