//! `wobblog export`: a campaign as Parquet datasets, one folder per table,
//! opened with Polars, pyarrow and DuckDB as their users would, default
//! options only (their Python packages; `hil-tests/install-tools.sh`
//! installs them).

mod analysis_support;

use analysis_support::{python, standard_log, stdout_of, wobblog, write_log, Ride};
use serde_json::json;
use std::path::Path;

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
            } else if run == 3 {
                other_log(&path)
            } else {
                standard_log(&path).0.t_s.len()
            }
        })
        .collect()
}

/// A log as long as the standard one, with other bytes (a byte-identical
/// copy would be one input), written to `path`; its number of frames.
fn other_log(path: &Path) -> usize {
    let (_, extras) = standard_log(path);
    let ride = Ride::new(30.0, 5.0, 15.0, 2.0, 0.4);
    write_log(path, &ride, &extras);
    ride.t_s.len()
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

/// Opens each table of the dataset `argv[1]` with Polars, pyarrow and
/// DuckDB, every one with its default options, and reports what each sees.
const READ_BACK: &str = r#"
import json, sys
import duckdb, polars as pl, pyarrow.parquet as pq
ds = sys.argv[1]
out = {}
frames = pl.scan_parquet(ds + "/frames/")
out["polars_run_type"] = str(frames.collect_schema()["run"])
out["polars_counts"] = frames.group_by("run").len().sort("run").collect().rows()
out["polars_utc_type"] = str(frames.collect_schema()["utc"])
table = pq.read_table(ds + "/frames")
out["pyarrow_run_type"] = str(table.schema.field("run").type)
import pyarrow.dataset
out["pyarrow_dataset_runs"] = sorted(set(pyarrow.dataset.dataset(ds + "/frames").to_table().column("run").to_pylist()))
out["first_column"] = pq.read_schema(f"{ds}/frames/RUN00001.parquet").names[0]
events = pl.read_parquet(ds + "/events/")
out["events_schema"] = {k: str(v) for k, v in events.schema.items()}
out["events"] = events.select("run", "event").rows()
out["pyarrow_rows"] = table.num_rows
out["duckdb_counts"] = duckdb.sql(
    f"SELECT run, typeof(run), count(*) FROM '{ds}/frames/**/*.parquet' GROUP BY ALL ORDER BY run"
).fetchall()
runs = pl.scan_parquet(ds + "/runs/")
episodes = pl.scan_parquet(ds + "/episodes/")
out["episodes_schema"] = {k: str(v) for k, v in episodes.collect_schema().items()}
out["runs_schema"] = {k: str(v) for k, v in runs.collect_schema().items()}
out["unstable"] = (
    episodes.filter(pl.col("stability") == "unstable")
    .join(runs, on="run")
    .select("run", pl.col("speed_at_onset_mps").round(2), "censored", "censored_episodes",
            (pl.col("wobble_speed_mps") == pl.col("speed_at_onset_mps")).alias("same"))
    .sort("run").collect().rows()
)
out["pyarrow_episodes"] = pq.read_table(ds + "/episodes").num_rows
out["duckdb_runs"] = duckdb.sql(
    f"SELECT count(*), min(first_utc)::VARCHAR FROM '{ds}/runs/*.parquet'"
).fetchall()
units = {}
for table in ["frames/RUN00001.parquet", "runs/part-0.parquet", "episodes/part-0.parquet", "events/part-0.parquet"]:
    meta = pq.read_schema(f"{ds}/{table}").metadata
    units[table] = {k.decode()[5:]: v.decode() for k, v in meta.items() if k.startswith(b"unit.")}
out["units"] = units
print(json.dumps(out, default=str))
"#;

#[test]
fn each_table_opens_as_a_dataset_in_polars_pyarrow_and_duckdb() {
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
        assert!(ds.join(format!("frames/RUN{run:05}.parquet")).is_file());
    }
    let Some(seen) = python(READ_BACK, &[ds.as_os_str()]) else {
        return;
    };
    // The run in every file, an integer in every reader, also where
    // partition folders are not read (pyarrow.dataset's defaults).
    assert_eq!(seen["polars_run_type"], "Int64");
    assert_eq!(seen["pyarrow_run_type"], "int64");
    assert_eq!(seen["pyarrow_dataset_runs"], json!([1, 2, 3]));
    assert_eq!(seen["first_column"], "run");
    // The events table: the alerts and markers of every run.
    let events = &seen["events_schema"];
    assert_eq!(events["run"], "Int64");
    assert_eq!(events["utc"], "Datetime(time_unit='us', time_zone='UTC')");
    assert_eq!(events["freq_hz"], "Float64");
    assert_eq!(events["details"], "String");
    // Each run's events are those `wobblog events` lists, in its order.
    for run in 1..=3 {
        let log = dir.path().join(format!("card/RUN{run:05}.WBL"));
        let listed = stdout_of(wobblog().arg("events").arg(&log).arg("--json"));
        let names: Vec<serde_json::Value> = listed
            .lines()
            .map(|l| serde_json::from_str::<serde_json::Value>(l).unwrap()["event"].clone())
            .collect();
        let in_table: Vec<serde_json::Value> = seen["events"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r[0] == run)
            .map(|r| r[1].clone())
            .collect();
        assert!(names.len() >= 4, "{names:?}");
        assert_eq!(in_table, names, "run {run}");
    }
    let counts: Vec<serde_json::Value> = frames
        .iter()
        .enumerate()
        .map(|(i, n)| json!([i + 1, n]))
        .collect();
    assert_eq!(seen["polars_counts"], json!(counts));
    let duck: Vec<serde_json::Value> = frames
        .iter()
        .enumerate()
        .map(|(i, n)| json!([i + 1, "BIGINT", n]))
        .collect();
    assert_eq!(seen["duckdb_counts"], json!(duck));
    assert_eq!(seen["pyarrow_rows"], frames.iter().sum::<usize>());
    assert!(seen["polars_utc_type"]
        .as_str()
        .unwrap()
        .starts_with("Datetime(time_unit='us', time_zone='UTC'"));
    // The censoring columns, typed.
    let episodes = &seen["episodes_schema"];
    assert_eq!(episodes["censored"], "Boolean");
    assert_eq!(episodes["cut_at_start"], "String");
    assert_eq!(episodes["cut_at_end"], "String");
    assert_eq!(seen["runs_schema"]["censored_episodes"], "Int64");
    assert_eq!(
        seen["unstable"],
        json!([
            [1, 5.0, false, 0, true],
            [2, 5.0, false, 0, true],
            [3, 5.0, false, 0, true]
        ])
    );
    assert_eq!(seen["pyarrow_episodes"], 3);
    let runs = &seen["duckdb_runs"][0];
    assert_eq!(runs[0], 3);
    assert!(
        runs[1].as_str().unwrap().starts_with("2020-03-18 10:00:01"),
        "{runs}"
    );
    // Units on every table.
    let units = &seen["units"];
    assert_eq!(units["frames/RUN00001.parquet"]["gz_dps"], "deg/s");
    assert_eq!(units["runs/part-0.parquet"]["distance_m"], "m");
    assert_eq!(units["runs/part-0.parquet"]["first_utc"], "UTC");
    assert_eq!(units["episodes/part-0.parquet"]["sigma_per_s"], "1/s");
    assert_eq!(units["episodes/part-0.parquet"]["freq_hz"], "Hz");
    assert_eq!(units["episodes/part-0.parquet"]["censored"], "");
    assert_eq!(units["events/part-0.parquet"]["amp_deg"], "deg");
}

/// A folder of cards, one log each (different bytes: copies would be one
/// input), exported; what Polars, pyarrow and DuckDB see of each frame
/// table's `card` and `run` (`None` without their Python packages).
fn cards_read_back(names: &[&str]) -> Option<serde_json::Value> {
    let dir = tempfile::tempdir().unwrap();
    let cards = dir.path().join("cards");
    for (i, name) in names.iter().enumerate() {
        std::fs::create_dir_all(cards.join(name)).unwrap();
        let path = cards.join(name).join("RUN00001.WBL");
        let (_, extras) = standard_log(&path);
        let ride = Ride::new(30.0, 5.0, 15.0, 2.0, 0.4 + 0.05 * i as f64);
        write_log(&path, &ride, &extras);
    }
    let ds = dir.path().join("ds");
    wobblog()
        .arg("export")
        .arg(&cards)
        .arg("-o")
        .arg(&ds)
        .assert()
        .success();
    assert!(ds.join("runs/part-0.parquet").is_file());
    assert!(ds.join("episodes/part-0.parquet").is_file());
    let script = r#"
import json, sys
import duckdb, polars as pl, pyarrow.parquet as pq
ds = sys.argv[1]
polars = pl.scan_parquet(ds + "/frames/").select("card", "run").unique().sort("card").collect().rows()
table = pq.read_table(ds + "/frames", columns=["card", "run"]).to_pylist()
arrow = sorted({(r["card"], r["run"]) for r in table})
duck = duckdb.sql(f"SELECT DISTINCT card, run FROM '{ds}/frames/**/*.parquet' ORDER BY card").fetchall()
print(json.dumps({"polars": polars, "arrow": arrow, "duck": duck}))
"#;
    python(script, &[ds.as_os_str()])
}

#[test]
fn a_folder_of_cards_is_partitioned_by_card_and_run() {
    let Some(seen) = cards_read_back(&["blue", "red"]) else {
        return;
    };
    for reader in ["polars", "arrow", "duck"] {
        assert_eq!(seen[reader], json!([["blue", 1], ["red", 1]]), "{reader}");
    }
}

/// Card names that are Hive syntax, an escape or a line break reach each
/// reader as they are on the card (each escaped in the partition path).
#[test]
fn odd_card_names_read_back_as_they_are() {
    let names = ["a b", "a%2Fb", "line\nbreak", "rider=anna"];
    let Some(seen) = cards_read_back(&names) else {
        return;
    };
    let want: Vec<_> = names.iter().map(|n| json!([n, 1])).collect();
    for reader in ["polars", "arrow", "duck"] {
        assert_eq!(seen[reader], json!(want), "{reader}");
    }
}

#[test]
fn a_bad_log_is_reported_and_left_out_unless_strict() {
    let dir = tempfile::tempdir().unwrap();
    let card_dir = dir.path().join("card");
    let frames = card(&card_dir);
    std::fs::write(card_dir.join("RUN00004.WBL"), b"").unwrap();
    let ds = dir.path().join("season");
    let out = export(&card_dir, &ds);
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("RUN00004.WBL") && stderr.contains("left out"),
        "{stderr}"
    );
    let script = r#"
import json, sys
import polars as pl
ds = sys.argv[1]
runs = pl.read_parquet(ds + "/runs/").get_column("run").to_list()
frames = pl.scan_parquet(ds + "/frames/").select(pl.len()).collect().item()
print(json.dumps({"runs": runs, "frames": frames}))
"#;
    assert!(!ds.join("frames/RUN00004.parquet").exists());
    if let Some(seen) = python(script, &[ds.as_os_str()]) {
        assert_eq!(seen["runs"], json!([1, 2, 3]));
        assert_eq!(seen["frames"], frames.iter().sum::<usize>());
    }
}

#[test]
fn the_dataset_appears_whole_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let card_dir = dir.path().join("card");
    card(&card_dir);
    std::fs::write(card_dir.join("RUN00004.WBL"), vec![0u8; 4096]).unwrap();
    let ds = dir.path().join("season");
    let out = wobblog()
        .arg("export")
        .arg(&card_dir)
        .arg("-o")
        .arg(&ds)
        .arg("--strict")
        .output()
        .unwrap();
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

#[test]
fn a_dangling_link_at_the_target_is_refused_before_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let card_dir = dir.path().join("card");
    card(&card_dir);
    let ds = dir.path().join("season");
    std::os::unix::fs::symlink("nowhere", &ds).unwrap();
    let out = export(&card_dir, &ds);
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("exists already"), "{err}");
    // Refused at once: no log was read, so no run was written.
    assert!(!err.contains("runs written"), "{err}");
    assert!(std::fs::symlink_metadata(&ds).unwrap().is_symlink());
}

#[test]
fn a_temporary_dataset_left_by_a_killed_run_is_removed_by_the_next() {
    let dir = tempfile::tempdir().unwrap();
    let card_dir = dir.path().join("card");
    card(&card_dir);
    let left = dir.path().join(".season.k1LLed.tmp");
    std::fs::create_dir_all(left.join("frames")).unwrap();
    std::fs::write(left.join("frames/RUN00001.parquet"), b"half").unwrap();
    // One whose writer lives (its lock held) stays.
    let live = dir.path().join(".season.al1ve0.tmp");
    std::fs::create_dir(&live).unwrap();
    let held = std::fs::File::open(&live).unwrap();
    held.lock().unwrap();
    let out = export(&card_dir, &dir.path().join("season"));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!left.exists(), "{err}");
    assert!(err.contains("left by an interrupted run"), "{err}");
    assert!(live.exists());
}

#[test]
fn a_signal_at_any_moment_leaves_no_temporary_dataset() {
    // The signal's clean-up once raced the worker's folders: an early
    // SIGINT left `.season.XXXXXX.tmp/` in about half the runs.
    let dir = tempfile::tempdir().unwrap();
    let card_dir = dir.path().join("card");
    card(&card_dir);
    for delay_ms in [0, 1, 2, 3, 5, 8, 12, 20, 30, 50] {
        let ds = dir.path().join("season");
        let _ = std::fs::remove_dir_all(&ds);
        let mut child = std::process::Command::new(wobblog().get_program())
            .arg("export")
            .arg(&card_dir)
            .arg("-o")
            .arg(&ds)
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(delay_ms));
        let _ = std::process::Command::new("kill")
            .args(["-s", "INT", &child.id().to_string()])
            .status();
        let _ = child.wait();
        let left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(".season."))
            .collect();
        assert!(left.is_empty(), "after {delay_ms} ms: {left:?}");
    }
}
