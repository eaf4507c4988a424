//! `wobblog model plot`: the seed paper's Figure 4 for a parameter file:
//! with `--both` the non-holonomic counterpart (no lateral slip, torso and
//! twist free) thick and the tyre model thin, as in the paper.

use std::path::PathBuf;

use wobble_model::{Mode, Model};

use super::figure::{critical_marks, EigenFigure, Layer, Line};
use super::{load, param_error, sweep, Speeds};
use crate::output::Output;
use crate::plot::{render, ImageKind};
use crate::CliError;

/// Modes drawn unless `--all-modes` (the twist, near 30 Hz, would squash
/// the frequency axis).
pub const NAMED_MODES: [Mode; 6] = [
    Mode::Wobble,
    Mode::Weave,
    Mode::Capsize,
    Mode::Castering,
    Mode::Lean,
    Mode::Sway,
];

/// Arguments of `wobblog model plot`.
#[derive(clap::Args)]
pub struct Args {
    /// Parameter file (TOML or BicycleParameters `*Benchmark.txt`).
    pub params: PathBuf,
    /// The image to write: `.png` or `.svg`.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Speeds FROM:TO:STEP, m/s.
    #[arg(long, default_value = "0:10:0.05")]
    pub speeds: Speeds,
    /// Also draw the non-holonomic counterpart of the bicycle (thick; the
    /// tyre model then thin): the paper's Figure 4.
    #[arg(long)]
    pub both: bool,
    /// Also draw the twist and the modes named `other` (tyre lags, ...).
    #[arg(long)]
    pub all_modes: bool,
    /// The figure's size and resolution (`--size`, `--dpi`).
    #[command(flatten)]
    pub figure: crate::plot::FigureArgs,
}

/// Runs `wobblog model plot`.
pub fn run(args: &Args) -> Result<(), CliError> {
    ImageKind::of(&args.output)?;
    let (set, model) = load(&args.params, false)?;
    let out = Output::create(&args.output, &[&args.params])?;
    let both = args.both && matches!(model, Model::Wobble(_));
    let mut layers = Vec::new();
    if both {
        let no_slip = Model::no_slip_of(&set).map_err(|e| param_error(&e))?;
        layers.push(Layer {
            label: "no lateral slip (non-holonomic)".into(),
            sweep: sweep(&no_slip, &args.speeds.0, &args.params)?,
            line: Line::Thick,
        });
    }
    let own = sweep(&model, &args.speeds.0, &args.params)?;
    let mut modes = NAMED_MODES.to_vec();
    if args.all_modes {
        modes.extend([Mode::Twist, Mode::Other]);
    }
    let critical = critical_marks(&model, &own, &modes);
    layers.push(Layer {
        label: label(&model),
        sweep: own,
        line: if both { Line::Thin } else { Line::Thick },
    });
    let figure = EigenFigure {
        title: set.name.clone(),
        layers,
        modes,
        measured: Vec::new(),
        critical,
    };
    render(&figure, out, &args.figure)
}

fn label(model: &Model) -> String {
    match model {
        Model::Whipple(_) => "Whipple".into(),
        Model::Wobble(_) => "wobble model (tyres)".into(),
        Model::NoSlip(_) => "no lateral slip".into(),
    }
}
