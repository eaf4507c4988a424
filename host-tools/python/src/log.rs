//! `wobblog.Log`: one card log, opened as `wobblog info` reads it, and
//! what the CLI's per-log commands give of it.

use std::convert::Infallible;
use std::path::PathBuf;

use pyo3::prelude::*;
use pyo3::types::PyDict;
use wobblog::analysis::campaign_kicks::load_campaign_kicks;
use wobblog::analysis::{estimate_roll_deg, Ride, Run};
use wobblog::cmd::events::{walk, JsonEvent};
use wobblog::export::columns::{self, Column, Kind, Value};
use wobblog::summary::Summary;

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

/// A card log (`RUNnnnnn.WBL`), read once on opening for its summary.
///
/// Damage (lost blocks, damaged bytes, dropouts) is reported on opening as
/// a `wobblog.DamageWarning` per loss; what survived is still read.
#[pyclass(module = "wobblog", name = "Log", frozen)]
pub struct Log {
    path: PathBuf,
    summary: Summary,
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
        let summary = detached(py, &path.display().to_string(), || {
            wobblog::cmd::info::summarise(&path)
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
        Ok(Self { path, summary })
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
        let chosen = columns::select(columns.map(|c| c.join(",")).as_deref())
            .map_err(|e| WobblogError::new_err(format!("{}: {e}", self.shown())))?;
        let window = window(start.as_ref(), end.as_ref())?;
        let path = self.path.clone();
        // Its losses were reported on opening.
        py.detach(|| crate::frames::decode(&path, chosen, window))
            .map(|(table, _)| table)
    }

    /// Alerts, markers, faults, dropouts and damage in time order: one dict
    /// per event, as the lines of `wobblog events --json`.
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let path = self.path.clone();
        let lines = detached(py, &self.shown(), || {
            let mut lines = Vec::new();
            let walked = walk(&path, |e, utc| {
                let line = JsonEvent {
                    t_s: e.t_s,
                    utc,
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
            let mut table = TableBuilder::new(ROLL_COLUMNS.to_vec());
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
