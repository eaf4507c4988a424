//! `wobblog margin --model PARAMS`: the model-informed estimate. Chosen
//! parameters of the wobble model (default the steering-head stiffness and
//! damping) are fitted to the kicks' sigma and frequency with the model
//! crate's fit (`wobble_model::fit`); the fitted model's wobble speed is
//! where its wobble mode's growth rate crosses zero, and its interval the
//! range of that speed over the corners of the fitted parameters' 95 %
//! intervals (conservative: the box holds the joint region).

use std::path::Path;

use serde::Serialize;
use wobble_model::fit::{fit, Estimate, Observation, Weights};
use wobble_model::{sweep::mode_at, Mode, Model, ParamSet};

use crate::cmd::model::{key_error, load_set, param_error};
use crate::CliError;

/// The parameters fitted unless others are named.
pub const DEFAULT_PARAMS: [&str; 2] = ["steer_head.stiffness", "steer_head.damping"];
/// Scatter of a kick's frequency that weights the fit, Hz.
const FREQ_SD_HZ: f64 = 0.05;
/// Speeds searched for the fitted model's wobble speed, m/s.
const SEARCH_MPS: (f64, f64, f64) = (0.5, 15.0, 0.05);

/// The model-informed estimate, as reported.
#[derive(Clone, Debug, Serialize)]
pub struct ModelEstimate {
    /// The fitted model's wobble speed, m/s.
    pub wobble_speed_mps: Option<f64>,
    /// Its 95 % interval, `hi` null where no corner crosses.
    pub ci95_mps: [Option<f64>; 2],
    /// Kicks fitted.
    pub kicks_used: usize,
    /// Kicks left out (the regression's rejects).
    pub kicks_rejected: usize,
    /// How it was made.
    pub method: String,
    /// The parameter file.
    pub params_file: String,
    /// Each fitted parameter with its 95 % half width.
    pub params: Vec<FittedParam>,
    /// RMS residuals of frequency (Hz) and sigma (1/s).
    pub rms_freq_hz: f64,
    /// See `rms_freq_hz`.
    pub rms_sigma_per_s: f64,
    /// The fitted model's sigma against speed `(u, sigma)`, for the figure.
    #[serde(skip)]
    pub curve: Vec<(f64, f64)>,
}

/// One fitted parameter.
#[derive(Clone, Debug, Serialize)]
pub struct FittedParam {
    /// Key in the file.
    pub key: String,
    /// Fitted value, in the file's unit.
    pub value: f64,
    /// Half width of its 95 % interval.
    pub ci95: f64,
    /// The unit.
    pub unit: String,
}

/// The wobble mode's growth rate of `set` over the search grid.
fn growth_curve(set: &ParamSet) -> Option<Vec<(f64, f64)>> {
    let model = Model::from_set(set).ok()?;
    let (lo, hi, step) = SEARCH_MPS;
    let speeds: Vec<f64> = (0..)
        .map(|i| lo + f64::from(i) * step)
        .take_while(|&u| u <= hi)
        .collect();
    let values = mode_at(&model, Mode::Wobble, &speeds).ok()??;
    Some(
        speeds
            .into_iter()
            .zip(values.iter().map(|v| v.re))
            .collect(),
    )
}

/// The first speed where `curve` crosses zero upwards (linear between).
fn crossing(curve: &[(f64, f64)]) -> Option<f64> {
    curve.windows(2).find_map(|w| {
        let ((u0, s0), (u1, s1)) = (w[0], w[1]);
        (s0 < 0.0 && s1 >= 0.0).then(|| u0 + (u1 - u0) * (-s0) / (s1 - s0))
    })
}

/// Fits `keys` of the file at `path` to `kicks` (speed, frequency, sigma,
/// sigma's uncertainty) and gives the fitted model's wobble speed.
pub fn estimate(
    path: &Path,
    keys: &[String],
    kicks: &[(f64, f64, f64, f64)],
    rejected: usize,
) -> Result<ModelEstimate, CliError> {
    let set = load_set(path)?;
    for key in keys {
        set.value(key).map_err(|e| key_error(&set, &e))?;
    }
    let obs: Vec<Observation> = kicks
        .iter()
        .map(|&(u, f, s, _)| Observation {
            speed_mps: u,
            freq_hz: f,
            sigma_per_s: s,
        })
        .collect();
    let mut sds: Vec<f64> = kicks.iter().map(|k| k.3).collect();
    sds.sort_by(f64::total_cmp);
    let sigma_sd = sds.get(sds.len() / 2).copied().unwrap_or(0.1).max(0.02);
    let weights = Weights {
        freq_sd_hz: FREQ_SD_HZ,
        sigma_sd_per_s: sigma_sd,
    };
    let result = fit(&set, keys, &obs, weights).map_err(|e| param_error(&e))?;
    let curve = growth_curve(&result.set).unwrap_or_default();
    let speed = crossing(&curve);
    // The wobble speed at every corner of the parameters' intervals.
    let corners: Vec<Option<f64>> = (0..1usize << keys.len())
        .map(|mask| {
            let mut corner = result.set.clone();
            for (k, e) in result.estimates.iter().enumerate() {
                let sign = if mask >> k & 1 == 1 { 1.0 } else { -1.0 };
                let v = (e.value + sign * e.ci95).max(1e-6 * e.value.abs());
                corner
                    .set_value(&e.key, v, "corner of the 95 % interval")
                    .ok()?;
            }
            growth_curve(&corner).as_deref().and_then(crossing)
        })
        .collect();
    let lo = corners
        .iter()
        .flatten()
        .copied()
        .fold(f64::INFINITY, f64::min);
    let hi = if corners.iter().all(Option::is_some) {
        corners.iter().flatten().copied().fold(0.0, f64::max)
    } else {
        f64::NAN
    };
    Ok(ModelEstimate {
        wobble_speed_mps: speed,
        ci95_mps: [lo.is_finite().then_some(lo), hi.is_finite().then_some(hi)],
        kicks_used: kicks.len(),
        kicks_rejected: rejected,
        method: format!(
            "model fit (wobble_model::fit, Levenberg-Marquardt) of {} to the kicks' sigma and \
             frequency (weights: {FREQ_SD_HZ} Hz, {sigma_sd:.3} 1/s, the kicks' median SD); the \
             fitted model's wobble-mode zero crossing; 95 % interval: range of the crossing over \
             the corners of the parameters' 95 % intervals",
            keys.join(", ")
        ),
        params_file: path.display().to_string(),
        params: result
            .estimates
            .iter()
            .map(|e: &Estimate| FittedParam {
                key: e.key.clone(),
                value: e.value,
                ci95: e.ci95,
                unit: e.unit.clone(),
            })
            .collect(),
        rms_freq_hz: result.rms_freq_hz,
        rms_sigma_per_s: result.rms_sigma_per_s,
        curve,
    })
}
