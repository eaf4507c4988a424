//! Naming followed branches by mode, from their participation over the whole
//! speed range.
//!
//! Branches that are complex conjugates of each other over at least
//! [`OSCILLATING_SHARE`] of the speeds form one mode (a weave that splits into
//! two real roots at low speed is one mode with two branches); a mode
//! oscillates if it is complex over that share of its speeds. Real roots that
//! meet briefly and part again (capsize and castering of some bicycles near
//! 1 m/s) stay two real modes. At up to [`SAMPLES`] speeds spread over the sweep each
//! branch's eigenvector is computed (inverse iteration) and the squared
//! magnitudes of its angle states are shared out: roll, steer, torso, twist,
//! tyre lags (rates and velocities left out: they scale with the eigenvalue).
//! A mode's participation is the mean over its branches and those speeds.
//!
//! - the mode with the largest torso share (at least [`LEAN_MIN_TORSO`]) is
//!   `lean`, the upper body rolling on the hip: a tense rider's lean
//!   oscillation carries much steer, but it is not the wobble; on a rigid
//!   rider (a hip of 12 000 N m/rad and more on the first test bicycle) it
//!   is the upper body against the frame at 19-31 Hz, mostly tyre lags;
//! - beside that lean, any other oscillation at 2 Hz or more on average with
//!   the tyre lags at least [`SWAY_MIN_TYRE`] of it and the twist not its
//!   largest angle is the `sway`: the main frame rolling and sliding
//!   sideways on the tyres' lateral compliance (mostly the rear tyre's,
//!   whose cornering stiffness sets its frequency), under an upper body the
//!   hip holds, or, on a rigid rider, with the upper body rolling along
//!   (its steer then more than its roll);
//! - of the oscillations with the twist their largest angle, the one with
//!   the largest twist share of its angles is the `twist`, the front
//!   assembly twisting on the head's compliance, whatever its tyre lags:
//!   the front tyre's lateral stiffness is the twist's second spring, so
//!   its lags grow as the relaxation length shortens (37 times the twist
//!   at 63 Hz with a 0.08 m front relaxation length);
//! - tyre lags more than [`TYRE_DOMINANCE`] times its largest angle: `other`;
//! - torso the largest angle: `lean`;
//! - roll or steer the largest, oscillating somewhere, with at least
//!   [`WEAVE_MIN_ROLL_PER_STEER`] roll per steer and below 2 Hz on average: the
//!   one with the largest roll share (of roll and steer) is the `weave` (a
//!   castering pair made complex by the tyre lags steers);
//! - steer the largest, oscillating at 2 Hz or more on average: the lowest such
//!   is the `wobble`;
//! - real throughout with roll the largest: the slowest (smallest mean
//!   `|re|`) is `capsize`;
//! - steer the largest and below 2 Hz, not the weave: the fastest decaying is
//!   `castering`;
//! - anything else `other`.
//!
//! The names are taken on a reference sweep, [`REFERENCE_STEP_MPS`] apart
//! from 0 to [`REFERENCE_TOP_MPS`] (the model's natural range, where the
//! weave still has its low-speed form), whatever speeds were asked for:
//! the reference speeds are followed together with the asked ones
//! ([`speeds`]), so each branch at the asked speeds is a branch of the
//! reference sweep and carries its name. A single speed, a short or high
//! range or a coarse grid names each eigenvalue as the 0-14 m/s sweep does.

use nalgebra::{Complex, DMatrix};

use crate::eig::eigenvector;
use crate::model::StateRole;
use crate::sweep::{Mode, REAL_TOL};

/// Share of the speeds over which two branches are conjugate to be one
/// mode, and over which a mode is complex to oscillate.
pub const OSCILLATING_SHARE: f64 = 0.25;
/// The mode with the largest torso share is the lean if it has this much
/// (a rigid rider's lean: 0.02 at 5 m/s at 50 000 N m/rad).
pub const LEAN_MIN_TORSO: f64 = 0.01;
/// Speeds at which eigenvectors are computed.
pub const SAMPLES: usize = 16;
/// A mode whose tyre lags are this many times its largest angle is a tyre mode.
pub const TYRE_DOMINANCE: f64 = 4.0;
/// The sway's tyre lags: at least this share of its participation.
pub const SWAY_MIN_TYRE: f64 = 0.5;
/// Weave rolls: at least this much roll per steer (amplitudes).
pub const WEAVE_MIN_ROLL_PER_STEER: f64 = 0.2;
/// Wobble is faster than this on average, rad/s (2 Hz).
pub const WOBBLE_MIN_RAD_S: f64 = 4.0 * std::f64::consts::PI;
/// The reference sweep names are taken on: 0 to this, m/s.
pub const REFERENCE_TOP_MPS: f64 = 14.0;
/// The reference sweep's step, m/s (the tracking halves it where in doubt).
pub const REFERENCE_STEP_MPS: f64 = 0.5;
/// The reference sweep's number of speeds.
const REFERENCE_SPEEDS: usize = 1 + (REFERENCE_TOP_MPS / REFERENCE_STEP_MPS) as usize;

/// One speed a sweep evaluates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Speed {
    /// m/s.
    pub(crate) u: f64,
    /// Its index among the asked speeds, if asked.
    pub(crate) asked: Option<usize>,
    /// Whether it is a speed of the reference sweep.
    pub(crate) reference: bool,
}

/// The speeds a sweep over `asked` (increasing) evaluates, increasing: the
/// asked ones and the reference sweep's, a reference speed within 1e-9 m/s
/// of an asked one being that one (lazily: memory does not grow with the
/// number of speeds).
pub(crate) fn speeds(asked: &[f64]) -> impl Iterator<Item = Speed> + '_ {
    let reference = |i: usize| (i < REFERENCE_SPEEDS).then_some(i as f64 * REFERENCE_STEP_MPS);
    let (mut a, mut r) = (0, 0);
    std::iter::from_fn(move || {
        let next = match (asked.get(a), reference(r)) {
            (None, None) => return None,
            (Some(&u), Some(ur)) if (u - ur).abs() <= 1e-9 => Speed {
                u,
                asked: Some(a),
                reference: true,
            },
            (Some(&u), Some(ur)) if ur < u => Speed {
                u: ur,
                asked: None,
                reference: true,
            },
            (Some(&u), _) => Speed {
                u,
                asked: Some(a),
                reference: false,
            },
            (None, Some(ur)) => Speed {
                u: ur,
                asked: None,
                reference: true,
            },
        };
        a += usize::from(next.asked.is_some());
        r += usize::from(next.reference);
        Some(next)
    })
}

/// Shares of the angles in a mode: roll, steer, torso, twist, tyre.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
struct Shares([f64; 5]);

const ANGLES: [StateRole; 4] = [
    StateRole::Roll,
    StateRole::Steer,
    StateRole::Torso,
    StateRole::Twist,
];

/// A mode: its branches and what they do over the sweep.
struct Group {
    members: Vec<usize>,
    shares: Shares,
    oscillates: bool,
    /// Mean `|im|` over the speeds where it is complex, rad/s.
    freq: f64,
    /// Mean real part, 1/s.
    mean_re: f64,
    /// Mean `|re|`, 1/s.
    mean_abs_re: f64,
}

impl Group {
    fn largest_angle(&self) -> (StateRole, f64) {
        ANGLES
            .iter()
            .zip(self.shares.0)
            .map(|(r, s)| (*r, s))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((StateRole::Rate, 0.0))
    }

    fn share(&self, role: StateRole) -> f64 {
        ANGLES
            .iter()
            .position(|r| *r == role)
            .map_or(self.shares.0[4], |i| self.shares.0[i])
    }

    fn tyre_only(&self) -> bool {
        self.shares.0[4] > TYRE_DOMINANCE * TYRE_DOMINANCE * self.largest_angle().1
    }

    fn planar(&self) -> bool {
        !self.tyre_only() && matches!(self.largest_angle().0, StateRole::Roll | StateRole::Steer)
    }

    fn weave_like(&self) -> bool {
        let (roll, steer) = (self.share(StateRole::Roll), self.share(StateRole::Steer));
        self.planar()
            && self.oscillates
            && self.freq < WOBBLE_MIN_RAD_S
            && roll >= WEAVE_MIN_ROLL_PER_STEER * WEAVE_MIN_ROLL_PER_STEER * steer
    }

    /// The frame swaying on the tyres: an oscillation carried mostly by the
    /// tyre lags, of any angle but the twist (the steer's, under the roll's
    /// and the torso's on a tense rider, takes over on a rigid one).
    fn sway_like(&self) -> bool {
        self.oscillates
            && self.freq >= WOBBLE_MIN_RAD_S
            && self.shares.0[4] >= SWAY_MIN_TYRE
            && self.largest_angle().0 != StateRole::Twist
    }

    fn wobble_like(&self) -> bool {
        self.planar()
            && self.oscillates
            && self.freq >= WOBBLE_MIN_RAD_S
            && self.largest_angle().0 == StateRole::Steer
    }
}

/// Disjoint sets of branch indices.
fn find(parent: &mut [usize], i: usize) -> usize {
    let mut r = i;
    while parent[r] != r {
        r = parent[r];
    }
    parent[i] = r;
    r
}

/// The indices of up to [`SAMPLES`] speeds spread over `n`.
fn sample_indices(n: usize) -> Vec<usize> {
    if n <= SAMPLES {
        return (0..n).collect();
    }
    let mut v: Vec<usize> = (0..SAMPLES)
        .map(|i| (i * (n - 1) + (SAMPLES - 1) / 2) / (SAMPLES - 1))
        .collect();
    v.dedup();
    v
}

fn shares_of(vector: &nalgebra::DVector<Complex<f64>>, roles: &[StateRole]) -> Shares {
    let mut s = [0.0; 5];
    for (role, c) in roles.iter().zip(vector.iter()) {
        let slot = match role {
            StateRole::Roll => 0,
            StateRole::Steer => 1,
            StateRole::Torso => 2,
            StateRole::Twist => 3,
            StateRole::Tyre => 4,
            StateRole::Rate => continue,
        };
        s[slot] += c.norm_sqr();
    }
    let total: f64 = s.iter().sum();
    if total > 0.0 {
        for x in &mut s {
            *x /= total;
        }
    }
    Shares(s)
}

/// The branch whose value is the conjugate of branch `i`'s, to 1e-9 of its
/// size, if any.
fn conjugate_partner(values: &[Complex<f64>], i: usize) -> Option<usize> {
    let v = values[i];
    let tol = (1e-9 * v.norm().max(1.0)).powi(2);
    (0..values.len())
        .filter(|&j| j != i)
        .map(|j| (j, (values[j] - v.conj()).norm_sqr()))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .filter(|&(_, d)| d <= tol)
        .map(|(j, _)| j)
}

/// What naming needs of a sweep, gathered one speed at a time (so that a
/// sweep need not be held whole): per branch its mean participation at the
/// sample speeds and sums of its values, per pair of branches the speeds
/// at which they are conjugates.
pub(crate) struct Stats {
    roles: Vec<StateRole>,
    samples: Vec<usize>,
    /// Speeds added so far.
    k: usize,
    branches: usize,
    shares: Vec<Shares>,
    /// `conjugate[i * branches + j]`: speeds at which `j` is `i`'s conjugate.
    conjugate: Vec<usize>,
    /// Per branch: speeds at which it is complex, and the sums of `|im|`
    /// there, of `re` and of `|re|` over all speeds.
    complex: Vec<usize>,
    sum_abs_im: Vec<f64>,
    sum_re: Vec<f64>,
    sum_abs_re: Vec<f64>,
}

impl Stats {
    /// Statistics of the reference sweep of a model with states of `roles`.
    pub(crate) fn new(roles: &[StateRole]) -> Self {
        Self {
            roles: roles.to_vec(),
            samples: sample_indices(REFERENCE_SPEEDS),
            k: 0,
            branches: 0,
            shares: Vec::new(),
            conjugate: Vec::new(),
            complex: Vec::new(),
            sum_abs_im: Vec::new(),
            sum_re: Vec::new(),
            sum_abs_re: Vec::new(),
        }
    }

    /// Adds the branches' `values` at the next reference speed `u`; `state_matrix`
    /// gives the matrix whose eigenvectors are taken at the sample speeds.
    pub(crate) fn add(
        &mut self,
        u: f64,
        values: &[Complex<f64>],
        state_matrix: &dyn Fn(f64) -> DMatrix<f64>,
    ) {
        let n = values.len();
        if self.k == 0 {
            self.branches = n;
            self.shares = vec![Shares::default(); n];
            self.conjugate = vec![0; n * n];
            self.complex = vec![0; n];
            self.sum_abs_im = vec![0.0; n];
            self.sum_re = vec![0.0; n];
            self.sum_abs_re = vec![0.0; n];
        }
        if self.samples.binary_search(&self.k).is_ok() {
            let a = state_matrix(u);
            let weight = 1.0 / self.samples.len() as f64;
            // The lower member of a pair has its partner's shares (its
            // eigenvector is the conjugate): one inverse iteration per pair.
            let mut got: Vec<Option<Shares>> = vec![None; n];
            for i in (0..n).filter(|&i| values[i].im >= 0.0) {
                got[i] = Some(shares_of(&eigenvector(&a, values[i]), &self.roles));
            }
            for i in 0..n {
                let shares = match got[i] {
                    Some(shares) => shares,
                    None => conjugate_partner(values, i)
                        .and_then(|j| got[j])
                        .unwrap_or_else(|| shares_of(&eigenvector(&a, values[i]), &self.roles)),
                };
                for (x, y) in self.shares[i].0.iter_mut().zip(shares.0) {
                    *x += y * weight;
                }
            }
        }
        for (i, &v) in values.iter().enumerate() {
            self.sum_re[i] += v.re;
            self.sum_abs_re[i] += v.re.abs();
            if v.im.abs() > REAL_TOL {
                self.complex[i] += 1;
                self.sum_abs_im[i] += v.im.abs();
            }
            if v.im <= REAL_TOL {
                continue;
            }
            if let Some(j) = conjugate_partner(values, i) {
                self.conjugate[i * n + j] += 1;
            }
        }
        self.k += 1;
    }

    /// Branches that are conjugates of each other over at least
    /// [`OSCILLATING_SHARE`] of the speeds, as groups.
    fn conjugate_groups(&self) -> Vec<Vec<usize>> {
        let n = self.branches;
        let mut parent: Vec<usize> = (0..n).collect();
        for i in 0..n {
            for j in 0..n {
                if self.conjugate[i * n + j] as f64 >= OSCILLATING_SHARE * REFERENCE_SPEEDS as f64 {
                    let (a, b) = (find(&mut parent, i), find(&mut parent, j));
                    parent[a] = b;
                }
            }
        }
        let mut groups: Vec<Vec<usize>> = Vec::new();
        let mut root_of: Vec<Option<usize>> = vec![None; n];
        for i in 0..n {
            let r = find(&mut parent, i);
            match root_of[r] {
                Some(g) => groups[g].push(i),
                None => {
                    root_of[r] = Some(groups.len());
                    groups.push(vec![i]);
                }
            }
        }
        groups
    }

    /// The mode of each branch.
    pub(crate) fn modes(&self) -> Vec<Mode> {
        let n = REFERENCE_SPEEDS;
        let groups: Vec<Group> = self
            .conjugate_groups()
            .into_iter()
            .map(|members| {
                let mut sh = [0.0; 5];
                for &m in &members {
                    for (x, y) in sh.iter_mut().zip(self.shares[m].0) {
                        *x += y / members.len() as f64;
                    }
                }
                let sum = |v: &[f64]| members.iter().map(|&m| v[m]).sum::<f64>();
                let complex: usize = members.iter().map(|&m| self.complex[m]).sum();
                let count = (members.len() * n) as f64;
                Group {
                    shares: Shares(sh),
                    oscillates: complex as f64 >= OSCILLATING_SHARE * count,
                    freq: sum(&self.sum_abs_im) / complex.max(1) as f64,
                    mean_re: sum(&self.sum_re) / count,
                    mean_abs_re: sum(&self.sum_abs_re) / count,
                    members,
                }
            })
            .collect();
        classify(&groups, self.branches)
    }
}

/// The mode of each of `branches` branches, from their groups.
fn classify(groups: &[Group], branches: usize) -> Vec<Mode> {
    let lean = pick(
        groups,
        |g| g.share(StateRole::Torso) >= LEAN_MIN_TORSO,
        |g| g.share(StateRole::Torso),
    );
    // The lean is neither weave nor wobble.
    let not_lean = |g: &Group| lean.is_none_or(|l| !std::ptr::eq(g, &groups[l]));
    // The weave rolls; a castering pair made complex by the tyre lags steers.
    let weave = pick(
        groups,
        |g| g.weave_like() && not_lean(g),
        |g| g.share(StateRole::Roll) / (g.share(StateRole::Roll) + g.share(StateRole::Steer)),
    );
    let wobble = pick(groups, |g| g.wobble_like() && not_lean(g), |g| -g.freq);
    let twist = pick(
        groups,
        |g| g.oscillates && g.largest_angle().0 == StateRole::Twist,
        |g| g.share(StateRole::Twist) / g.shares.0[..4].iter().sum::<f64>(),
    );
    let capsize = pick(
        groups,
        |g| g.planar() && !g.oscillates && g.largest_angle().0 == StateRole::Roll,
        |g| -g.mean_abs_re,
    );
    let castering = pick(
        groups,
        |g| {
            g.planar()
                && g.largest_angle().0 == StateRole::Steer
                && g.freq < WOBBLE_MIN_RAD_S
                && !g.weave_like()
        },
        |g| -g.mean_re,
    );
    let mut modes = vec![Mode::Other; branches];
    for (i, g) in groups.iter().enumerate() {
        let mode = match g.largest_angle().0 {
            _ if Some(i) == lean => Mode::Lean,
            _ if Some(i) == twist => Mode::Twist,
            _ if lean.is_some() && g.sway_like() => Mode::Sway,
            _ if g.tyre_only() => Mode::Other,
            StateRole::Torso => Mode::Lean,
            _ if Some(i) == weave => Mode::Weave,
            _ if Some(i) == wobble => Mode::Wobble,
            _ if Some(i) == capsize => Mode::Capsize,
            _ if Some(i) == castering => Mode::Castering,
            _ => Mode::Other,
        };
        for &m in &g.members {
            modes[m] = mode;
        }
    }
    modes
}

/// The index of the group passing `keep` with the largest `score`.
fn pick(
    groups: &[Group],
    keep: impl Fn(&Group) -> bool,
    score: impl Fn(&Group) -> f64,
) -> Option<usize> {
    groups
        .iter()
        .enumerate()
        .filter(|(_, g)| keep(g))
        .max_by(|a, b| score(a.1).total_cmp(&score(b.1)))
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 0.1 m/s grid from 0 holds the reference speeds up to round-off
    /// (`15.0 * 0.1` is 1.5000000000000002): every fifth speed is both, and
    /// nothing is evaluated twice.
    #[test]
    fn reference_speeds_on_an_asked_grid_are_the_asked_ones() {
        let asked: Vec<f64> = (0..=140).map(|i| f64::from(i) * 0.1).collect();
        let got: Vec<Speed> = speeds(&asked).collect();
        assert_eq!(got.len(), 141);
        for (k, s) in got.iter().enumerate() {
            assert_eq!((s.u, s.asked), (asked[k], Some(k)));
            assert_eq!(s.reference, k % 5 == 0, "{} m/s", s.u);
        }
    }

    /// Asked speeds off the reference grid and beyond it come in order
    /// between the 29 reference speeds (0, 0.5, ..., 14 m/s).
    #[test]
    fn asked_speeds_off_the_reference_grid_are_merged_in_order() {
        let got: Vec<Speed> = speeds(&[3.3, 20.0]).collect();
        assert_eq!(got.len(), 31);
        assert!(got.windows(2).all(|w| w[0].u < w[1].u));
        let asked: Vec<(usize, f64)> = got
            .iter()
            .filter_map(|s| s.asked.map(|k| (k, s.u)))
            .collect();
        assert_eq!(asked, [(0, 3.3), (1, 20.0)]);
        let reference: Vec<f64> = got.iter().filter(|s| s.reference).map(|s| s.u).collect();
        assert_eq!(reference.len(), 29);
        assert_eq!((reference[7], reference[28]), (3.5, 14.0));
        assert!(got.iter().all(|s| s.reference != s.asked.is_some()));
    }

    /// A group of one branch (`member`) with shares of roll, steer, torso,
    /// twist and tyre lags, oscillating at `hz` on average (0: real) with
    /// mean real part `re`.
    fn group(member: usize, shares: [f64; 5], hz: f64, re: f64) -> Group {
        Group {
            members: vec![member],
            shares: Shares(shares),
            oscillates: hz > 0.0,
            freq: std::f64::consts::TAU * hz,
            mean_re: re,
            mean_abs_re: re.abs(),
        }
    }

    /// A 15 Hz oscillation of the frame on its tyres (roll its largest angle,
    /// the tyre lags 0.6 of it, not 4 times the roll) is the `sway` beside a
    /// rider's lean (a group with a torso share), and without one (no rider
    /// on a hip) no sway: the steer oscillation beside it is the wobble, it
    /// is `other`.
    #[test]
    fn the_sway_is_named_only_beside_a_lean() {
        let sway = || group(0, [0.25, 0.1, 0.0, 0.05, 0.6], 15.0, -4.0);
        let wobble = || group(1, [0.1, 0.8, 0.0, 0.0, 0.1], 7.0, -2.0);
        let lean = group(2, [0.3, 0.3, 0.3, 0.0, 0.1], 4.0, -9.0);
        assert_eq!(
            classify(&[sway(), wobble()], 2),
            [Mode::Other, Mode::Wobble]
        );
        assert_eq!(
            classify(&[sway(), wobble(), lean], 3),
            [Mode::Sway, Mode::Wobble, Mode::Lean]
        );
    }

    /// The module's rules where two groups compete for a name, worked by
    /// hand: of three weave-like oscillations the one rolling most of its
    /// roll and steer is the weave (0.97 of them; not the one rolling most
    /// of all its angles, nor the one steering least); of two steer oscillations above 2 Hz the
    /// lower is the wobble; of two real roll modes the slowest is the
    /// capsize; of two real steer modes the fastest decaying is the
    /// castering, and a weave-like oscillation steering most is no
    /// castering (it decays faster still); a real root carried by the tyre
    /// lags, slower than either capsize candidate, is `other`; of two
    /// oscillations of the tyre lags that twist the fork more than they
    /// steer, the one twisting it most of its angles is the `twist` (a
    /// single angle, the twist, beats three fifths), the other `other`. The
    /// losers are `other`.
    #[test]
    fn of_two_candidates_each_rule_names_the_one_the_docs_say() {
        let groups = [
            group(0, [0.8, 0.15, 0.0, 0.0, 0.05], 0.5, -1.0),
            group(1, [0.6, 0.02, 0.0, 0.0, 0.38], 0.5, -1.0),
            group(2, [0.1, 0.8, 0.0, 0.0, 0.1], 9.0, -2.0),
            group(3, [0.1, 0.8, 0.0, 0.0, 0.1], 7.0, -2.0),
            group(4, [0.8, 0.1, 0.0, 0.0, 0.1], 0.0, 3.0),
            group(5, [0.8, 0.1, 0.0, 0.0, 0.1], 0.0, 0.5),
            group(6, [0.2, 0.7, 0.0, 0.0, 0.1], 0.0, -5.0),
            group(7, [0.2, 0.7, 0.0, 0.0, 0.1], 0.0, -20.0),
            group(8, [0.45, 0.5, 0.0, 0.0, 0.05], 0.5, -100.0),
            group(9, [0.05, 0.0, 0.0, 0.0, 0.95], 0.0, 0.1),
            group(10, [0.0, 0.0, 0.0, 0.05, 0.95], 20.0, -3.0),
            group(11, [0.1, 0.004, 0.0, 0.0, 0.896], 0.5, -1.0),
            group(12, [0.0, 0.02, 0.0, 0.03, 0.95], 30.0, -9.0),
        ];
        let o = Mode::Other;
        assert_eq!(
            classify(&groups, groups.len()),
            [
                o,
                Mode::Weave,
                o,
                Mode::Wobble,
                o,
                Mode::Capsize,
                o,
                Mode::Castering,
                o,
                o,
                Mode::Twist,
                o,
                o
            ]
        );
    }
}
