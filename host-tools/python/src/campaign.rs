//! `wobblog.margin`: the predicted wobble speed of a kick campaign, as
//! `wobblog margin --json` reports it.

use std::path::PathBuf;

use clap::ValueEnum;
use pyo3::prelude::*;
use wobblog::analysis::campaign_kicks::{load_campaign_kicks, Prefer};
use wobblog::analysis::margin::{Trend, RIDE_MARGIN};
use wobblog::cmd::logs::expand;
use wobblog::cmd::margin::{full_report, Args, KickRow};
use wobblog::CliError;

use crate::errors::{detached, warn_damage, WobblogError};

/// A value of a clap choice (`kicks="best"`), as the CLI parses it.
fn choice<T: ValueEnum>(what: &str, text: &str) -> PyResult<T> {
    T::from_str(text, true).map_err(|_| {
        let known: Vec<String> = T::value_variants()
            .iter()
            .filter_map(|v| v.to_possible_value().map(|p| p.get_name().to_owned()))
            .collect();
        WobblogError::new_err(format!("{what}={text:?}: one of {}", known.join(", ")))
    })
}

/// The `Prefer` of a `kicks` argument.
pub fn prefer(text: &str) -> PyResult<Prefer> {
    choice("kicks", text)
}

/// The kicks of one log, or why it could not be read.
type LogKicks = (
    PathBuf,
    Result<(wobblog::summary::Summary, Vec<KickRow>), CliError>,
);

/// Predicts the wobble speed from every kick of the logs in `inputs`
/// (files, or directories of `*.WBL`).
#[pyfunction]
#[pyo3(signature = (inputs, model = None, kicks = "best", trend = "line", ride_margin_pct = 100.0 * RIDE_MARGIN, params = None))]
pub fn margin<'py>(
    py: Python<'py>,
    inputs: Vec<PathBuf>,
    model: Option<PathBuf>,
    kicks: &str,
    trend: &str,
    ride_margin_pct: f64,
    params: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyAny>> {
    if inputs.is_empty() {
        return Err(WobblogError::new_err("margin: no logs given"));
    }
    if !(0.0..=90.0).contains(&ride_margin_pct) {
        return Err(WobblogError::new_err(format!(
            "ride_margin_pct={ride_margin_pct}: a per cent from 0 to 90"
        )));
    }
    let args = Args {
        inputs,
        json: true,
        plot: None,
        model,
        params: params.unwrap_or_default(),
        kicks: prefer(kicks)?,
        trend: choice::<Trend>("trend", trend)?,
        ride_margin: ride_margin_pct,
        mode: wobblog::analysis::KickMode::Wobble,
        figure: wobblog::plot::FigureArgs::default(),
    };
    let logs = detached(py, "margin", || {
        Ok(wobblog::inputs::distinct(expand(&args.inputs)?))
    })?;
    let per_log: Vec<LogKicks> = detached(py, "margin", || {
        Ok(logs
            .iter()
            .map(|log| (log.clone(), kicks_of(log, args.kicks)))
            .collect())
    })?;
    // A log that cannot be read is a warning while others can: the CLI
    // reports it and goes on with the rest.
    let mut rows = Vec::new();
    let mut failures = Vec::new();
    for (log, result) in per_log {
        match result {
            Ok((summary, kicks)) => {
                for line in wobblog::cmd::logs::warnings(&summary.losses) {
                    warn_damage(py, &format!("{}: {line}", log.display()))?;
                }
                rows.extend(kicks);
            }
            Err(e) => failures.push(e.to_string()),
        }
    }
    if rows.is_empty() && !failures.is_empty() {
        return Err(WobblogError::new_err(failures.join("; ")));
    }
    for failure in &failures {
        warn_damage(py, &format!("{failure} (the other logs are used)"))?;
    }
    let (report, _) = detached(py, "margin", || full_report(rows, &args))?;
    crate::json::to_py(py, &report)
}

/// The kicks of `log` as the margin report lists them.
fn kicks_of(
    log: &std::path::Path,
    prefer: Prefer,
) -> Result<(wobblog::summary::Summary, Vec<KickRow>), CliError> {
    let (summary, kicks) = load_campaign_kicks(log, prefer)?;
    let name = log.display().to_string();
    let rows = kicks
        .into_iter()
        .map(|kick| KickRow {
            log: name.clone(),
            kick,
            used: false,
        })
        .collect();
    Ok((summary, rows))
}
