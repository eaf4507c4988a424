//! `wobblog model plot`: the seed paper's Figure 4 for a parameter file,
//! optionally with the Whipple limit of the same bicycle.

use std::path::PathBuf;

use wobble_model::{Mode, Model};

use super::figure::{EigenFigure, Layer, Line};
use super::{load, sweep, Speeds};
use crate::output::Output;
use crate::plot::{render, ImageKind};
use crate::CliError;

/// Modes drawn unless `--all-modes` (the twist, near 30 Hz, would squash
/// the frequency axis).
pub const NAMED_MODES: [Mode; 5] = [
    Mode::Wobble,
    Mode::Weave,
    Mode::Capsize,
    Mode::Castering,
    Mode::Lean,
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
    /// Also draw the Whipple limit of the bicycle (dashed).
    #[arg(long)]
    pub both: bool,
    /// Also draw the twist and the modes named `other` (tyre lags, ...).
    #[arg(long)]
    pub all_modes: bool,
}

/// Runs `wobblog model plot`.
pub fn run(args: &Args) -> Result<(), CliError> {
    ImageKind::of(&args.output)?;
    let (set, model) = load(&args.params, false)?;
    let out = Output::create(&args.output, &[&args.params])?;
    let mut layers = vec![Layer {
        label: label(&model),
        sweep: sweep(&model, &args.speeds.0, &args.params)?,
        line: Line::Thick,
    }];
    if args.both && matches!(model, Model::Wobble(_)) {
        let (_, whipple) = load(&args.params, true)?;
        layers.push(Layer {
            label: "Whipple limit".into(),
            sweep: sweep(&whipple, &args.speeds.0, &args.params)?,
            line: Line::Dashed,
        });
    }
    let mut modes = NAMED_MODES.to_vec();
    if args.all_modes {
        modes.extend([Mode::Twist, Mode::Other]);
    }
    let figure = EigenFigure {
        title: set.name.clone(),
        layers,
        modes,
        measured: Vec::new(),
    };
    render(&figure, out)
}

fn label(model: &Model) -> String {
    match model {
        Model::Whipple(_) => "Whipple".into(),
        Model::Wobble(_) => "wobble model".into(),
    }
}
