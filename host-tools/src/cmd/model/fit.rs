//! `wobblog model fit`: least-squares fit of chosen parameters to the
//! measured wobble frequencies and growth rates (censored episodes left
//! out), with 95 % confidence intervals, and the fitted parameter file,
//! which keeps its evidence: each fitted value's interval, the logs and
//! episodes it came from, and every episode's residual.

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
    let used: Vec<&episodes::LoggedEpisode> = found
        .iter()
        .filter(|e| !e.censored() && e.mode() == Mode::Wobble)
        .collect();
    let obs: Vec<_> = used.iter().map(|e| e.observation()).collect();
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
    let mut fitted = result.set.clone();
    let evidence = Evidence::of(&used, &result);
    fitted.name = format!("{}, fitted to {}", fitted.name, evidence.episodes);
    fitted.source = format!(
        "{}; fitted by wobblog model fit to {}",
        fitted.source, evidence.what
    );
    for e in &result.estimates {
        fitted
            .set_value(&e.key, e.value, &evidence.source_of(e))
            .map_err(|err| param_error(&err))?;
    }
    let residuals = residual_lines(&fitted, &used).map_err(|e| CliError::file(&args.params, e))?;
    out.write_all((to_toml(&fitted) + &residuals).as_bytes())
        .map_err(|e| out.error(e))?;
    out.commit()?;
    print(stdout, &text)?;
    loaded
}

/// What a fit was made from, in words for the fitted file.
struct Evidence {
    /// `12 wobble episodes`.
    episodes: String,
    /// `12 wobble episodes of 3 logs (RUN00001.WBL, ...); rms residuals ...`.
    what: String,
}

/// Logs named in the fitted file at most; more are counted.
const LOGS_NAMED: usize = 8;

impl Evidence {
    fn of(used: &[&episodes::LoggedEpisode], result: &wobble_model::fit::FitResult) -> Self {
        let mut logs: Vec<&str> = used.iter().map(|e| e.log.as_str()).collect();
        logs.dedup();
        let mut named = logs
            .iter()
            .take(LOGS_NAMED)
            .copied()
            .collect::<Vec<_>>()
            .join(", ");
        if logs.len() > LOGS_NAMED {
            let _ = write!(named, " and {} more", logs.len() - LOGS_NAMED);
        }
        let episodes = crate::words::plural(used.len(), "wobble episode");
        let what = format!(
            "{episodes} of {} ({named}); rms residuals {:.3} Hz, {:.3} 1/s",
            crate::words::plural(logs.len(), "log"),
            result.rms_freq_hz,
            result.rms_sigma_per_s
        );
        Self { episodes, what }
    }

    /// The source of a fitted value: its interval and what it came from.
    fn source_of(&self, e: &wobble_model::fit::Estimate) -> String {
        format!(
            "fitted by wobblog model fit: {} +/- {} {} (95 %), to {}",
            e.value, e.ci95, e.unit, self.what
        )
    }
}

/// Every episode fitted, measured against the fitted model's wobble at
/// its speed, as TOML comments (the file still loads as it did).
fn residual_lines(
    fitted: &wobble_model::ParamSet,
    used: &[&episodes::LoggedEpisode],
) -> Result<String, String> {
    let model = wobble_model::Model::from_set(fitted).map_err(|e| e.to_string())?;
    let speeds: Vec<f64> = used.iter().map(|e| e.episode.speed_at_onset_mps).collect();
    let at = wobble_model::sweep::mode_at(&model, Mode::Wobble, &speeds)
        .map_err(|e| e.to_string())?
        .unwrap_or_default();
    let mut o = String::from(
        "\n# The episodes fitted, measured minus the fitted model's wobble at the same speed:\n\
         # log, onset_s, speed_mps, freq_hz, d_freq_hz, sigma_per_s, d_sigma_per_s\n",
    );
    for (e, w) in used.iter().zip(at) {
        let ep = &e.episode;
        let _ = writeln!(
            o,
            "# {}, {:.2}, {:.3}, {:.3}, {:.3}, {:.3}, {:.3}",
            crate::text::escape_controls(&e.log),
            ep.onset_s,
            ep.speed_at_onset_mps,
            ep.freq_hz,
            ep.freq_hz - w.im / std::f64::consts::TAU,
            ep.sigma_per_s,
            ep.sigma_per_s - w.re
        );
    }
    Ok(o)
}
