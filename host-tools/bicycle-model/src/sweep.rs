//! Eigenvalues against speed, followed continuously from one speed to the
//! next ([`crate::track`]: eigenvalues only) and named by mode from their
//! participation over a reference sweep from 0 to 14 m/s followed with the
//! asked speeds ([`crate::naming`]: eigenvectors at a few speeds), so the
//! names do not depend on the speeds asked for.

use std::fmt;

use nalgebra::{Complex, DMatrix};

use crate::critical::{Brackets, CriticalSpeed};
use crate::eig::{eigenvalues_near, pencil_eigenvalues_near};
use crate::model::{Model, StateRole};
use crate::naming::{self, Speed, Stats};
use crate::track::{EigenvaluesAt, EigenvaluesFn, Tracker};

/// The name of a mode.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Mode {
    /// Steering oscillation at 6-9 Hz (extended model).
    Wobble,
    /// Low-frequency roll-and-steer oscillation.
    Weave,
    /// Slow falling over (real).
    Capsize,
    /// Fast steer alignment (real).
    Castering,
    /// Rider torso leaning on the hip.
    Lean,
    /// The bicycle swaying on its tyres: the main frame rolling and sliding
    /// sideways on the tyres' lateral compliance (their slip lags carry most
    /// of the mode), the upper body rolling against it on the hip.
    Sway,
    /// Steering-head twist.
    Twist,
    /// Anything else (tyre lags, ...).
    Other,
}

impl Mode {
    /// Lower-case name, as in the CSV interface.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Wobble => "wobble",
            Self::Weave => "weave",
            Self::Capsize => "capsize",
            Self::Castering => "castering",
            Self::Lean => "lean",
            Self::Sway => "sway",
            Self::Twist => "twist",
            Self::Other => "other",
        }
    }
}

impl fmt::Display for Mode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// One eigenvalue followed across speed.
#[derive(Clone, Debug, PartialEq)]
pub struct Branch {
    /// Its mode.
    pub mode: Mode,
    /// Its value at each speed of the sweep.
    pub values: Vec<Complex<f64>>,
}

/// Eigenvalues of a model at a list of speeds, as branches.
#[derive(Clone, Debug, PartialEq)]
pub struct Sweep {
    /// The speeds, m/s, increasing.
    pub speeds_mps: Vec<f64>,
    /// One branch per eigenvalue.
    pub branches: Vec<Branch>,
}

/// Why a sweep failed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum SweepError {
    /// No speeds were given.
    #[error("no speeds to evaluate")]
    NoSpeeds,
    /// The eigenvalue solver did not converge (non-finite matrix entries).
    #[error("the eigenvalues at {0} m/s could not be computed (non-finite state matrix)")]
    Eigen(f64),
}

/// Imaginary parts below this count as real, rad/s.
pub const REAL_TOL: f64 = 1e-7;

impl Sweep {
    /// Evaluates `model` at every speed (increasing), calling `progress`
    /// after each.
    pub fn run(
        model: &Model,
        speeds_mps: &[f64],
        progress: impl FnMut(usize),
    ) -> Result<Self, SweepError> {
        let roles = model.state_roles();
        Self::run_with(
            &matrix_of(model),
            &eigenvalues_of(model),
            &roles,
            speeds_mps,
            progress,
        )
    }

    /// [`Self::run`] on any state matrix function with states of `roles`
    /// (a model with a controller or other states added, say).
    ///
    /// # Errors
    /// As [`Self::run`].
    pub fn run_matrices(
        state_matrix: impl Fn(f64) -> DMatrix<f64>,
        roles: &[StateRole],
        speeds_mps: &[f64],
        progress: impl FnMut(usize),
    ) -> Result<Self, SweepError> {
        let eigen = |u: f64, guesses: &[Complex<f64>]| eigenvalues_near(&state_matrix(u), guesses);
        Self::run_with(&state_matrix, &eigen, roles, speeds_mps, progress)
    }

    /// [`Self::run_matrices`], the eigenvalues at each speed from `eigen`.
    fn run_with(
        state_matrix: &dyn Fn(f64) -> DMatrix<f64>,
        eigen: EigenvaluesAt,
        roles: &[StateRole],
        speeds_mps: &[f64],
        mut progress: impl FnMut(usize),
    ) -> Result<Self, SweepError> {
        let mut values: Vec<Vec<Complex<f64>>> = Vec::new();
        let mut stats = Stats::new(roles);
        each_speed(eigen, speeds_mps, |at, v| {
            if at.reference {
                stats.add(at.u, v, state_matrix);
            }
            let Some(k) = at.asked else { return };
            if values.is_empty() {
                values = v
                    .iter()
                    .map(|_| Vec::with_capacity(speeds_mps.len()))
                    .collect();
            }
            for (b, x) in values.iter_mut().zip(v) {
                b.push(*x);
            }
            progress(k);
        })?;
        Ok(Self {
            speeds_mps: speeds_mps.to_vec(),
            branches: stats
                .modes()
                .into_iter()
                .zip(values)
                .map(|(mode, values)| Branch { mode, values })
                .collect(),
        })
    }

    /// The branches of `mode`.
    pub fn of(&self, mode: Mode) -> impl Iterator<Item = &Branch> {
        self.branches.iter().filter(move |b| b.mode == mode)
    }

    /// The branch of `mode` with the non-negative imaginary part (of a
    /// pair) or the only one, if the model has that mode.
    #[must_use]
    pub fn upper(&self, mode: Mode) -> Option<&Branch> {
        self.of(mode).max_by(|a, b| {
            let sum = |br: &Branch| br.values.iter().map(|v| v.im).sum::<f64>();
            sum(a).total_cmp(&sum(b))
        })
    }
}

/// Tracks the eigenvalues `eigen` gives over `speeds_mps` (increasing)
/// and the reference sweep naming takes its names on ([`naming::speeds`]),
/// handing each speed's values (always in the same branch order) to `visit`.
fn each_speed(
    eigen: EigenvaluesAt,
    speeds_mps: &[f64],
    mut visit: impl FnMut(Speed, &[Complex<f64>]),
) -> Result<(), SweepError> {
    if speeds_mps.is_empty() {
        return Err(SweepError::NoSpeeds);
    }
    let mut tracker = Tracker::new(eigen);
    for at in naming::speeds(speeds_mps) {
        visit(at, tracker.step(at.u)?);
    }
    Ok(())
}

/// A sweep's modes and critical speeds, found without holding its values
/// (memory independent of the number of speeds); [`Survey::replay`] then
/// gives the values speed by speed. This is [`Sweep::run`] and
/// [`crate::critical_speeds`] for sweeps too long to hold: it evaluates
/// every speed twice.
#[derive(Clone, Debug)]
pub struct Survey {
    /// The mode of each branch, in the branch order of [`Survey::replay`].
    pub modes: Vec<Mode>,
    /// The critical speeds, as [`crate::critical_speeds`] gives them.
    pub critical: Vec<CriticalSpeed>,
}

impl Survey {
    /// Follows and names the eigenvalues of `model` over `speeds_mps`
    /// (increasing) and finds its critical speeds, calling `progress` after
    /// each speed.
    ///
    /// # Errors
    /// As [`Sweep::run`].
    pub fn run(
        model: &Model,
        speeds_mps: &[f64],
        mut progress: impl FnMut(usize),
    ) -> Result<Self, SweepError> {
        let roles = model.state_roles();
        let matrix = matrix_of(model);
        let mut stats = Stats::new(&roles);
        let mut brackets = Brackets::default();
        each_speed(&eigenvalues_of(model), speeds_mps, |at, v| {
            if at.reference {
                stats.add(at.u, v, &matrix);
            }
            if let Some(k) = at.asked {
                brackets.add(at.u, v);
                progress(k);
            }
        })?;
        let modes = stats.modes();
        let critical = brackets.refine(model, &modes);
        Ok(Self { modes, critical })
    }

    /// Follows the eigenvalues of `model` over `speeds_mps` again (the same
    /// model and speeds as [`Survey::run`]) and hands each speed's values to
    /// `visit`, branch `i` of mode `self.modes[i]`; stops at `visit`'s first
    /// error.
    ///
    /// # Errors
    /// `visit`'s error, or as [`Sweep::run`].
    pub fn replay<E: From<SweepError>>(
        &self,
        model: &Model,
        speeds_mps: &[f64],
        mut visit: impl FnMut(f64, &[Complex<f64>]) -> Result<(), E>,
    ) -> Result<(), E> {
        let mut failed = None;
        each_speed(&eigenvalues_of(model), speeds_mps, |at, v| {
            if failed.is_none() && at.asked.is_some() {
                failed = visit(at.u, v).err();
            }
        })?;
        failed.map_or(Ok(()), Err)
    }
}

/// `model`'s state matrix as a function of speed (from its pencil if affine).
pub(crate) fn matrix_of(model: &Model) -> Box<dyn Fn(f64) -> DMatrix<f64> + '_> {
    match model.pencil() {
        Some(pencil) => Box::new(move |u| pencil.at(u)),
        None => Box::new(|u| model.state_matrix(u)),
    }
}

/// `model`'s eigenvalues at a speed, given guesses (from its pencil
/// straight into the solver's storage if affine).
fn eigenvalues_of(model: &Model) -> Box<EigenvaluesFn<'_>> {
    match model.pencil() {
        Some(pencil) => Box::new(move |u, guesses| pencil_eigenvalues_near(&pencil, u, guesses)),
        None => Box::new(|u, guesses| eigenvalues_near(&model.state_matrix(u), guesses)),
    }
}

/// Grid step for following a mode up to given speeds, m/s.
const FOLLOW_STEP_MPS: f64 = 0.25;

/// The `mode` eigenvalue (upper member) of `model` at each of `speeds_mps`
/// (any order), followed along a grid from 0 m/s so that it is the same
/// branch at every speed; `None` if the model has no such mode.
pub fn mode_at(
    model: &Model,
    mode: Mode,
    speeds_mps: &[f64],
) -> Result<Option<Vec<Complex<f64>>>, SweepError> {
    let top = speeds_mps.iter().copied().fold(0.0, f64::max);
    let mut grid: Vec<f64> = (0..)
        .map(|i| f64::from(i) * FOLLOW_STEP_MPS)
        .take_while(|&u| u <= top + FOLLOW_STEP_MPS)
        .chain(speeds_mps.iter().copied())
        .collect();
    grid.sort_by(f64::total_cmp);
    grid.dedup();
    let sweep = Sweep::run(model, &grid, |_| {})?;
    Ok(sweep.upper(mode).map(|b| {
        speeds_mps
            .iter()
            .map(|u| {
                let k = grid.partition_point(|g| g < u);
                b.values[k.min(b.values.len() - 1)]
            })
            .collect()
    }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The names are the CSV interface's (`wobblog model eig`).
    #[test]
    fn mode_names_are_the_interface_names() {
        let all = [
            Mode::Wobble,
            Mode::Weave,
            Mode::Capsize,
            Mode::Castering,
            Mode::Lean,
            Mode::Sway,
            Mode::Twist,
            Mode::Other,
        ];
        let names: Vec<String> = all.iter().map(ToString::to_string).collect();
        assert_eq!(
            names,
            [
                "wobble",
                "weave",
                "capsize",
                "castering",
                "lean",
                "sway",
                "twist",
                "other"
            ]
        );
    }

    proptest! {
        /// Where nothing is in doubt no step is halved: real lines 30 1/s
        /// apart and a conjugate pair close to the real axis between them,
        /// all parallel (the pair's members within the moves of each other,
        /// a pair no doubt), cost one evaluation per speed (the asked 0-10
        /// m/s every `step` and the reference's beyond) and naming's 16
        /// samples; a line crossing the pair at 5 m/s costs more.
        #[test]
        fn steps_are_halved_only_where_in_doubt(step in 0.2..1.0f64, slope in -8.0..-1.0f64) {
            let n = (10.0 / step) as u32;
            let speeds: Vec<f64> = (0..=n).map(|i| f64::from(i) * step).collect();
            let merged = crate::naming::speeds(&speeds).count();
            let calls = |cross: bool| {
                let count = std::cell::Cell::new(0);
                let matrix = |u: f64| {
                    count.set(count.get() + 1);
                    let m = slope * u;
                    let last = if cross { 30.0 + m - 6.0 * u } else { 30.0 + m };
                    DMatrix::from_row_slice(4, 4, &[
                        m - 30.0, 0.0, 0.0, 0.0,
                        0.0, m, -0.05, 0.0,
                        0.0, 0.05, m, 0.0,
                        0.0, 0.0, 0.0, last,
                    ])
                };
                Sweep::run_matrices(matrix, &[StateRole::Rate; 4], &speeds, |_| {}).unwrap();
                count.get()
            };
            prop_assert_eq!(calls(false), merged + crate::naming::SAMPLES);
            prop_assert!(calls(true) > merged + crate::naming::SAMPLES);
        }

        /// Two real eigenvalues that meet without colliding, `m(u) +/-
        /// sqrt(s^2 (u - u0)^2 + c^2)` on a common drift `m(u) = k u` (as
        /// the lean's fast root meets the rear tyre's lag near `-u /
        /// sigma`), part on the sides they came from: on any grid the branch
        /// that starts above stays above, where a straight extrapolation
        /// across the turn carries each onto the other's path.
        #[test]
        fn roots_that_meet_without_colliding_keep_their_sides_on_any_grid(
            u0 in 1.0..8.0f64,
            slope in 1.0..8.0f64,
            half_gap in 0.2..1.0f64,
            drift in -6.0..0.0f64,
            step in 0.05..1.0f64,
        ) {
            let matrix = |u: f64| {
                let (d, m) = (slope * (u - u0), drift * u);
                DMatrix::from_row_slice(2, 2, &[m + d, half_gap, half_gap, m - d])
            };
            let n = (10.0 / step) as u32;
            let speeds: Vec<f64> = (0..=n).map(|i| f64::from(i) * step).collect();
            let sweep = Sweep::run_matrices(matrix, &[StateRole::Rate; 2], &speeds, |_| {}).unwrap();
            let (a, b) = (&sweep.branches[0].values, &sweep.branches[1].values);
            let upper = a[0].re > b[0].re;
            for (k, u) in speeds.iter().enumerate() {
                prop_assert_eq!(a[k].re > b[k].re, upper, "at {} m/s: {} and {}", u, a[k], b[k]);
            }
        }

        /// Eigenvalues moving on straight lines, crossing or not, are each
        /// followed on their own line: the extrapolation carries a branch
        /// through a crossing instead of swapping it with its neighbour.
        #[test]
        fn branches_follow_straight_lines_through_crossings(
            lines in proptest::collection::vec((-20.0..20.0f64, -5.0..5.0f64), 2..6),
        ) {
            // Lines that start apart (by more than a step moves them: the
            // first step has no slope to extrapolate) and never coincide.
            for (i, a) in lines.iter().enumerate() {
                for b in &lines[i + 1..] {
                    prop_assume!((a.1 - b.1).abs() > 0.5 && (a.0 - b.0).abs() > 1.5);
                }
            }
            let n = lines.len();
            let speeds: Vec<f64> = (0..=100).map(|i| f64::from(i) * 0.1).collect();
            let matrix = |u: f64| {
                DMatrix::from_diagonal(&nalgebra::DVector::from_iterator(n, lines.iter().map(|(a, b)| a + b * u)))
            };
            let sweep = Sweep::run_matrices(matrix, &vec![StateRole::Rate; n], &speeds, |_| {}).unwrap();
            for branch in &sweep.branches {
                let start = branch.values[0].re;
                let (a, b) = *lines.iter().min_by(|x, y| (x.0 - start).abs().total_cmp(&(y.0 - start).abs())).unwrap();
                for (u, v) in speeds.iter().zip(&branch.values) {
                    prop_assert!((v.re - (a + b * u)).abs() < 1e-9, "at {} m/s: {} not on {} + {} u", u, v, a, b);
                }
            }
        }
    }
}
