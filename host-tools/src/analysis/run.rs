//! A whole run in memory, one column per channel: what the offline analyses
//! and plots work on (they look both ways in time, so they cannot stream).

use std::path::{Path, PathBuf};

use wobble_core::format::Event;

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

    fn push(&mut self, row: &Row) {
        self.t_s.push(row.t_s);
        self.steer_deg.push(row.steer_deg);
        self.speed_mps.push(row.speed_mps);
        self.gyro_dps.push(row.gyro_dps);
        self.accel_g.push(row.accel_g);
    }

    /// Reads the log at `path`. A log damaged in places loads what survived:
    /// its losses are in `summary.losses`, and the analyses split the run at
    /// the gaps.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let mut builder = SummaryBuilder::new();
        let mut rows = RowAssembler::new();
        let mut run = Self {
            path: path.to_path_buf(),
            ..Self::default()
        };
        let stats = read_log(path, |event| {
            builder.observe(&event);
            if let Event::Record(record) = event {
                rows.push(&record, &mut |row: &Row| run.push(row));
            }
        })?;
        rows.finish(&mut |row: &Row| run.push(row));
        run.summary = builder.finish(&stats);
        if run.t_s.is_empty() {
            return Err(CliError::file(path, "no frames in the log"));
        }
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
        f64::from(self.summary.sample_rate_hz.unwrap_or(100).max(1))
    }

    /// The run's name for reports: the file name.
    #[must_use]
    pub fn name(&self) -> String {
        self.path.file_name().map_or_else(
            || self.path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        )
    }

    /// Mean wheel speed over `t_s ± half_width_s`, m/s (the nearest frame's
    /// speed if none falls inside).
    #[must_use]
    pub fn speed_around(&self, t_s: f64, half_width_s: f64) -> f64 {
        let lo = self.t_s.partition_point(|&t| t < t_s - half_width_s);
        let hi = self.t_s.partition_point(|&t| t <= t_s + half_width_s);
        if hi > lo {
            return self.speed_mps[lo..hi].iter().sum::<f64>() / (hi - lo) as f64;
        }
        let i = lo.min(self.len().saturating_sub(1));
        self.speed_mps.get(i).copied().unwrap_or(0.0)
    }
}
