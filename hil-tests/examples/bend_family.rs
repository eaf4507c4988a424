//! The family of bicycles the margin line's bend prior is taken from: for
//! each, sigma's shape relative to its wobble speed `u*`, the number
//! `beta` of `wobblog::analysis::margin::bend`, and the family's mean and
//! spread.
//!
//! ```text
//! cargo run -p wobble-hil --release --example bend_family
//! ```
//!
//! Each bicycle is the closed loop of the simulated campaigns (the wobble
//! model and the balancing rider, `corpus::simulated::bike`): the
//! campaigns' four, the bicycles nothing was tuned on (the paper's test
//! bicycle as the parameter files in `host-tools/bicycle-model/params`
//! describe it, with its variants), every `paper-test-bicycle*.toml` file
//! there, and each of those with one of the steering head's stiffness
//! and damping, the front tyre's cornering stiffness and relaxation
//! length, times 0.8 and 1.25. `beta` is that of the parabola through
//! sigma at `u*/2`, at `0.85 u*` (the fastest kicks of a campaign) and at
//! `u*` (zero): `h(x) = p x + (beta/2) x^2`, `x = u/u* - 1`, `h(-1/2) =
//! -1`, `h(-0.15) = sigma(0.85 u*) / D`, `D = -sigma(u*/2)`: the bend the
//! line must extrapolate. A bicycle without a wobble speed between the
//! rider's slowest balanced speed and 12 m/s, or whose wobble mode the
//! model does not follow down to half of it, is listed and left out; so is
//! one whose sigma does not rise all the way from `u*/2` to `u*` (`beta`
//! of 8 or more in size: the wobble band's mode switches to another on the
//! way, which no damping extrapolation sees), and a bicycle whose figures repeat an
//! earlier one's (a parameter file that is also a campaign variant). The
//! spread is given as the family's SD and, about the prior's mean
//! `wobblog::analysis::margin::BEND_SHAPE_MEAN`, as the RMS of the shapes
//! on each side of it (the two-piece prior's two SDs).

use wobble_hil::corpus::signal::FS_HZ;
use wobble_hil::corpus::simulated::bike::{load_params, Bike};
use wobble_hil::corpus::simulated::campaign::{self, wobble_speed_mps};
use wobble_model::ParamSet;
use wobblog::analysis::margin::BEND_SHAPE_MEAN;

/// The varied parameters.
const KEYS: [&str; 4] = [
    "steer_head.stiffness",
    "steer_head.damping",
    "front_tyre.cornering_stiffness",
    "front_tyre.relaxation_length",
];

/// `(u*, D, beta)` of `set`, or why not.
fn shape(set: &ParamSet) -> Result<(f64, f64, f64), String> {
    let mut bike = Bike::from_set(set, 1.0 / FS_HZ)?;
    let w = wobble_speed_mps(&mut bike).ok_or("no wobble speed below 12 m/s")?;
    let mut sigma = |u: f64| {
        bike.wobble(u, false)
            .map(|m| m.value.re)
            .ok_or(format!("no wobble mode at {u:.2} m/s"))
    };
    let d = -sigma(0.5 * w)?;
    let s85 = sigma(0.85 * w)? / d;
    if d <= 0.0 {
        return Err(format!("unstable at half its wobble speed ({d:.3})"));
    }
    // -0.5 p + 0.125 beta = -1 and -0.15 p + 0.01125 beta = s85.
    let det = -0.5 * 0.011_25 + 0.15 * 0.125;
    let beta = (-0.5 * s85 - 0.15) / det;
    Ok((w, d, beta))
}

fn main() -> Result<(), String> {
    let mut sets: Vec<(String, ParamSet)> = Vec::new();
    let mut variants = campaign::variants()?;
    variants.extend(campaign::unseen_variants()?);
    for v in &variants {
        sets.push((v.name.to_owned(), v.params()?));
    }
    let dir =
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../host-tools/bicycle-model/params");
    let mut files: Vec<String> = std::fs::read_dir(&dir)
        .map_err(|e| format!("{}: {e}", dir.display()))?
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .filter(|n| n.starts_with("paper-test-bicycle") && n.ends_with(".toml"))
        .collect();
    files.sort();
    for f in &files {
        sets.push((f.clone(), load_params(f)?));
    }
    let bases = sets.clone();
    for (name, set) in &bases {
        for key in KEYS {
            let Ok(value) = set.value(key) else { continue };
            for factor in [0.8, 1.25] {
                let mut varied = set.clone();
                varied
                    .set_value(key, value * factor, "bend family variation")
                    .map_err(|e| e.to_string())?;
                sets.push((format!("{name}, {key} x {factor}"), varied));
            }
        }
    }
    println!("| bicycle | wobble speed, m/s | D = -sigma(u*/2), 1/s | beta |");
    println!("|---|---|---|---|");
    let mut betas = Vec::new();
    let mut seen: Vec<(String, String)> = Vec::new();
    for (name, set) in &sets {
        match shape(set) {
            Ok((w, d, beta)) => {
                let figures = format!("{w:.4} {d:.4} {beta:.4}");
                if let Some((first, _)) = seen.iter().find(|(_, f)| *f == figures) {
                    println!(
                        "| {name} | {w:.2} | {d:.3} | {beta:+.2} (the same bicycle as {first}) |"
                    );
                    continue;
                }
                seen.push((name.clone(), figures));
                if beta.abs() >= 8.0 {
                    println!("| {name} | {w:.2} | {d:.3} | {beta:+.2}: left out, a mode switch |");
                    continue;
                }
                println!("| {name} | {w:.2} | {d:.3} | {beta:+.2} |");
                betas.push(beta);
            }
            Err(why) => println!("| {name} | - | - | left out: {why} |"),
        }
    }
    let n = betas.len() as f64;
    let mean = betas.iter().sum::<f64>() / n;
    let sd = (betas.iter().map(|b| (b - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let (lo, hi) = betas
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    let side = |above: bool| {
        let d: Vec<f64> = betas
            .iter()
            .map(|b| b - BEND_SHAPE_MEAN)
            .filter(|d| (*d > 0.0) == above)
            .collect();
        let rms = (d.iter().map(|d| d * d).sum::<f64>() / d.len().max(1) as f64).sqrt();
        (d.len(), rms)
    };
    let ((n_convex, convex), (n_concave, concave)) = (side(true), side(false));
    println!();
    println!(
        "{} bicycles: beta mean {mean:+.2}, SD {sd:.2}, range {lo:+.2} to {hi:+.2}; about \
         {BEND_SHAPE_MEAN}: {n_convex} more convex (RMS {convex:.2}), {n_concave} more concave \
         (RMS {concave:.2})",
        betas.len()
    );
    Ok(())
}
