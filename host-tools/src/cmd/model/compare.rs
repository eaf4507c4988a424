//! `wobblog model compare`: the seed paper's Figure 8, the model's wobble
//! mode against speed with every measured episode laid over it (and its
//! weave with the weave's ring-downs, when the logs hold any), and the
//! residuals (measured minus model) printed.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use wobble_model::sweep::mode_at;
use wobble_model::Mode;

use super::episodes::{self, LoggedEpisode};
use super::figure::{critical_marks, EigenFigure, Layer, Line};
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
    /// The figure's size and resolution (`--size`, `--dpi`).
    #[command(flatten)]
    pub figure: crate::plot::FigureArgs,
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
    let mut at_model = vec![None; found.len()];
    let mut missing = String::new();
    for mode in [Mode::Wobble, Mode::Weave] {
        let of_mode: Vec<usize> = (0..found.len())
            .filter(|&i| found[i].mode() == mode)
            .collect();
        if of_mode.is_empty() {
            continue;
        }
        let speeds: Vec<f64> = of_mode
            .iter()
            .map(|&i| found[i].episode.speed_at_onset_mps)
            .collect();
        let values = mode_at(&model, mode, &speeds).map_err(|e| CliError::file(&args.params, e))?;
        let Some(values) = values else {
            // A Whipple bicycle has a weave and no wobble: its episodes of
            // a mode the model lacks are said, not compared.
            let _ = writeln!(
                missing,
                "the model has no {} mode: {} not compared",
                mode.name(),
                crate::words::plural(of_mode.len(), "episode")
            );
            continue;
        };
        for (&i, v) in of_mode.iter().zip(values) {
            at_model[i] = Some(v);
        }
    }
    let text = residual_table(&found, &at_model) + &missing;
    print(stdout, &text)?;
    // A log that could not be read fails the command: the figure is not
    // committed then, and an old one stays as it was.
    if let (Some(out), Ok(())) = (out, &loaded) {
        let figure = figure(&set.name, &model, &args.speeds.0, &args.params, &found)?;
        render(&figure, out, &args.figure)?;
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
    let weave = found.iter().any(|e| e.mode() == Mode::Weave);
    let own = sweep(model, speeds, params)?;
    let modes = if weave {
        vec![Mode::Wobble, Mode::Weave]
    } else {
        vec![Mode::Wobble]
    };
    Ok(EigenFigure {
        title: if weave {
            format!("{name}: wobble and weave modes and measured episodes")
        } else {
            format!("{name}: wobble mode and measured episodes")
        },
        critical: critical_marks(model, &own, &modes),
        layers: vec![Layer {
            label: "model".into(),
            sweep: own,
            line: Line::Thick,
        }],
        modes,
        measured: found.iter().map(LoggedEpisode::measured).collect(),
    })
}

/// Each episode of `found` against the model's value of its mode
/// (`at_model`, in the same order).
fn residual_table(
    found: &[LoggedEpisode],
    at_model: &[Option<wobble_model::Complex<f64>>],
) -> String {
    let mut o = String::from(
        "log            mode    onset_s  speed_mps  freq_hz  model_hz  d_freq_hz  sigma_per_s  model_per_s  d_sigma_per_s  source     censored\n",
    );
    let (mut sf, mut ss, mut n) = (0.0, 0.0, 0usize);
    for (e, w) in found.iter().zip(at_model) {
        let Some(w) = w else { continue };
        let model_hz = w.im / std::f64::consts::TAU;
        let (df, ds) = (e.episode.freq_hz - model_hz, e.episode.sigma_per_s - w.re);
        if !e.censored() {
            sf += df * df;
            ss += ds * ds;
            n += 1;
        }
        let _ = writeln!(
            o,
            "{:<13}  {:<6} {:8.2}  {:9.2}  {:7.2}  {:8.2}  {:9.2}  {:11.2}  {:11.2}  {:13.2}  {:<9}  {}",
            e.log,
            e.episode.mode.as_str(),
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
