//! `wobblog model eig`: eigenvalues against speed, per mode, and the
//! critical speeds. The CSV (`speed_mps,mode,re_per_s,im_rad_per_s`, one row
//! per eigenvalue, both members of a complex pair) is an interface others
//! rely on: the critical speeds go to stderr with it, never into it.

use std::io::Write;
use std::path::PathBuf;

use serde::Serialize;
use wobble_model::{critical_speeds, CriticalSpeed, Sweep};

use super::{load_as, sweep, Speeds, Variant};
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
    /// Speeds FROM:TO:STEP, m/s.
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

#[derive(Serialize)]
struct Row<'a> {
    speed_mps: f64,
    mode: &'a str,
    re_per_s: f64,
    im_rad_per_s: f64,
}

/// Runs `wobblog model eig`. The rows are written as they are formatted
/// (one speed at a time), never held as a whole text.
pub fn run(args: &Args) -> Result<(), CliError> {
    let variant = match (args.whipple, args.contacts) {
        (true, _) => Variant::Whipple,
        (false, Contacts::Tyres) => Variant::Own,
        (false, Contacts::NoSlip) => Variant::NoSlip,
    };
    let (_, model) = load_as(&args.params, variant)?;
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.params])?;
    let sweep = sweep(&model, &args.speeds.0, &args.params)?;
    let critical = critical_speeds(&model, &sweep);
    let written = match args.format {
        Format::Csv => {
            for c in &critical {
                eprintln!("wobblog: {}", describe(c));
            }
            write_csv(&mut out, &sweep)
        }
        Format::Table => write_table(&mut out, &sweep, &critical),
        Format::Jsonl => write_jsonl(&mut out, &sweep, &critical),
    };
    written.map_err(|e| out.error(e))?;
    out.commit()
}

/// The rows at the `k`-th speed, by mode, then imaginary part.
fn rows_at(sweep: &Sweep, k: usize) -> impl Iterator<Item = Row<'static>> {
    let u = sweep.speeds_mps[k];
    let mut at: Vec<_> = sweep
        .branches
        .iter()
        .map(|b| (b.mode, b.values[k]))
        .collect();
    at.sort_by(|a, b| {
        a.0.cmp(&b.0)
            .then(a.1.im.total_cmp(&b.1.im))
            .then(a.1.re.total_cmp(&b.1.re))
    });
    at.into_iter().map(move |(mode, v)| Row {
        speed_mps: u,
        mode: mode.name(),
        re_per_s: v.re,
        // The solver's round-off on a real eigenvalue is no oscillation.
        im_rad_per_s: if v.im.abs() <= wobble_model::sweep::REAL_TOL {
            0.0
        } else {
            v.im
        },
    })
}

/// Every row, in speed order.
fn rows(sweep: &Sweep) -> impl Iterator<Item = Row<'static>> + '_ {
    (0..sweep.speeds_mps.len()).flat_map(move |k| rows_at(sweep, k))
}

fn write_csv(o: &mut dyn Write, sweep: &Sweep) -> std::io::Result<()> {
    o.write_all(b"speed_mps,mode,re_per_s,im_rad_per_s\n")?;
    for r in rows(sweep) {
        writeln!(
            o,
            "{},{},{},{}",
            r.speed_mps, r.mode, r.re_per_s, r.im_rad_per_s
        )?;
    }
    Ok(())
}

fn write_table(
    o: &mut dyn Write,
    sweep: &Sweep,
    critical: &[CriticalSpeed],
) -> std::io::Result<()> {
    o.write_all(b"speed_mps  mode          re_per_s  im_rad_per_s   freq_hz\n")?;
    for r in rows(sweep) {
        writeln!(
            o,
            "{:9.3}  {:<9}  {:11.5}  {:12.5}  {:8.4}",
            r.speed_mps,
            r.mode,
            r.re_per_s,
            r.im_rad_per_s,
            r.im_rad_per_s.abs() / std::f64::consts::TAU
        )?;
    }
    o.write_all(b"\ncritical speeds:\n")?;
    if critical.is_empty() {
        o.write_all(b"  none in this speed range\n")?;
    }
    for c in critical {
        writeln!(o, "  {}", describe(c))?;
    }
    Ok(())
}

fn write_jsonl(
    o: &mut dyn Write,
    sweep: &Sweep,
    critical: &[CriticalSpeed],
) -> std::io::Result<()> {
    for r in rows(sweep) {
        serde_json::to_writer(&mut *o, &r)?;
        o.write_all(b"\n")?;
    }
    for c in critical {
        let line = serde_json::json!({
            "critical_speed_mps": c.speed_mps,
            "mode": c.mode.name(),
            "unstable_above": c.unstable_above,
            "kind": c.kind(),
            "im_rad_per_s": c.im_rad_per_s,
        });
        serde_json::to_writer(&mut *o, &line)?;
        o.write_all(b"\n")?;
    }
    Ok(())
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
