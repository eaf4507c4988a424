//! `wobblog.Log`: one card log, opened as `wobblog info` reads it, and
//! what the CLI's per-log commands give of it.

use std::convert::Infallible;
use std::path::PathBuf;

use arrow_array::cast::AsArray;
use arrow_array::types::{Float64Type, TimestampMicrosecondType};
use arrow_array::{Array, RecordBatch};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use wobblog::analysis::campaign_kicks::load_campaign_kicks;
use wobblog::analysis::{estimate_roll_deg, Ride, Run};
use wobblog::cmd::events::{walk, JsonEvent};
use wobblog::export::columns::{self, Column, Kind, Value};
use wobblog::summary::{Summary, SummaryBuilder};
use wobblog::time::TimeWindow;
use wobblog::CliError;

use crate::errors::{detached, warn_damage, WobblogError};
use crate::stream::Table;
use crate::table::TableBuilder;
use crate::window::window;

/// Keys of `info` that count what the log lost (`Log.damage`).
const DAMAGE_KEYS: [&str; 11] = [
    "frames_dropped",
    "dropouts",
    "lost_blocks",
    "frames_lost",
    "damaged_blocks",
    "bytes_skipped",
    "repeated_blocks",
    "out_of_range",
    "time_jumps",
    "forward_time_jumps",
    "losses",
];

/// A card log (`RUNnnnnn.WBL`), decoded once on opening: its summary and
/// its frames come from that one pass, and the frames are kept for
/// [`Log::frames`], which hands out (slices of) them without a copy.
///
/// Damage (lost blocks, damaged bytes, dropouts) is reported on opening as
/// a `wobblog.DamageWarning` per loss; what survived is still read.
#[pyclass(module = "wobblog", name = "Log", frozen)]
pub struct Log {
    path: PathBuf,
    summary: Summary,
    /// Every frame in every column of [`columns::COLUMNS`].
    frames: Table,
    /// First and last boot time of the frames, s.
    span_s: Option<(f64, f64)>,
    /// The log has a UTC sync pair.
    has_utc: bool,
}

/// A `t_s`, `roll_deg` pair of the roll table.
type RollRow = (f64, f64);

const ROLL_COLUMNS: [Column<RollRow>; 2] = [
    Column {
        name: "t_s",
        kind: Kind::Number,
        value: |r| Value::Number(Some(r.0)),
    },
    Column {
        name: "roll_deg",
        kind: Kind::Number,
        value: |r| Value::Number(Some(r.1)),
    },
];

impl Log {
    /// Opens the log at `path`, warning of its losses.
    pub fn open(py: Python<'_>, path: PathBuf) -> PyResult<Self> {
        // One pass: what `wobblog info` summarises and every frame, the
        // summary's row totals taken from the frames' rows.
        let (summary, decoded) = py.detach(|| {
            let mut builder = SummaryBuilder::rows_elsewhere();
            let mut decoded = crate::frames::walk(
                &path,
                &columns::COLUMNS,
                TimeWindow::default(),
                &mut builder,
            )?;
            let rows = std::mem::take(&mut decoded.row_stats);
            PyResult::Ok((builder.finish_with_rows(&decoded.stats, rows), decoded))
        })?;
        // The logger's own dropouts too: frames missing from the data
        // whatever their cause (`wobblog info` counts them with the losses).
        let dropped = (summary.frames_dropped > 0).then(|| {
            let kinds: Vec<String> = summary
                .dropouts
                .iter()
                .map(|(kind, n)| format!("{n} {kind}"))
                .collect();
            format!(
                "{} frames dropped by the logger ({})",
                summary.frames_dropped,
                kinds.join(", ")
            )
        });
        let losses = wobblog::cmd::logs::warnings(&summary.losses);
        for line in dropped.iter().chain(&losses) {
            warn_damage(py, &format!("{}: {line}", path.display()))?;
        }
        Ok(Self {
            path,
            summary,
            frames: decoded.table,
            span_s: decoded.span_s,
            has_utc: decoded.has_utc,
        })
    }

    /// The frames in `chosen` inside `window`, from those decoded on
    /// opening: the columns picked and the rows sliced, nothing copied.
    fn frames_in(&self, chosen: &[Column], window: &TimeWindow) -> Result<Table, CliError> {
        window.check_order(&self.path)?;
        let (schema, batches) = self.frames.parts();
        let index = |name: &str| {
            schema
                .index_of(name)
                .map_err(|e| CliError::file(&self.path, e))
        };
        let picked = chosen
            .iter()
            .map(|c| index(c.name))
            .collect::<Result<Vec<usize>, _>>()?;
        let t = index("t_s")?;
        let utc = index("utc")?;
        let mut kept = Vec::new();
        for batch in batches {
            if window.is_all() {
                kept.push(batch.clone());
                continue;
            }
            let t_s = batch.column(t).as_primitive::<Float64Type>();
            let utc_us = batch.column(utc).as_primitive::<TimestampMicrosecondType>();
            // As `wobblog decode`: a row is in when its boot time or UTC (ms) is.
            let inside = |i: usize| {
                let utc_ms = utc_us.is_valid(i).then(|| utc_us.value(i) / 1000);
                window.contains(t_s.value(i), utc_ms)
            };
            // Runs of rows inside, each a slice of the batch.
            let mut i = 0;
            while i < batch.num_rows() {
                if !inside(i) {
                    i += 1;
                    continue;
                }
                let start = i;
                while i < batch.num_rows() && inside(i) {
                    i += 1;
                }
                kept.push(batch.slice(start, i - start));
            }
        }
        if kept.iter().all(|b| b.num_rows() == 0) && !window.is_all() {
            return Err(window.selects_nothing(&self.path, "frames", self.span_s, self.has_utc));
        }
        let projected = kept
            .iter()
            .map(|b| b.project(&picked))
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| CliError::file(&self.path, e))?;
        let schema = std::sync::Arc::new(
            schema
                .project(&picked)
                .map_err(|e| CliError::file(&self.path, e))?,
        );
        // At least one batch, empty for no rows, so every consumer sees the
        // columns.
        let projected = if projected.is_empty() {
            vec![RecordBatch::new_empty(schema.clone())]
        } else {
            projected
        };
        Ok(Table::new(schema, projected))
    }

    fn shown(&self) -> String {
        self.path.display().to_string()
    }
}

#[pymethods]
impl Log {
    /// The log's path.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// What `wobblog info --json` prints, as a dict with the same keys.
    #[getter]
    fn info<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        crate::json::to_py(py, &self.summary)
    }

    /// The configuration the log was recorded with (its header's
    /// `key=value` lines, the `CONFIG.TXT` keys), values as text.
    #[getter]
    fn config<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for line in &self.summary.config {
            let (key, value) = line.split_once('=').unwrap_or((line.as_str(), ""));
            dict.set_item(key.trim(), value.trim())?;
        }
        Ok(dict)
    }

    /// What the decoder reported lost: the damage counters of `info` and
    /// its `losses` (each lost stretch with its time).
    #[getter]
    fn damage<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let info = self.info(py)?;
        let dict = PyDict::new(py);
        for key in DAMAGE_KEYS {
            dict.set_item(key, info.get_item(key)?)?;
        }
        Ok(dict)
    }

    /// The decoded 100 Hz frames, one row each, in the columns of
    /// `wobblog decode` (or those named in `columns`, in that order), from
    /// `start` to `end` (both inclusive: seconds since boot, or UTC
    /// datetimes).
    #[pyo3(signature = (columns = None, start = None, end = None))]
    fn frames(
        &self,
        py: Python<'_>,
        columns: Option<Vec<String>>,
        start: Option<Bound<'_, PyAny>>,
        end: Option<Bound<'_, PyAny>>,
    ) -> PyResult<Table> {
        let chosen = columns::select_from(columns.map(|c| c.join(",")).as_deref(), &[])
            .map_err(|e| WobblogError::new_err(format!("{}: {e}", self.shown())))?;
        let window = window(start.as_ref(), end.as_ref())?;
        // Decoded on opening, where its losses were reported.
        detached(py, &self.shown(), || self.frames_in(&chosen, &window))
    }

    /// Alerts, markers, faults, dropouts and damage in time order: one dict
    /// per event, as the lines of `wobblog events --json`.
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let path = self.path.clone();
        let lines = detached(py, &self.shown(), || {
            let mut lines = Vec::new();
            let walked = walk(&path, |e, utc_us| {
                let line = JsonEvent {
                    t_s: e.t_s,
                    utc: utc_us.and_then(wobblog::time::iso8601_unix_us),
                    kind: &e.kind,
                };
                lines.push(serde_json::to_value(line).unwrap_or_default());
                Ok::<(), Infallible>(())
            })?;
            let Ok(()) = walked;
            Ok(lines)
        })?;
        crate::json::to_py(py, &lines)
    }

    /// Every wobble episode whose onset is from `start` to `end`: the object
    /// `wobblog wobble --json` prints (`log`, `wobble_speed_mps`,
    /// `episodes`).
    #[pyo3(signature = (start = None, end = None))]
    fn episodes<'py>(
        &self,
        py: Python<'py>,
        start: Option<Bound<'py, PyAny>>,
        end: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let window = window(start.as_ref(), end.as_ref())?;
        let path = self.path.clone();
        let report = detached(py, &self.shown(), || {
            wobblog::cmd::wobble::episodes_of(&Ride::load(&path)?, &window)
        })?;
        crate::json::to_py(py, &report)
    }

    /// Every kick ring-down of the log as `wobblog margin --json` lists it
    /// (without `used`, which the campaign's regression decides). `kicks`:
    /// `best`, `card` or `host`, as `margin --kicks`.
    #[pyo3(signature = (kicks = "best"))]
    fn kicks<'py>(&self, py: Python<'py>, kicks: &str) -> PyResult<Bound<'py, PyAny>> {
        let prefer = crate::campaign::prefer(kicks)?;
        let path = self.path.clone();
        let found = detached(py, &self.shown(), || {
            load_campaign_kicks(&path, prefer).map(|(_, kicks)| kicks)
        })?;
        let rows = crate::json::to_py(py, &found)?;
        for row in rows.try_iter()? {
            row?.set_item("log", self.shown())?;
        }
        Ok(rows)
    }

    /// The roll angle estimate `wobblog plot` draws: a table of `t_s`
    /// (s since boot) and `roll_deg` (degrees, positive leaning right), one
    /// row per frame.
    fn roll(&self, py: Python<'_>) -> PyResult<Table> {
        let path = self.path.clone();
        detached(py, &self.shown(), || {
            let run = Run::load(&path)?;
            let roll = estimate_roll_deg(&run);
            let mut table = TableBuilder::new(&ROLL_COLUMNS);
            for row in run.t_s.iter().copied().zip(roll) {
                table
                    .push(&row)
                    .map_err(|e| wobblog::CliError::file(&path, e))?;
            }
            let (schema, batches) = table
                .finish()
                .map_err(|e| wobblog::CliError::file(&path, e))?;
            Ok(Table::new(schema, batches))
        })
    }

    fn __repr__(&self) -> String {
        format!("wobblog.Log({:?})", self.shown())
    }
}
