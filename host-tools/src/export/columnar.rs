//! Rows turned into typed columns: one vector of values per column (and
//! which rows have one), filled a row at a time and taken a batch at a time.
//! The Parquet writer writes them as column chunks and the Python package
//! hands them to Arrow, so both build their columns here, with the names,
//! order and types of the column table ([`super::columns`]).
//!
//! Decoded frames ([`Row`]) have columns of their own, [`RowColumns`], that
//! store each field straight into its vector; any other table is filled
//! through its columns' value functions ([`ValueColumns`]).

use super::columns::{Column, Kind, Value, COLUMNS, RUN_COLUMN};
use crate::rows::{GpsColumns, Row};

/// One column's values for a batch of rows: a slot per row (absent values
/// hold a default, `0.0` or `0`, so numbers are laid out as Arrow lays them
/// out), with which rows have a value where the column can lack one.
#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    /// [`Kind::Number`]: a number in every row.
    Number(Vec<f64>),
    /// [`Kind::OptNumber`]: numbers, and which rows have one.
    OptNumber(Vec<f64>, Vec<bool>),
    /// [`Kind::Label`]: names.
    Label(Vec<Option<&'static str>>),
    /// [`Kind::Utc`]: µs since 1970, and which rows have a time.
    Utc(Vec<i64>, Vec<bool>),
    /// [`Kind::Integer`]: whole numbers, and which rows have one.
    Integer(Vec<i64>, Vec<bool>),
    /// [`Kind::Text`]: text.
    Text(Vec<Option<String>>),
    /// [`Kind::Bool`]: truth values, and which rows have one.
    Bool(Vec<bool>, Vec<bool>),
}

impl Values {
    /// Empty values of `kind`, with room for `rows` rows.
    #[must_use]
    pub fn with_capacity(kind: Kind, rows: usize) -> Self {
        let present = || Vec::with_capacity(rows);
        match kind {
            Kind::Number => Self::Number(Vec::with_capacity(rows)),
            Kind::OptNumber => Self::OptNumber(Vec::with_capacity(rows), present()),
            Kind::Label => Self::Label(Vec::with_capacity(rows)),
            Kind::Utc => Self::Utc(Vec::with_capacity(rows), present()),
            Kind::Integer => Self::Integer(Vec::with_capacity(rows), present()),
            Kind::Text => Self::Text(Vec::with_capacity(rows)),
            Kind::Bool => Self::Bool(Vec::with_capacity(rows), present()),
        }
    }

    /// Number of rows.
    #[must_use]
    pub fn len(&self) -> usize {
        match self {
            Self::Number(v) | Self::OptNumber(v, _) => v.len(),
            Self::Label(v) => v.len(),
            Self::Utc(v, _) | Self::Integer(v, _) => v.len(),
            Self::Text(v) => v.len(),
            Self::Bool(v, _) => v.len(),
        }
    }

    /// No rows.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends one cell of a column named `name`.
    ///
    /// # Errors
    /// A value of another kind than the column's, or none in a column of
    /// [`Kind::Number`].
    fn push(&mut self, name: &str, value: Value) -> Result<(), String> {
        fn slot<T: Default>(values: &mut Vec<T>, present: &mut Vec<bool>, v: Option<T>) {
            present.push(v.is_some());
            values.push(v.unwrap_or_default());
        }
        match (self, value) {
            (Self::Number(values), Value::Number(Some(v))) => values.push(v),
            (Self::Number(_), Value::Number(None)) => {
                return Err(format!("{name} has no value in a row"))
            }
            (Self::OptNumber(values, present), Value::Number(v)) => slot(values, present, v),
            (Self::Label(values), Value::Label(v)) => values.push(v),
            (Self::Utc(values, present), Value::Utc(v))
            | (Self::Integer(values, present), Value::Integer(v)) => slot(values, present, v),
            (Self::Text(values), Value::Text(v)) => values.push(v),
            (Self::Bool(values, present), Value::Bool(v)) => slot(values, present, v),
            _ => return Err(format!("{name}: value of the wrong type")),
        }
        Ok(())
    }
}

/// The values of the rows that have one (`present`), for writers that
/// store only those (Parquet).
#[must_use]
pub fn present_only<T: Clone>(values: &[T], present: &[bool]) -> Vec<T> {
    values
        .iter()
        .zip(present)
        .filter(|(_, &p)| p)
        .map(|(v, _)| v.clone())
        .collect()
}

/// Typed columns being filled from rows of `R`.
pub trait ColumnBuffers<R>: Send {
    /// Appends one row.
    ///
    /// # Errors
    /// A value that does not fit its column (see [`Values`]).
    fn push(&mut self, row: &R) -> Result<(), String>;

    /// Rows appended since the last [`Self::take`].
    fn len(&self) -> usize;

    /// No rows since the last [`Self::take`].
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The values of the rows appended since the last call, one entry per
    /// column in the columns' order; the buffers start empty again.
    fn take(&mut self) -> Vec<Values>;
}

/// The buffers for a table of `columns` of any row type, with room for
/// `rows` rows per batch: [`ValueColumns`] (decoded frames have
/// [`row_buffers`]).
#[must_use]
pub fn buffers<R: 'static>(columns: &[Column<R>], rows: usize) -> Box<dyn ColumnBuffers<R>> {
    Box::new(ValueColumns::new(columns, rows))
}

/// Any table, filled through its columns' value functions.
pub struct ValueColumns<R> {
    columns: Vec<Column<R>>,
    values: Vec<Values>,
    rows: usize,
    capacity: usize,
}

impl<R> ValueColumns<R> {
    /// Buffers for `columns`, with room for `rows` rows per batch.
    #[must_use]
    pub fn new(columns: &[Column<R>], rows: usize) -> Self {
        Self {
            values: columns
                .iter()
                .map(|c| Values::with_capacity(c.kind, rows))
                .collect(),
            columns: columns.to_vec(),
            rows: 0,
            capacity: rows,
        }
    }
}

impl<R> ColumnBuffers<R> for ValueColumns<R> {
    fn push(&mut self, row: &R) -> Result<(), String> {
        for (column, values) in self.columns.iter().zip(&mut self.values) {
            values.push(column.name, (column.value)(row))?;
        }
        self.rows += 1;
        Ok(())
    }

    fn len(&self) -> usize {
        self.rows
    }

    fn take(&mut self) -> Vec<Values> {
        self.rows = 0;
        self.columns
            .iter()
            .zip(&mut self.values)
            .map(|(c, v)| std::mem::replace(v, Values::with_capacity(c.kind, self.capacity)))
            .collect()
    }
}

/// The buffers for decoded frames in `columns`: each field stored straight
/// into its vector ([`RowColumns`]) when every column is one of
/// [`COLUMNS`] or [`RUN_COLUMN`], else through the value functions.
#[must_use]
pub fn row_buffers(columns: &[Column<Row>], rows: usize) -> Box<dyn ColumnBuffers<Row>> {
    match RowColumns::new(columns, rows) {
        Some(fast) => Box::new(fast),
        None => Box::new(ValueColumns::new(columns, rows)),
    }
}

/// A field of [`Row`] that is a column of [`COLUMNS`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Field {
    T,
    Accel(usize),
    Gyro(usize),
    Steer,
    Speed,
    GpsLat,
    GpsLon,
    GpsSpeed,
    GpsFix,
    Utc,
    Run,
}

impl Field {
    /// The field of the column `name` of [`COLUMNS`] (a test holds the two
    /// together).
    fn of(name: &str) -> Option<Self> {
        Some(match name {
            "t_s" => Self::T,
            "ax_g" => Self::Accel(0),
            "ay_g" => Self::Accel(1),
            "az_g" => Self::Accel(2),
            "gx_dps" => Self::Gyro(0),
            "gy_dps" => Self::Gyro(1),
            "gz_dps" => Self::Gyro(2),
            "steer_deg" => Self::Steer,
            "speed_mps" => Self::Speed,
            "gps_lat_deg" => Self::GpsLat,
            "gps_lon_deg" => Self::GpsLon,
            "gps_speed_mps" => Self::GpsSpeed,
            "gps_fix" => Self::GpsFix,
            "utc" => Self::Utc,
            "run" => Self::Run,
            _ => return None,
        })
    }

    /// The field `column` is, if it is one of [`COLUMNS`] (or the run).
    pub(crate) fn of_column(column: &Column<Row>) -> Option<Self> {
        let known = COLUMNS
            .iter()
            .chain([&RUN_COLUMN])
            .any(|k| k.name == column.name && k.kind == column.kind);
        Self::of(column.name).filter(|_| known)
    }
}

/// Decoded frames as columns: every field of a row is stored into its own
/// vector as the row comes (no per-cell dispatch), and the chosen columns
/// are taken by name.
pub struct RowColumns {
    fields: Vec<Field>,
    capacity: usize,
    t_s: Vec<f64>,
    accel_g: [Vec<f64>; 3],
    gyro_dps: [Vec<f64>; 3],
    steer_deg: Vec<f64>,
    speed_mps: Vec<f64>,
    /// Latitude, longitude, speed; 0.0 where the row has none.
    gps: [Vec<f64>; 3],
    has_gps: Vec<bool>,
    has_gps_speed: Vec<bool>,
    gps_fix: Vec<Option<&'static str>>,
    utc_us: Vec<i64>,
    has_utc: Vec<bool>,
    run: Vec<i64>,
    has_run: Vec<bool>,
    /// Rows not yet in the columns: stored a few hundred at a time, one
    /// column after the other, each a tight loop (one row at a time, the
    /// seventeen buffers' length checks and stores cost more than the row).
    staged: Vec<Row>,
}

/// Rows staged before they are stored (a few pages of rows).
const STAGED_ROWS: usize = 128;

impl RowColumns {
    /// Columns for `columns` (with room for `rows` rows per batch), `None`
    /// if one of them is not one of [`COLUMNS`].
    #[must_use]
    pub fn new(columns: &[Column<Row>], rows: usize) -> Option<Self> {
        let fields = columns
            .iter()
            .map(Field::of_column)
            .collect::<Option<Vec<Field>>>()?;
        let mut new = Self {
            fields,
            capacity: rows,
            t_s: Vec::new(),
            accel_g: Default::default(),
            gyro_dps: Default::default(),
            steer_deg: Vec::new(),
            speed_mps: Vec::new(),
            gps: Default::default(),
            has_gps: Vec::new(),
            has_gps_speed: Vec::new(),
            gps_fix: Vec::new(),
            utc_us: Vec::new(),
            has_utc: Vec::new(),
            run: Vec::new(),
            has_run: Vec::new(),
            staged: Vec::with_capacity(STAGED_ROWS),
        };
        new.reserve();
        Some(new)
    }

    /// Every column of numbers.
    fn numbers(&mut self) -> impl Iterator<Item = &mut Vec<f64>> {
        [&mut self.t_s, &mut self.steer_deg, &mut self.speed_mps]
            .into_iter()
            .chain(&mut self.accel_g)
            .chain(&mut self.gyro_dps)
            .chain(&mut self.gps)
    }

    fn reserve(&mut self) {
        let n = self.capacity;
        for v in self.numbers() {
            v.reserve(n);
        }
        self.has_gps.reserve(n);
        self.has_gps_speed.reserve(n);
        self.gps_fix.reserve(n);
        self.utc_us.reserve(n);
        self.has_utc.reserve(n);
        self.run.reserve(n);
        self.has_run.reserve(n);
    }
}

/// A frame's row as the frame columns read it: a [`Row`], or a frame kept
/// as counts with what fills it (`super::frame_columns`), converted as it
/// is read.
pub(crate) trait FrameFields {
    fn t_s(&self) -> f64;
    fn accel_g(&self, axis: usize) -> f64;
    fn gyro_dps(&self, axis: usize) -> f64;
    fn steer_deg(&self) -> f64;
    fn speed_mps(&self) -> f64;
    fn gps(&self) -> Option<&GpsColumns>;
    fn utc_us(&self) -> Option<i64>;
    fn run(&self) -> Option<u32>;
}

impl FrameFields for &Row {
    fn t_s(&self) -> f64 {
        self.t_s
    }
    fn accel_g(&self, axis: usize) -> f64 {
        self.accel_g[axis]
    }
    fn gyro_dps(&self, axis: usize) -> f64 {
        self.gyro_dps[axis]
    }
    fn steer_deg(&self) -> f64 {
        self.steer_deg
    }
    fn speed_mps(&self) -> f64 {
        self.speed_mps
    }
    fn gps(&self) -> Option<&GpsColumns> {
        self.gps.as_ref()
    }
    fn utc_us(&self) -> Option<i64> {
        self.utc_us
    }
    fn run(&self) -> Option<u32> {
        self.run
    }
}

impl RowColumns {
    /// Stores the staged rows in the columns.
    fn store_staged(&mut self) {
        let staged = std::mem::take(&mut self.staged);
        self.store(staged.iter());
        self.staged = staged;
        self.staged.clear();
    }

    /// Stores `rows` (a few hundred: they are read once per column, so
    /// they should sit in the nearest cache) in the columns.
    pub(crate) fn store<R: FrameFields>(&mut self, rows: impl Iterator<Item = R> + Clone) {
        let gps_speed = |r: &R| r.gps().and_then(|g| g.speed_mps);
        self.t_s.extend(rows.clone().map(|r| r.t_s()));
        for (i, v) in self.accel_g.iter_mut().enumerate() {
            v.extend(rows.clone().map(|r| r.accel_g(i)));
        }
        for (i, v) in self.gyro_dps.iter_mut().enumerate() {
            v.extend(rows.clone().map(|r| r.gyro_dps(i)));
        }
        self.steer_deg.extend(rows.clone().map(|r| r.steer_deg()));
        self.speed_mps.extend(rows.clone().map(|r| r.speed_mps()));
        let [lat, lon, speed] = &mut self.gps;
        lat.extend(rows.clone().map(|r| r.gps().map_or(0.0, |g| g.lat_deg)));
        lon.extend(rows.clone().map(|r| r.gps().map_or(0.0, |g| g.lon_deg)));
        speed.extend(rows.clone().map(|r| gps_speed(&r).unwrap_or_default()));
        self.has_gps.extend(rows.clone().map(|r| r.gps().is_some()));
        self.has_gps_speed
            .extend(rows.clone().map(|r| gps_speed(&r).is_some()));
        self.gps_fix
            .extend(rows.clone().map(|r| r.gps().map(|g| g.fix.as_str())));
        self.utc_us
            .extend(rows.clone().map(|r| r.utc_us().unwrap_or_default()));
        self.has_utc
            .extend(rows.clone().map(|r| r.utc_us().is_some()));
        self.run
            .extend(rows.clone().map(|r| r.run().map_or(0, i64::from)));
        self.has_run.extend(rows.map(|r| r.run().is_some()));
    }

    /// The chosen columns' values, the buffers left empty.
    pub(crate) fn into_values(mut self) -> Vec<Values> {
        self.take_chosen()
    }

    fn take_chosen(&mut self) -> Vec<Values> {
        use std::mem::take;
        self.store_staged();
        let [lat, lon, speed] = &mut self.gps;
        self.fields
            .iter()
            .map(|field| match *field {
                Field::T => Values::Number(take(&mut self.t_s)),
                Field::Accel(i) => Values::Number(take(&mut self.accel_g[i])),
                Field::Gyro(i) => Values::Number(take(&mut self.gyro_dps[i])),
                Field::Steer => Values::Number(take(&mut self.steer_deg)),
                Field::Speed => Values::Number(take(&mut self.speed_mps)),
                Field::GpsLat => Values::OptNumber(take(lat), self.has_gps.clone()),
                Field::GpsLon => Values::OptNumber(take(lon), self.has_gps.clone()),
                Field::GpsSpeed => Values::OptNumber(take(speed), take(&mut self.has_gps_speed)),
                Field::GpsFix => Values::Label(take(&mut self.gps_fix)),
                Field::Utc => Values::Utc(take(&mut self.utc_us), take(&mut self.has_utc)),
                Field::Run => Values::Integer(take(&mut self.run), take(&mut self.has_run)),
            })
            .collect()
    }
}

impl ColumnBuffers<Row> for RowColumns {
    fn push(&mut self, row: &Row) -> Result<(), String> {
        self.staged.push(*row);
        if self.staged.len() == STAGED_ROWS {
            self.store_staged();
        }
        Ok(())
    }

    fn len(&self) -> usize {
        self.t_s.len() + self.staged.len()
    }

    fn take(&mut self) -> Vec<Values> {
        let chosen = self.take_chosen();
        // What no column took starts the next batch empty too.
        for v in self.numbers() {
            v.clear();
        }
        self.has_gps.clear();
        self.has_gps_speed.clear();
        self.gps_fix.clear();
        self.utc_us.clear();
        self.has_utc.clear();
        self.run.clear();
        self.has_run.clear();
        self.reserve();
        chosen
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wobble_core::format::{FixMode, FrameStatus};

    fn rows() -> Vec<Row> {
        let base = Row {
            t_s: 1.25,
            accel_g: [0.01, -0.5, 1.0],
            gyro_dps: [3.5, -2.25, 0.125],
            steer_deg: -1.5,
            speed_mps: 4.2,
            wheel_count: 7,
            status: FrameStatus::default(),
            gps: None,
            utc_us: None,
            derived: Default::default(),
            run: None,
        };
        let fix = GpsColumns {
            lat_deg: 52.0,
            lon_deg: 4.375,
            speed_mps: Some(4.0),
            fix: FixMode::Fix3d,
        };
        vec![
            base,
            Row {
                t_s: 1.26,
                gps: Some(fix),
                utc_us: Some(1_584_538_100_000_000),
                ..base
            },
            Row {
                t_s: 1.27,
                gps: Some(GpsColumns {
                    speed_mps: None,
                    fix: FixMode::Fix2d,
                    ..fix
                }),
                ..base
            },
        ]
    }

    #[test]
    fn every_frame_column_is_a_field_stored_as_its_value_function_gives_it() {
        // A dataset's frame file: the run first, in some rows (the decoder's
        // rows have none).
        let mut columns = vec![RUN_COLUMN];
        columns.extend(COLUMNS);
        let mut fast = RowColumns::new(&columns, 4).expect("every column has a field");
        let mut slow = ValueColumns::new(&columns, 4);
        for (k, row) in rows().into_iter().enumerate() {
            let row = Row {
                run: (k > 0).then_some(7),
                ..row
            };
            fast.push(&row).unwrap();
            slow.push(&row).unwrap();
        }
        assert_eq!(fast.len(), 3);
        let taken = fast.take();
        assert_eq!(
            taken[0],
            Values::Integer(vec![0, 7, 7], vec![false, true, true])
        );
        assert_eq!(taken, slow.take());
        assert!(fast.is_empty() && slow.is_empty());
    }

    #[test]
    fn chosen_columns_come_in_their_order_batch_after_batch() {
        let chosen = super::super::columns::select(Some("utc,steer_deg,gps_fix")).unwrap();
        let mut fast = row_buffers(&chosen, 2);
        let mut slow = ValueColumns::new(&chosen, 2);
        for _ in 0..2 {
            for row in rows() {
                fast.push(&row).unwrap();
                slow.push(&row).unwrap();
            }
            let taken = fast.take();
            assert_eq!(taken.len(), 3);
            assert!(matches!(taken[0], Values::Utc(..)));
            assert_eq!(taken, slow.take());
        }
    }

    #[test]
    fn a_missing_number_or_a_value_of_another_kind_is_refused() {
        let columns: [Column<Option<f64>>; 1] = [Column {
            name: "x",
            kind: Kind::Number,
            value: |r| Value::Number(*r),
        }];
        let mut buffers = buffers(&columns, 1);
        assert!(buffers.push(&Some(1.0)).is_ok());
        assert_eq!(buffers.push(&None).unwrap_err(), "x has no value in a row");
        let wrong: [Column<Option<f64>>; 1] = [Column {
            name: "y",
            kind: Kind::Utc,
            value: |r| Value::Number(*r),
        }];
        assert_eq!(
            ValueColumns::new(&wrong, 1).push(&Some(1.0)).unwrap_err(),
            "y: value of the wrong type"
        );
    }
}
