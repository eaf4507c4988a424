//! `wobblog export`: a campaign as a Hive-partitioned Parquet dataset,
//! queried through DuckDB (its Python wheel; the test command installs it).

mod analysis_support;

use std::path::Path;
use std::process::Command;

use analysis_support::{standard_log, wobblog, write_log, Ride};

/// A card with three runs of different lengths, each with one unstable
/// wobble; returns their frame counts.
fn card(dir: &Path) -> Vec<usize> {
    std::fs::create_dir_all(dir).unwrap();
    (1..=3)
        .map(|run| {
            let path = dir.join(format!("RUN{run:05}.WBL"));
            if run == 2 {
                let ride = Ride::new(32.0, 5.0, 15.0, 2.0, 0.5);
                write_log(&path, &ride, &standard_log(&dir.join("tmp.wbl")).1);
                std::fs::remove_file(dir.join("tmp.wbl")).unwrap();
                ride.t_s.len()
            } else {
                standard_log(&path).0.t_s.len()
            }
        })
        .collect()
}

/// Runs `sql` in DuckDB; its rows as JSON arrays. `None` when the DuckDB
/// wheel is missing outside CI; under CI (`CI=true`) that fails the test.
fn duckdb(sql: &str) -> Option<Vec<serde_json::Value>> {
    let script = "import duckdb, json, sys\n\
        rows = duckdb.sql(sys.argv[1]).fetchall()\n\
        print(json.dumps([list(r) for r in rows], default=str))";
    let out = Command::new("python3").args(["-c", script, sql]).output();
    let missing = out.as_ref().map_or(true, |o| {
        String::from_utf8_lossy(&o.stderr).contains("No module named 'duckdb'")
    });
    if missing {
        assert!(
            std::env::var("CI").as_deref() != Ok("true"),
            "DuckDB's Python wheel is missing: run `python3 -m pip install duckdb` (hil-tests/install-tools.sh does)"
        );
        eprintln!("SKIPPED: DuckDB's Python wheel is not installed (pip install duckdb)");
        return None;
    }
    let out = out.unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    Some(serde_json::from_slice(&out.stdout).unwrap())
}

/// Runs `wobblog export DIR -o DS`.
fn export(dir: &Path, ds: &Path) -> std::process::Output {
    wobblog()
        .arg("export")
        .arg(dir)
        .arg("-o")
        .arg(ds)
        .output()
        .unwrap()
}

#[test]
fn duckdb_queries_a_dataset_of_several_runs() {
    let dir = tempfile::tempdir().unwrap();
    let frames = card(&dir.path().join("card"));
    let ds = dir.path().join("season");
    wobblog()
        .arg("export")
        .arg(dir.path().join("card"))
        .arg("-o")
        .arg(&ds)
        .assert()
        .success();
    for run in 1..=3 {
        assert!(ds.join(format!("run={run:05}/part-0.parquet")).is_file());
    }
    let q = |sql: &str| duckdb(&sql.replace("DS", &ds.display().to_string()));
    let Some(counts) = q(
        "SELECT run, count(*) FROM read_parquet('DS/**/run=*/*.parquet', \
         hive_partitioning = true, hive_types = {'run': INTEGER}) GROUP BY run ORDER BY run",
    ) else {
        return;
    };
    let expected: Vec<serde_json::Value> = frames
        .iter()
        .enumerate()
        .map(|(i, n)| serde_json::json!([i + 1, n]))
        .collect();
    assert_eq!(counts, expected);
    let unstable = q(
        "SELECT e.run, round(e.speed_at_onset_mps, 2), r.wobble_speed_mps = e.speed_at_onset_mps \
         FROM 'DS/episodes.parquet' e JOIN 'DS/runs.parquet' r USING (run) \
         WHERE e.stability = 'unstable' ORDER BY e.run",
    )
    .unwrap();
    assert_eq!(
        unstable,
        [
            serde_json::json!([1, 5.0, true]),
            serde_json::json!([2, 5.0, true]),
            serde_json::json!([3, 5.0, true])
        ]
    );
    let utc =
        q("SELECT any_value(typeof(utc)), min(utc) FROM read_parquet('DS/run=00001/*.parquet')")
            .unwrap();
    assert_eq!(utc[0][0], "TIMESTAMP WITH TIME ZONE");
    assert!(
        utc[0][1]
            .as_str()
            .unwrap()
            .starts_with("2020-03-18 10:00:01"),
        "{utc:?}"
    );
}

#[test]
fn a_folder_of_cards_is_partitioned_by_card_and_run() {
    let dir = tempfile::tempdir().unwrap();
    let cards = dir.path().join("cards");
    for name in ["blue", "red"] {
        std::fs::create_dir_all(cards.join(name)).unwrap();
        standard_log(&cards.join(name).join("RUN00001.WBL"));
    }
    let ds = dir.path().join("ds");
    wobblog()
        .arg("export")
        .arg(&cards)
        .arg("-o")
        .arg(&ds)
        .assert()
        .success();
    for name in ["blue", "red"] {
        assert!(ds
            .join(format!("card={name}/run=00001/part-0.parquet"))
            .is_file());
    }
    assert!(ds.join("runs.parquet").is_file() && ds.join("episodes.parquet").is_file());
}

#[test]
fn the_dataset_appears_whole_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let card_dir = dir.path().join("card");
    card(&card_dir);
    std::fs::write(card_dir.join("RUN00004.WBL"), vec![0u8; 4096]).unwrap();
    let ds = dir.path().join("season");
    let out = export(&card_dir, &ds);
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("RUN00004.WBL"));
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, ["card"], "nothing but the card is left");

    // An existing dataset is never replaced.
    std::fs::remove_file(card_dir.join("RUN00004.WBL")).unwrap();
    std::fs::create_dir(&ds).unwrap();
    std::fs::write(ds.join("mine.txt"), "keep").unwrap();
    let out = export(&card_dir, &ds);
    assert_eq!(out.status.code(), Some(1));
    assert_eq!(
        std::fs::read_to_string(ds.join("mine.txt")).unwrap(),
        "keep"
    );
}
