//! `wobblog encode` then `decode` returns the CSV rows within the format's
//! quantisation.

use std::path::Path;

use proptest::collection::vec;
use proptest::prelude::*;
use wobblog::cmd::{decode, encode};
use wobblog::export::Format;

#[derive(Clone, Debug)]
struct CsvRow {
    t_s: f64,
    values: [f64; 8],
    gps: Option<(f64, f64, f64, &'static str)>,
}

fn rows() -> impl Strategy<Value = Vec<CsvRow>> {
    let value_ranges = (
        -15.9..15.9f64,
        -15.9..15.9f64,
        -15.9..15.9f64,
        -1000.0..1000.0f64,
        -1000.0..1000.0f64,
        -1000.0..1000.0f64,
        -300.0..300.0f64,
        0.0..60.0f64,
    );
    let gps = proptest::option::of((
        -90.0..90.0f64,
        -180.0..180.0f64,
        0.0..514.0f64,
        prop_oneof![Just("2d"), Just("3d")],
    ));
    (vec((value_ranges, gps, 0..40u64), 1..600), 0..10_000u64).prop_map(|(items, start_cs)| {
        let mut t_cs = start_cs;
        items
            .into_iter()
            .map(|((a, b, c, d, e, f, g, h), gps, jitter_us)| {
                t_cs += 1;
                CsvRow {
                    t_s: t_cs as f64 / 100.0 + jitter_us as f64 * 1e-6,
                    values: [a, b, c, d, e, f, g, h],
                    gps,
                }
            })
            .collect()
    })
}

fn to_csv(rows: &[CsvRow]) -> String {
    let mut s = String::from("t_s,ax_g,ay_g,az_g,gx_dps,gy_dps,gz_dps,steer_deg,speed_mps,gps_lat_deg,gps_lon_deg,gps_speed_mps,gps_fix\n");
    for r in rows {
        s.push_str(&format!("{}", r.t_s));
        for v in r.values {
            s.push_str(&format!(",{v}"));
        }
        match r.gps {
            Some((lat, lon, speed, fix)) => s.push_str(&format!(",{lat},{lon},{speed},{fix}\n")),
            None => s.push_str(",,,,\n"),
        }
    }
    s
}

fn round_trip(csv: &str, format: Format) -> String {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("run.wbl");
    let out = std::fs::File::create(&log).unwrap();
    encode::encode(csv.as_bytes(), Path::new("in.csv"), out, &log, false).unwrap();
    let mut decoded = Vec::new();
    let losses = decode::decode_to(
        &log,
        &decode::Export::all(format),
        &mut decoded,
        Path::new("out"),
    )
    .unwrap();
    assert!(losses.describe().is_empty());
    String::from_utf8(decoded).unwrap()
}

/// Largest error a stored value may show: half a count of each column.
const TOLERANCE: [f64; 8] = [
    0.5 / 2048.0,
    0.5 / 2048.0,
    0.5 / 2048.0,
    0.5 / 32.0,
    0.5 / 32.0,
    0.5 / 32.0,
    0.005,
    0.0005,
];

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    #[test]
    fn csv_round_trip_within_quantisation(rows in rows()) {
        let out = round_trip(&to_csv(&rows), Format::Csv);
        let mut reader = csv::Reader::from_reader(out.as_bytes());
        let decoded: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
        prop_assert_eq!(decoded.len(), rows.len());
        for (row, rec) in rows.iter().zip(&decoded) {
            let num = |i: usize| rec[i].parse::<f64>().unwrap();
            prop_assert!((num(0) - row.t_s).abs() <= 0.5e-6, "t_s {} vs {}", num(0), row.t_s);
            for (i, (v, tol)) in row.values.iter().zip(TOLERANCE).enumerate() {
                prop_assert!((num(i + 1) - v).abs() <= tol * 1.001 + 1e-9, "column {} {} vs {}", i + 1, num(i + 1), v);
            }
            match row.gps {
                Some((lat, lon, speed, fix)) => {
                    prop_assert!((num(9) - lat).abs() <= 0.51e-7);
                    prop_assert!((num(10) - lon).abs() <= 0.51e-7);
                    prop_assert!((num(11) - speed).abs() <= 0.0051);
                    prop_assert_eq!(&rec[12], fix);
                }
                // A missing number is NaN, a missing name empty.
                None => prop_assert!(&rec[9] == "NaN" && &rec[11] == "NaN" && rec[12].is_empty()),
            }
        }
    }

    #[test]
    fn jsonl_has_the_same_rows_as_csv(rows in rows()) {
        let csv_text = to_csv(&rows);
        let jsonl = round_trip(&csv_text, Format::Jsonl);
        let csv_out = round_trip(&csv_text, Format::Csv);
        let mut reader = csv::Reader::from_reader(csv_out.as_bytes());
        let header = reader.headers().unwrap().clone();
        for (line, rec) in jsonl.lines().zip(reader.records()) {
            let rec = rec.unwrap();
            let obj: serde_json::Value = serde_json::from_str(line).unwrap();
            for (name, field) in header.iter().zip(rec.iter()) {
                match obj.get(name) {
                    Some(serde_json::Value::String(s)) => prop_assert_eq!(s.as_str(), field),
                    // An empty or NaN cell is a null: every key is on every line.
                    Some(serde_json::Value::Null) => prop_assert!(field.is_empty() || field == "NaN", "{} null", name),
                    Some(v) => prop_assert_eq!(v.as_f64().unwrap(), field.parse::<f64>().unwrap()),
                    None => prop_assert!(false, "{} missing from JSON", name),
                }
            }
        }
        prop_assert_eq!(jsonl.lines().count(), rows.len());
    }
}

#[test]
fn missing_columns_are_zero() {
    let out = round_trip("t_s,steer_deg\n0.01,1.5\n0.02,-2.25\n", Format::Csv);
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(
        lines[1],
        "0.01,0.0,0.0,0.0,0.0,0.0,0.0,1.5,0.0,NaN,NaN,NaN,,"
    );
    assert_eq!(
        lines[2],
        "0.02,0.0,0.0,0.0,0.0,0.0,0.0,-2.25,0.0,NaN,NaN,NaN,,"
    );
}

/// `csv` with a `utc` column appended: `utc_us[i]` (µs since 1970) for
/// data row `i`, empty where `None`.
fn with_utc(csv: &str, utc_us: &[Option<i64>]) -> String {
    let mut lines = csv.lines();
    let mut out = format!("{},utc\n", lines.next().unwrap());
    for (line, us) in lines.zip(utc_us) {
        let utc = us.map_or(String::new(), |us| {
            wobblog::time::iso8601_unix_us(us).unwrap()
        });
        out.push_str(&format!("{line},{utc}\n"));
    }
    out
}

/// The `utc` column of a decoded CSV.
fn utc_column(csv: &str) -> Vec<String> {
    let mut reader = csv::Reader::from_reader(csv.as_bytes());
    let at = reader
        .headers()
        .unwrap()
        .iter()
        .position(|h| h == "utc")
        .unwrap();
    reader
        .records()
        .map(|r| r.unwrap()[at].to_string())
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Whatever UTC a CSV gives its rows (a clock that drifts, steps or
    /// stands still against UTC), the log built from it decodes to the same
    /// UTC text on every row; rows before the first UTC stay without one.
    #[test]
    fn utc_round_trips_to_the_microsecond(
        rows in rows(),
        start_us in 946_684_810_000_000i64..4_102_444_000_000_000,
        steps_us in vec(prop_oneof![6 => Just(10_000i64), 2 => 9_990..10_010i64, 1 => 0..12_000i64, 1 => -3000..1_000_000i64], 600),
        first in 0..50usize,
    ) {
        let mut us = start_us;
        let utc: Vec<Option<i64>> = (0..rows.len())
            .map(|i| {
                us += steps_us[i];
                (i >= first).then_some(us)
            })
            .collect();
        let given = with_utc(&to_csv(&rows), &utc);
        let expected: Vec<String> = utc_column(&given);
        prop_assert_eq!(utc_column(&round_trip(&given, Format::Csv)), expected);
    }
}

#[test]
fn a_decoded_log_encodes_to_the_same_utc() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("ride.csv");
    let first = wobblog::time::parse_iso8601_us("2020-03-18T10:00:01.000Z").unwrap();
    // A GPS clock 0.4 ms off the logger's frames on some rows, as real
    // pairs are.
    let utc: Vec<Option<i64>> = (0..3000)
        .map(|i| (i >= 100).then(|| first + (i - 100) * 10_000 + 400 * i64::from(i % 7 == 0)))
        .collect();
    let rows: Vec<CsvRow> = (0..3000)
        .map(|i| CsvRow {
            t_s: 1.0 + f64::from(i) / 100.0,
            values: [0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.5, 5.0],
            gps: None,
        })
        .collect();
    std::fs::write(&csv, with_utc(&to_csv(&rows), &utc)).unwrap();
    let once = round_trip(&std::fs::read_to_string(&csv).unwrap(), Format::Csv);
    let twice = round_trip(&once, Format::Csv);
    assert_eq!(once, twice);
    let column = utc_column(&once);
    assert_eq!(column[99], "");
    assert_eq!(column[100], "2020-03-18T10:00:01.000000Z");
    assert_eq!(column[105], "2020-03-18T10:00:01.050400Z");
    assert_eq!(column[2999], "2020-03-18T10:00:29.990000Z");
}

#[test]
fn a_column_encode_does_not_know_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("ride.csv");
    std::fs::write(&csv, "t_s,steer,speed_mps\n0.01,1.5,4.0\n").unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let out = assert_cmd::Command::cargo_bin("wobblog")
        .unwrap()
        .args(["encode", "--csv"])
        .arg(&csv)
        .arg("-o")
        .arg(&log)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("ride.csv")
            && stderr.contains("no column \"steer\"")
            && stderr.contains("steer_deg"),
        "{stderr}"
    );
    assert!(!log.exists());
}
