//! Following eigenvalues from one speed to the next by continuity, from the
//! eigenvalues alone.
//!
//! Each branch is predicted at the next speed by linear extrapolation from
//! its two previous values; the eigenvalues found there are assigned to the
//! predictions greedily in order of distance, which is exact when the step is
//! small against the gaps between eigenvalues. Where it is not (a prediction
//! about as near another eigenvalue as the one it got) the step is halved,
//! down to a 64th of the grid's step, so that a coarse grid follows the same
//! branches as a fine one. Near a double root (the weave splitting into two
//! real roots) any assignment is continuous: the two conjugates a real
//! prediction meets there are not counted as a doubt.

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
    fn predict(&self, u: f64) -> Vec<Complex<f64>> {
        let (ul, vl) = &self.last;
        match &self.prev {
            Some((up, vp)) if ul > up => vl
                .iter()
                .zip(vp)
                .map(|(l, p)| l + (l - p) * ((u - ul) / (ul - up)))
                .collect(),
            _ => vl.clone(),
        }
    }

    fn push(&mut self, u: f64, values: Vec<Complex<f64>>) {
        let last = std::mem::replace(&mut self.last, (u, values));
        self.prev = Some(last);
    }
}

/// The eigenvalues at each of `speeds` (increasing), as branches:
/// `result[branch][speed]`. `eigenvalues(u)` gives the unordered eigenvalues
/// at `u` (`None` if they cannot be computed); `progress` is called after each
/// speed of the grid.
pub(crate) fn track(
    eigenvalues: &dyn Fn(f64) -> Option<Vec<Complex<f64>>>,
    speeds: &[f64],
    progress: &mut dyn FnMut(usize),
) -> Result<Vec<Vec<Complex<f64>>>, SweepError> {
    let at = |u: f64| eigenvalues(u).ok_or(SweepError::Eigen(u));
    let Some(&first) = speeds.first() else {
        return Err(SweepError::NoSpeeds);
    };
    let start = at(first)?;
    let mut branches: Vec<Vec<Complex<f64>>> = start.iter().map(|&v| vec![v]).collect();
    let mut state = State {
        prev: None,
        last: (first, start),
    };
    progress(0);
    for (k, &u) in speeds.iter().enumerate().skip(1) {
        let found = at(u)?;
        advance(&mut state, u, found, MAX_HALVINGS, &at)?;
        for (b, v) in branches.iter_mut().zip(&state.last.1) {
            b.push(*v);
        }
        progress(k);
    }
    Ok(branches)
}

/// Moves `state` to `u`, where the eigenvalues are `found`, halving the step
/// while the assignment is in doubt.
fn advance(
    state: &mut State,
    u: f64,
    found: Vec<Complex<f64>>,
    halvings: u32,
    at: &dyn Fn(f64) -> Result<Vec<Complex<f64>>, SweepError>,
) -> Result<(), SweepError> {
    let predicted = state.predict(u);
    let (assigned, doubtful) = assign(&predicted, &found);
    if doubtful && halvings > 0 {
        let mid = 0.5 * (state.last.0 + u);
        advance(state, mid, at(mid)?, halvings - 1, at)?;
        return advance(state, u, found, halvings - 1, at);
    }
    state.push(u, assigned);
    Ok(())
}

/// The eigenvalue of `found` for each prediction (greedy nearest pairs), and
/// whether any assignment was in doubt.
fn assign(predicted: &[Complex<f64>], found: &[Complex<f64>]) -> (Vec<Complex<f64>>, bool) {
    let mut pairs: Vec<(f64, usize, usize)> = Vec::with_capacity(predicted.len() * found.len());
    for (i, p) in predicted.iter().enumerate() {
        for (j, f) in found.iter().enumerate() {
            pairs.push(((f - p).norm(), i, j));
        }
    }
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut taken = vec![false; found.len()];
    let mut out: Vec<Option<usize>> = vec![None; predicted.len()];
    for &(_, i, j) in &pairs {
        if out[i].is_none() && !taken[j] {
            out[i] = Some(j);
            taken[j] = true;
        }
    }
    let scale = found.iter().fold(1.0_f64, |m, f| m.max(f.norm()));
    let mut doubtful = false;
    for (i, p) in predicted.iter().enumerate() {
        let Some(j) = out[i] else { continue };
        let d1 = (found[j] - p).norm();
        if d1 <= 1e-9 * scale {
            continue;
        }
        let rival = found
            .iter()
            .enumerate()
            .filter(|&(k, f)| {
                // The conjugate a real prediction meets is no rival: either
                // member continues the branch.
                let conjugate = (f - found[j].conj()).norm() <= 1e-12 * scale && p.im.abs() < d1;
                k != j && !conjugate
            })
            .map(|(_, f)| (f - p).norm())
            .fold(f64::INFINITY, f64::min);
        if d1 > DOUBT * rival {
            doubtful = true;
        }
    }
    let values = out
        .iter()
        .enumerate()
        .map(|(i, j)| j.map_or(predicted[i], |j| found[j]))
        .collect();
    (values, doubtful)
}
