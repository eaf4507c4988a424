//! What the rider takes from the prediction: a riding limit, the highest
//! speed for the next pass, and whether sigma rises towards the slowest
//! kicks.

use serde::Serialize;

use super::fit::weighted_poly;
use super::{Margin, MIN_SPAN_MPS};

/// The default riding margin, a fraction of the lower bound: on the stress
/// campaigns (`host-tools/docs/kick-testing.md`, "Stress campaigns") the
/// lower bound lay more than 5 % above the truth in 1.2 % of the
/// campaigns and more than 10 % in 0.4 % (1.9 % of the convex class, a
/// shape beyond the prior's mean), so a limit 10 % below the lower bound
/// stays below the wobble speed in 99.7 % of them (98.7 % of the convex
/// class).
pub const RIDE_MARGIN: f64 = 0.10;

/// The riding limit and the next pass.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Advice {
    /// Ride below this, m/s: the interval's lower bound less the riding
    /// margin (none without a lower bound).
    pub ride_below_mps: Option<f64>,
    /// The highest speed for the next pass, m/s: the riding limit, and no
    /// more than one measured range (at least [`MIN_SPAN_MPS`]) beyond the
    /// fastest kick, so that the next prediction extrapolates no further
    /// than this one trusts.
    pub next_pass_max_mps: Option<f64>,
    /// The riding margin, a fraction of the lower bound.
    pub margin_fraction: f64,
}

/// The advice from `m` with a riding margin of `fraction` of the lower
/// bound (non-finite or negative: the default; at most 0.9).
#[must_use]
pub fn advise(m: &Margin, fraction: f64) -> Advice {
    let fraction = if fraction.is_finite() && fraction >= 0.0 {
        fraction.min(0.9)
    } else {
        RIDE_MARGIN
    };
    let ride_below_mps = m.ci95_mps[0].map(|lo| lo * (1.0 - fraction));
    let next_pass_max_mps = match (ride_below_mps, m.speed_range_mps) {
        (Some(limit), Some([lo, hi])) => Some(limit.min(hi + (hi - lo).max(MIN_SPAN_MPS))),
        _ => None,
    };
    Advice {
        ride_below_mps,
        next_pass_max_mps,
        margin_fraction: fraction,
    }
}

/// A warning when sigma rises towards lower speeds among the slowest half
/// of the kicks kept (at least three): the slope of their weighted line
/// below zero by more than its standard error. A mode whose damping
/// weakens as the speed falls may turn unstable below the kicks (a
/// low-speed wobble), which no extrapolation upwards can see.
#[must_use]
pub fn low_speed_rise(u: &[f64], y: &[f64], weights: &[f64]) -> Option<String> {
    let mut kept: Vec<usize> = (0..u.len()).filter(|&i| weights[i] > 0.0).collect();
    kept.sort_by(|&a, &b| u[a].total_cmp(&u[b]));
    kept.truncate(kept.len().div_ceil(2));
    if kept.len() < 3 {
        return None;
    }
    let pick = |v: &[f64]| kept.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let (coef, inv) = weighted_poly(&pick(u), &pick(y), &pick(weights), 2)?;
    let (b, se) = (coef[1], inv[(1, 1)].max(0.0).sqrt());
    (b + se < 0.0).then(|| {
        format!(
            "sigma rises towards lower speeds among the slowest kicks ({b:.3} +/- {se:.3} 1/s \
             per m/s): a low-speed wobble may exist below {:.2} m/s",
            u[kept[0]]
        )
    })
}
