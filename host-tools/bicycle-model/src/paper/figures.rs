//! What the seed paper reads off a model: critical speeds and the
//! frequencies and real parts of its modes against speed.

use std::f64::consts::TAU;

use nalgebra::Complex;

use crate::critical::{critical_speeds, CriticalSpeed};
use crate::eig::eigen;
use crate::model::{Model, StateRole};
use crate::sweep::{Mode, Sweep, SweepError};

/// Speeds from 0 to 14 m/s every `step` m/s (the range the paper's
/// figures and this crate's naming share).
#[must_use]
pub fn grid(step: f64) -> Vec<f64> {
    let n = (14.0 / step).round() as usize;
    (0..=n).map(|i| i as f64 * 14.0 / n as f64).collect()
}

/// A model's sweep and critical speeds.
#[derive(Clone, Debug)]
pub struct Figures {
    /// Eigenvalues against speed, named.
    pub sweep: Sweep,
    /// Where each named mode's real part changes sign.
    pub critical: Vec<CriticalSpeed>,
    model: Model,
}

impl Figures {
    /// Evaluates `model` at `speeds` (increasing).
    ///
    /// # Errors
    /// When the eigenvalues cannot be computed at some speed.
    pub fn of(model: &Model, speeds: &[f64]) -> Result<Self, SweepError> {
        let sweep = Sweep::run(model, speeds, |_| {})?;
        let critical = critical_speeds(model, &sweep);
        Ok(Self {
            sweep,
            critical,
            model: model.clone(),
        })
    }

    /// The first speed where `mode` turns unstable (`unstable_above`) or
    /// stable with rising speed; infinite if it does not on the sweep.
    #[must_use]
    pub fn speed(&self, mode: Mode, unstable_above: bool) -> f64 {
        self.critical
            .iter()
            .find(|c| c.mode == mode && c.unstable_above == unstable_above)
            .map_or(f64::INFINITY, |c| c.speed_mps)
    }

    /// The wobble speed, the paper's section 3: where an unstable wobble
    /// first appears with rising speed (the sweep's first speed if it is
    /// unstable there already; infinite if it never is).
    #[must_use]
    pub fn wobble_speed(&self) -> f64 {
        let first = self.sweep.speeds_mps[0];
        if self.value(Mode::Wobble, first).is_some_and(|v| v.re > 0.0) {
            return first;
        }
        self.speed(Mode::Wobble, true)
    }

    /// The wobble frequency where it turns unstable, Hz (NaN if it does
    /// not).
    #[must_use]
    pub fn onset_hz(&self) -> f64 {
        let u = self.wobble_speed();
        if u.is_finite() {
            self.hz(Mode::Wobble, u)
        } else {
            f64::NAN
        }
    }

    /// The upper member of `mode` at `u` m/s, linear between the sweep's
    /// speeds; `None` if the model has no such mode or `u` is outside.
    #[must_use]
    pub fn value(&self, mode: Mode, u: f64) -> Option<Complex<f64>> {
        let branch = self.sweep.upper(mode)?;
        let s = &self.sweep.speeds_mps;
        let k = s.partition_point(|&x| x < u);
        if k == 0 {
            return (u == s[0]).then(|| branch.values[0]);
        }
        let (lo, hi) = (s.get(k - 1)?, s.get(k)?);
        let t = (u - lo) / (hi - lo);
        Some(branch.values[k - 1] * (1.0 - t) + branch.values[k] * t)
    }

    /// The rider's lean at `u` m/s, from the state matrix rather than the
    /// naming: of the eigenvalues there (the upper member of a pair), the
    /// one whose eigenvector gives the torso the largest share of its angle
    /// and tyre-lag states. An overdamped lean is real roots that a tyre
    /// lag's root crosses, so a branch named `lean` over the sweep can be
    /// that lag's root at a given speed; this is the upper body's own (a
    /// share of the angles alone would take a root of the tyre lags whose
    /// tiny angles happen to be mostly torso). `None` without a torso.
    #[must_use]
    pub fn lean_at(&self, u: f64) -> Option<Complex<f64>> {
        let roles = self.model.state_roles();
        let torso_share = |v: &nalgebra::DVector<Complex<f64>>| {
            let (mut torso, mut all) = (0.0, 0.0);
            for (r, c) in roles.iter().zip(v.iter()) {
                match r {
                    StateRole::Rate => {}
                    StateRole::Torso => {
                        torso += c.norm_sqr();
                        all += c.norm_sqr();
                    }
                    _ => all += c.norm_sqr(),
                }
            }
            torso / all.max(f64::MIN_POSITIVE)
        };
        eigen(&self.model.state_matrix(u))?
            .into_iter()
            .filter(|e| e.value.im >= 0.0)
            .map(|e| (e.value, torso_share(&e.vector)))
            .filter(|(_, s)| *s > 0.0)
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(v, _)| v)
    }

    /// The frequency of `mode` at `u`, Hz (NaN if there is none).
    #[must_use]
    pub fn hz(&self, mode: Mode, u: f64) -> f64 {
        self.value(mode, u).map_or(f64::NAN, |v| v.im / TAU)
    }

    /// The real part of `mode` at `u`, 1/s (NaN if there is none).
    #[must_use]
    pub fn re(&self, mode: Mode, u: f64) -> f64 {
        self.value(mode, u).map_or(f64::NAN, |v| v.re)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grid_spans_0_to_14_mps_evenly() {
        let g = grid(0.25);
        assert_eq!(g.len(), 57);
        assert_eq!(g[0], 0.0);
        assert!((g[56] - 14.0).abs() < 1e-12);
        assert!((g[1] - 0.25).abs() < 1e-12);
    }
}
