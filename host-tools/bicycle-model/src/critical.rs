//! Critical speeds: every sign change of a named mode's real part (weave
//! speed, capsize speed, wobble speed, ...), bracketed on a sweep's grid,
//! narrowed by following the branch through the bracket in small steps, and
//! refined by Brent's method (`roots` crate) on the real part of that branch.
//!
//! A real part within round-off of zero has no sign: the zero roots of a
//! model at standstill (tyre lags, `v` and `r` at u = 0) never make a
//! critical speed.

use nalgebra::{Complex, DMatrix};
use roots::{find_root_brent, SimpleConvergency};
use serde::Serialize;

use crate::eig::eigenvalues;
use crate::model::Model;
use crate::sweep::{matrix_of, Mode, Sweep, REAL_TOL};

/// A state matrix as a function of speed.
type StateMatrix<'a> = dyn Fn(f64) -> DMatrix<f64> + 'a;

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

/// The eigenvalue of `matrix(u)` nearest `guess`.
fn nearest(matrix: &StateMatrix, u: f64, guess: Complex<f64>) -> Complex<f64> {
    eigenvalues(&matrix(u))
        .unwrap_or_default()
        .into_iter()
        .min_by(|x, y| (x - guess).norm().total_cmp(&(y - guess).norm()))
        .unwrap_or(guess)
}

/// Follows the branch from `(ua, a)` to `(ub, b)` in small steps and returns
/// the first step over which its real part changes sign, with the values at
/// the step's ends.
fn narrow(
    matrix: &StateMatrix,
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
            nearest(matrix, u, guess)
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

/// A sign change of one branch's real part between two speeds of a grid.
#[derive(Clone, Copy, Debug)]
struct Bracket {
    branch: usize,
    below: (f64, Complex<f64>),
    above: (f64, Complex<f64>),
}

/// The sign changes of every branch, gathered one speed at a time (so that
/// a sweep need not be held whole).
#[derive(Clone, Debug, Default)]
pub(crate) struct Brackets {
    /// Per branch, the last speed with a signed real part and the value there.
    last: Vec<Option<(f64, Complex<f64>)>>,
    found: Vec<Bracket>,
}

impl Brackets {
    /// Adds the branches' `values` at the next speed `u`.
    pub(crate) fn add(&mut self, u: f64, values: &[Complex<f64>]) {
        if self.last.is_empty() {
            self.last = vec![None; values.len()];
        }
        for (branch, (&v, last)) in values.iter().zip(self.last.iter_mut()).enumerate() {
            if sign(v) == 0 {
                continue;
            }
            let Some((uj, vj)) = last.replace((u, v)) else {
                continue;
            };
            // The lower member of a pair repeats its partner's crossing.
            if sign(vj) == sign(v) || (vj.im < -REAL_TOL && v.im < -REAL_TOL) {
                continue;
            }
            self.found.push(Bracket {
                branch,
                below: (uj, vj),
                above: (u, v),
            });
        }
    }

    /// Each bracketed sign change of a named branch (`modes[branch]`),
    /// refined, in speed order.
    pub(crate) fn refine(&self, model: &Model, modes: &[Mode]) -> Vec<CriticalSpeed> {
        let matrix = matrix_of(model);
        let mut out: Vec<CriticalSpeed> = self
            .found
            .iter()
            .filter(|b| modes.get(b.branch).is_some_and(|&m| m != Mode::Other))
            .filter_map(|b| refine(&*matrix, modes[b.branch], b))
            .collect();
        out.sort_by(|a, b| a.speed_mps.total_cmp(&b.speed_mps));
        out
    }
}

/// The bracketed sign change, narrowed and refined by Brent's method.
fn refine(matrix: &StateMatrix, mode: Mode, bracket: &Bracket) -> Option<CriticalSpeed> {
    let ((ua, a), (ub, b)) = narrow(matrix, bracket.below, bracket.above);
    let at = |u: f64| nearest(matrix, u, a + (b - a) * ((u - ua) / (ub - ua)));
    let mut conv = SimpleConvergency {
        eps: SPEED_TOL_MPS,
        max_iter: 200,
    };
    let u = find_root_brent(ua, ub, |u| at(u).re, &mut conv).ok()?;
    let im = at(u).im.abs();
    Some(CriticalSpeed {
        mode,
        speed_mps: u,
        unstable_above: b.re > 0.0,
        im_rad_per_s: if im > REAL_TOL { im } else { 0.0 },
    })
}

/// Every sign change of the real part of a named mode within the sweep.
#[must_use]
pub fn critical_speeds(model: &Model, sweep: &Sweep) -> Vec<CriticalSpeed> {
    let mut brackets = Brackets::default();
    let mut values = Vec::with_capacity(sweep.branches.len());
    for (k, &u) in sweep.speeds_mps.iter().enumerate() {
        values.clear();
        values.extend(sweep.branches.iter().map(|b| b.values[k]));
        brackets.add(u, &values);
    }
    let modes: Vec<Mode> = sweep.branches.iter().map(|b| b.mode).collect();
    brackets.refine(model, &modes)
}
