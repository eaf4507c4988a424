//! The wobble speed predicted from kicks below it, by damping
//! extrapolation (the flutter-margin idea of flight testing): each kick's
//! ring-down gives the wobble mode's growth rate sigma at its speed, sigma
//! rises towards zero as the speed approaches the wobble speed, and the
//! trend's zero is the prediction.
//!
//! - **Trend**: a line bent by an assumed curvature, `sigma = a + b u +
//!   (k/2) u^2` with `a`, `b` fitted and `k` fixed ([`Trend::Line`], the
//!   default), or a quadratic `sigma = a + b u + c u^2` fitted whole
//!   ([`Trend::Quadratic`]). sigma bends mostly beyond the kicks, where no
//!   fit can see it, so the line takes a bend *shape* relative to the
//!   wobble speed ([`bend`], [`BendPrior`]: the curvature follows the
//!   prediction, so the same shape serves a bicycle wobbling at 3 m/s and
//!   one at 7 m/s) and its interval allows for a different one ([`Bend`]).
//! - **Fit** ([`fit`]): each kick's variance is its stated `sd^2` plus the
//!   between-kick variance `tau^2` of the true damping (a random effect,
//!   estimated after outlier rejection); outliers rejected by Tukey
//!   bisquare reweighting on that scale, from Siegel's repeated-median
//!   line (a quadratic: from Huber's).
//! - **Interval** ([`interval`]): profile likelihood. The 95 % interval of
//!   the zero `u*` is the set of speeds `u` at which the trend's value is
//!   not significantly different from zero: `f(u)^2 <= t^2 x(u)^T V x(u)`,
//!   `V` the fit's covariance, the bend allowance added, `t` Student's
//!   with `n - p` degrees of freedom (`n` kicks kept): for a line this is
//!   Fieller's interval. It is bounded only where the data bound it, so
//!   data that cannot bound the wobble speed give an open interval, and
//!   [`Margin::open_because`] says why.
//! - **Refusals**: fewer than [`MIN_KICKS`] kicks, a speed range narrower
//!   than [`MIN_SPAN_MPS`], or an extrapolation beyond the fastest kick
//!   longer than [`MAX_EXTRAPOLATION`] times the measured range: the
//!   result says so (`warnings`), and the interval's upper end is open.
//! - **Advice** ([`advice`]): the riding limit (the lower bound less a
//!   stated margin) and the highest speed for the next pass; a warning when
//!   sigma rises towards the slowest kicks (a low-speed wobble may lie
//!   below them).
//!
//! Assumption: sigma is smooth in speed, and bends between the kicks and
//! the wobble speed within the allowance.

pub mod advice;
pub mod bend;
pub mod fit;
pub mod interval;
#[cfg(test)]
mod tests;
pub mod weave;

use serde::Serialize;

pub use advice::{Advice, RIDE_MARGIN};
pub use bend::{Bend, BendPrior, BEND_SHAPE_MEAN, BEND_SHAPE_SD_CONCAVE, BEND_SHAPE_SD_CONVEX};
pub use fit::BISQUARE_C;
pub use interval::t_975;

use fit::robust_fit;
use interval::{profile_interval, slope, upward_zero, value, variance};

/// One kick as the regression sees it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KickPoint {
    /// Speed, m/s.
    pub speed_mps: f64,
    /// Growth rate, 1/s.
    pub sigma_per_s: f64,
    /// Standard uncertainty of sigma, 1/s.
    pub sigma_sd_per_s: f64,
    /// Frequency, Hz.
    pub freq_hz: f64,
}

impl From<&super::kicks::Kick> for KickPoint {
    fn from(k: &super::kicks::Kick) -> Self {
        Self {
            speed_mps: k.speed_mps,
            sigma_per_s: k.sigma_per_s,
            sigma_sd_per_s: k.sigma_sd_per_s,
            freq_hz: k.freq_hz,
        }
    }
}

impl From<&super::campaign_kicks::CampaignKick> for KickPoint {
    fn from(k: &super::campaign_kicks::CampaignKick) -> Self {
        Self {
            speed_mps: k.speed_mps,
            sigma_per_s: k.sigma_per_s,
            sigma_sd_per_s: k.sigma_sd_per_s,
            freq_hz: k.freq_hz,
        }
    }
}

/// The shape of sigma against speed the regression fits.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Trend {
    /// `sigma = a + b u + (k/2) u^2`, `a` and `b` fitted, `k` the
    /// curvature assumed ([`BendPrior`]), with an allowance for a
    /// different bend beyond the kicks ([`Bend`]).
    #[default]
    Line,
    /// `sigma = a + b u + c u^2`, all three fitted.
    Quadratic,
}

impl Trend {
    /// Coefficients fitted.
    #[must_use]
    pub const fn terms(self) -> usize {
        match self {
            Self::Line => 2,
            Self::Quadratic => 3,
        }
    }
}

/// The prediction.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Margin {
    /// The predicted wobble speed, m/s (`None` when the data give none).
    pub wobble_speed_mps: Option<f64>,
    /// Its 95 % interval; the upper end `None` when the data cannot bound
    /// it, both `None` without a prediction.
    pub ci95_mps: [Option<f64>; 2],
    /// Why the interval is open above, when it is.
    pub open_because: Option<String>,
    /// The riding limit and the next pass ([`advice`]).
    pub advice: Advice,
    /// Kicks the fit used (weight above zero).
    pub kicks_used: usize,
    /// Kicks it gave no weight (outliers) or could not use (unusable
    /// uncertainty, a growing ring).
    pub kicks_rejected: usize,
    /// How the prediction and its interval were made.
    pub method: String,
    /// The trend fitted.
    pub trend: Trend,
    /// Its coefficients `[a (1/s), b (1/s per m/s), c (1/s per (m/s)^2)]`
    /// (for the line `c` is fixed: half the curvature assumed), if any.
    pub coefficients: Option<Vec<f64>>,
    /// The fit's covariance of the fitted coefficients (rows; `a` and `b`
    /// for the line).
    pub covariance: Option<Vec<Vec<f64>>>,
    /// The kicks' scatter about the trend over their stated SDs alone
    /// (chi-square with weights `1 / sd^2` over the degrees of freedom):
    /// about 1 when they scatter as their uncertainties say.
    pub unit_variance: Option<f64>,
    /// The between-kick SD of the true damping, 1/s (`tau`).
    pub between_kick_sd_per_s: Option<f64>,
    /// The allowance for sigma's bend the line makes (none for a
    /// quadratic, which fits it).
    pub bend: Option<Bend>,
    /// Degrees of freedom of the t quantile.
    pub dof: usize,
    /// Speeds of the kicks used, slowest and fastest, m/s.
    pub speed_range_mps: Option<[f64; 2]>,
    /// Why the answer is weaker than it looks, in words.
    pub warnings: Vec<String>,
    /// Each input kick's final weight, `1 / (sd^2 + tau^2)` (0: rejected).
    pub weights: Vec<f64>,
}

impl Margin {
    /// The fitted trend at `u` with its 95 % band for a wobble speed at
    /// `u`: `(sigma, lo, hi)`; the band is moved by the bend the shape
    /// gives a wobble speed there ([`Bend::at`]).
    #[must_use]
    pub fn band(&self, u: f64) -> Option<(f64, f64, f64)> {
        let coef = self.coefficients.as_ref()?;
        let cov = self.covariance.as_ref()?;
        Some(band_at(coef, cov, self.bend.as_ref(), t_975(self.dof), u))
    }

    /// The fitted trend at `u` with the fit's own 95 % band, no bend
    /// allowed for: `(sigma, lo, hi)`.
    #[must_use]
    pub fn fit_band(&self, u: f64) -> Option<(f64, f64, f64)> {
        let coef = self.coefficients.as_ref()?;
        let cov = self.covariance.as_ref()?;
        Some(band_at(coef, cov, None, t_975(self.dof), u))
    }

    /// The riding limit and next pass for a riding margin of `fraction`
    /// of the lower bound ([`advice`]).
    pub fn set_riding_margin(&mut self, fraction: f64) {
        self.advice = advice::advise(self, fraction);
    }
}

/// The trend `coef` at `u` and its band of `t` standard uncertainties:
/// the fit's, and the bend's for a wobble speed at `u` ([`Bend::at`]).
fn band_at(coef: &[f64], cov: &[Vec<f64>], bend: Option<&Bend>, t: f64, u: f64) -> (f64, f64, f64) {
    let y = value(coef, u);
    let (shift, sd) = bend.map_or((0.0, 0.0), |b| b.at(u, y, -value(coef, 0.5 * u)));
    let half = t * (variance(cov, u).max(0.0) + sd * sd).sqrt();
    (y, y + shift - half, y + shift + half)
}

/// A prediction needs at least this many kicks.
pub const MIN_KICKS: usize = 6;
/// ... spread over at least this range of speed, m/s.
pub const MIN_SPAN_MPS: f64 = 0.75;
/// An extrapolation beyond the fastest kick longer than this times the
/// measured range is not trusted: the interval is left open above.
pub const MAX_EXTRAPOLATION: f64 = 1.0;
/// The interval is searched up to this many measured ranges beyond the
/// fastest kick; an end further out is open.
const SEARCH_RANGES: f64 = 4.0;
/// Rounds of the bend's curvature following the predicted wobble speed.
const BEND_ROUNDS: usize = 30;

/// The method, in words, as `wobblog margin` reports it.
#[must_use]
pub fn method(trend: Trend, prior: BendPrior) -> String {
    let shape = match trend {
        Trend::Line => "line",
        Trend::Quadratic => "quadratic",
    };
    let bend = match trend {
        Trend::Line => format!(
            ", the line bent by a shape relative to the wobble speed (k u*^2 / -sigma(u*/2) = \
             {}, SD {} towards convex, {} towards concave)",
            prior.mean, prior.sd_convex, prior.sd_concave
        ),
        Trend::Quadratic => String::new(),
    };
    let start = match trend {
        Trend::Line => "a repeated-median start",
        Trend::Quadratic => "Huber",
    };
    format!(
        "damping extrapolation: robust {shape} of sigma against speed (weights 1/(sd^2 + tau^2), \
         tau the between-kick SD by Paule-Mandel after {start} then Tukey bisquare rejection), \
         its zero; 95 % interval by profile likelihood (the speeds where the trend is not \
         significantly non-zero, t with n-{} dof{bend})",
        trend.terms()
    )
}

/// Predicts the wobble speed from `kicks` with the default trend.
#[must_use]
pub fn predict(kicks: &[KickPoint]) -> Margin {
    predict_with(kicks, Trend::default())
}

/// Predicts the wobble speed from `kicks` by fitting `trend` (a line with
/// the default [`BendPrior`]).
#[must_use]
pub fn predict_with(kicks: &[KickPoint], trend: Trend) -> Margin {
    predict_bent(kicks, trend, BendPrior::DEFAULT)
}

/// The kicks a fit can take: a positive finite speed, a finite growth
/// rate and a finite non-negative uncertainty.
fn usable(k: &KickPoint) -> bool {
    k.speed_mps.is_finite()
        && k.speed_mps > 0.0
        && k.sigma_per_s.is_finite()
        && k.sigma_sd_per_s.is_finite()
        && k.sigma_sd_per_s >= 0.0
}

/// The speed up to which the zero and the interval are searched, from
/// the slowest and fastest kicks.
fn search_cap(lo: f64, hi: f64) -> f64 {
    hi + SEARCH_RANGES * (hi - lo).max(MIN_SPAN_MPS)
}

/// The line's fit with the bend's curvature following the prediction:
/// fitted with half of `k` taken out, `k` from the prior at the fit's zero
/// and damping at half of it, until `k` settles (secant steps on `c`, the
/// first a plain one; or the trend has no zero: the last `k` that gave
/// one). The fit and `c = k/2`.
fn bent_line(
    (u, y, sd): (&[f64], &[f64], &[f64]),
    prior: BendPrior,
    cap: f64,
) -> Option<(fit::RobustFit, f64)> {
    let lo = u.iter().copied().fold(f64::INFINITY, f64::min);
    let fit_at = |c: f64| {
        let unbent: Vec<f64> = u.iter().zip(y).map(|(u, y)| y - c * u * u).collect();
        robust_fit(u, &unbent, sd, 2)
    };
    // What the prior asks of `c` given the fit made with `c`.
    let wanted = |fit: &fit::RobustFit, c: f64| {
        let coef = [fit.coef[0], fit.coef[1], c];
        let zero = upward_zero(&coef, lo, cap)?;
        Some(0.5 * prior.curvature(zero, -value(&coef, 0.5 * zero)).0)
    };
    let mut best = (fit_at(0.0)?, 0.0);
    let mut last: Option<(f64, f64)> = None;
    for _ in 0..BEND_ROUNDS {
        let c = best.1;
        let Some(next) = wanted(&best.0, c) else {
            break;
        };
        let r = next - c;
        if r.abs() <= 1e-7 * next.abs().max(1e-3) {
            break;
        }
        let step = match last {
            Some((c0, r0)) if (r - r0).abs() > 1e-15 => {
                let s = c - r * (c - c0) / (r - r0);
                if s.is_finite() {
                    s
                } else {
                    next
                }
            }
            _ => next,
        };
        last = Some((c, r));
        let fit = fit_at(step)?;
        if wanted(&fit, step).is_none() {
            break;
        }
        best = (fit, step);
    }
    Some(best)
}

/// Predicts the wobble speed from `kicks` by fitting `trend`, a line
/// assuming `prior` about sigma's bend (a quadratic ignores it).
#[must_use]
pub fn predict_bent(kicks: &[KickPoint], trend: Trend, prior: BendPrior) -> Margin {
    let usable: Vec<usize> = (0..kicks.len()).filter(|&i| usable(&kicks[i])).collect();
    let mut out = Margin {
        wobble_speed_mps: None,
        ci95_mps: [None, None],
        open_because: None,
        advice: Advice::default(),
        kicks_used: 0,
        kicks_rejected: kicks.len(),
        method: method(trend, prior),
        trend,
        coefficients: None,
        covariance: None,
        unit_variance: None,
        between_kick_sd_per_s: None,
        bend: None,
        dof: 0,
        speed_range_mps: None,
        warnings: Vec::new(),
        weights: vec![0.0; kicks.len()],
    };
    estimate(kicks, &usable, prior, &mut out);
    if out.ci95_mps[1].is_none() && out.open_because.is_none() {
        out.open_because = out.warnings.first().cloned();
    }
    out.set_riding_margin(RIDE_MARGIN);
    out
}

/// The estimate of [`predict_bent`] into `out`.
fn estimate(kicks: &[KickPoint], usable: &[usize], prior: BendPrior, out: &mut Margin) {
    let trend = out.trend;
    if usable.len() < MIN_KICKS {
        out.warnings.push(format!(
            "too few kicks: {} usable, a prediction needs at least {MIN_KICKS}",
            usable.len()
        ));
        return;
    }
    let u: Vec<f64> = usable.iter().map(|&i| kicks[i].speed_mps).collect();
    let y: Vec<f64> = usable.iter().map(|&i| kicks[i].sigma_per_s).collect();
    let sd: Vec<f64> = usable.iter().map(|&i| kicks[i].sigma_sd_per_s).collect();
    let (all_lo, all_hi) = u.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &u| {
        (lo.min(u), hi.max(u))
    });
    let fitted = match trend {
        Trend::Line => bent_line((&u, &y, &sd), prior, search_cap(all_lo, all_hi)),
        Trend::Quadratic => robust_fit(&u, &y, &sd, 3).map(|f| (f, 0.0)),
    };
    let Some((fit, c_prior)) = fitted else {
        out.warnings.push(format!(
            "the kicks' speeds do not spread enough to fit a {}",
            match trend {
                Trend::Line => "line",
                Trend::Quadratic => "quadratic (it needs three speeds or more)",
            }
        ));
        return;
    };
    for (k, &i) in usable.iter().enumerate() {
        out.weights[i] = fit.weights[k];
    }
    let used: Vec<usize> = (0..u.len()).filter(|&k| fit.weights[k] > 0.0).collect();
    out.kicks_used = used.len();
    out.kicks_rejected = kicks.len() - used.len();
    let (lo_u, hi_u) = used.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &k| {
        (lo.min(u[k]), hi.max(u[k]))
    });
    out.speed_range_mps = Some([lo_u, hi_u]);
    let coef = match trend {
        Trend::Line => vec![fit.coef[0], fit.coef[1], c_prior],
        Trend::Quadratic => fit.coef.clone(),
    };
    out.coefficients = Some(coef.clone());
    out.covariance = Some(fit.cov.clone());
    out.unit_variance = Some(fit.unit_variance);
    out.between_kick_sd_per_s = Some(fit.tau2.sqrt());
    out.dof = used.len().saturating_sub(trend.terms()).max(1);
    if used.len() < MIN_KICKS {
        out.warnings.push(format!(
            "too few kicks: {} carry weight, a prediction needs at least {MIN_KICKS}",
            used.len()
        ));
        return;
    }
    if let Some(w) = advice::low_speed_rise(&u, &y, &fit.weights) {
        out.warnings.push(w);
    }
    let span = hi_u - lo_u;
    let cap = search_cap(lo_u, hi_u);
    let zero = upward_zero(&coef, lo_u, cap);
    if trend == Trend::Line {
        let w = &fit.weights;
        let sw: f64 = w.iter().sum();
        let mean = u.iter().zip(w).map(|(u, w)| u * w).sum::<f64>() / sw;
        let var_u = u
            .iter()
            .zip(w)
            .map(|(u, w)| w * (u - mean).powi(2))
            .sum::<f64>()
            / sw;
        out.bend = Some(Bend {
            mean_mps: mean,
            variance_mps2: var_u,
            prior_per_s_mps2: 2.0 * c_prior,
            shape: prior,
        });
    }
    let bend = out.bend.clone();
    let t = t_975(out.dof);
    // The speeds the data allow as the wobble speed.
    let inside = |v: f64| {
        let (_, lo, hi) = band_at(&coef, &fit.cov, bend.as_ref(), t, v);
        lo <= 0.0 && 0.0 <= hi
    };
    let rising = slope(&coef, hi_u);
    let step = span.max(MIN_SPAN_MPS) / 400.0;
    let Some(zero) = zero else {
        if rising.is_nan() || rising <= 0.0 {
            out.warnings.push(format!(
                "sigma does not rise with speed at the fastest kicks ({rising:.3} 1/s per m/s): \
                 no wobble speed ahead"
            ));
        } else {
            out.warnings
                .push("the trend does not reach zero within the speeds searched".into());
            // What the data still say: the speeds from the fastest kick up
            // at which the trend could be zero.
            out.ci95_mps[0] = (0..=((cap - hi_u) / step) as usize)
                .map(|i| hi_u + step * i as f64)
                .find(|&v| inside(v));
        }
        return;
    };
    out.wobble_speed_mps = Some(zero);
    let mut open = Vec::new();
    if span < MIN_SPAN_MPS {
        open.push(format!(
            "narrow speed range: {lo_u:.2}-{hi_u:.2} m/s, at least {MIN_SPAN_MPS} m/s needed"
        ));
    }
    let reach = zero - hi_u;
    if reach > MAX_EXTRAPOLATION * span {
        open.push(format!(
            "long extrapolation: {reach:.2} m/s beyond the fastest kick, over {:.1} times the \
             measured range ({span:.2} m/s); kick closer to the prediction's lower bound",
            reach / span.max(1e-9)
        ));
    }
    let (lo, hi) = profile_interval(inside, zero, (step, cap));
    out.ci95_mps = [lo, hi.filter(|_| open.is_empty())];
    if hi.is_none() {
        // A trend within its noise puts the zero anywhere beyond the lower
        // bound: no point estimate is given.
        out.wobble_speed_mps = None;
        open.push(
            "the rise of sigma with speed is not significant against its noise and the bend \
             allowed for (the band holds zero up to the \
             end of the search): only a lower bound"
                .into(),
        );
    }
    if !open.is_empty() {
        out.open_because = Some(open.join("; "));
    }
    out.warnings.extend(open);
}
