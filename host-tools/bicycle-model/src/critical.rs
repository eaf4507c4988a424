//! Critical speeds: every sign change of a named mode's real part (weave
//! speed, capsize speed, wobble speed, ...), bracketed on a sweep's grid and
//! refined by Newton's method on the real part of that branch ([`newton`]:
//! one eigenvalue and its derivative per step, no full solution), then
//! checked by one full eigenvalue solution to be the same branch. Where
//! Newton's method fails or the check is in doubt, the branch is followed
//! through the bracket in small steps and refined by Brent's method
//! (`roots` crate) instead.
//!
//! A real part within round-off of zero has no sign: the zero roots of a
//! model at standstill (tyre lags, `v` and `r` at u = 0) never make a
//! critical speed.

mod newton;

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

/// Tolerance on a critical speed, m/s: Brent's, and Newton's last step.
const SPEED_TOL_MPS: f64 = 1e-13;
/// Steps a bracket is followed in before Brent's method.
const BRACKET_STEPS: usize = 16;

/// The sign of a real part, `0` within round-off of zero.
fn sign(v: Complex<f64>) -> i8 {
    let re = v.re.abs();
    // `|v| <= |re| + |im|`: a real part above the bound's share is signed
    // without the square root, which every value of a sweep would cost.
    if re <= 1e-10 * (re + v.im.abs()).max(1.0) && re <= 1e-10 * v.norm().max(1.0) {
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

/// The bracketed sign change, refined: the crossing's speed and eigenvalue.
fn refine(matrix: &StateMatrix, mode: Mode, bracket: &Bracket) -> Option<CriticalSpeed> {
    let (u, value) = by_newton(matrix, bracket).or_else(|| by_brent(matrix, bracket))?;
    let im = value.im.abs();
    Some(CriticalSpeed {
        mode,
        speed_mps: u,
        unstable_above: bracket.above.1.re > 0.0,
        im_rad_per_s: if im > REAL_TOL { im } else { 0.0 },
    })
}

/// Relative step of the central difference for `dA/du`: exact but for
/// round-off (about 1e-12 relative) where `A(u)` is at most quadratic in
/// the speed (the affine pencil, the Whipple model).
const SLOPE_STEP: f64 = 1e-4;

/// The crossing by Newton's method from the bracket's straight line, kept
/// only if one full eigenvalue solution there finds Newton's eigenvalue and
/// finds it the one the line points to without doubt: every other
/// eigenvalue at least twice as far from the line's value (as
/// [`crate::track`] decides a step).
fn by_newton(matrix: &StateMatrix, bracket: &Bracket) -> Option<(f64, Complex<f64>)> {
    let ((ua, a), (ub, b)) = (bracket.below, bracket.above);
    let line = |u: f64| a + (b - a) * ((u - ua) / (ub - ua));
    let start = ua + (ub - ua) * (a.re / (a.re - b.re));
    let slope = |u: f64| {
        let h = SLOPE_STEP * u.abs().max(1.0);
        (matrix(u + h) - matrix(u - h)) / (2.0 * h)
    };
    let (u, value) = newton::crossing(matrix, &slope, (ua, ub), (start, line(start)))?;
    let mut values = eigenvalues(&matrix(u))?;
    let on_line = line(u);
    values.sort_by(|x, y| (x - on_line).norm().total_cmp(&(y - on_line).norm()));
    let (nearest, next) = (*values.first()?, values.get(1).copied());
    let same = (nearest - value).norm() <= 1e-6 * nearest.norm().max(1.0);
    let clear = next.is_none_or(|n| (n - on_line).norm() >= 2.0 * (nearest - on_line).norm());
    (same && clear).then_some((u, nearest))
}

/// The crossing by following the branch through the bracket in small steps
/// and Brent's method on the step where its real part changes sign.
fn by_brent(matrix: &StateMatrix, bracket: &Bracket) -> Option<(f64, Complex<f64>)> {
    let ((ua, a), (ub, b)) = narrow(matrix, bracket.below, bracket.above);
    let at = |u: f64| nearest(matrix, u, a + (b - a) * ((u - ua) / (ub - ua)));
    let mut conv = SimpleConvergency {
        eps: SPEED_TOL_MPS,
        max_iter: 200,
    };
    let u = find_root_brent(ua, ub, |u| at(u).re, &mut conv).ok()?;
    Some((u, at(u)))
}

/// Every sign change of the real part of a named mode within the sweep.
#[must_use]
pub fn critical_speeds(model: &Model, sweep: &Sweep) -> Vec<CriticalSpeed> {
    let modes: Vec<Mode> = sweep.branches.iter().map(|b| b.mode).collect();
    brackets_of(sweep).refine(model, &modes)
}

/// The sign changes of every branch of `sweep`.
fn brackets_of(sweep: &Sweep) -> Brackets {
    let mut brackets = Brackets::default();
    let mut values = Vec::with_capacity(sweep.branches.len());
    for (k, &u) in sweep.speeds_mps.iter().enumerate() {
        values.clear();
        values.extend(sweep.branches.iter().map(|b| b.values[k]));
        brackets.add(u, &values);
    }
    brackets
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use nalgebra::DVector;
    use proptest::prelude::*;

    use super::*;
    use crate::model::StateRole;
    use crate::params::ParamSet;

    /// The companion matrix of `l^3 + c2 l^2 + c1 l + c0`.
    fn companion(c2: f64, c1: f64, c0: f64) -> DMatrix<f64> {
        DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -c0, -c1, -c2])
    }

    fn brackets(matrix: &StateMatrix, speeds: &[f64]) -> Vec<Bracket> {
        let n = matrix(0.0).nrows();
        let sweep = Sweep::run_matrices(matrix, &vec![StateRole::Rate; n], speeds, |_| {}).unwrap();
        brackets_of(&sweep).found
    }

    proptest! {
        /// `l^3 + c u l^2 + c1 l + c0` has its Hopf point where the Hurwitz
        /// determinant `c u c1 - c0` is zero, at `u = c0 / (c c1)`, with
        /// roots `+-i sqrt(c1)` (and `-c u`): Newton's method finds it on
        /// any grid of 6 or more speeds, to round-off.
        #[test]
        fn newton_puts_a_cubics_hopf_point_where_hurwitz_does(
            c in 0.5..2.0f64, c1 in 0.5..4.0f64, c0 in 0.5..4.0f64,
            speeds in 6..400usize, offset in 0.0..1.0f64,
        ) {
            let hopf = c0 / (c * c1);
            let step = 2.0 * hopf / speeds as f64;
            let grid: Vec<f64> = (0..=speeds).map(|i| (i as f64 + offset) * step).collect();
            let matrix = |u: f64| companion(c * u, c1, c0);
            let found = brackets(&matrix, &grid);
            prop_assert_eq!(found.len(), 1, "{:?}", found);
            let (u, value) = by_newton(&matrix, &found[0]).expect("refined by Newton's method");
            prop_assert!((u - hopf).abs() < 1e-12 * hopf.max(1.0), "{} against {}", u, hopf);
            prop_assert!((value - Complex::new(0.0, c1.sqrt())).norm() < 1e-10, "{}", value);
            let critical = refine(&matrix, Mode::Weave, &found[0]).unwrap();
            prop_assert!(!critical.unstable_above);
            prop_assert_eq!(critical.kind(), "oscillatory");
        }
    }

    /// A real part has no sign within 1e-10 of the eigenvalue's size (or of
    /// 1, for an eigenvalue smaller than 1), by hand at and around the bound.
    #[test]
    fn a_real_part_within_round_off_of_zero_has_no_sign() {
        for (re, im, want) in [
            (0.0, 0.0, 0),
            (1e-12, 0.0, 0),
            (-1e-12, 0.0, 0),
            (-2e-10, 0.0, -1),
            (0.5, 0.0, 1),
            (1e-11, 50.0, 0),
            (-3e-9, 40.0, 0),
            (5e-9, 40.0, 1),
            (-5e-9, 40.0, -1),
        ] {
            assert_eq!(sign(Complex::new(re, im)), want, "{re} + {im} i");
        }
    }

    /// Two real roots through zero, `u^2 - 1` and `u^2 - 0.98`, on a grid
    /// too coarse for a straight line between them: at the first one's
    /// crossing the line points at the second, so Newton's result is
    /// rejected and the branch is followed through the bracket instead.
    #[test]
    fn a_crossing_the_line_does_not_point_to_is_followed_through_the_bracket() {
        let matrix =
            |u: f64| DMatrix::from_diagonal(&DVector::from_vec(vec![u * u - 1.0, u * u - 0.98]));
        let found = brackets(&matrix, &[0.5, 1.5]);
        let first = found.iter().find(|b| b.below.1.re == -0.75).unwrap();
        assert_eq!(by_newton(&matrix, first), None);
        let critical = refine(&matrix, Mode::Capsize, first).unwrap();
        assert!((critical.speed_mps - 1.0).abs() < 1e-13, "{critical:?}");
        assert!(critical.unstable_above);
        assert_eq!(critical.kind(), "real");
    }

    /// The benchmark bicycle's weave and capsize speeds (Meijaard et al.
    /// 2007; 14 digits from independent implementations, as in
    /// `tests/whipple_benchmark.rs`) by Newton's method from brackets as
    /// wide as 0.5 and 2 m/s, to 1e-10 m/s.
    #[test]
    fn the_benchmarks_critical_speeds_by_newton_on_coarse_grids() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/benchmark.toml");
        let model = Model::from_set(&ParamSet::load(&path).unwrap()).unwrap();
        let matrix = matrix_of(&model);
        for step in [0.5, 2.0] {
            let speeds: Vec<f64> = (0..=(10.0 / step) as usize)
                .map(|i| i as f64 * step)
                .collect();
            let sweep = Sweep::run(&model, &speeds, |_| {}).unwrap();
            let mut found: Vec<f64> = brackets_of(&sweep)
                .found
                .iter()
                .filter(|b| [Mode::Weave, Mode::Capsize].contains(&sweep.branches[b.branch].mode))
                .map(|b| {
                    by_newton(&*matrix, b)
                        .expect("refined by Newton's method")
                        .0
                })
                .collect();
            found.sort_by(f64::total_cmp);
            assert_eq!(found.len(), 2, "step {step}: {found:?}");
            assert!(
                (found[0] - 4.29238253634111).abs() < 1e-10,
                "step {step}: {found:?}"
            );
            assert!(
                (found[1] - 6.02426201538837).abs() < 1e-10,
                "step {step}: {found:?}"
            );
        }
    }

    /// Roots `u - 1` and `u - 0.95`, the first one's bracket [0.5, 1.5] with
    /// a line lifted off the real axis by `lift`: Newton's method finds the
    /// crossing at 1 m/s either way, and the check keeps it only if the
    /// other root (0.05 from it) is at least twice as far from the line's
    /// value there as the crossing is.
    #[test]
    fn newtons_crossing_is_kept_only_if_the_line_points_at_it_without_doubt() {
        let matrix = |u: f64| DMatrix::from_diagonal(&DVector::from_vec(vec![u - 1.0, u - 0.95]));
        let bracket = |lift: f64| Bracket {
            branch: 0,
            below: (0.5, Complex::new(-0.5, lift)),
            above: (1.5, Complex::new(0.5, lift)),
        };
        // 0.01 from the crossing, 0.051 from the other root: clear.
        let (u, value) = by_newton(&matrix, &bracket(0.01)).expect("clear");
        assert!(
            (u - 1.0).abs() < 1e-13 && value.norm() < 1e-13,
            "{u} {value}"
        );
        // 0.04 from the crossing, 0.064 from the other root: in doubt.
        assert_eq!(by_newton(&matrix, &bracket(0.04)), None);
    }

    /// Two oscillations `(u - 1) ± 5i` and `(u - 0.85) ± 5i` and a decay at
    /// -0.5 1/s, the first one's bracket [0.2, 1.3] (uneven about its
    /// crossing at 1 m/s): the bracket's straight line is the branch
    /// itself, so it points at the crossing's `5i` without doubt; the other
    /// oscillation is 0.15 from it, the conjugate 10 away, the decay (the
    /// smallest value) 5.02. A line drawn wrong (from the other end, scaled,
    /// or not divided by the bracket's width, 1.1 m/s) points nearer the
    /// other oscillation, and a sort by anything but the distance from the
    /// line's value finds another root.
    #[test]
    fn the_bracket_line_points_at_the_crossing_beside_a_near_oscillation() {
        let pair = |re: f64| DMatrix::from_row_slice(2, 2, &[re, -5.0, 5.0, re]);
        let matrix = |u: f64| {
            let mut m = DMatrix::zeros(5, 5);
            m.view_mut((0, 0), (2, 2)).copy_from(&pair(u - 1.0));
            m.view_mut((2, 2), (2, 2)).copy_from(&pair(u - 0.85));
            m[(4, 4)] = -0.5;
            m
        };
        let bracket = Bracket {
            branch: 0,
            below: (0.2, Complex::new(-0.8, 5.0)),
            above: (1.3, Complex::new(0.3, 5.0)),
        };
        let (u, value) = by_newton(&matrix, &bracket).expect("kept");
        assert!((u - 1.0).abs() < 1e-12, "{u}");
        assert!((value - Complex::new(0.0, 5.0)).norm() < 1e-12, "{value}");
    }

    /// On the test bicycle's 1000-speed sweep every crossing is refined by
    /// Newton's method, to the speed the branch followed in small steps and
    /// Brent's method give, in at most 4 steps (each evaluates `A(u)` three
    /// times, for itself and the central difference; the check once more).
    #[test]
    fn the_test_bicycles_crossings_take_newtons_method() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/test-bicycle.toml");
        let model = Model::from_set(&ParamSet::load(&path).unwrap()).unwrap();
        let speeds: Vec<f64> = (0..1000).map(|i| f64::from(i) * 0.01).collect();
        let sweep = Sweep::run(&model, &speeds, |_| {}).unwrap();
        let matrix = matrix_of(&model);
        let named: Vec<Bracket> = brackets_of(&sweep)
            .found
            .into_iter()
            .filter(|b| sweep.branches[b.branch].mode != Mode::Other)
            .collect();
        assert!(named.len() >= 2, "{named:?}");
        for b in &named {
            let evaluations = std::cell::Cell::new(0);
            let counted = |u: f64| {
                evaluations.set(evaluations.get() + 1);
                matrix(u)
            };
            let (u, value) = by_newton(&counted, b).expect("refined by Newton's method");
            assert!(
                evaluations.get() <= 4 * 3 + 1,
                "{} evaluations",
                evaluations.get()
            );
            let (ub, vb) = by_brent(&*matrix, b).unwrap();
            assert!((u - ub).abs() < 1e-11, "{u} against Brent's {ub}");
            assert!((value - vb).norm() < 1e-9, "{value} against Brent's {vb}");
        }
    }
}
