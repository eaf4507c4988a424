//! Rows as lines of text, CSV or JSON, formatted by hand into a string.
//!
//! By hand rather than through the `csv` writer: every cell of a row is a
//! number, a fixed lower-case name or an ISO time, none of which needs
//! quotes, and the writer's per-cell quoting scan and buffering were a third
//! of `decode`'s time on a 64 MiB log (`docs/robustness.md`). The output is
//! the `csv` writer's, byte for byte: `csv_lines_are_the_csv_writers` checks
//! it against that writer.

use super::columns::{Column, Value};
use crate::rows::Row;

/// How rows become lines of text.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineFormat {
    /// CSV records with this field delimiter.
    Csv {
        /// The field delimiter.
        delimiter: u8,
    },
    /// JSON objects, `null` for an absent value.
    Json,
}

impl LineFormat {
    /// Appends the line of `row`'s `columns` to `line`.
    pub fn line(self, line: &mut String, columns: &[Column], row: &Row) {
        match self {
            Self::Csv { delimiter } => csv_record(line, columns, row, delimiter),
            Self::Json => json_line(line, columns, row),
        }
    }
}

/// Appends the CSV record of `row`'s `columns` to `line`, `\n` ended, as
/// the `csv` writer's default settings write it.
#[cfg(test)]
pub fn csv_line<R>(line: &mut String, columns: &[Column<R>], row: &R) {
    csv_record(line, columns, row, b',');
}

/// [`csv_line`] with fields separated by `delimiter`.
fn csv_record<R>(line: &mut String, columns: &[Column<R>], row: &R, delimiter: u8) {
    let delimiter = char::from(delimiter);
    let mut num = zmij::Buffer::new();
    let mut int = itoa::Buffer::new();
    let mut time = [0u8; UTC_LEN];
    let start = line.len();
    for (i, column) in columns.iter().enumerate() {
        if i > 0 {
            line.push(delimiter);
        }
        match (column.value)(row) {
            Value::Number(Some(v)) => line.push_str(num.format(v)),
            Value::Label(Some(s)) => push_csv_text(line, s, delimiter),
            Value::Utc(Some(us)) => line.push_str(utc_text(us, &mut time)),
            Value::Integer(Some(n)) => line.push_str(int.format(n)),
            Value::Text(Some(s)) => push_csv_text(line, &s, delimiter),
            Value::Bool(Some(b)) => line.push_str(if b { "true" } else { "false" }),
            // A missing number is `NaN`, never an empty cell: the GPS
            // columns are empty in the first rows of every ride, and
            // Polars' default CSV reader, typing from the first 100 rows,
            // would read them as text. pandas and DuckDB read `NaN` as a
            // missing number too.
            Value::Number(None) => line.push_str(MISSING_NUMBER),
            Value::Label(None)
            | Value::Utc(None)
            | Value::Integer(None)
            | Value::Text(None)
            | Value::Bool(None) => {}
        }
    }
    // A record of one empty cell would read back as a blank line: the
    // `csv` writer quotes it.
    if line.len() == start {
        line.push_str("\"\"");
    }
    line.push('\n');
}

/// A number a row does not have, in CSV.
pub const MISSING_NUMBER: &str = "NaN";

/// `s` as a CSV cell: in quotes, with quotes doubled, if it holds the
/// delimiter, a quote or a line break (the `csv` writer's "necessary" style).
fn push_csv_text(line: &mut String, s: &str, delimiter: char) {
    if s.contains([delimiter, '"', '\r', '\n']) {
        line.push('"');
        line.push_str(&s.replace('"', "\"\""));
        line.push('"');
    } else {
        line.push_str(s);
    }
}

/// Appends the JSON object of `row`'s `columns` to `line`, `\n` ended; an
/// absent value is `null`, so every line has every key and readers that
/// infer a schema from the first lines see the columns a ride without an
/// early GPS fix has. Written by hand: every key is a plain column name and
/// every string value a fixed name, an ISO time or a file name (escaped by
/// serde), and nothing is allocated per number (the one-hour export is
/// benchmarked).
pub fn json_line(line: &mut String, columns: &[Column], row: &Row) {
    let mut num = zmij::Buffer::new();
    let mut int = itoa::Buffer::new();
    let mut time = [0u8; UTC_LEN];
    let start = line.len();
    line.push('{');
    for column in columns {
        let value = (column.value)(row);
        if line.len() > start + 1 {
            line.push(',');
        }
        line.push('"');
        line.push_str(column.name);
        line.push_str("\":");
        match value {
            Value::Number(Some(v)) => line.push_str(num.format(v)),
            Value::Label(Some(s)) => {
                line.push('"');
                line.push_str(s);
                line.push('"');
            }
            Value::Utc(Some(us)) => {
                line.push('"');
                line.push_str(utc_text(us, &mut time));
                line.push('"');
            }
            Value::Integer(Some(n)) => line.push_str(int.format(n)),
            Value::Text(Some(s)) => {
                // Serialising a string cannot fail.
                line.push_str(&serde_json::Value::String(s).to_string());
            }
            Value::Bool(Some(b)) => line.push_str(if b { "true" } else { "false" }),
            _ => line.push_str("null"),
        }
    }
    line.push_str("}\n");
}

/// Length of `2020-03-18T13:28:20.600250Z`.
const UTC_LEN: usize = 27;
/// UTC in ISO 8601 to the microsecond, as [`crate::time::iso8601_unix_us`]
/// writes it (Parquet's precision), into `buf` without allocating; empty
/// outside the card's dates.
fn utc_text(us: i64, buf: &mut [u8; UTC_LEN]) -> &str {
    const MS_PER_DAY: i64 = 86_400_000;
    const UNIX_MS_AT_2000: i64 = 10_957 * MS_PER_DAY;
    let since_2000 = us.div_euclid(1000) - UNIX_MS_AT_2000;
    let Ok(days_since_2000) = u16::try_from(since_2000.div_euclid(MS_PER_DAY)) else {
        return "";
    };
    let ms = since_2000.rem_euclid(MS_PER_DAY);
    let utc = wobble_core::format::UtcTime {
        days_since_2000,
        ms_of_day: ms as u32,
    };
    let (year, month, day) = utc.date();
    let mut put = |at: usize, value: i64, digits: usize| {
        let mut v = value;
        for i in (0..digits).rev() {
            buf[at + i] = b'0' + (v % 10) as u8;
            v /= 10;
        }
    };
    put(0, i64::from(year), 4);
    put(5, i64::from(month), 2);
    put(8, i64::from(day), 2);
    put(11, ms / 3_600_000, 2);
    put(14, ms / 60_000 % 60, 2);
    put(17, ms / 1000 % 60, 2);
    put(20, ms % 1000, 3);
    put(23, us.rem_euclid(1000), 3);
    for (at, sep) in [
        (4, b'-'),
        (7, b'-'),
        (10, b'T'),
        (13, b':'),
        (16, b':'),
        (19, b'.'),
        (26, b'Z'),
    ] {
        buf[at] = sep;
    }
    std::str::from_utf8(buf).unwrap_or("")
}

#[cfg(test)]
mod tests {
    use super::super::columns::{Kind, COLUMNS};
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn fast_utc_text_is_iso8601() {
        let mut buf = [0u8; UTC_LEN];
        for ms in [
            946_684_800_000i64,
            1_584_538_100_600,
            1_584_575_999_999,
            4_102_444_800_123,
        ] {
            for us in [0, 1, 250, 999] {
                let at = ms * 1000 + us;
                assert_eq!(
                    utc_text(at, &mut buf),
                    crate::time::iso8601_unix_us(at).unwrap()
                );
            }
        }
        assert_eq!(utc_text(0, &mut buf), "");
    }

    /// The record the `csv` writer makes of the same cells.
    fn csv_writers_line<R>(columns: &[Column<R>], row: &R) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut time = [0u8; UTC_LEN];
        for column in columns {
            let cell = match (column.value)(row) {
                Value::Number(v) => Some(v.map_or(MISSING_NUMBER.to_owned(), |v| {
                    zmij::Buffer::new().format(v).to_owned()
                })),
                Value::Label(s) => s.map(str::to_owned),
                Value::Utc(us) => us.map(|us| utc_text(us, &mut time).to_owned()),
                Value::Integer(n) => n.map(|n| n.to_string()),
                Value::Text(s) => s,
                Value::Bool(b) => b.map(|b| b.to_string()),
            };
            w.write_field(cell.unwrap_or_default()).unwrap();
        }
        w.write_record(None::<&[u8]>).unwrap();
        String::from_utf8(w.into_inner().unwrap()).unwrap()
    }

    fn any_row() -> impl Strategy<Value = Row> {
        use wobble_core::format::{FixMode, FrameStatus};
        let gps = prop::option::of((
            -90.0..90.0f64,
            -180.0..180.0f64,
            prop::option::of(0.0..100.0f64),
            prop::sample::select(vec![FixMode::Fix2d, FixMode::Fix3d]),
        ));
        (
            (
                any::<f64>(),
                prop::array::uniform3(any::<f64>()),
                prop::array::uniform3(-2000.0..2000.0f64),
            ),
            (-300.0..300.0f64, 0.0..40.0f64, any::<u16>(), any::<u8>()),
            gps,
            prop::option::of(0..4_102_444_800_000_000i64),
        )
            .prop_map(
                |((t_s, accel_g, gyro_dps), (steer, speed, count, status), gps, utc_us)| Row {
                    t_s,
                    accel_g,
                    gyro_dps,
                    steer_deg: steer,
                    speed_mps: speed,
                    wheel_count: count,
                    status: FrameStatus(status),
                    gps: gps.map(
                        |(lat_deg, lon_deg, speed_mps, fix)| crate::rows::GpsColumns {
                            lat_deg,
                            lon_deg,
                            speed_mps,
                            fix,
                        },
                    ),
                    utc_us,
                    derived: Default::default(),
                    run: None,
                },
            )
    }

    proptest! {
        #[test]
        fn csv_lines_are_the_csv_writers(
            row in any_row(),
            picks in prop::collection::vec(0..COLUMNS.len(), 1..20),
        ) {
            let columns: Vec<Column> =
                picks.iter().map(|&i| COLUMNS[i]).collect();
            let mut line = String::new();
            csv_line(&mut line, &columns, &row);
            prop_assert_eq!(line, csv_writers_line(&columns, &row));
        }

        #[test]
        fn text_cells_are_quoted_as_the_csv_writer_quotes(
            text in prop::option::of("[a-z,\"\r\n ]{0,12}"),
            count in 1..3usize,
        ) {
            let column = Column::<Option<String>> {
                name: "card",
                kind: Kind::Text,
                value: |s| Value::Text(s.clone()),
            };
            let columns = vec![column; count];
            let mut line = String::new();
            csv_line(&mut line, &columns, &text);
            prop_assert_eq!(line, csv_writers_line(&columns, &text));
        }

        /// Each JSON line parses (serde_json) to exactly the present cells:
        /// numbers, names, times, whole numbers and escaped text.
        #[test]
        fn json_lines_parse_to_their_cells(
            row in any_row(),
            picks in prop::sample::subsequence((0..COLUMNS.len() + 2).collect::<Vec<_>>(), 1..=COLUMNS.len() + 2),
        ) {
            let finite = |v: f64| if v.is_finite() { v } else { 0.0 };
            let row = Row {
                t_s: finite(row.t_s),
                accel_g: row.accel_g.map(finite),
                ..row
            };
            let extra = [
                Column {
                    name: "wheel_count",
                    kind: Kind::Integer,
                    value: |r: &Row| Value::Integer(Some(i64::from(r.wheel_count) - 40_000)),
                },
                Column {
                    name: "card",
                    kind: Kind::Text,
                    value: |r: &Row| Value::Text(Some(format!("\"{}\"\\\u{e9}\n", r.status.0))),
                },
            ];
            let columns: Vec<Column> = picks
                .iter()
                .map(|&i| COLUMNS.get(i).copied().unwrap_or_else(|| extra[i - COLUMNS.len()]))
                .collect();
            let mut line = String::new();
            json_line(&mut line, &columns, &row);
            prop_assert!(line.ends_with('\n') && line.matches('\n').count() == 1, "{}", line);
            let parsed: serde_json::Map<String, serde_json::Value> =
                serde_json::from_str(&line).map_err(|e| TestCaseError::fail(format!("{e}: {line}")))?;
            let mut time = [0u8; UTC_LEN];
            for column in &columns {
                // Every key is there; an absent value is `null`.
                let cell = parsed.get(column.name);
                prop_assert!(cell.is_some(), "{} left out", column.name);
                let cell = cell.filter(|v| !v.is_null());
                let expected = match (column.value)(&row) {
                    Value::Number(v) => v.map(serde_json::Value::from),
                    Value::Label(s) => s.map(serde_json::Value::from),
                    Value::Utc(us) => us.map(|us| utc_text(us, &mut time).into()),
                    Value::Integer(n) => n.map(serde_json::Value::from),
                    Value::Text(s) => s.map(serde_json::Value::from),
                    Value::Bool(b) => b.map(serde_json::Value::from),
                };
                // serde_json reads a number to within an ulp, not to the bit.
                let near = |a: &serde_json::Value, b: &serde_json::Value| match (a.as_f64(), b.as_f64()) {
                    // Subnormals carry fewer digits: a few of their ulps.
                    (Some(x), Some(y)) if a.is_f64() => (x - y).abs() <= 1e-15 * y.abs() || (x - y).abs() <= 1e-321,
                    _ => a == b,
                };
                prop_assert!(
                    cell.zip(expected.as_ref()).map_or(cell.is_none() && expected.is_none(), |(a, b)| near(a, b)),
                    "{}: {:?} for {:?}", column.name, cell, expected
                );
            }
            prop_assert_eq!(parsed.len(), columns.len());
        }
    }
}
