//! `wobblog model`: the linear bicycle models of the `wobble-model` crate
//! (Whipple benchmark, extended wobble model) against speed.

pub mod compare;
pub mod eig;
pub mod episodes;
pub mod figure;
pub mod fit;
pub mod plot;
pub mod sweep;

use std::path::Path;
use std::str::FromStr;

use indicatif::{ProgressBar, ProgressStyle};
use wobble_model::{Model, ParamError, ParamSet, Problem, Survey, Sweep};

use crate::CliError;

/// The `model` subcommands.
#[derive(clap::Subcommand)]
pub enum Command {
    /// Eigenvalues against speed, per mode, and the critical speeds.
    Eig(eig::Args),
    /// Eigenvalues against speed as a figure (the seed paper's Figure 4).
    Plot(plot::Args),
    /// Scale one parameter by several factors: critical speeds and a figure.
    Sweep(sweep::Args),
    /// The model's wobble mode with measured episodes over it (Figure 8), residuals printed.
    Compare(compare::Args),
    /// Fit parameters to measured wobble episodes; confidence intervals and the fitted file.
    Fit(fit::Args),
}

/// Runs a `model` subcommand.
pub fn run(command: &Command) -> Result<(), CliError> {
    match command {
        Command::Eig(args) => eig::run(args),
        Command::Plot(args) => plot::run(args),
        Command::Sweep(args) => sweep::run(args),
        Command::Compare(args) => compare::run(args),
        Command::Fit(args) => fit::run(args),
    }
}

/// Sweeps with more speeds than this show a progress bar (on a terminal).
const PROGRESS_MIN_SPEEDS: usize = 200;
/// Most speeds one sweep may have.
const MAX_SPEEDS: usize = 1_000_000;

/// A speed range `A:B:STEP`, m/s.
#[derive(Clone, Debug, PartialEq)]
pub struct Speeds(pub Vec<f64>);

impl FromStr for Speeds {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(':').collect();
        let [a, b, step] = parts.as_slice() else {
            return Err(format!(
                "{s:?}: expected FROM:TO:STEP in m/s, e.g. 0:10:0.05"
            ));
        };
        let num = |t: &str| -> Result<f64, String> {
            t.trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| format!("{s:?}: {t:?} is not a number"))
        };
        let (a, b, step) = (num(a)?, num(b)?, num(step)?);
        if a < 0.0 || b < a || step <= 0.0 {
            return Err(format!(
                "{s:?}: need 0 <= FROM <= TO and STEP > 0 (speeds in m/s)"
            ));
        }
        // A small tolerance keeps TO itself when (TO - FROM) / STEP is an
        // integer up to rounding.
        let n = ((b - a) / step + 1e-9).floor();
        if n >= MAX_SPEEDS as f64 {
            return Err(format!("{s:?}: more than {MAX_SPEEDS} speeds"));
        }
        Ok(Self(
            (0..=n as usize).map(|i| a + i as f64 * step).collect(),
        ))
    }
}

/// A parameter-file error as the CLI reports it: the file, the parameter
/// and what is wrong.
#[must_use]
pub fn param_error(e: &ParamError) -> CliError {
    if e.param.is_empty() {
        CliError::file(&e.path, &e.problem)
    } else {
        CliError::file(&e.path, format!("{}: {}", e.param, e.problem))
    }
}

/// [`param_error`] about a parameter of `set` named on the command line: a
/// name the file does not have gets the closest one it has, or their list.
#[must_use]
pub fn key_error(set: &ParamSet, e: &ParamError) -> CliError {
    if e.problem != Problem::Unknown || e.param.is_empty() {
        return param_error(e);
    }
    let known: Vec<&str> = set.iter().map(|(k, _)| k).collect();
    let hint = crate::words::suggest(&e.param, &known, "parameters of the file");
    CliError::file(&e.path, format!("{}: {}; {hint}", e.param, e.problem))
}

/// Reads a parameter file, printing its notes (lines left out, defaults
/// taken) on stderr.
pub fn load_set(path: &Path) -> Result<ParamSet, CliError> {
    let set = ParamSet::load(path).map_err(|e| param_error(&e))?;
    for note in &set.notes {
        eprintln!("wobblog: {}: {note}", path.display());
    }
    Ok(set)
}

/// Reads a parameter file and builds its model (its Whipple limit with
/// `whipple`).
pub fn load(path: &Path, whipple: bool) -> Result<(ParamSet, Model), CliError> {
    load_as(
        path,
        if whipple {
            Variant::Whipple
        } else {
            Variant::Own
        },
    )
}

/// Which model of a parameter file.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The file's own model.
    Own,
    /// Its Whipple limit (rider locked, rigid head, no slip).
    Whipple,
    /// Its non-holonomic counterpart (no slip, torso and twist free).
    NoSlip,
}

/// Reads a parameter file and builds the `variant` of its model.
pub fn load_as(path: &Path, variant: Variant) -> Result<(ParamSet, Model), CliError> {
    let set = load_set(path)?;
    let model = match variant {
        Variant::Own => Model::from_set(&set),
        Variant::Whipple => Model::whipple_of(&set),
        Variant::NoSlip => Model::no_slip_of(&set),
    }
    .map_err(|e| param_error(&e))?;
    Ok((set, model))
}

/// Eigenvalues of `model` at every speed, behind a progress bar on long
/// sweeps (drawn only when stderr is a terminal).
pub fn sweep(model: &Model, speeds: &[f64], file: &Path) -> Result<Sweep, CliError> {
    let bar = progress_bar(speeds.len(), "eigenvalues");
    let sweep = Sweep::run(model, speeds, |_| bar.inc(1));
    bar.finish_and_clear();
    sweep.map_err(|e| CliError::file(file, e))
}

/// [`sweep`] without holding the values: the modes and critical speeds of
/// `model` over `speeds`, for [`Survey::replay`] to give the values.
pub fn survey(model: &Model, speeds: &[f64], file: &Path) -> Result<Survey, CliError> {
    let bar = progress_bar(speeds.len(), "modes");
    let survey = Survey::run(model, speeds, |_| bar.inc(1));
    bar.finish_and_clear();
    survey.map_err(|e| CliError::file(file, e))
}

/// A progress bar over `speeds` speeds, hidden on short sweeps.
fn progress_bar(speeds: usize, what: &str) -> ProgressBar {
    let bar = if speeds > PROGRESS_MIN_SPEEDS {
        ProgressBar::new(speeds as u64)
    } else {
        ProgressBar::hidden()
    };
    if let Ok(style) =
        ProgressStyle::with_template(&format!("{what} {{bar:40}} {{pos}}/{{len}} speeds"))
    {
        bar.set_style(style.progress_chars("=> "));
    }
    bar
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speed_ranges_include_both_ends() {
        let s: Speeds = "0:10:0.05".parse().unwrap();
        assert_eq!(s.0.len(), 201);
        assert!((s.0[200] - 10.0).abs() < 1e-12);
        assert_eq!("2:2:1".parse::<Speeds>().unwrap().0, vec![2.0]);
    }

    #[test]
    fn bad_speed_ranges_are_refused() {
        for bad in [
            "",
            "1:2",
            "a:2:1",
            "3:2:1",
            "0:1:0",
            "0:1:-1",
            "-1:1:1",
            "0:inf:1",
            "0:1e9:1e-3",
        ] {
            assert!(bad.parse::<Speeds>().is_err(), "{bad}");
        }
    }
}
