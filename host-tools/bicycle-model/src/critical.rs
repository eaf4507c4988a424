//! Critical speeds: every sign change of a named mode's real part (weave
//! speed, capsize speed, wobble speed, ...), bracketed on a sweep's grid,
//! narrowed by following the branch through the bracket in small steps, and
//! refined by Brent's method (`roots` crate) on the real part of that branch.
//!
//! A real part within round-off of zero has no sign: the zero roots of a
//! model at standstill (tyre lags, `v` and `r` at u = 0) never make a
//! critical speed.

use nalgebra::Complex;
use roots::{find_root_brent, SimpleConvergency};
use serde::Serialize;

use crate::eig::eigenvalues;
use crate::model::Model;
use crate::sweep::{Mode, Sweep, REAL_TOL};

/// One zero crossing of a mode's real part.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct CriticalSpeed {
    /// The mode.
    #[serde(serialize_with = "mode_name")]
    pub mode: Mode,
    /// Where its real part is zero, m/s.
    pub speed_mps: f64,
    /// True if the mode is unstable above this speed (and stable below).
    pub unstable_above: bool,
    /// Its imaginary part there, rad/s (0 for a real root crossing zero).
    pub im_rad_per_s: f64,
}

impl CriticalSpeed {
    /// `oscillatory` (a pair crossing the imaginary axis, a Hopf point) or
    /// `real` (a real root through zero, a divergence).
    #[must_use]
    pub fn kind(&self) -> &'static str {
        if self.im_rad_per_s > REAL_TOL {
            "oscillatory"
        } else {
            "real"
        }
    }
}

fn mode_name<S: serde::Serializer>(m: &Mode, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(m.name())
}

/// Brent's tolerance on speed, m/s.
const SPEED_TOL_MPS: f64 = 1e-13;
/// Steps a bracket is followed in before Brent's method.
const BRACKET_STEPS: usize = 16;

/// The sign of a real part, `0` within round-off of zero.
fn sign(v: Complex<f64>) -> i8 {
    if v.re.abs() <= 1e-10 * v.norm().max(1.0) {
        0
    } else if v.re > 0.0 {
        1
    } else {
        -1
    }
}

/// The eigenvalue of `model` at `u` nearest `guess`.
fn nearest(model: &Model, u: f64, guess: Complex<f64>) -> Complex<f64> {
    eigenvalues(&model.state_matrix(u))
        .unwrap_or_default()
        .into_iter()
        .min_by(|x, y| (x - guess).norm().total_cmp(&(y - guess).norm()))
        .unwrap_or(guess)
}

/// Follows the branch from `(ua, a)` to `(ub, b)` in small steps and returns
/// the first step over which its real part changes sign, with the values at
/// the step's ends.
fn narrow(
    model: &Model,
    (ua, a): (f64, Complex<f64>),
    (ub, b): (f64, Complex<f64>),
) -> ((f64, Complex<f64>), (f64, Complex<f64>)) {
    let h = (ub - ua) / BRACKET_STEPS as f64;
    let (mut prev, mut last) = ((ua, a), (ua, a));
    for i in 1..=BRACKET_STEPS {
        let u = if i == BRACKET_STEPS {
            ub
        } else {
            ua + h * i as f64
        };
        let guess = if last.0 > prev.0 {
            last.1 + (last.1 - prev.1) * ((u - last.0) / (last.0 - prev.0))
        } else {
            last.1
        };
        let v = if i == BRACKET_STEPS {
            b
        } else {
            nearest(model, u, guess)
        };
        if sign(v) != 0 && sign(v) != sign(last.1) && sign(last.1) != 0 {
            return (last, (u, v));
        }
        prev = last;
        if sign(v) != 0 {
            last = (u, v);
        }
    }
    ((ua, a), (ub, b))
}

/// Every sign change of the real part of a named mode within the sweep.
#[must_use]
pub fn critical_speeds(model: &Model, sweep: &Sweep) -> Vec<CriticalSpeed> {
    let mut out = Vec::new();
    for branch in &sweep.branches {
        if branch.mode == Mode::Other {
            continue;
        }
        let v = &branch.values;
        // The last speed with a signed real part.
        let mut last: Option<usize> = None;
        for k in 0..v.len() {
            if sign(v[k]) == 0 {
                continue;
            }
            let Some(j) = last.replace(k) else { continue };
            if sign(v[j]) == sign(v[k]) {
                continue;
            }
            // The lower member of a pair repeats its partner's crossing.
            if v[j].im < -REAL_TOL && v[k].im < -REAL_TOL {
                continue;
            }
            let ((ua, a), (ub, b)) = narrow(
                model,
                (sweep.speeds_mps[j], v[j]),
                (sweep.speeds_mps[k], v[k]),
            );
            let at = |u: f64| nearest(model, u, a + (b - a) * ((u - ua) / (ub - ua)));
            let mut conv = SimpleConvergency {
                eps: SPEED_TOL_MPS,
                max_iter: 200,
            };
            if let Ok(u) = find_root_brent(ua, ub, |u| at(u).re, &mut conv) {
                let im = at(u).im.abs();
                out.push(CriticalSpeed {
                    mode: branch.mode,
                    speed_mps: u,
                    unstable_above: b.re > 0.0,
                    im_rad_per_s: if im > REAL_TOL { im } else { 0.0 },
                });
            }
        }
    }
    out.sort_by(|a, b| a.speed_mps.total_cmp(&b.speed_mps));
    out
}
