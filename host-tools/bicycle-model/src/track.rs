//! Following eigenvalues from one speed to the next by continuity, from the
//! eigenvalues alone.
//!
//! Each branch is predicted at the next speed by linear extrapolation from
//! its two previous values; the eigenvalues found there are assigned to the
//! predictions greedily in order of distance, which is exact when the step is
//! small against the gaps between eigenvalues. Where it is not, the step is
//! halved, down to a 64th of the grid's step, so that a coarse grid follows
//! the same branches as a fine one. It is not where a prediction is about as
//! near another eigenvalue as the one it got, or where two branches moved
//! against each other by about as much as the swapped assignment would have
//! moved them (their difference changing by as much as its size): where a
//! root's path turns beside another's, as two real roots that meet without
//! colliding do, the extrapolation from before the turn lands nearer the
//! other path, and only the step's ends, not the prediction, show it. Near
//! a double root (the weave splitting into two real roots) any assignment is
//! continuous: the two conjugates a real prediction meets there, and a pair
//! that is a double root or conjugates at either end of the step, are not
//! counted as a doubt.

use nalgebra::Complex;

use crate::sweep::SweepError;

/// A step is halved at most this many times.
const MAX_HALVINGS: u32 = 6;
/// A prediction whose assigned value is farther than this share of the
/// distance to the next candidate is in doubt.
const DOUBT: f64 = 0.5;

/// Where the tracks are: their values at the last two speeds evaluated.
struct State {
    prev: Option<(f64, Vec<Complex<f64>>)>,
    last: (f64, Vec<Complex<f64>>),
}

impl State {
    fn predict(&self, u: f64, out: &mut Vec<Complex<f64>>) {
        let (ul, vl) = &self.last;
        out.clear();
        match &self.prev {
            Some((up, vp)) if ul > up => out.extend(
                vl.iter()
                    .zip(vp)
                    .map(|(l, p)| l + (l - p) * ((u - ul) / (ul - up))),
            ),
            _ => out.extend_from_slice(vl),
        }
    }

    /// Makes `values` the last, handing the oldest buffer back in `values`.
    fn push(&mut self, u: f64, values: &mut Vec<Complex<f64>>) {
        let last = std::mem::replace(&mut self.last, (u, std::mem::take(values)));
        if let Some((_, old)) = self.prev.replace(last) {
            *values = old;
        }
    }
}

/// Buffers reused from one speed to the next.
#[derive(Default)]
struct Scratch {
    predicted: Vec<Complex<f64>>,
    assigned: Vec<Complex<f64>>,
    /// Squared distances, `predicted x found`.
    dist: Vec<f64>,
    choice: Vec<usize>,
    /// Each prediction's second nearest value.
    runner_up: Vec<usize>,
    taken: Vec<bool>,
    /// Each branch's move over the step.
    moved: Vec<f64>,
}

/// The eigenvalues at a speed, given the branches' predicted values there
/// (none at the first speed) as the solver's guesses.
pub(crate) type EigenvaluesFn<'a> = dyn Fn(f64, &[Complex<f64>]) -> Option<Vec<Complex<f64>>> + 'a;
/// A borrowed [`EigenvaluesFn`].
pub(crate) type EigenvaluesAt<'a> = &'a EigenvaluesFn<'a>;

/// Eigenvalues followed from speed to speed: [`Tracker::step`] gives the
/// branches' values at each next speed, always in the same branch order.
pub(crate) struct Tracker<'a> {
    eigenvalues: EigenvaluesAt<'a>,
    state: Option<State>,
    scratch: Scratch,
}

impl<'a> Tracker<'a> {
    /// A tracker of the eigenvalues `eigenvalues(u, guesses)` gives
    /// (unordered, `None` where they cannot be computed; `guesses` are the
    /// branches' predicted values at `u`, none at the first speed).
    pub(crate) fn new(eigenvalues: EigenvaluesAt<'a>) -> Self {
        Self {
            eigenvalues,
            state: None,
            scratch: Scratch::default(),
        }
    }

    fn at(&self, u: f64, guesses: &[Complex<f64>]) -> Result<Vec<Complex<f64>>, SweepError> {
        (self.eigenvalues)(u, guesses).ok_or(SweepError::Eigen(u))
    }

    /// The branches' values at `u`, above every speed stepped to before.
    pub(crate) fn step(&mut self, u: f64) -> Result<&[Complex<f64>], SweepError> {
        match self.state.take() {
            None => {
                self.state = Some(State {
                    prev: None,
                    last: (u, self.at(u, &[])?),
                });
            }
            Some(mut state) => {
                let done = self.advance(&mut state, u, None, MAX_HALVINGS);
                self.state = Some(state);
                done?;
            }
        }
        Ok(self.state.as_ref().map_or(&[], |s| &s.last.1))
    }

    /// Moves `state` to `u`, where the eigenvalues are `found` (computed
    /// here, from the predictions, if `None`), halving the step while the
    /// assignment is in doubt.
    fn advance(
        &mut self,
        state: &mut State,
        u: f64,
        found: Option<Vec<Complex<f64>>>,
        halvings: u32,
    ) -> Result<(), SweepError> {
        let mut predicted = std::mem::take(&mut self.scratch.predicted);
        state.predict(u, &mut predicted);
        let found = match found {
            Some(found) => found,
            None => self.at(u, &predicted)?,
        };
        let doubtful = assign(&predicted, &found, &mut self.scratch)
            || crossed(
                &state.last.1,
                &self.scratch.assigned,
                &mut self.scratch.moved,
            );
        self.scratch.predicted = predicted;
        if doubtful && halvings > 0 {
            let mid = 0.5 * (state.last.0 + u);
            self.advance(state, mid, None, halvings - 1)?;
            return self.advance(state, u, Some(found), halvings - 1);
        }
        state.push(u, &mut self.scratch.assigned);
        Ok(())
    }
}

/// Puts the eigenvalue of `found` for each prediction (greedy nearest pairs)
/// into `scratch.assigned`; returns whether any assignment was in doubt.
fn assign(predicted: &[Complex<f64>], found: &[Complex<f64>], scratch: &mut Scratch) -> bool {
    let (np, nf) = (predicted.len(), found.len());
    let Scratch {
        assigned,
        dist,
        choice,
        runner_up,
        taken,
        ..
    } = scratch;
    dist.clear();
    dist.extend(
        predicted
            .iter()
            .flat_map(|p| found.iter().map(move |f| (f - p).norm_sqr())),
    );
    // Each prediction's nearest value; when these are all different, they
    // are what the greedy pairing gives, without sorting every pair.
    choice.clear();
    runner_up.clear();
    for row in dist.chunks_exact(nf.max(1)).take(np) {
        let (first, second) = nearest_two(row);
        choice.push(first);
        runner_up.push(second);
    }
    choice.resize(np, usize::MAX);
    taken.clear();
    taken.resize(nf, false);
    let mut distinct = true;
    for &j in choice.iter() {
        distinct &= !std::mem::replace(&mut taken[j], true);
    }
    if !distinct {
        greedy(dist, np, nf, choice, taken);
    }
    let scale = found
        .iter()
        .fold(1.0_f64, |m, f| m.max(f.norm_sqr()))
        .sqrt();
    let (same, conj_tol) = ((1e-9 * scale).powi(2), (1e-12 * scale).powi(2));
    let mut doubtful = false;
    for (i, p) in predicted.iter().enumerate() {
        let j = choice[i];
        if j == usize::MAX {
            continue;
        }
        let d1 = dist[i * nf + j];
        if d1 <= same {
            continue;
        }
        let row = &dist[i * nf..(i + 1) * nf];
        // The conjugate a real prediction meets is no rival: either member
        // continues the branch.
        let exempt =
            |k: usize| (found[k] - found[j].conj()).norm_sqr() <= conj_tol && p.im * p.im < d1;
        // The nearest other value (the runner-up when each prediction got
        // its nearest), or, if that is the exempt conjugate, the nearest of
        // the rest.
        let other = if distinct {
            runner_up[i]
        } else {
            nearest_but(row, j)
        };
        let rival = match other {
            usize::MAX => f64::INFINITY,
            k if exempt(k) => row
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != j && !exempt(k))
                .map(|(_, d)| *d)
                .fold(f64::INFINITY, f64::min),
            k => row[k],
        };
        if d1 > DOUBT * DOUBT * rival {
            doubtful = true;
        }
    }
    assigned.clear();
    assigned.extend(choice.iter().enumerate().map(|(i, &j)| {
        if j == usize::MAX {
            predicted[i]
        } else {
            found[j]
        }
    }));
    doubtful
}

/// Whether two branches moved, against each other, from `last` to
/// `assigned` by more than [`DOUBT`] of what the swapped assignment would
/// have moved them: two roots whose difference changes about as much as its
/// size over the step, as where one root's path turns beside another's (two
/// real roots that meet without colliding part on the sides they came from,
/// and the step's straight extrapolation may carry each onto the other's
/// path) or where two paths cross. Pairs that are a double root or
/// conjugates at either end are no doubt: either member continues either
/// branch there. `moved` is scratch space (each branch's squared move).
fn crossed(last: &[Complex<f64>], assigned: &[Complex<f64>], moved: &mut Vec<f64>) -> bool {
    moved.clear();
    moved.extend(last.iter().zip(assigned).map(|(a, b)| (b - a).norm_sqr()));
    // The difference changes by at most the two moves, `m`, so the sum is
    // at least `2 |before| - m`: a doubt needs `|before| < 1.5 m`, so
    // `|before|^2 < 4.5 (m_i^2 + m_j^2)`. Most steps have no such pair;
    // this first pass, without branches, finds whether any has.
    let near = |i: usize, j: usize| (last[i] - last[j]).norm_sqr() < 4.5 * (moved[i] + moved[j]);
    let mut any_near = false;
    for (i, (a, ma)) in last.iter().zip(moved.iter()).enumerate() {
        for (b, mb) in last[i + 1..].iter().zip(&moved[i + 1..]) {
            any_near |= (a - b).norm_sqr() < 4.5 * (ma + mb);
        }
    }
    if !any_near {
        return false;
    }
    let scale = assigned
        .iter()
        .chain(last)
        .fold(1.0_f64, |m, v| m.max(v.norm_sqr()))
        .sqrt();
    let (same, conj_tol) = ((1e-9 * scale).powi(2), (1e-12 * scale).powi(2));
    let mates = |a: Complex<f64>, b: Complex<f64>| (a - b.conj()).norm_sqr() <= conj_tol;
    (0..last.len()).any(|i| {
        (i + 1..last.len()).any(|j| {
            let (before, after) = (last[i] - last[j], assigned[i] - assigned[j]);
            near(i, j)
                && before.norm_sqr() > same
                && after.norm_sqr() > same
                && !mates(last[i], last[j])
                && !mates(assigned[i], assigned[j])
                && (after - before).norm_sqr() > DOUBT * DOUBT * (after + before).norm_sqr()
        })
    })
}

/// The indices of the smallest of `d` (the first of equals) and of the
/// smallest of the rest (`usize::MAX` where there is none).
fn nearest_two(d: &[f64]) -> (usize, usize) {
    let (mut first, mut second) = (usize::MAX, usize::MAX);
    for (k, x) in d.iter().enumerate() {
        if first == usize::MAX || x.total_cmp(&d[first]).is_lt() {
            second = first;
            first = k;
        } else if second == usize::MAX || x.total_cmp(&d[second]).is_lt() {
            second = k;
        }
    }
    (first, second)
}

/// The index of the smallest of `d` but `d[but]` (`usize::MAX` if none).
fn nearest_but(d: &[f64], but: usize) -> usize {
    d.iter()
        .enumerate()
        .filter(|&(j, _)| j != but)
        .min_by(|a, b| a.1.total_cmp(b.1))
        .map_or(usize::MAX, |(j, _)| j)
}

/// Greedy nearest pairs over all of `dist` (`np x nf`), into `choice`
/// (`usize::MAX` for a prediction left without a value).
fn greedy(dist: &[f64], np: usize, nf: usize, choice: &mut [usize], taken: &mut Vec<bool>) {
    let mut pairs: Vec<(f64, usize, usize)> = (0..np)
        .flat_map(|i| (0..nf).map(move |j| (dist[i * nf + j], i, j)))
        .collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    taken.clear();
    taken.resize(nf, false);
    choice.fill(usize::MAX);
    for &(_, i, j) in &pairs {
        if choice[i] == usize::MAX && !taken[j] {
            choice[i] = j;
            taken[j] = true;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The nearest and the runner-up by hand, the first of equals first;
    /// the nearest but one given index; nothing where there is nothing.
    #[test]
    fn nearest_two_and_nearest_but_pick_by_hand() {
        let d = [3.0, 1.0, 2.0, 1.0, 0.5];
        assert_eq!(nearest_two(&d), (4, 1));
        assert_eq!(nearest_two(&d[..4]), (1, 3));
        assert_eq!(nearest_two(&[2.0, 1.0, 3.0]), (1, 0));
        assert_eq!(nearest_two(&[7.0]), (0, usize::MAX));
        assert_eq!(nearest_two(&[]), (usize::MAX, usize::MAX));
        assert_eq!(nearest_but(&d, 4), 1);
        assert_eq!(nearest_but(&d, 1), 4);
        assert_eq!(nearest_but(&[2.0, 1.0, 3.0], 1), 0);
        assert_eq!(nearest_but(&[7.0], 0), usize::MAX);
    }
}
