//! Synthetic wobble episodes: what a fit would see on a bicycle whose
//! parameters are known, for the fit's tests and benchmarks.

use crate::fit::{Observation, Weights};
use crate::model::Model;
use crate::params::{ParamError, ParamSet, Problem};
use crate::sweep::{mode_at, Mode};

/// A fitting problem with a known answer: the steering head's stiffness and
/// damping of `truth`, to be found from its wobble episodes.
#[derive(Clone, Debug)]
pub struct Synthetic {
    /// The parameters to fit.
    pub keys: Vec<String>,
    /// Their true values.
    pub truth: Vec<f64>,
    /// The bicycle with the true values.
    pub set: ParamSet,
    /// Its wobble eigenvalue at each episode's speed, without noise.
    pub observations: Vec<Observation>,
    /// The scatter the episodes are weighted by (and noise is drawn at).
    pub weights: Weights,
}

impl Synthetic {
    /// `start` with its head stiffness 15 % higher and its head damping 20 %
    /// lower, observed at 3-8 m/s every 0.5 m/s (11 episodes) and weighted
    /// by 0.03 Hz and 0.1 1/s.
    ///
    /// # Errors
    /// A set without a steering head, or whose model has no wobble mode.
    pub fn steering_head(start: &ParamSet) -> Result<Self, ParamError> {
        let keys = vec![
            "steer_head.stiffness".to_string(),
            "steer_head.damping".to_string(),
        ];
        let mut set = start.clone();
        let mut truth = Vec::new();
        for (key, factor) in keys.iter().zip([1.15, 0.8]) {
            let value = factor * start.value(key)?;
            set.set_value(key, value, "synthetic truth")?;
            truth.push(value);
        }
        let speeds: Vec<f64> = (0..11).map(|i| 3.0 + 0.5 * f64::from(i)).collect();
        let observations = observations(&set, &speeds)?;
        Ok(Self {
            keys,
            truth,
            set,
            observations,
            weights: Weights {
                freq_sd_hz: 0.03,
                sigma_sd_per_s: 0.1,
            },
        })
    }
}

/// The wobble eigenvalue of `set` at each of `speeds_mps`, as episodes.
///
/// # Errors
/// A set the model refuses, or whose model has no wobble mode.
pub fn observations(set: &ParamSet, speeds_mps: &[f64]) -> Result<Vec<Observation>, ParamError> {
    let no_wobble = |why: String| set.error("", Problem::Unphysical(why));
    let wobble = mode_at(&Model::from_set(set)?, Mode::Wobble, speeds_mps)
        .map_err(|e| no_wobble(e.to_string()))?
        .ok_or_else(|| no_wobble("the model has no wobble mode".into()))?;
    Ok(speeds_mps
        .iter()
        .zip(&wobble)
        .map(|(&u, w)| Observation {
            speed_mps: u,
            freq_hz: w.im / std::f64::consts::TAU,
            sigma_per_s: w.re,
        })
        .collect())
}
