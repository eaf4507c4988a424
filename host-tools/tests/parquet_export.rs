//! `wobblog decode --format parquet`: read back with the parquet crate, the
//! file holds the CSV's rows and columns with the same values.

mod analysis_support;

use std::fs::File;
use std::path::Path;

use analysis_support::wobblog;
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;
use wobblog::export::CSV_COLUMNS;

fn decode(log: &Path, format: &str, out: &Path) {
    wobblog()
        .arg("decode")
        .arg(log)
        .args(["--format", format, "-o"])
        .arg(out)
        .assert()
        .success();
}

/// A CSV cell as the Parquet field it must equal.
fn same(cell: &str, field: &Field) -> bool {
    match field {
        // CSV writes a missing number as NaN, a missing name or time empty.
        Field::Null => cell.is_empty() || cell == "NaN",
        Field::Double(v) => cell.parse::<f64>().is_ok_and(|c| c == *v),
        Field::Str(s) => cell == s,
        // The same microsecond.
        Field::TimestampMicros(us) => wobblog::time::parse_iso8601_us(cell) == Some(*us),
        _ => false,
    }
}

#[test]
fn parquet_matches_csv_row_for_row() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let (csv_path, pq_path) = (dir.path().join("run.csv"), dir.path().join("run.parquet"));
    decode(&log, "csv", &csv_path);
    decode(&log, "parquet", &pq_path);

    let mut csv = csv::Reader::from_path(&csv_path).unwrap();
    let header: Vec<String> = csv.headers().unwrap().iter().map(String::from).collect();
    let csv_rows: Vec<csv::StringRecord> = csv.records().map(Result::unwrap).collect();

    let reader = SerializedFileReader::new(File::open(&pq_path).unwrap()).unwrap();
    let meta = reader.metadata().file_metadata();
    assert_eq!(meta.num_rows() as usize, csv_rows.len());
    let names: Vec<&str> = meta
        .schema_descr()
        .columns()
        .iter()
        .map(|c| c.name())
        .collect();
    assert_eq!(names, header);
    assert_eq!(names[..CSV_COLUMNS.len()], CSV_COLUMNS);
    assert_eq!(names[CSV_COLUMNS.len()..], ["utc"]);

    let mut rows = 0;
    let mut with_gps = 0;
    for (row, csv_row) in reader.get_row_iter(None).unwrap().zip(&csv_rows) {
        let row = row.unwrap();
        for ((name, field), cell) in row.get_column_iter().zip(csv_row.iter()) {
            assert!(
                same(cell, field),
                "row {rows} {name}: csv {cell:?}, parquet {field:?}"
            );
        }
        with_gps += usize::from(&csv_row[9] != "NaN");
        rows += 1;
    }
    assert_eq!(rows, csv_rows.len());
    // The log has GPS and a GPS outage: both kinds of rows were compared.
    assert!(
        with_gps > 0 && with_gps < rows,
        "{with_gps} of {rows} rows with GPS"
    );
}

#[test]
fn long_run_spans_several_row_groups() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("LONG.WBL");
    let ride = analysis_support::Ride::new(700.0, 5.0, 10.0, 1.0, 0.0);
    analysis_support::write_log(&log, &ride, &analysis_support::Extras::default());
    let pq_path = dir.path().join("long.parquet");
    decode(&log, "parquet", &pq_path);
    let reader = SerializedFileReader::new(File::open(&pq_path).unwrap()).unwrap();
    assert!(reader.metadata().num_row_groups() > 1);
    assert_eq!(
        reader.metadata().file_metadata().num_rows() as usize,
        ride.t_s.len()
    );
}

#[test]
fn unreadable_log_leaves_no_parquet_bytes() {
    let dir = tempfile::tempdir().unwrap();
    let junk = dir.path().join("JUNK.WBL");
    std::fs::write(&junk, vec![0u8; 2048]).unwrap();
    let out = dir.path().join("out.parquet");
    wobblog()
        .arg("decode")
        .arg(&junk)
        .args(["--format", "parquet", "-o"])
        .arg(&out)
        .assert()
        .code(1);
    assert_eq!(std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0), 0);
}

#[test]
fn parquet_carries_the_log_metadata_and_a_dictionary_gps_fix() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    let ride = analysis_support::Ride::new(5.0, 5.0, 0.0, 0.0, 0.0);
    let extras = analysis_support::Extras {
        gps: true,
        config: vec![
            "wheel.circumference_m=2.1".into(),
            "alert.enabled=on".into(),
        ],
        ..Default::default()
    };
    analysis_support::write_log(&log, &ride, &extras);
    let pq_path = dir.path().join("run.parquet");
    wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&pq_path)
        .assert()
        .success();
    let reader = SerializedFileReader::new(File::open(&pq_path).unwrap()).unwrap();
    let meta = reader.metadata();
    let kv: std::collections::BTreeMap<String, String> = meta
        .file_metadata()
        .key_value_metadata()
        .unwrap()
        .iter()
        .map(|kv| (kv.key.clone(), kv.value.clone().unwrap_or_default()))
        .collect();
    assert_eq!(kv["firmware"], "test");
    assert_eq!(kv["run"], "3");
    assert_eq!(kv["device_id"], "07".repeat(12));
    assert_eq!(kv["sample_rate_hz"], "100");
    assert_eq!(kv["config"], "wheel.circumference_m=2.1\nalert.enabled=on");
    assert_eq!(kv["first_utc"], "2020-03-18T10:00:01.000000Z");
    assert_eq!(kv["unit.steer_deg"], "deg");
    assert_eq!(kv["unit.gx_dps"], "deg/s");
    assert_eq!(kv["unit.speed_mps"], "m/s");

    let group = meta.row_group(0);
    let fix = group
        .columns()
        .iter()
        .find(|c| c.column_path().string() == "gps_fix")
        .unwrap();
    assert!(fix.dictionary_page_offset().is_some(), "{fix:?}");
    assert!(
        fix.encodings()
            .any(|e| e == parquet::basic::Encoding::RLE_DICTIONARY),
        "{fix:?}"
    );
    let utc = meta
        .file_metadata()
        .schema_descr()
        .columns()
        .iter()
        .find(|c| c.name() == "utc")
        .unwrap()
        .logical_type_ref();
    assert!(
        matches!(
            utc,
            Some(parquet::basic::LogicalType::Timestamp(t)) if t.is_adjusted_to_u_t_c
        ),
        "{utc:?}"
    );
}
