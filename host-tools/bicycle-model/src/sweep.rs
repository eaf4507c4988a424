//! Eigenvalues against speed, followed continuously from one speed to the
//! next and named by mode.
//!
//! Tracking: each eigenvalue at a new speed is matched to the branch whose
//! linear extrapolation from the two previous speeds lies nearest (pairs
//! assigned greedily in order of distance, which is exact when the step is
//! small against the gaps between eigenvalues).
//!
//! Naming, per branch, from its eigenvector at the middle of the speeds
//! where it oscillates (or of all speeds, for a real branch): the angle
//! (roll, steer, torso, twist, tyre) with the largest share decides.
//! Oscillating roll/steer branches are the weave (the lowest frequency) and
//! the wobble (the next); real ones are capsize (roll, the slowest) and
//! castering (steer, the fastest decay). Torso branches are `lean`, twist
//! branches `twist`, tyre lags and the rest `other`.

use std::fmt;

use nalgebra::{Complex, DMatrix};

use crate::eig::{eigen, Eigen};
use crate::model::{Model, StateRole};

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
        Self::run_matrices(
            |u| model.state_matrix(u),
            &model.state_roles(),
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
        mut progress: impl FnMut(usize),
    ) -> Result<Self, SweepError> {
        if speeds_mps.is_empty() {
            return Err(SweepError::NoSpeeds);
        }
        let mut tracks: Vec<Vec<Eigen>> = Vec::new();
        for (k, &u) in speeds_mps.iter().enumerate() {
            let found = eigen(&state_matrix(u)).ok_or(SweepError::Eigen(u))?;
            if tracks.is_empty() {
                tracks = found.into_iter().map(|e| vec![e]).collect();
            } else {
                assign(&mut tracks, found, k);
            }
            progress(k);
        }
        let branches = name_branches(&tracks, roles);
        Ok(Self {
            speeds_mps: speeds_mps.to_vec(),
            branches,
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

/// Extends every track with the eigenvalue of `found` nearest its
/// prediction.
fn assign(tracks: &mut [Vec<Eigen>], found: Vec<Eigen>, k: usize) {
    let predicted: Vec<Complex<f64>> = tracks
        .iter()
        .map(|t| {
            let last = t[k - 1].value;
            if k >= 2 {
                last * 2.0 - t[k - 2].value
            } else {
                last
            }
        })
        .collect();
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(tracks.len() * found.len());
    for (i, p) in predicted.iter().enumerate() {
        for (j, f) in found.iter().enumerate() {
            pairs.push(((f.value - p).norm(), i, j));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut slot: Vec<Option<Eigen>> = found.into_iter().map(Some).collect();
    let mut done = vec![false; tracks.len()];
    for (_, i, j) in pairs {
        if done[i] {
            continue;
        }
        if let Some(e) = slot[j].take() {
            tracks[i].push(e);
            done[i] = true;
        }
    }
}

/// What an eigenvector says about its mode: the largest of the mechanical
/// angles (roll, steer, torso, twist), the roll-to-steer ratio, and whether
/// the tyre lags dominate everything.
#[derive(Clone, Copy)]
struct Shape {
    role: StateRole,
    roll_over_steer: f64,
    tyre_only: bool,
}

/// A mode whose tyre lags are this many times its largest angle is a tyre mode.
const TYRE_DOMINANCE: f64 = 4.0;
/// Weave rolls: at least this much roll per steer.
const WEAVE_MIN_ROLL_PER_STEER: f64 = 0.2;
/// Wobble is faster than this, rad/s (2 Hz; the weave stays below it in
/// the speed range of interest).
const WOBBLE_MIN_RAD_S: f64 = 4.0 * std::f64::consts::PI;

fn shape(e: &Eigen, roles: &[StateRole]) -> Shape {
    let size = |want: StateRole| {
        roles
            .iter()
            .zip(e.vector.iter())
            .filter(|(r, _)| **r == want)
            .map(|(_, c)| c.norm())
            .fold(0.0, f64::max)
    };
    let mech = [
        StateRole::Roll,
        StateRole::Steer,
        StateRole::Torso,
        StateRole::Twist,
    ]
    .map(|r| (r, size(r)));
    let (role, largest) = mech
        .iter()
        .copied()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((StateRole::Rate, 0.0));
    let steer = size(StateRole::Steer);
    Shape {
        role,
        roll_over_steer: if steer > 0.0 {
            size(StateRole::Roll) / steer
        } else {
            f64::INFINITY
        },
        tyre_only: size(StateRole::Tyre) > TYRE_DOMINANCE * largest,
    }
}

fn name_branches(tracks: &[Vec<Eigen>], roles: &[StateRole]) -> Vec<Branch> {
    struct Seen {
        shape: Shape,
        oscillates: bool,
        freq: f64,
        re_at: f64,
        mean_re: f64,
    }
    let seen: Vec<Seen> = tracks
        .iter()
        .map(|t| {
            let complex: Vec<usize> = (0..t.len())
                .filter(|&k| t[k].value.im.abs() > REAL_TOL)
                .collect();
            let at = complex
                .get(complex.len() / 2)
                .copied()
                .unwrap_or(t.len() / 2);
            Seen {
                shape: shape(&t[at], roles),
                oscillates: !complex.is_empty(),
                freq: t[at].value.im.abs(),
                re_at: t[at].value.re,
                mean_re: t.iter().map(|e| e.value.re).sum::<f64>() / t.len() as f64,
            }
        })
        .collect();
    let planar =
        |s: &Seen| !s.shape.tyre_only && matches!(s.shape.role, StateRole::Roll | StateRole::Steer);
    let weave_like =
        |s: &Seen| planar(s) && s.oscillates && s.shape.roll_over_steer >= WEAVE_MIN_ROLL_PER_STEER;
    let wobble_like = |s: &Seen| {
        planar(s) && s.oscillates && s.shape.role == StateRole::Steer && s.freq >= WOBBLE_MIN_RAD_S
    };
    // The lowest frequency of each kind; both members of a pair share it.
    let lowest = |keep: &dyn Fn(&Seen) -> bool| {
        seen.iter()
            .filter(|s| keep(s))
            .map(|s| s.freq)
            .min_by(f64::total_cmp)
    };
    let weave_freq = lowest(&weave_like);
    let wobble_freq = lowest(&|s: &Seen| wobble_like(s) && Some(s.freq) != weave_freq);
    // The two members of an oscillating pair.
    let partners = |a: &Seen, b: &Seen| {
        a.oscillates
            && (a.freq - b.freq).abs() <= 1e-9 * a.freq.max(1.0)
            && (a.re_at - b.re_at).abs() <= 1e-9 * a.re_at.abs().max(1.0)
    };
    let same =
        |s: &Seen, f: Option<f64>| f.is_some_and(|f| (s.freq - f).abs() <= 1e-9 * f.max(1.0));
    let capsize = pick(
        &seen,
        |s| planar(s) && !s.oscillates && s.shape.role == StateRole::Roll,
        |s| -s.mean_re.abs(),
    );
    let castering = pick(
        &seen,
        |s| {
            planar(s)
                && s.shape.role == StateRole::Steer
                && s.freq < WOBBLE_MIN_RAD_S
                && !weave_like(s)
        },
        |s| -s.mean_re,
    );
    seen.iter()
        .zip(tracks)
        .enumerate()
        .map(|(i, (s, t))| {
            let mode = match s.shape.role {
                _ if s.shape.tyre_only => Mode::Other,
                StateRole::Torso => Mode::Lean,
                StateRole::Twist => Mode::Twist,
                _ if weave_like(s) && same(s, weave_freq) => Mode::Weave,
                _ if wobble_like(s) && same(s, wobble_freq) => Mode::Wobble,
                _ if Some(i) == capsize => Mode::Capsize,
                _ if castering.is_some_and(|c| i == c || partners(&seen[c], s)) => Mode::Castering,
                _ => Mode::Other,
            };
            Branch {
                mode,
                values: t.iter().map(|e| e.value).collect(),
            }
        })
        .collect()
}

/// The index of the branch passing `keep` with the largest `score`.
fn pick<S>(seen: &[S], keep: impl Fn(&S) -> bool, score: impl Fn(&S) -> f64) -> Option<usize> {
    seen.iter()
        .enumerate()
        .filter(|(_, s)| keep(s))
        .max_by(|a, b| score(a.1).total_cmp(&score(b.1)))
        .map(|(i, _)| i)
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
                "twist",
                "other"
            ]
        );
    }

    proptest! {
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
