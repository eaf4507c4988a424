//! A run's frames, one column per channel, and reading them from a log.
//! The commands stream the frames through the analyses (which hold a
//! window of them); a whole run in memory is for tests and small logs.

use std::path::{Path, PathBuf};

use wobble_core::format::{DecodeStats, Event};

use crate::reader::read_log;
use crate::rows::{Row, RowAssembler};
use crate::summary::{Summary, SummaryBuilder};
use crate::CliError;

/// The channels of one run, one entry per decoded frame.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// The log it was read from.
    pub path: PathBuf,
    /// Time since boot, s.
    pub t_s: Vec<f64>,
    /// Steering angle, degrees.
    pub steer_deg: Vec<f64>,
    /// Wheel speed, m/s.
    pub speed_mps: Vec<f64>,
    /// Angular rate x/y/z, deg/s.
    pub gyro_dps: Vec<[f64; 3]>,
    /// Acceleration x/y/z, g.
    pub accel_g: Vec<[f64; 3]>,
    /// What `wobblog info` says about it: alerts, markers, losses.
    pub summary: Summary,
}

impl Run {
    /// A run from rows (in time order) and its summary.
    #[must_use]
    pub fn from_rows(path: &Path, rows: &[Row], summary: Summary) -> Self {
        let mut run = Self {
            path: path.to_path_buf(),
            summary,
            ..Self::default()
        };
        rows.iter().for_each(|row| run.push(row));
        run
    }

    /// Appends one frame.
    pub fn push(&mut self, row: &Row) {
        self.t_s.push(row.t_s);
        self.steer_deg.push(row.steer_deg);
        self.speed_mps.push(row.speed_mps);
        self.gyro_dps.push(row.gyro_dps);
        self.accel_g.push(row.accel_g);
    }

    /// Appends frame `i` of `other`.
    pub fn push_from(&mut self, other: &Self, i: usize) {
        self.t_s.push(other.t_s[i]);
        self.steer_deg.push(other.steer_deg[i]);
        self.speed_mps.push(other.speed_mps[i]);
        self.gyro_dps.push(other.gyro_dps[i]);
        self.accel_g.push(other.accel_g[i]);
    }

    /// Forgets the first `n` frames (a window moving through a stream).
    pub fn drop_front(&mut self, n: usize) {
        self.t_s.drain(..n);
        self.steer_deg.drain(..n);
        self.speed_mps.drain(..n);
        self.gyro_dps.drain(..n);
        self.accel_g.drain(..n);
    }

    /// Reads the log at `path`. A log damaged in places loads what survived:
    /// its losses are in `summary.losses`, and the analyses split the run at
    /// the gaps.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let empty = |_: &SummaryBuilder| Self {
            path: path.to_path_buf(),
            ..Self::default()
        };
        let (summary, mut run) = stream_rows(path, empty, |run, row| run.push(row))?;
        run.summary = summary;
        Ok(run)
    }

    /// Number of frames.
    #[must_use]
    pub fn len(&self) -> usize {
        self.t_s.len()
    }

    /// Whether the run has no frames.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.t_s.is_empty()
    }

    /// Nominal frame rate, Hz.
    #[must_use]
    pub fn sample_rate_hz(&self) -> f64 {
        self.summary.frame_rate_hz()
    }

    /// The run's name for reports: the file name.
    #[must_use]
    pub fn name(&self) -> String {
        log_name(&self.path)
    }
}

/// Reads the log at `path` in one pass, in bounded memory, into an analysis
/// that `make` creates at the first frame from what the log has said by
/// then (its header: the frame rate and config lines, the log's first
/// records): `visit` gets every frame as a row, in file order. Returns what
/// `wobblog info` says about the log, and the analysis. A log without a
/// frame is an error.
pub fn stream_rows<A>(
    path: &Path,
    make: impl Fn(&SummaryBuilder) -> A,
    mut visit: impl FnMut(&mut A, &Row),
) -> Result<(Summary, A), CliError> {
    let mut builder = SummaryBuilder::new();
    let mut rows = RowAssembler::new();
    let mut analysis = None;
    let stats = read_log(path, |event| {
        builder.observe(&event);
        if let Event::Record(record) = event {
            let told = &builder;
            rows.push(&record, &mut |row: &Row| {
                visit(analysis.get_or_insert_with(|| make(told)), row);
            });
        }
    })?;
    let told = &builder;
    rows.finish(&mut |row: &Row| visit(analysis.get_or_insert_with(|| make(told)), row));
    let summary = builder.finish(&stats);
    match analysis {
        Some(analysis) => Ok((summary, analysis)),
        None => Err(CliError::file(path, "no frames in the log")),
    }
}

/// Reads the log at `path` in one pass, calling `observe` with every
/// decoder event and `visit` with every frame as a row, in file order.
pub fn read_rows(
    path: &Path,
    mut observe: impl FnMut(&Event<'_>),
    mut visit: impl FnMut(&Row),
) -> Result<DecodeStats, CliError> {
    let mut rows = RowAssembler::new();
    let stats = read_log(path, |event| {
        observe(&event);
        if let Event::Record(record) = event {
            rows.push(&record, &mut visit);
        }
    })?;
    rows.finish(&mut visit);
    Ok(stats)
}

/// A log's name for reports: its file name.
#[must_use]
pub fn log_name(path: &Path) -> String {
    path.file_name().map_or_else(
        || crate::text::shown(path),
        |n| n.to_string_lossy().into_owned(),
    )
}
