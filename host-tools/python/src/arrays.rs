//! `wobblog.episodes` and `wobblog.kicks` on arrays from any source (another
//! logger, a filtered DataFrame): the same searches the CLI runs on a log,
//! fed the samples as a log's frames.

use std::path::PathBuf;

use pyo3::prelude::*;
use wobblog::analysis::campaign_kicks::{combine, Prefer};
use wobblog::analysis::{find_kicks, Ride, Run};
use wobblog::cmd::detect::wheel_circumference_m;
use wobblog::time::TimeWindow;

use crate::errors::{detached, WobblogError};

/// The analyses' frame rate: the logger's, Hz.
const RATE_HZ: f64 = 100.0;
/// How far a step of `t_s` may be from 10 ms and still be one frame on,
/// s (the logger's own clock jitters by microseconds).
const STEP_TOLERANCE_S: f64 = 1e-3;
/// What the arrays are called in results (`log`).
const SOURCE: &str = "<arrays>";

/// A run of the samples: `t_s` given (increasing; steps of 10 ms, or gaps),
/// or `i / rate_hz` with `rate_hz` the logger's 100 Hz.
fn run_of(
    steer_deg: Vec<f64>,
    speed_mps: Vec<f64>,
    rate_hz: f64,
    t_s: Option<Vec<f64>>,
) -> PyResult<Run> {
    if (rate_hz - RATE_HZ).abs() > 1e-9 {
        return Err(WobblogError::new_err(format!(
            "rate_hz={rate_hz}: the analyses run on the logger's 100 Hz frames; resample the data \
             to 100 Hz first (as `wobblog encode --resample` does a CSV)"
        )));
    }
    if steer_deg.len() != speed_mps.len() {
        return Err(WobblogError::new_err(format!(
            "steer_deg has {} samples, speed_mps {}: one of each per frame",
            steer_deg.len(),
            speed_mps.len()
        )));
    }
    let t_s = match t_s {
        Some(t) => {
            if t.len() != steer_deg.len() {
                return Err(WobblogError::new_err(format!(
                    "t_s has {} samples, steer_deg {}: one of each per frame",
                    t.len(),
                    steer_deg.len()
                )));
            }
            check_steps(&t)?;
            t
        }
        None => (0..steer_deg.len()).map(|i| i as f64 / rate_hz).collect(),
    };
    if let Some(i) = steer_deg
        .iter()
        .chain(&speed_mps)
        .chain(&t_s)
        .position(|v| !v.is_finite())
    {
        return Err(WobblogError::new_err(format!(
            "sample {} is not a finite number (NaN or infinite): drop or fill such samples first",
            i % steer_deg.len().max(1)
        )));
    }
    let n = t_s.len();
    Ok(Run {
        path: PathBuf::from(SOURCE),
        t_s,
        steer_deg,
        speed_mps,
        gyro_dps: vec![[0.0; 3]; n],
        accel_g: vec![[0.0; 3]; n],
        summary: Default::default(),
    })
}

/// Times must increase by 10 ms a frame; a longer step is a gap, which the
/// analyses split at as at a log's lost blocks.
fn check_steps(t_s: &[f64]) -> PyResult<()> {
    let period = 1.0 / RATE_HZ;
    for (i, pair) in t_s.windows(2).enumerate() {
        let step = pair[1] - pair[0];
        if step < period - STEP_TOLERANCE_S {
            return Err(WobblogError::new_err(format!(
                "t_s[{}] - t_s[{i}] = {step} s: times must increase by 0.01 s a frame (100 Hz), \
                 or more across a gap",
                i + 1
            )));
        }
    }
    Ok(())
}

/// Wobble episodes in the samples: the object `wobblog wobble --json`
/// prints for a log (`log` is `<arrays>`).
#[pyfunction]
#[pyo3(signature = (steer_deg, speed_mps, rate_hz = RATE_HZ, t_s = None))]
pub fn episodes<'py>(
    py: Python<'py>,
    steer_deg: Vec<f64>,
    speed_mps: Vec<f64>,
    rate_hz: f64,
    t_s: Option<Vec<f64>>,
) -> PyResult<Bound<'py, PyAny>> {
    let run = run_of(steer_deg, speed_mps, rate_hz, t_s)?;
    let report = detached(py, SOURCE, || {
        wobblog::cmd::wobble::episodes_of(&Ride::of(&run), &TimeWindow::default())
    })?;
    crate::json::to_py(py, &report)
}

/// Kick ring-downs in the samples, as `Log.kicks(kicks="host")` lists a
/// log's (`log` is `<arrays>`). `wheel_circumference_m`: the wheel the
/// speed was measured with (the logger's default when not given).
#[pyfunction]
#[pyo3(signature = (steer_deg, speed_mps, rate_hz = RATE_HZ, t_s = None, wheel_circumference_m = None))]
pub fn kicks<'py>(
    py: Python<'py>,
    steer_deg: Vec<f64>,
    speed_mps: Vec<f64>,
    rate_hz: f64,
    t_s: Option<Vec<f64>>,
    wheel_circumference_m: Option<f64>,
) -> PyResult<Bound<'py, PyAny>> {
    let run = run_of(steer_deg, speed_mps, rate_hz, t_s)?;
    let wheel_m = match wheel_circumference_m {
        Some(w) if w.is_finite() && w > 0.0 => w,
        Some(w) => {
            return Err(WobblogError::new_err(format!(
                "wheel_circumference_m={w}: a length in metres above 0"
            )))
        }
        None => detached(py, SOURCE, || self::wheel_circumference_m(&[]))?,
    };
    let found = detached(py, SOURCE, || {
        Ok(combine(
            find_kicks(&run, wheel_m),
            &[],
            Prefer::Host,
            |_| None,
        ))
    })?;
    let rows = crate::json::to_py(py, &found)?;
    for row in rows.try_iter()? {
        row?.set_item("log", SOURCE)?;
    }
    Ok(rows)
}
