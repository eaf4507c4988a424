//! `wobblog model eig`: eigenvalues against speed, per mode, and the
//! critical speeds. The CSV (`speed_mps,mode,re_per_s,im_rad_per_s`, one row
//! per eigenvalue, both members of a complex pair) is an interface others
//! rely on: the critical speeds go to stderr with it, never into it.

use std::fmt::Write as _;
use std::io::Write as _;
use std::path::PathBuf;

use serde::Serialize;
use wobble_model::{critical_speeds, CriticalSpeed, Sweep};

use super::{load, sweep, Speeds};
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

/// Runs `wobblog model eig`.
pub fn run(args: &Args) -> Result<(), CliError> {
    let (_, model) = load(&args.params, args.whipple)?;
    let mut out = Output::create_or_stdout(args.output.as_deref(), &[&args.params])?;
    let sweep = sweep(&model, &args.speeds.0, &args.params)?;
    let critical = critical_speeds(&model, &sweep);
    let text = match args.format {
        Format::Csv => {
            for c in &critical {
                eprintln!("wobblog: {}", describe(c));
            }
            csv_text(&sweep)
        }
        Format::Table => table_text(&sweep, &critical),
        Format::Jsonl => jsonl_text(&sweep, &critical),
    };
    out.write_all(text.as_bytes()).map_err(|e| out.error(e))?;
    out.commit()
}

/// Rows in speed order; within a speed by mode, then imaginary part.
fn rows(sweep: &Sweep) -> Vec<Row<'_>> {
    let mut rows = Vec::with_capacity(sweep.speeds_mps.len() * sweep.branches.len());
    for (k, &u) in sweep.speeds_mps.iter().enumerate() {
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
        rows.extend(at.into_iter().map(|(mode, v)| Row {
            speed_mps: u,
            mode: mode.name(),
            re_per_s: v.re,
            // The solver's round-off on a real eigenvalue is no oscillation.
            im_rad_per_s: if v.im.abs() <= wobble_model::sweep::REAL_TOL {
                0.0
            } else {
                v.im
            },
        }));
    }
    rows
}

fn csv_text(sweep: &Sweep) -> String {
    let mut o = String::from("speed_mps,mode,re_per_s,im_rad_per_s\n");
    for r in rows(sweep) {
        let _ = writeln!(
            o,
            "{},{},{},{}",
            r.speed_mps, r.mode, r.re_per_s, r.im_rad_per_s
        );
    }
    o
}

fn table_text(sweep: &Sweep, critical: &[CriticalSpeed]) -> String {
    let mut o = String::from("speed_mps  mode          re_per_s  im_rad_per_s   freq_hz\n");
    for r in rows(sweep) {
        let _ = writeln!(
            o,
            "{:9.3}  {:<9}  {:11.5}  {:12.5}  {:8.4}",
            r.speed_mps,
            r.mode,
            r.re_per_s,
            r.im_rad_per_s,
            r.im_rad_per_s.abs() / std::f64::consts::TAU
        );
    }
    o.push_str("\ncritical speeds:\n");
    if critical.is_empty() {
        o.push_str("  none in this speed range\n");
    }
    for c in critical {
        let _ = writeln!(o, "  {}", describe(c));
    }
    o
}

fn jsonl_text(sweep: &Sweep, critical: &[CriticalSpeed]) -> String {
    let mut o = String::new();
    for r in rows(sweep) {
        o.push_str(&serde_json::to_string(&r).unwrap_or_default());
        o.push('\n');
    }
    for c in critical {
        o.push_str(
            &serde_json::json!({
                "critical_speed_mps": c.speed_mps,
                "mode": c.mode.name(),
                "unstable_above": c.unstable_above,
                "kind": c.kind(),
                "im_rad_per_s": c.im_rad_per_s,
            })
            .to_string(),
        );
        o.push('\n');
    }
    o
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
