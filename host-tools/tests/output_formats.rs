//! What `decode -o NAME` writes for each name, read back with the readers
//! researchers use: pandas' and Polars' CSV and JSON lines readers (their
//! Python packages; `hil-tests/install-tools.sh` installs them).

mod analysis_support;

use analysis_support::{decode_to, late_fix_log, python};

/// Reads each file given with pandas and Polars, default options (the
/// separator named for a `.tsv`), and reports column types and values.
const READ_BACK: &str = r#"
import json, sys
import pandas as pd, polars as pl
out = {}
for path in sys.argv[1:]:
    sep = "\t" if ".tsv" in path else ","
    if ".jsonl" in path:
        frame = pd.read_json(path, lines=True)
        # JSON has no NaN: the first 100 lines, which Polars' default types
        # from, hold only nulls in the GPS keys, so the whole file is
        # scanned for the types.
        polars = pl.read_ndjson(path, infer_schema_length=None)
    else:
        frame = pd.read_csv(path, sep=sep)
        polars = pl.read_csv(path, separator=sep)
    fixed = frame[frame["gps_lat_deg"].notna()]
    polars_fixed = polars.fill_nan(None).drop_nulls("gps_lat_deg")
    out[path.rsplit("/", 1)[1]] = {
        "rows": len(frame),
        "pandas": {c: str(frame[c].dtype) for c in ["t_s", "steer_deg", "gps_lat_deg", "gps_lon_deg", "gps_speed_mps"]},
        "polars": {c: str(polars.schema[c]) for c in polars.columns},
        "polars_fixes": len(polars_fixed),
        "utc": polars_fixed["utc"][0],
        "fixes": len(fixed),
        "first_fix": [float(fixed["t_s"].iloc[0]), float(fixed["gps_lat_deg"].iloc[0]), float(fixed["gps_lon_deg"].iloc[0])],
    }
print(json.dumps(out))
"#;

#[test]
fn text_outputs_read_back_numeric_in_pandas_and_polars() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    late_fix_log(&log);
    let names = [
        "run.csv",
        "run.tsv",
        "run.csv.gz",
        "run.jsonl",
        "run.jsonl.gz",
    ];
    for name in names {
        let out = decode_to(&log, &dir.path().join(name), &[]);
        assert!(
            out.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let gz = std::fs::read(dir.path().join("run.csv.gz")).unwrap();
    assert_eq!(gz[..2], [0x1f, 0x8b], "gzip magic");
    let tsv = std::fs::read_to_string(dir.path().join("run.tsv")).unwrap();
    assert!(tsv.starts_with("t_s\tax_g\t"), "{}", &tsv[..40]);
    let paths: Vec<_> = names.iter().map(|n| dir.path().join(n)).collect();
    let args: Vec<&std::ffi::OsStr> = paths.iter().map(|p| p.as_os_str()).collect();
    let Some(seen) = python(READ_BACK, &args) else {
        return;
    };
    for name in names {
        let file = &seen[name];
        assert_eq!(file["rows"], 2000, "{name}");
        for column in [
            "t_s",
            "steer_deg",
            "gps_lat_deg",
            "gps_lon_deg",
            "gps_speed_mps",
        ] {
            assert_eq!(file["pandas"][column], "float64", "{name} {column}");
        }
        // Polars, default options for CSV: every number a Float64, the
        // names and times text.
        for (column, dtype) in file["polars"].as_object().unwrap() {
            let text = ["gps_fix", "utc"].contains(&column.as_str());
            let expected = if text { "String" } else { "Float64" };
            assert_eq!(dtype, expected, "{name} {column}");
        }
        assert_eq!(file["polars"].as_object().unwrap().len(), 14, "{name}");
        assert_eq!(file["fixes"], 1600, "{name}");
        assert_eq!(file["polars_fixes"], 1600, "{name}");
        // UTC to the microsecond (the log's first sync pair is at 10:00:00 UTC at boot).
        let utc = file["utc"].as_str().unwrap();
        assert_eq!(
            utc.len(),
            "2020-03-18T10:00:06.000000Z".len(),
            "{name} {utc}"
        );
        // Latitude and longitude each their own value (the track runs north
        // from 52.2 N along 6.88 E).
        let first = &file["first_fix"];
        assert_eq!(first[0], 5.0, "{name}");
        assert!(
            (first[1].as_f64().unwrap() - 52.2).abs() < 0.01,
            "{name} {first}"
        );
        assert!(
            (first[2].as_f64().unwrap() - 6.88).abs() < 1e-6,
            "{name} {first}"
        );
    }
}

#[test]
fn a_delimiter_is_honoured_and_unknown_names_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    late_fix_log(&log);
    let semi = dir.path().join("run.csv");
    let out = decode_to(
        &log,
        &semi,
        &["--delimiter", ";", "--columns", "t_s,gps_lat_deg,utc"],
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let mut reader = csv::ReaderBuilder::new()
        .delimiter(b';')
        .from_path(&semi)
        .unwrap();
    assert_eq!(reader.headers().unwrap(), vec!["t_s", "gps_lat_deg", "utc"]);
    let rows: Vec<csv::StringRecord> = reader.records().map(Result::unwrap).collect();
    assert_eq!(rows.len(), 2000);
    assert_eq!(&rows[0][1], "NaN");
    assert!(rows[1999][1].parse::<f64>().is_ok());

    for name in ["run.json", "run.txt", "run.gpx", "run.parquet.gz"] {
        let target = dir.path().join(name);
        let out = decode_to(&log, &target, &[]);
        assert_eq!(out.status.code(), Some(2), "{name}");
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(
            stderr.contains(name) && stderr.contains(".csv.gz"),
            "{stderr}"
        );
        assert!(!target.exists(), "{name}");
    }
    // An explicit --format is honoured whatever the name.
    let txt = dir.path().join("run.txt");
    let out = decode_to(&log, &txt, &["--format", "jsonl"]);
    assert!(out.status.success());
    assert!(std::fs::read_to_string(&txt)
        .unwrap()
        .starts_with("{\"t_s\":1.0,"));
    let out = decode_to(&log, &dir.path().join("x.parquet"), &["--delimiter", ";"]);
    assert_eq!(out.status.code(), Some(2));
}
