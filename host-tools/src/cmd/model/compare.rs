//! `wobblog model compare`: the seed paper's Figure 8, the model's wobble
//! mode against speed with every measured episode laid over it, and the
//! residuals (measured minus model) printed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use wobble_model::sweep::mode_at;
use wobble_model::Mode;

use super::episodes::{self, LoggedEpisode};
use super::figure::{EigenFigure, Layer, Line};
use super::{load, sweep, Speeds};
use crate::cmd::logs::{expand, print};
use crate::output::Output;
use crate::plot::{render, ImageKind};
use crate::CliError;

/// Arguments of `wobblog model compare`.
#[derive(clap::Args)]
pub struct Args {
    /// Parameter file (TOML or BicycleParameters `*Benchmark.txt`).
    pub params: PathBuf,
    /// Card logs (`RUNnnnnn.WBL`) or card folders (every `*.WBL` at
    /// their top, in name order).
    #[arg(required = true, value_name = "LOGS|DIRS")]
    pub logs: Vec<PathBuf>,
    /// Also draw the figure into this `.png` or `.svg` file.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Speeds of the model curve FROM:TO:STEP, m/s.
    #[arg(long, default_value = "0:10:0.05")]
    pub speeds: Speeds,
}

/// Runs `wobblog model compare`.
pub fn run(args: &Args) -> Result<(), CliError> {
    if let Some(o) = &args.output {
        ImageKind::of(o)?;
    }
    let (set, model) = load(&args.params, false)?;
    let logs = crate::inputs::distinct(expand(&args.logs)?);
    let mut inputs: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    inputs.push(&args.params);
    let out = args
        .output
        .as_deref()
        .map(|o| Output::create(o, &inputs))
        .transpose()?;
    let stdout = Output::stdout(&inputs)?;
    let (found, loaded) = episodes::load(&logs);
    let speeds: Vec<f64> = found.iter().map(|e| e.episode.speed_at_onset_mps).collect();
    let wobble = mode_at(&model, Mode::Wobble, &speeds)
        .map_err(|e| CliError::file(&args.params, e))?
        .ok_or_else(|| CliError::file(&args.params, "the model has no wobble mode"))?;
    let text = residual_table(&found, &wobble);
    print(stdout, &text)?;
    // A log that could not be read fails the command: the figure is not
    // committed then, and an old one stays as it was.
    if let (Some(out), Ok(())) = (out, &loaded) {
        let figure = figure(&set.name, &model, &args.speeds.0, &args.params, &found)?;
        render(&figure, out)?;
    }
    loaded
}

/// Figure 8 over the model: the wobble mode of `model` (named `name`, from
/// the file `params`) at `speeds` with every episode of `found` on it.
pub fn figure(
    name: &str,
    model: &wobble_model::Model,
    speeds: &[f64],
    params: &Path,
    found: &[LoggedEpisode],
) -> Result<EigenFigure, CliError> {
    Ok(EigenFigure {
        title: format!("{name}: wobble mode and measured episodes"),
        layers: vec![Layer {
            label: "model".into(),
            sweep: sweep(model, speeds, params)?,
            line: Line::Thick,
        }],
        modes: vec![Mode::Wobble],
        measured: found.iter().map(LoggedEpisode::measured).collect(),
    })
}

fn residual_table(found: &[LoggedEpisode], wobble: &[wobble_model::Complex<f64>]) -> String {
    let mut o = String::from(
        "log            onset_s  speed_mps  freq_hz  model_hz  d_freq_hz  sigma_per_s  model_per_s  d_sigma_per_s  source     censored\n",
    );
    let (mut sf, mut ss, mut n) = (0.0, 0.0, 0usize);
    for (e, w) in found.iter().zip(wobble) {
        let model_hz = w.im / std::f64::consts::TAU;
        let (df, ds) = (e.episode.freq_hz - model_hz, e.episode.sigma_per_s - w.re);
        if !e.censored() {
            sf += df * df;
            ss += ds * ds;
            n += 1;
        }
        let _ = writeln!(
            o,
            "{:<13} {:8.2}  {:9.2}  {:7.2}  {:8.2}  {:9.2}  {:11.2}  {:11.2}  {:13.2}  {:<9}  {}",
            e.log,
            e.episode.onset_s,
            e.episode.speed_at_onset_mps,
            e.episode.freq_hz,
            model_hz,
            df,
            e.episode.sigma_per_s,
            w.re,
            ds,
            e.episode.source.as_str(),
            if e.censored() { "yes" } else { "no" }
        );
    }
    if n > 0 {
        let _ = writeln!(
            o,
            "rms residuals over {}: {:.3} Hz, {:.3} 1/s",
            crate::words::plural(n, "episode"),
            (sf / n as f64).sqrt(),
            (ss / n as f64).sqrt()
        );
    } else {
        o.push_str("no episodes to compare\n");
    }
    o
}
