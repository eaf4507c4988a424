//! Least-squares fit of chosen parameters to measured wobble eigenvalues
//! (frequency and growth rate at the speed of each episode), by
//! Levenberg-Marquardt (`levenberg-marquardt` crate) on a central-difference
//! Jacobian, with confidence intervals from the covariance
//! `s^2 (J^T J)^-1` (normal approximation, `s^2` the reduced chi-square).
//!
//! Parameters are fitted as the logarithms of factors on the file's values:
//! every unknown is of order one whatever its unit, and a parameter never
//! changes sign (stiffnesses, dampings and masses stay physical). The
//! intervals are carried back to the values to first order.

use levenberg_marquardt::{LeastSquaresProblem, LevenbergMarquardt};
use nalgebra::{storage::Owned, DMatrix, DVector, Dyn};

use crate::model::Model;
use crate::params::{ParamError, ParamSet, Problem};
use crate::sweep::{mode_at, Mode};

/// One measured wobble episode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Observation {
    /// Speed at onset, m/s.
    pub speed_mps: f64,
    /// Frequency, Hz.
    pub freq_hz: f64,
    /// Growth rate (negative: decay), 1/s.
    pub sigma_per_s: f64,
}

/// Measurement scatter that weights the residuals.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Weights {
    /// Standard deviation of a measured frequency, Hz.
    pub freq_sd_hz: f64,
    /// Standard deviation of a measured growth rate, 1/s.
    pub sigma_sd_per_s: f64,
}

/// One fitted parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Estimate {
    /// Its name in the file.
    pub key: String,
    /// The fitted value, in the file's unit.
    pub value: f64,
    /// Half width of the 95 % confidence interval, in the file's unit.
    pub ci95: f64,
    /// The file's unit.
    pub unit: String,
}

/// What a fit found.
#[derive(Clone, Debug, PartialEq)]
pub struct FitResult {
    /// The parameter set with the fitted values.
    pub set: ParamSet,
    /// Each fitted parameter.
    pub estimates: Vec<Estimate>,
    /// RMS of the frequency residuals, Hz.
    pub rms_freq_hz: f64,
    /// RMS of the growth-rate residuals, 1/s.
    pub rms_sigma_per_s: f64,
    /// Model evaluations used.
    pub evaluations: usize,
}

/// Factor step of the central differences.
const STEP: f64 = 1e-4;
/// 97.5 % quantile of the normal distribution.
const Z_975: f64 = 1.959_963_984_540_054;

/// The least-squares problem: residuals of every episode at given factors.
struct EpisodeFit<'a> {
    base: &'a ParamSet,
    keys: &'a [String],
    start: Vec<f64>,
    obs: &'a [Observation],
    weights: Weights,
    factors: DVector<f64>,
    evaluations: std::cell::Cell<usize>,
}

impl EpisodeFit<'_> {
    fn set_at(&self, factors: &DVector<f64>) -> Result<ParamSet, ParamError> {
        let mut set = self.base.clone();
        for ((key, v0), f) in self.keys.iter().zip(&self.start).zip(factors.iter()) {
            set.set_value(key, v0 * f.exp(), "fitted to measured wobble episodes")?;
        }
        Ok(set)
    }

    fn residuals_at(&self, factors: &DVector<f64>) -> Option<DVector<f64>> {
        self.evaluations.set(self.evaluations.get() + 1);
        let model = Model::from_set(&self.set_at(factors).ok()?).ok()?;
        let speeds: Vec<f64> = self.obs.iter().map(|o| o.speed_mps).collect();
        let wobble = mode_at(&model, Mode::Wobble, &speeds).ok()??;
        let mut r = DVector::zeros(2 * self.obs.len());
        for (i, (o, w)) in self.obs.iter().zip(wobble).enumerate() {
            r[2 * i] = (o.freq_hz - w.im / std::f64::consts::TAU) / self.weights.freq_sd_hz;
            r[2 * i + 1] = (o.sigma_per_s - w.re) / self.weights.sigma_sd_per_s;
        }
        Some(r)
    }
}

impl LeastSquaresProblem<f64, Dyn, Dyn> for EpisodeFit<'_> {
    type ResidualStorage = Owned<f64, Dyn>;
    type JacobianStorage = Owned<f64, Dyn, Dyn>;
    type ParameterStorage = Owned<f64, Dyn>;

    fn set_params(&mut self, x: &DVector<f64>) {
        self.factors.copy_from(x);
    }

    fn params(&self) -> DVector<f64> {
        self.factors.clone()
    }

    fn residuals(&self) -> Option<DVector<f64>> {
        self.residuals_at(&self.factors)
    }

    fn jacobian(&self) -> Option<DMatrix<f64>> {
        let n = self.factors.len();
        let mut j = DMatrix::zeros(2 * self.obs.len(), n);
        for k in 0..n {
            let (mut hi, mut lo) = (self.factors.clone(), self.factors.clone());
            hi[k] += STEP;
            lo[k] -= STEP;
            let d = (self.residuals_at(&hi)? - self.residuals_at(&lo)?) / (2.0 * STEP);
            j.set_column(k, &d);
        }
        Some(j)
    }
}

/// Fits `keys` of `set` to `obs`: the model's eigenvalue named `wobble`
/// (followed from 0 m/s to each episode's speed) against each episode.
///
/// # Errors
/// A key not in the set, too few episodes, a model with no wobble mode at
/// the episodes' speeds, a search that did not converge, or parameters the
/// episodes do not determine ([`Problem::NotFitted`]).
pub fn fit(
    set: &ParamSet,
    keys: &[String],
    obs: &[Observation],
    weights: Weights,
) -> Result<FitResult, ParamError> {
    let start = keys
        .iter()
        .map(|k| set.value(k))
        .collect::<Result<Vec<f64>, _>>()?;
    if obs.len() * 2 <= keys.len() {
        return Err(set.error(
            "",
            Problem::Syntax(format!(
                "{} episodes cannot determine {} parameters",
                obs.len(),
                keys.len()
            )),
        ));
    }
    let problem = EpisodeFit {
        base: set,
        keys,
        start: start.clone(),
        obs,
        weights,
        factors: DVector::zeros(keys.len()),
        evaluations: std::cell::Cell::new(0),
    };
    let no_wobble = || {
        set.error(
            "",
            Problem::Unphysical("the model has no wobble mode at the episodes' speeds".into()),
        )
    };
    problem.residuals().ok_or_else(no_wobble)?;
    // A first step of at most a factor e^0.05 keeps the search on the
    // branch it starts on (the default bound of 100 is e^100 here).
    let (problem, report) = LevenbergMarquardt::new()
        .with_stepbound(0.05)
        .minimize(problem);
    let r = problem.residuals().ok_or_else(no_wobble)?;
    if !report.termination.was_successful() {
        return Err(set.error(
            "",
            Problem::NotFitted(format!(
                "the least-squares search did not converge ({:?}) after {} model evaluations",
                report.termination,
                problem.evaluations.get()
            )),
        ));
    }
    let j = problem.jacobian().ok_or_else(no_wobble)?;
    let dof = (r.len() - keys.len()).max(1) as f64;
    let s2 = r.norm_squared() / dof;
    let cov = (j.transpose() * &j)
        .try_inverse()
        .filter(|c| c.iter().all(|v| v.is_finite()))
        .map(|c| c * s2)
        .ok_or_else(|| {
            set.error(
                "",
                Problem::NotFitted(format!(
                    "the episodes do not determine {} (the wobble does not depend on them independently)",
                    keys.join(", ")
                )),
            )
        })?;
    let fitted = problem.set_at(&problem.factors)?;
    let estimates = keys
        .iter()
        .enumerate()
        .map(|(k, key)| {
            let value = start[k] * problem.factors[k].exp();
            Estimate {
                key: key.clone(),
                value,
                ci95: Z_975 * cov[(k, k)].max(0.0).sqrt() * value.abs(),
                unit: set
                    .quantity(key)
                    .map(|q| q.unit.clone())
                    .unwrap_or_default(),
            }
        })
        .collect();
    let rms = |offset: usize, sd: f64| {
        let sum: f64 = r
            .iter()
            .skip(offset)
            .step_by(2)
            .map(|v| (v * sd).powi(2))
            .sum();
        (sum / obs.len() as f64).sqrt()
    };
    Ok(FitResult {
        set: fitted,
        estimates,
        rms_freq_hz: rms(0, weights.freq_sd_hz),
        rms_sigma_per_s: rms(1, weights.sigma_sd_per_s),
        evaluations: problem.evaluations.get(),
    })
}
