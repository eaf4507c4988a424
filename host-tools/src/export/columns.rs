//! The columns of a decoded row: one table giving every export format the
//! same names, order and types, and `--columns` its choices. The same
//! column type describes the tables of a dataset (runs, episodes).

use crate::rows::Row;

/// The type of a column's values.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// A number in every row.
    Number,
    /// A number, absent in some rows.
    OptNumber,
    /// A lower-case name from a small set, absent in some rows.
    Label,
    /// A UTC time, absent before the first GPS sync pair.
    Utc,
    /// A whole number, absent in some rows.
    Integer,
    /// Free text (a file name).
    Text,
    /// True or false.
    Bool,
}

/// One cell.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// A number, or none.
    Number(Option<f64>),
    /// A name, or none.
    Label(Option<&'static str>),
    /// µs since 1970, or none.
    Utc(Option<i64>),
    /// A whole number, or none.
    Integer(Option<i64>),
    /// Text, or none.
    Text(Option<String>),
    /// True or false, or none.
    Bool(Option<bool>),
}

/// A column of a table of `R`s: its name (unit in the name), type and
/// value in a row.
pub struct Column<R = Row> {
    /// Header name, as in the CSV.
    pub name: &'static str,
    /// Type of its values.
    pub kind: Kind,
    /// Its value in a row.
    pub value: fn(&R) -> Value,
}

// By hand: derived impls would require `R: Clone`.
impl<R> Clone for Column<R> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<R> Copy for Column<R> {}

/// A column of numbers present in every row.
macro_rules! number {
    ($name:literal, $row:ident => $value:expr) => {
        Column {
            name: $name,
            kind: Kind::Number,
            value: |$row| Value::Number(Some($value)),
        }
    };
}

/// Every column in export order: the CSV's documented columns first, new
/// ones after them.
pub const COLUMNS: [Column; 14] = [
    number!("t_s", r => r.t_s),
    number!("ax_g", r => r.accel_g[0]),
    number!("ay_g", r => r.accel_g[1]),
    number!("az_g", r => r.accel_g[2]),
    number!("gx_dps", r => r.gyro_dps[0]),
    number!("gy_dps", r => r.gyro_dps[1]),
    number!("gz_dps", r => r.gyro_dps[2]),
    number!("steer_deg", r => r.steer_deg),
    number!("speed_mps", r => r.speed_mps),
    Column {
        name: "gps_lat_deg",
        kind: Kind::OptNumber,
        value: |r| Value::Number(r.gps.map(|g| g.lat_deg)),
    },
    Column {
        name: "gps_lon_deg",
        kind: Kind::OptNumber,
        value: |r| Value::Number(r.gps.map(|g| g.lon_deg)),
    },
    Column {
        name: "gps_speed_mps",
        kind: Kind::OptNumber,
        value: |r| Value::Number(r.gps.and_then(|g| g.speed_mps)),
    },
    Column {
        name: "gps_fix",
        kind: Kind::Label,
        value: |r| Value::Label(r.gps.map(|g| g.fix.as_str())),
    },
    Column {
        name: "utc",
        kind: Kind::Utc,
        value: |r| Value::Utc(r.utc_us),
    },
];

/// The run number of a dataset's frame files ([`Row::run`]): the first
/// column there, so that a file read alone, or by a reader that drops
/// partition folders, still says which run each frame is of.
pub const RUN_COLUMN: Column = Column {
    name: "run",
    kind: Kind::Integer,
    value: |r| Value::Integer(r.run.map(i64::from)),
};

/// A derived column: given only when named ([`super::derived`]).
macro_rules! derived {
    ($name:literal, $row:ident => $value:expr) => {
        Column {
            name: $name,
            kind: Kind::OptNumber,
            value: |$row| Value::Number($value),
        }
    };
}

/// The columns derived from the frames around a row
/// ([`super::derived`]), chosen by name only.
pub const DERIVED_COLUMNS: [Column; 3] = [
    derived!("roll_deg", r => r.derived.roll_deg),
    derived!("steer_bp_deg", r => r.derived.steer_bp_deg),
    derived!("wobble_env_deg", r => r.derived.wobble_env_deg),
];

/// The columns named in `list` (comma-separated, in the order given), or
/// every column but the derived ones for `None`.
///
/// # Errors
/// An unknown or repeated name, with the known ones.
pub fn select(list: Option<&str>) -> Result<Vec<Column>, String> {
    select_from(list, &DERIVED_COLUMNS)
}

/// [`select`] among the stored columns and `derived` (none where the
/// derived signals are not computed: the Python package's frames).
///
/// # Errors
/// An unknown or repeated name, with the known ones.
pub fn select_from(list: Option<&str>, derived: &[Column]) -> Result<Vec<Column>, String> {
    let Some(list) = list else {
        return Ok(COLUMNS.to_vec());
    };
    let mut chosen: Vec<Column> = Vec::new();
    for name in list.split(',').map(str::trim).filter(|n| !n.is_empty()) {
        let mut all = COLUMNS.iter().chain(derived);
        let column = all.find(|c| c.name == name).ok_or_else(|| {
            let known: Vec<&str> = COLUMNS.iter().chain(derived).map(|c| c.name).collect();
            format!("no column {name:?}; the columns are {}", known.join(","))
        })?;
        if chosen.iter().any(|c| c.name == name) {
            return Err(format!("column {name:?} is named twice"));
        }
        chosen.push(*column);
    }
    if chosen.is_empty() {
        return Err("--columns names no column".into());
    }
    Ok(chosen)
}
