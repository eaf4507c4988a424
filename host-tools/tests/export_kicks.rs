//! The data set's `kicks` table is `wobblog margin`'s kicks: the same
//! kicks with the same values and source, `used` as the prediction's
//! weights say (an outlier not), and a `mode` column.

mod analysis_support;

use std::path::Path;

use analysis_support::{kick_pass, wobblog, write_log, Extras};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;
use serde_json::Value;

/// Every row of the Parquet file at `path`, as (column, value) pairs.
fn rows_of(path: &Path) -> Vec<Vec<(String, Field)>> {
    let reader = SerializedFileReader::new(std::fs::File::open(path).unwrap()).unwrap();
    reader
        .get_row_iter(None)
        .unwrap()
        .map(|r| {
            r.unwrap()
                .get_column_iter()
                .map(|(n, f)| (n.clone(), f.clone()))
                .collect()
        })
        .collect()
}

fn cell<'a>(row: &'a [(String, Field)], name: &str) -> &'a Field {
    &row.iter().find(|(n, _)| n == name).unwrap().1
}

fn number(row: &[(String, Field)], name: &str) -> f64 {
    match cell(row, name) {
        Field::Double(v) => *v,
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn the_kicks_table_is_margins_kicks() {
    let dir = tempfile::tempdir().unwrap();
    let card = dir.path().join("card");
    std::fs::create_dir(&card).unwrap();
    // Eleven passes of a campaign whose wobble speed is 4 m/s, and one
    // whose ring decays as a bicycle wobbling at 9 m/s would: an outlier.
    for i in 0..12u32 {
        let u = 2.0 + 0.12 * f64::from(i);
        let wobble_mps = if i == 5 { 9.0 } else { 4.0 };
        let ride = kick_pass(u, wobble_mps, 6.5, i);
        write_log(
            &card.join(format!("RUN{:05}.WBL", i + 1)),
            &ride,
            &Extras::default(),
        );
    }
    let out = wobblog()
        .args(["margin", "--json"])
        .arg(&card)
        .output()
        .unwrap();
    assert!(out.status.success());
    let margin: Value = serde_json::from_slice(&out.stdout).unwrap();
    let set = dir.path().join("set");
    let out = wobblog()
        .arg("export")
        .arg(&card)
        .arg("-o")
        .arg(&set)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows = rows_of(&set.join("kicks/part-0.parquet"));
    let kicks = margin["kicks"].as_array().unwrap();
    assert_eq!(rows.len(), kicks.len());
    assert_eq!(kicks.len(), 12);
    let mut unused = 0;
    for (row, k) in rows.iter().zip(kicks) {
        assert_eq!(cell(row, "mode"), &Field::Str("wobble".into()));
        assert_eq!(
            cell(row, "source"),
            &Field::Str(k["source"].as_str().unwrap().into())
        );
        for name in [
            "t_s",
            "speed_mps",
            "freq_hz",
            "sigma_per_s",
            "sigma_sd_per_s",
            "amp_deg",
        ] {
            assert_eq!(number(row, name), k[name].as_f64().unwrap(), "{name}");
        }
        assert_eq!(
            cell(row, "used"),
            &Field::Bool(k["used"].as_bool().unwrap())
        );
        let log = Path::new(k["log"].as_str().unwrap()).file_name().unwrap();
        assert_eq!(
            cell(row, "log"),
            &Field::Str(log.to_string_lossy().into_owned())
        );
        unused += usize::from(!k["used"].as_bool().unwrap());
    }
    assert_eq!(unused, 1, "the outlier is the one kick not used");
    assert_eq!(margin["kicks_rejected"], 1);
}
