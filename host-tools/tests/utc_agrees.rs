//! UTC is one thing: `info`, `decode` (CSV, Parquet), `events`, `wobble`,
//! `summary`, `gpx` and MCAP give the same UTC for the same instants of a
//! log, read back with the tools their users have (gpxpy, pyarrow, the
//! `mcap` crate).

mod analysis_support;

use analysis_support::{info_json, python, stdout_of, wobblog};

/// The `t_s,utc` rows of the CSV decode.
fn csv_utc(log: &std::path::Path) -> Vec<(f64, String)> {
    let text = stdout_of(
        wobblog()
            .arg("decode")
            .arg(log)
            .args(["--columns", "t_s,utc"]),
    );
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    reader
        .records()
        .map(|r| {
            let r = r.unwrap();
            (r[0].parse().unwrap(), r[1].to_string())
        })
        .collect()
}

const READ_BACK: &str = r#"
import json, sys
import gpxpy, pyarrow.parquet as pq
gpx = gpxpy.parse(open(sys.argv[1]))
times = [p.time.strftime("%Y-%m-%dT%H:%M:%S.%f")[:-3] + "Z"
         for t in gpx.tracks for s in t.segments for p in s.points]
table = pq.read_table(sys.argv[2], columns=["t_s", "utc"]).to_pylist()
parquet = [[r["t_s"], r["utc"].strftime("%Y-%m-%dT%H:%M:%S.%f") + "Z"] for r in table if r["utc"]]
print(json.dumps({"gpx": times, "parquet": parquet}))
"#;

#[test]
fn info_decode_gpx_and_mcap_agree_on_utc() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let rows = csv_utc(&log);
    let with_utc: Vec<&(f64, String)> = rows.iter().filter(|r| !r.1.is_empty()).collect();
    assert!(with_utc.len() > 2000);

    let info = info_json(&log);
    assert_eq!(info["first_utc"], with_utc[0].1.as_str());
    assert_eq!(info["last_utc"], with_utc.last().unwrap().1.as_str());
    let text = stdout_of(wobblog().arg("info").arg(&log));
    assert!(
        text.contains(&format!(
            "utc:          {} to {}",
            with_utc[0].1,
            with_utc.last().unwrap().1
        )),
        "{text}"
    );

    // Events at a frame's time have that frame's UTC.
    let utc_of = |t: f64| {
        rows.iter()
            .find(|r| (r.0 - t).abs() < 1e-9)
            .map(|r| r.1.clone())
            .unwrap()
    };
    let events = stdout_of(wobblog().arg("events").arg(&log).arg("--json"));
    let mut kinds = Vec::new();
    for line in events.lines() {
        let e: serde_json::Value = serde_json::from_str(line).unwrap();
        let t = e["t_s"].as_f64().unwrap();
        assert_eq!(e["utc"], utc_of(t).as_str(), "{line}");
        kinds.push(e["event"].as_str().unwrap().to_string());
    }
    assert_eq!(kinds, ["marker", "alert_on", "alert_off", "marker"]);
    let table = stdout_of(wobblog().arg("events").arg(&log));
    assert!(table.contains(&utc_of(16.0)), "{table}");

    // A wobble's onset: the UTC of its time, within the frame it falls in.
    let wobble = stdout_of(wobblog().arg("wobble").arg(&log).arg("--json"));
    let run: serde_json::Value = serde_json::from_str(wobble.lines().next().unwrap()).unwrap();
    let episode = &run["episodes"][0];
    let onset = episode["onset_s"].as_f64().unwrap();
    let onset_utc = episode["onset_utc"].as_str().unwrap();
    let frame = rows.iter().rev().find(|r| r.0 <= onset).unwrap();
    let us = |text: &str| wobblog::time::parse_iso8601_us(text).unwrap();
    let expected = us(&frame.1) + ((onset - frame.0) * 1e6).round() as i64;
    assert!(
        (us(onset_utc) - expected).abs() <= 1,
        "{onset_utc} {frame:?}"
    );

    // `summary` gives `info`'s first UTC.
    let summary = stdout_of(
        wobblog()
            .arg("summary")
            .arg(dir.path())
            .args(["--format", "jsonl"]),
    );
    let row: serde_json::Value = serde_json::from_str(summary.lines().next().unwrap()).unwrap();
    assert_eq!(row["first_utc"], info["first_utc"]);

    // MCAP log times are the CSV's UTC, to the microsecond the CSV's text
    // has.
    let mcap = dir.path().join("run.mcap");
    wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&mcap)
        .assert()
        .success();
    let bytes = std::fs::read(&mcap).unwrap();
    let sensors: Vec<u64> = mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(Result::unwrap)
        .filter(|m| m.channel.topic == "/sensors")
        .map(|m| m.log_time)
        .collect();
    assert_eq!(sensors.len(), rows.len());
    for (ns, (_, utc)) in sensors.iter().zip(&rows).filter(|(_, r)| !r.1.is_empty()) {
        assert_eq!(ns % 1000, 0, "a whole microsecond");
        let us = i64::try_from(ns / 1000).unwrap();
        assert_eq!(&wobblog::time::iso8601_unix_us(us).unwrap(), utc);
    }

    let gpx = dir.path().join("run.gpx");
    wobblog()
        .arg("gpx")
        .arg(&log)
        .arg("-o")
        .arg(&gpx)
        .assert()
        .success();
    let parquet = dir.path().join("run.parquet");
    wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&parquet)
        .assert()
        .success();
    let Some(seen) = python(READ_BACK, &[gpx.as_os_str(), parquet.as_os_str()]) else {
        return;
    };
    // Every GPX point's time (the fix's own, to its millisecond) is the UTC
    // `decode` gives a row.
    let utc_texts: std::collections::BTreeSet<String> = with_utc
        .iter()
        .map(|r| format!("{}Z", &r.1[..23]))
        .collect();
    let gpx_times = seen["gpx"].as_array().unwrap();
    assert!(gpx_times.len() > 400);
    for time in gpx_times {
        assert!(utc_texts.contains(time.as_str().unwrap()), "{time}");
    }
    // Parquet's microseconds are the CSV's.
    let parquet_rows = seen["parquet"].as_array().unwrap();
    assert_eq!(parquet_rows.len(), with_utc.len());
    for (p, c) in parquet_rows.iter().zip(&with_utc) {
        assert_eq!(p[0].as_f64().unwrap(), c.0);
        let micro = p[1].as_str().unwrap();
        assert_eq!(micro, c.1, "{micro}");
    }
}
