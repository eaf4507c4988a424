//! `wobblog model sweep`: one parameter scaled by several factors, the
//! critical speeds of each variant, and the seed paper's Figures 7, 9-11
//! (standard thick, smaller factors thin, larger dotted).

use std::fmt::Write as _;
use std::path::PathBuf;

use wobble_model::paper::variation;
use wobble_model::{critical_speeds, Mode, Model, ParamSet};

use super::eig::describe;
use super::figure::{EigenFigure, Layer, Line};
use super::{key_error, param_error, sweep, Speeds};
use crate::cmd::logs::print;
use crate::output::Output;
use crate::plot::{render, ImageKind};
use crate::CliError;

/// Arguments of `wobblog model sweep`.
#[derive(clap::Args)]
pub struct Args {
    /// Parameter file (TOML or BicycleParameters `*Benchmark.txt`).
    pub params: PathBuf,
    /// The parameter to vary, as named in the file (`section.key`), or
    /// `rider.mass` for the rider's whole mass (the file needs `[rider_legs]`).
    #[arg(long, value_name = "KEY")]
    pub param: String,
    /// Factors to scale it by, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "0.5,1,2")]
    pub factors: Vec<f64>,
    /// Speeds FROM:TO:STEP, m/s.
    #[arg(long, default_value = "0:10:0.05")]
    pub speeds: Speeds,
    /// Also draw the figure into this `.png` or `.svg` file.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The figure's size and resolution (`--size`, `--dpi`).
    #[command(flatten)]
    pub figure: crate::plot::FigureArgs,
}

/// One variant of the parameter set: a parameter of the file scaled, or
/// the rider's whole mass (`rider.mass`, the seed paper's Figure 9).
pub fn variant(set: &ParamSet, key: &str, factor: f64) -> Result<ParamSet, CliError> {
    variation::scaled_key(set, key, factor).map_err(|e| key_error(set, &e))
}

/// Runs `wobblog model sweep`.
pub fn run(args: &Args) -> Result<(), CliError> {
    if let Some(o) = &args.output {
        ImageKind::of(o)?;
    }
    if args.factors.iter().any(|f| !f.is_finite() || *f <= 0.0) {
        return Err(CliError::Usage("--factors must be positive numbers".into()));
    }
    let set = super::load_set(&args.params)?;
    let stdout = Output::stdout(&[&args.params])?;
    let out = args
        .output
        .as_deref()
        .map(|o| Output::create(o, &[&args.params]))
        .transpose()?;
    let mut text = String::new();
    let mut layers = Vec::new();
    for &factor in &args.factors {
        let model =
            Model::from_set(&variant(&set, &args.param, factor)?).map_err(|e| param_error(&e))?;
        let s = sweep(&model, &args.speeds.0, &args.params)?;
        let _ = writeln!(
            text,
            "{} x {factor} ({}):",
            args.param,
            value_text(&set, &args.param, factor)
        );
        let critical = critical_speeds(&model, &s);
        if critical.is_empty() {
            text.push_str("  no critical speed in this speed range\n");
        }
        for c in &critical {
            let _ = writeln!(text, "  {}", describe(c));
        }
        let line = if (factor - 1.0).abs() < 1e-12 {
            Line::Thick
        } else if factor < 1.0 {
            Line::Thin
        } else {
            Line::Dotted
        };
        layers.push(Layer {
            label: format!("x {factor}"),
            sweep: s,
            line,
        });
    }
    print(stdout, &text)?;
    if let Some(out) = out {
        let figure = EigenFigure {
            title: format!("{}: {} x {:?}", set.name, args.param, args.factors),
            layers,
            modes: if args.param.starts_with("hip.") {
                vec![Mode::Wobble, Mode::Weave, Mode::Lean]
            } else {
                vec![Mode::Wobble, Mode::Weave]
            },
            measured: Vec::new(),
            critical: Vec::new(),
        };
        render(&figure, out, &args.figure)?;
    }
    Ok(())
}

fn value_text(set: &ParamSet, key: &str, factor: f64) -> String {
    if key == variation::RIDER_MASS {
        return variation::rider_mass_kg(set)
            .map_or_else(|_| String::new(), |m| format!("{} kg", m * factor));
    }
    set.quantity(key)
        .map_or_else(String::new, |q| format!("{} {}", q.value * factor, q.unit))
}
