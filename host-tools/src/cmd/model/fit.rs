//! `wobblog model fit`: least-squares fit of chosen parameters to the
//! measured wobble frequencies and growth rates (censored episodes left
//! out), with 95 % confidence intervals, and the fitted parameter file.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::{Path, PathBuf};

use wobble_model::fit::{fit, Weights};
use wobble_model::params::to_toml;
use wobble_model::Mode;

use super::episodes;
use super::{key_error, param_error};
use crate::cmd::logs::{expand, print};
use crate::output::Output;
use crate::CliError;

/// Arguments of `wobblog model fit`.
#[derive(clap::Args)]
pub struct Args {
    /// Parameter file (TOML).
    pub params: PathBuf,
    /// Card logs (`RUNnnnnn.WBL`) or card folders (every `*.WBL` at
    /// their top, in name order).
    #[arg(required = true, value_name = "LOGS|DIRS")]
    pub logs: Vec<PathBuf>,
    /// A parameter to fit, as named in the file (repeat for more).
    #[arg(long = "param", required = true, value_name = "KEY")]
    pub params_to_fit: Vec<String>,
    /// The fitted parameter file to write (TOML, whole or not at all).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Scatter of a measured frequency, Hz (weights the residuals).
    #[arg(long, default_value_t = 0.1)]
    pub freq_sd: f64,
    /// Scatter of a measured growth rate, 1/s.
    #[arg(long, default_value_t = 0.5)]
    pub sigma_sd: f64,
}

/// Runs `wobblog model fit`.
pub fn run(args: &Args) -> Result<(), CliError> {
    if !(args.freq_sd > 0.0 && args.sigma_sd > 0.0) {
        return Err(CliError::Usage(
            "--freq-sd and --sigma-sd must be positive".into(),
        ));
    }
    let set = super::load_set(&args.params)?;
    for key in &args.params_to_fit {
        set.value(key).map_err(|e| key_error(&set, &e))?;
    }
    let logs = crate::inputs::distinct(expand(&args.logs)?);
    let mut inputs: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    inputs.push(&args.params);
    let mut out = Output::create(&args.output, &inputs)?;
    let stdout = Output::stdout(&inputs)?;
    let (found, loaded) = episodes::load(&logs);
    // The fit is the wobble's: the weave's ring-downs are not fitted.
    let obs: Vec<_> = found
        .iter()
        .filter(|e| !e.censored() && e.mode() == Mode::Wobble)
        .map(episodes::LoggedEpisode::observation)
        .collect();
    let weights = Weights {
        freq_sd_hz: args.freq_sd,
        sigma_sd_per_s: args.sigma_sd,
    };
    let result = fit(&set, &args.params_to_fit, &obs, weights).map_err(|e| param_error(&e))?;
    let mut text = String::new();
    let _ = writeln!(
        text,
        "fitted to {} episodes ({} model evaluations):",
        obs.len(),
        result.evaluations
    );
    for e in &result.estimates {
        let _ = writeln!(
            text,
            "  {} = {:.6} +/- {:.6} {} (95 %)",
            e.key, e.value, e.ci95, e.unit
        );
    }
    let _ = writeln!(
        text,
        "rms residuals: {:.3} Hz, {:.3} 1/s",
        result.rms_freq_hz, result.rms_sigma_per_s
    );
    let mut fitted = result.set;
    fitted.source = format!("{} (fitted by wobblog model fit)", fitted.source);
    out.write_all(to_toml(&fitted).as_bytes())
        .map_err(|e| out.error(e))?;
    out.commit()?;
    print(stdout, &text)?;
    loaded
}
