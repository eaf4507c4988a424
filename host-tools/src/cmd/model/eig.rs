//! `wobblog model eig`: eigenvalues against speed, per mode, and the
//! critical speeds. The CSV (`speed_mps,mode,re_per_s,im_rad_per_s`, one row
//! per eigenvalue, both members of a complex pair) is an interface others
//! rely on: the critical speeds go to stderr with it, never into it.

use std::io::Write;
use std::path::PathBuf;

use serde::Serialize;
use wobble_model::{Complex, CriticalSpeed, Mode, SweepError};

use super::{load_as, survey, Speeds, Variant};
use crate::output::Output;
use crate::CliError;

/// Output formats.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Aligned columns, then the critical speeds.
    Table,
    /// `speed_mps,mode,re_per_s,im_rad_per_s`; critical speeds on stderr.
    Csv,
    /// One JSON object per eigenvalue, then one per critical speed.
    Jsonl,
}

/// The contact model of `--contacts`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Contacts {
    /// The file's tyre model.
    Tyres,
    /// Lateral no-slip at both contacts.
    NoSlip,
}

/// Arguments of `wobblog model eig`.
#[derive(clap::Args)]
pub struct Args {
    /// Parameter file: TOML (`params/*.toml`) or a BicycleParameters
    /// `*Benchmark.txt`.
    pub params: PathBuf,
    /// Speeds FROM:TO:STEP, m/s. The modes are named on a 0-14 m/s
    /// reference sweep followed into these speeds: a single speed (`5:5:1`)
    /// or any range names each mode as the full sweep does.
    #[arg(long, default_value = "0:10:0.1")]
    pub speeds: Speeds,
    /// Output format.
    #[arg(long, value_enum, default_value_t = Format::Table)]
    pub format: Format,
    /// Evaluate the Whipple limit of the bicycle (rider locked, rigid head,
    /// tyres without slip) instead of its own model.
    #[arg(long)]
    pub whipple: bool,
    /// The contacts: `tyres` (the file's model) or `no-slip`, its
    /// non-holonomic counterpart (the same bodies, no lateral slip at either
    /// contact, torso and twist free: the seed paper's thick line of Figure 4).
    #[arg(long, value_enum, default_value_t = Contacts::Tyres, conflicts_with = "whipple")]
    pub contacts: Contacts,
    /// Write here instead of standard output (whole or not at all).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

/// One eigenvalue: a row of the CSV and a line of the JSON lines.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Row {
    /// Forward speed, m/s.
    pub speed_mps: f64,
    /// The mode it belongs to (`weave`, `capsize`, `wobble`, ...).
    pub mode: &'static str,
    /// Real part, 1/s.
    pub re_per_s: f64,
    /// Imaginary part, rad/s (0 for a real eigenvalue).
    pub im_rad_per_s: f64,
}

/// Why handing out the rows stopped.
pub enum Failure<E> {
    /// The visitor's error.
    Visit(E),
    /// The eigenvalues could not be found.
    Sweep(SweepError),
}

impl<E> From<SweepError> for Failure<E> {
    fn from(e: SweepError) -> Self {
        Self::Sweep(e)
    }
}

/// Hands every eigenvalue of `model` at `speeds` to `visit`, speed by
/// speed, by mode (as `survey` named them), then imaginary part: the rows
/// of `wobblog model eig` (the Python package's `Model.eig` too).
///
/// # Errors
/// The first error of `visit`, or of the eigenvalue solver.
pub fn visit_rows<E>(
    model: &wobble_model::Model,
    survey: &wobble_model::Survey,
    speeds: &[f64],
    mut visit: impl FnMut(&Row) -> Result<(), E>,
) -> Result<(), Failure<E>> {
    let mut at = Vec::with_capacity(survey.modes.len());
    survey.replay(model, speeds, |u, values| {
        rows_at(&mut at, &survey.modes, values);
        for &(mode, v) in &at {
            visit(&row(u, mode, v)).map_err(Failure::Visit)?;
        }
        Ok(())
    })
}

/// Runs `wobblog model eig`. The sweep is never held whole: a first pass
/// names the modes and finds the critical speeds, a second writes the rows
/// speed by speed as it evaluates them, so memory does not grow with the
/// number of speeds.
pub fn run(args: &Args) -> Result<(), CliError> {
    let variant = match (args.whipple, args.contacts) {
        (true, _) => Variant::Whipple,
        (false, Contacts::Tyres) => Variant::Own,
        (false, Contacts::NoSlip) => Variant::NoSlip,
    };
    let (_, model) = load_as(&args.params, variant)?;
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.params])?;
    let speeds = &args.speeds.0;
    let survey = survey(&model, speeds, &args.params)?;
    let critical = &survey.critical;
    if args.format == Format::Csv {
        for c in critical {
            eprintln!("wobblog: {}", describe(c));
        }
    }
    let header: &[u8] = match args.format {
        Format::Csv => b"speed_mps,mode,re_per_s,im_rad_per_s\n",
        Format::Table => b"speed_mps  mode          re_per_s  im_rad_per_s   freq_hz\n",
        Format::Jsonl => b"",
    };
    out.write_all(header).map_err(|e| out.error(e))?;
    let written = visit_rows(&model, &survey, speeds, |row| {
        write_row(&mut out, args.format, row)
    });
    match written {
        Ok(()) => {}
        Err(Failure::Visit(e)) => return Err(out.error(e)),
        Err(Failure::Sweep(e)) => return Err(CliError::file(&args.params, e)),
    }
    let tail = match args.format {
        Format::Csv => Ok(()),
        Format::Table => write_table_tail(&mut out, critical),
        Format::Jsonl => write_jsonl_tail(&mut out, critical),
    };
    tail.map_err(|e| out.error(e))?;
    out.commit()
}

/// The values at one speed as `(mode, value)`, by mode, then imaginary part.
fn rows_at(at: &mut Vec<(Mode, Complex<f64>)>, modes: &[Mode], values: &[Complex<f64>]) {
    at.clear();
    at.extend(modes.iter().copied().zip(values.iter().copied()));
    at.sort_by(|a, b| {
        a.0.cmp(&b.0)
            .then(a.1.im.total_cmp(&b.1.im))
            .then(a.1.re.total_cmp(&b.1.re))
    });
}

fn row(u: f64, mode: Mode, v: Complex<f64>) -> Row {
    Row {
        speed_mps: u,
        mode: mode.name(),
        re_per_s: v.re,
        // The solver's round-off on a real eigenvalue is no oscillation.
        im_rad_per_s: if v.im.abs() <= wobble_model::sweep::REAL_TOL {
            0.0
        } else {
            v.im
        },
    }
}

fn write_row(o: &mut dyn Write, format: Format, r: &Row) -> std::io::Result<()> {
    match format {
        Format::Csv => writeln!(
            o,
            "{},{},{},{}",
            r.speed_mps, r.mode, r.re_per_s, r.im_rad_per_s
        ),
        Format::Table => writeln!(
            o,
            "{:9.3}  {:<9}  {:11.5}  {:12.5}  {:8.4}",
            r.speed_mps,
            r.mode,
            r.re_per_s,
            r.im_rad_per_s,
            r.im_rad_per_s.abs() / std::f64::consts::TAU
        ),
        Format::Jsonl => {
            serde_json::to_writer(&mut *o, r)?;
            o.write_all(b"\n")
        }
    }
}

fn write_table_tail(o: &mut dyn Write, critical: &[CriticalSpeed]) -> std::io::Result<()> {
    o.write_all(b"\ncritical speeds:\n")?;
    if critical.is_empty() {
        o.write_all(b"  none in this speed range\n")?;
    }
    for c in critical {
        writeln!(o, "  {}", describe(c))?;
    }
    Ok(())
}

fn write_jsonl_tail(o: &mut dyn Write, critical: &[CriticalSpeed]) -> std::io::Result<()> {
    for c in critical {
        serde_json::to_writer(&mut *o, &critical_json(c))?;
        o.write_all(b"\n")?;
    }
    Ok(())
}

/// A critical speed as a line of `wobblog model eig --format jsonl`.
#[must_use]
pub fn critical_json(c: &CriticalSpeed) -> serde_json::Value {
    serde_json::json!({
        "critical_speed_mps": c.speed_mps,
        "mode": c.mode.name(),
        "unstable_above": c.unstable_above,
        "kind": c.kind(),
        "im_rad_per_s": c.im_rad_per_s,
    })
}

/// `weave speed 4.292382536 m/s (stable above, oscillatory, 2.97 Hz)`.
#[must_use]
pub fn describe(c: &CriticalSpeed) -> String {
    format!(
        "{} speed {:.9} m/s ({} above, {}, {:.2} Hz)",
        c.mode.name(),
        c.speed_mps,
        if c.unstable_above {
            "unstable"
        } else {
            "stable"
        },
        c.kind(),
        c.im_rad_per_s / std::f64::consts::TAU
    )
}
