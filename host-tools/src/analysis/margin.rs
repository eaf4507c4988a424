//! The wobble speed predicted from kicks below it, by damping
//! extrapolation (the flutter-margin idea of flight testing): each kick's
//! ring-down gives the wobble mode's growth rate sigma at its speed, sigma
//! rises towards zero as the speed approaches the wobble speed, and the
//! trend's zero is the prediction.
//!
//! - **Trend**: a line bent by the model's curvature, `sigma = a + b u +
//!   (k/2) u^2` with `a`, `b` fitted and `k` fixed ([`Trend::Line`], the
//!   default), or a quadratic `sigma = a + b u + c u^2` fitted whole
//!   ([`Trend::Quadratic`]). sigma bends: on the model's bicycles its
//!   slope falls by about a quarter between half the wobble speed and the
//!   wobble speed, mostly beyond the kicks, where no fit can see it, so a
//!   straight line through kicks at 0.45-0.85 of it crosses zero early.
//!   The line takes the model's concave bend ([`BEND_MEAN_PER_S_MPS2`])
//!   and its interval allows for a bend that differs from it
//!   ([`Bend`], [`BEND_SD_PER_S_MPS2`]); a quadratic fitted to the kicks
//!   extrapolates the small bend it sees within their range and its
//!   noise, and does worse on the simulated campaigns
//!   (`host-tools/docs/kick-testing.md`).
//! - **Fit**: weighted by each kick's uncertainty (`1 / sd^2`) and made
//!   robust by iteratively reweighted least squares, Huber's weights first
//!   (a convex problem, so one far-off kick cannot pull the start away),
//!   then Tukey's bisquare from there: a kick more than [`BISQUARE_C`]
//!   scales off the trend (scale from the median absolute deviation of the
//!   standardised residuals, never below the stated uncertainties) gets no
//!   weight and is counted as rejected, so one bad kick cannot move the
//!   answer.
//! - **Interval**: profile likelihood. The 95 % interval of the zero `u*`
//!   is the set of speeds `u` at which the trend's value is not
//!   significantly different from zero: `f(u)^2 <= t^2 x(u)^T V x(u)`, with
//!   `x(u) = (1, u, u^2)`, `V` the fit's covariance scaled by the
//!   residuals' variance of unit weight (lack of fit widens it; never
//!   below 1), the line's bend allowance added to that variance, and `t`
//!   Student's with `n - p` degrees of freedom: for a line
//!   this is Fieller's interval. It is bounded only where the data bound
//!   it, so data that cannot bound the wobble speed give an open interval
//!   rather than a made-up one.
//! - **Refusals**: fewer than [`MIN_KICKS`] kicks, a speed range narrower
//!   than [`MIN_SPAN_MPS`], or an extrapolation beyond the fastest kick
//!   longer than [`MAX_EXTRAPOLATION`] times the measured range: the
//!   result says so (`warnings`), and the interval's upper end is open.
//!
//! Assumption: sigma is smooth in speed, and bends between the kicks and
//! the wobble speed by no more than the allowance.

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

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
    /// for the line), scaled by the residuals' variance of unit weight.
    pub covariance: Option<Vec<Vec<f64>>>,
    /// The residuals' variance of unit weight (chi-square over the degrees
    /// of freedom of the kicks used): about 1 when the kicks scatter as
    /// their uncertainties say.
    pub unit_variance: Option<f64>,
    /// The allowance for sigma's bend the line makes (none for a
    /// quadratic, which fits it).
    pub bend: Option<Bend>,
    /// Degrees of freedom of the t quantile.
    pub dof: usize,
    /// Speeds of the kicks used, slowest and fastest, m/s.
    pub speed_range_mps: Option<[f64; 2]>,
    /// Why the answer is weaker than it looks, in words.
    pub warnings: Vec<String>,
    /// Each input kick's final weight (0: rejected).
    pub weights: Vec<f64>,
}

impl Margin {
    /// The fitted trend at `u` with its 95 % band: `(sigma, lo, hi)`.
    #[must_use]
    pub fn band(&self, u: f64) -> Option<(f64, f64, f64)> {
        let coef = self.coefficients.as_ref()?;
        let cov = self.covariance.as_ref()?;
        let y = value(coef, u);
        let half = t_975(self.dof) * total_variance(cov, self.bend.as_ref(), u).sqrt();
        Some((y, y - half, y + half))
    }
}

/// The allowance the line makes for sigma's bend: its curvature
/// `k` is taken as unknown, `prior_per_s_mps2` (the bend the trend is
/// given, [`BendPrior`]) with standard deviation `sd_per_s_mps2`. A line
/// fitted by least squares to `a + b u + (d/2) u^2` is off at `u` by
/// exactly `(d/2) ((u - m)^2 - v)`, `m` and `v` the weighted mean and
/// variance of the kicks' speeds (the line absorbs the rest); the kicks
/// are fitted with the prior's bend taken out, so `d` is the curvature's
/// departure from the prior and the trend's value at `u` is uncertain by
/// that much more: in quadrature, `(sd/2) |(u - m)^2 - v|`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Bend {
    /// Weighted mean speed of the kicks used, m/s.
    pub mean_mps: f64,
    /// Weighted variance of their speeds, (m/s)^2.
    pub variance_mps2: f64,
    /// The curvature the trend is bent by, 1/s per (m/s)^2.
    pub prior_per_s_mps2: f64,
    /// Standard deviation of the curvature about it, 1/s per (m/s)^2.
    pub sd_per_s_mps2: f64,
}

/// What the line assumes about sigma's curvature beyond the kicks:
/// a curvature `mean_per_s_mps2` (the trend is `a + b u + (mean/2) u^2`,
/// `a` and `b` fitted), uncertain with standard deviation
/// `sd_per_s_mps2` ([`Bend`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BendPrior {
    /// Curvature assumed, 1/s per (m/s)^2.
    pub mean_per_s_mps2: f64,
    /// Its standard deviation, 1/s per (m/s)^2.
    pub sd_per_s_mps2: f64,
}

impl BendPrior {
    /// The default: the model's bend ([`BEND_MEAN_PER_S_MPS2`],
    /// [`BEND_SD_PER_S_MPS2`]).
    pub const DEFAULT: Self = Self {
        mean_per_s_mps2: BEND_MEAN_PER_S_MPS2,
        sd_per_s_mps2: BEND_SD_PER_S_MPS2,
    };
    /// No bend assumed, only allowed for, of either sign and the model's
    /// size: a straight line, as `wobblog margin` fitted it before it used
    /// the bend's sign.
    pub const UNSIGNED: Self = Self {
        mean_per_s_mps2: 0.0,
        sd_per_s_mps2: -BEND_MEAN_PER_S_MPS2,
    };
}

impl Bend {
    /// The standard uncertainty it adds to the trend's value at `u`, 1/s.
    #[must_use]
    pub fn sd_at(&self, u: f64) -> f64 {
        0.5 * self.sd_per_s_mps2 * ((u - self.mean_mps).powi(2) - self.variance_mps2).abs()
    }
}

/// The variance of the trend's value at `u`: the fit's, plus the bend's.
fn total_variance(cov: &[Vec<f64>], bend: Option<&Bend>, u: f64) -> f64 {
    variance(cov, u).max(0.0) + bend.map_or(0.0, |b| b.sd_at(u).powi(2))
}

/// A prediction needs at least this many kicks.
pub const MIN_KICKS: usize = 6;
/// ... spread over at least this range of speed, m/s.
pub const MIN_SPAN_MPS: f64 = 0.75;
/// An extrapolation beyond the fastest kick longer than this times the
/// measured range is not trusted: the interval is left open above.
pub const MAX_EXTRAPOLATION: f64 = 1.0;
/// Tukey's bisquare constant (95 % efficiency for Gaussian scatter).
pub const BISQUARE_C: f64 = 4.685;
/// Huber's constant (95 % efficiency), for the robust start.
const HUBER_K: f64 = 1.345;
/// Floor of a kick's uncertainty, 1/s: no kick is weighted as exact.
const MIN_SD_PER_S: f64 = 0.02;
/// IRLS iterations of each stage (each converges in a handful).
const ITERATIONS: usize = 50;
/// The curvature the line is bent by, 1/s per (m/s)^2 (see [`BendPrior`]).
/// On the wobble model's bicycles of the simulated campaigns sigma is
/// concave: its slope falls from 0.44, 0.37, 0.43 and 0.46 1/s per m/s at
/// 0.45 of the wobble speed to 0.34, 0.27, 0.33 and 0.39 at the wobble
/// speed, a mean curvature of -0.046, -0.037, -0.044 and -0.037 (`cargo
/// run -p wobble-hil --release --example wobble_bend`), rounded here. It
/// takes out the bias a straight line has (its zero falls early by about
/// 2.4 %).
pub const BEND_MEAN_PER_S_MPS2: f64 = -0.04;
/// The standard deviation of the curvature about [`BEND_MEAN_PER_S_MPS2`],
/// 1/s per (m/s)^2 (see [`Bend`]): half its size, so that the allowance
/// holds a concave bend from none (a straight trend) to twice the model's
/// at two SD. A convex bend (sigma steepening towards the wobble speed)
/// is outside it.
pub const BEND_SD_PER_S_MPS2: f64 = 0.02;
/// The interval is searched up to this many measured ranges beyond the
/// fastest kick; an end further out is open.
const SEARCH_RANGES: f64 = 4.0;

/// The method, in words, as `wobblog margin` reports it.
#[must_use]
pub fn method(trend: Trend) -> String {
    let shape = match trend {
        Trend::Line => "line",
        Trend::Quadratic => "quadratic",
    };
    let bend = match trend {
        Trend::Line => format!(
            ", the line bent by sigma's curvature on the model's bicycles \
             ({BEND_MEAN_PER_S_MPS2} 1/s per (m/s)^2, SD {BEND_SD_PER_S_MPS2})"
        ),
        Trend::Quadratic => String::new(),
    };
    format!(
        "damping extrapolation: robust {shape} of sigma against speed (weights 1/sd^2, Huber \
         then Tukey bisquare IRLS), its zero; 95 % interval by profile likelihood (the speeds \
         where the trend is not significantly non-zero, t with n-{} dof, covariance scaled by \
         the lack of fit{bend})",
        trend.terms()
    )
}

/// 97.5 % quantile of Student's t with `dof` degrees of freedom (the
/// Cornish-Fisher expansion about the normal quantile; within 0.2 % of the
/// tables from 3 degrees of freedom on).
#[must_use]
pub fn t_975(dof: usize) -> f64 {
    let z: f64 = 1.959_963_984_540_054;
    let n = dof.max(1) as f64;
    let (z3, z5, z7) = (z.powi(3), z.powi(5), z.powi(7));
    z + (z3 + z) / (4.0 * n)
        + (5.0 * z5 + 16.0 * z3 + 3.0 * z) / (96.0 * n * n)
        + (3.0 * z7 + 19.0 * z5 + 17.0 * z3 - 15.0 * z) / (384.0 * n * n * n)
}

/// `(1, u, u^2, ...)` for `terms` coefficients.
fn powers(u: f64, terms: usize) -> impl Iterator<Item = f64> {
    std::iter::successors(Some(1.0), move |p| Some(p * u)).take(terms)
}

/// The polynomial `coef` at `u`.
fn value(coef: &[f64], u: f64) -> f64 {
    coef.iter()
        .zip(powers(u, coef.len()))
        .map(|(c, p)| c * p)
        .sum()
}

/// Its slope at `u`.
fn slope(coef: &[f64], u: f64) -> f64 {
    coef.iter()
        .enumerate()
        .skip(1)
        .map(|(k, c)| k as f64 * c * u.powi(k as i32 - 1))
        .sum()
}

/// `x(u)^T V x(u)`: the variance of the fitted value at `u`.
fn variance(cov: &[Vec<f64>], u: f64) -> f64 {
    let x: Vec<f64> = powers(u, cov.len()).collect();
    cov.iter()
        .zip(&x)
        .map(|(row, xi)| xi * row.iter().zip(&x).map(|(v, xj)| v * xj).sum::<f64>())
        .sum()
}

/// Weighted least squares polynomial of `terms` coefficients through
/// `(u, y)` with weights `w`: the coefficients and `(X^T W X)^-1`. Speeds
/// are centred and scaled for the solve (so the normal matrix is well
/// conditioned), then mapped back.
fn weighted_poly(
    u: &[f64],
    y: &[f64],
    w: &[f64],
    terms: usize,
) -> Option<(Vec<f64>, DMatrix<f64>)> {
    let sw: f64 = w.iter().sum();
    if sw.is_nan() || sw <= 0.0 {
        return None;
    }
    let mid = u.iter().zip(w).map(|(u, w)| u * w).sum::<f64>() / sw;
    let half = u.iter().map(|u| (u - mid).abs()).fold(0.0, f64::max);
    if half.is_nan() || half <= 1e-9 {
        return None;
    }
    let x = DMatrix::from_fn(u.len(), terms, |i, k| ((u[i] - mid) / half).powi(k as i32));
    let xtw = DMatrix::from_fn(terms, u.len(), |k, i| x[(i, k)] * w[i]);
    let normal = &xtw * &x;
    let inv = normal.clone().cholesky()?.inverse();
    // A design that barely spans the terms (all weight on two speeds for a
    // quadratic) is no fit.
    let cond = normal.norm() * inv.norm();
    if cond.is_nan() || cond > 1e12 {
        return None;
    }
    let scaled = &inv * (&xtw * DVector::from_column_slice(y));
    // Back from z = (u - mid) / half to u: z^k = sum_j C(k, j) u^j
    // (-mid)^(k-j) / half^k, a linear map M with coef = M^T scaled.
    let m = DMatrix::from_fn(terms, terms, |k, j| {
        if j > k {
            0.0
        } else {
            binomial(k, j) * (-mid).powi((k - j) as i32) / half.powi(k as i32)
        }
    });
    let coef = m.transpose() * scaled;
    let cov = m.transpose() * inv * &m;
    Some((coef.iter().copied().collect(), cov))
}

fn binomial(n: usize, k: usize) -> f64 {
    (0..k).fold(1.0, |acc, i| acc * (n - i) as f64 / (i + 1) as f64)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => v[n / 2],
        _ => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// The robust fit: coefficients, scaled covariance, unit variance and
/// final weights.
struct RobustFit {
    coef: Vec<f64>,
    cov: Vec<Vec<f64>>,
    unit_variance: f64,
    weights: Vec<f64>,
}

/// IRLS from `coef` with the weight function `rho` of the residual in
/// units of `c` robust scales.
fn irls(
    data: (&[f64], &[f64], &[f64]),
    mut coef: Vec<f64>,
    c: f64,
    rho: fn(f64) -> f64,
) -> Option<(Vec<f64>, Vec<f64>)> {
    let (u, y, base) = data;
    let terms = coef.len();
    let mut w = base.to_vec();
    for _ in 0..ITERATIONS {
        // Residuals in units of each kick's own uncertainty.
        let z: Vec<f64> = (0..u.len())
            .map(|i| (y[i] - value(&coef, u[i])) * base[i].sqrt())
            .collect();
        // MAD scale (consistent for Gaussian scatter), never below the
        // stated uncertainties: a trend through the points is no reason to
        // trust them more than they say.
        let scale = (1.482_6 * median(z.iter().map(|v| v.abs()).collect())).max(1.0);
        w = z
            .iter()
            .zip(base)
            .map(|(z, b)| b * rho(z / (c * scale)))
            .collect();
        let (next, _) = weighted_poly(u, y, &w, terms)?;
        let moved: f64 = next.iter().zip(&coef).map(|(a, b)| (a - b).abs()).sum();
        coef = next;
        if moved < 1e-10 {
            break;
        }
    }
    Some((coef, w))
}

fn huber(r: f64) -> f64 {
    if r.abs() <= 1.0 {
        1.0
    } else {
        1.0 / r.abs()
    }
}

fn bisquare(r: f64) -> f64 {
    if r.abs() < 1.0 {
        (1.0 - r * r).powi(2)
    } else {
        0.0
    }
}

fn robust_fit(u: &[f64], y: &[f64], sd: &[f64], terms: usize) -> Option<RobustFit> {
    let base: Vec<f64> = sd
        .iter()
        .map(|s| 1.0 / s.max(MIN_SD_PER_S).powi(2))
        .collect();
    let (start, _) = weighted_poly(u, y, &base, terms)?;
    let (start, _) = irls((u, y, &base), start, HUBER_K, huber)?;
    let (coef, w) = irls((u, y, &base), start, BISQUARE_C, bisquare)?;
    let (_, inv) = weighted_poly(u, y, &w, terms)?;
    // Residual variance of unit weight from the weighted residuals, with
    // the degrees of freedom of the kicks that carry weight.
    let used = w.iter().filter(|w| **w > 0.0).count();
    let dof = used.saturating_sub(terms).max(1) as f64;
    let chi2 = (0..u.len())
        .map(|i| w[i] * (y[i] - value(&coef, u[i])).powi(2))
        .sum::<f64>();
    let s2 = chi2 / dof;
    // Never below what the kicks' own uncertainties give (unit weight).
    let scale = s2.max(1.0);
    let cov = (0..terms)
        .map(|r| (0..terms).map(|c| inv[(r, c)] * scale).collect())
        .collect();
    Some(RobustFit {
        coef,
        cov,
        unit_variance: s2,
        weights: w,
    })
}

/// The lowest speed above `from` where `coef` crosses zero upwards, if it
/// does below `to`.
fn upward_zero(coef: &[f64], from: f64, to: f64) -> Option<f64> {
    let steps = 2000;
    let h = (to - from) / f64::from(steps);
    let mut prev = (from, value(coef, from));
    if prev.1 >= 0.0 {
        // Already at or above zero at the slowest kick: the zero, if the
        // trend rises through it, lies below; look no further.
        return None;
    }
    for i in 1..=steps {
        let u = from + h * f64::from(i);
        let v = value(coef, u);
        if v >= 0.0 {
            return Some(bisect(|x| value(coef, x) < 0.0, prev.0, u));
        }
        prev = (u, v);
    }
    None
}

/// The boundary between `lo` (where `inside` holds) and `hi` (where it
/// does not), to 1e-9 m/s.
fn bisect(inside: impl Fn(f64) -> bool, mut lo: f64, mut hi: f64) -> f64 {
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if inside(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
        if (hi - lo).abs() < 1e-9 {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// The profile-likelihood interval around `zero`: the connected set of
/// speeds with `f(u)^2 <= t^2 var(u)` that holds it, searched down to 0
/// and up to `cap` on a grid of `step`; an end not found is `None`.
fn profile_interval(
    coef: &[f64],
    var: impl Fn(f64) -> f64,
    t: f64,
    zero: f64,
    (step, cap): (f64, f64),
) -> (Option<f64>, Option<f64>) {
    let inside = |u: f64| value(coef, u).powi(2) <= t * t * var(u);
    let walk = |dir: f64, limit: f64| {
        let mut u = zero;
        loop {
            let next = u + dir * step;
            if (dir < 0.0 && next <= limit) || (dir > 0.0 && next >= limit) {
                return None;
            }
            if !inside(next) {
                return Some(bisect(inside, u, next));
            }
            u = next;
        }
    };
    (walk(-1.0, 0.0), walk(1.0, cap))
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

/// Predicts the wobble speed from `kicks` by fitting `trend`, a line
/// assuming `prior` about sigma's curvature (a quadratic ignores it).
#[must_use]
pub fn predict_bent(kicks: &[KickPoint], trend: Trend, prior: BendPrior) -> Margin {
    let usable: Vec<usize> = (0..kicks.len())
        .filter(|&i| {
            let k = &kicks[i];
            k.speed_mps.is_finite()
                && k.speed_mps > 0.0
                && k.sigma_per_s.is_finite()
                && k.sigma_sd_per_s.is_finite()
                && k.sigma_sd_per_s >= 0.0
        })
        .collect();
    let mut out = Margin {
        wobble_speed_mps: None,
        ci95_mps: [None, None],
        kicks_used: 0,
        kicks_rejected: kicks.len(),
        method: method(trend),
        trend,
        coefficients: None,
        covariance: None,
        unit_variance: None,
        bend: None,
        dof: 0,
        speed_range_mps: None,
        warnings: Vec::new(),
        weights: vec![0.0; kicks.len()],
    };
    if usable.len() < MIN_KICKS {
        out.warnings.push(format!(
            "too few kicks: {} usable, a prediction needs at least {MIN_KICKS}",
            usable.len()
        ));
        return out;
    }
    let u: Vec<f64> = usable.iter().map(|&i| kicks[i].speed_mps).collect();
    let y: Vec<f64> = usable.iter().map(|&i| kicks[i].sigma_per_s).collect();
    let sd: Vec<f64> = usable.iter().map(|&i| kicks[i].sigma_sd_per_s).collect();
    // The line is fitted to the kicks with the prior's bend taken out, then
    // bent back: `c` of `a + b u + c u^2` is fixed at half the curvature.
    let c_prior = match trend {
        Trend::Line => 0.5 * prior.mean_per_s_mps2,
        Trend::Quadratic => 0.0,
    };
    let unbent: Vec<f64> = u.iter().zip(&y).map(|(u, y)| y - c_prior * u * u).collect();
    let Some(fit) = robust_fit(&u, &unbent, &sd, trend.terms()) else {
        out.warnings.push(format!(
            "the kicks' speeds do not spread enough to fit a {}",
            match trend {
                Trend::Line => "line",
                Trend::Quadratic => "quadratic (it needs three speeds or more)",
            }
        ));
        return out;
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
    out.dof = used.len().saturating_sub(trend.terms()).max(1);
    if used.len() < MIN_KICKS {
        out.warnings.push(format!(
            "too few kicks: {} carry weight, a prediction needs at least {MIN_KICKS}",
            used.len()
        ));
        return out;
    }
    if trend == Trend::Line {
        let w: Vec<f64> = fit.weights.clone();
        let sw: f64 = w.iter().sum();
        let mean = u.iter().zip(&w).map(|(u, w)| u * w).sum::<f64>() / sw;
        let var_u = u
            .iter()
            .zip(&w)
            .map(|(u, w)| w * (u - mean).powi(2))
            .sum::<f64>()
            / sw;
        out.bend = Some(Bend {
            mean_mps: mean,
            variance_mps2: var_u,
            prior_per_s_mps2: prior.mean_per_s_mps2,
            sd_per_s_mps2: prior.sd_per_s_mps2,
        });
    }
    let bend = out.bend.clone();
    let var = |v: f64| total_variance(&fit.cov, bend.as_ref(), v);
    let span = hi_u - lo_u;
    let cap = hi_u + SEARCH_RANGES * span.max(MIN_SPAN_MPS);
    let rising = slope(&coef, hi_u);
    let zero = upward_zero(&coef, lo_u, cap);
    let t = t_975(out.dof);
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
        }
        // What the data still say: the speeds from the fastest kick up at
        // which the trend could be zero.
        let inside = |v: f64| value(&coef, v).powi(2) <= t * t * var(v);
        out.ci95_mps[0] = (0..=((cap - hi_u) / step) as usize)
            .map(|i| hi_u + step * i as f64)
            .find(|&v| inside(v));
        return out;
    };
    out.wobble_speed_mps = Some(zero);
    let mut open = false;
    if span < MIN_SPAN_MPS {
        out.warnings.push(format!(
            "narrow speed range: {lo_u:.2}-{hi_u:.2} m/s, at least {MIN_SPAN_MPS} m/s needed"
        ));
        open = true;
    }
    let reach = zero - hi_u;
    if reach > MAX_EXTRAPOLATION * span {
        out.warnings.push(format!(
            "long extrapolation: {reach:.2} m/s beyond the fastest kick, over {:.1} times the \
             measured range ({span:.2} m/s); kick closer to the prediction's lower bound",
            reach / span.max(1e-9)
        ));
        open = true;
    }
    let (lo, hi) = profile_interval(&coef, var, t, zero, (step, cap));
    out.ci95_mps = [lo, hi.filter(|_| !open)];
    if hi.is_none() {
        // A trend within its noise puts the zero anywhere beyond the lower
        // bound: no point estimate is given.
        out.wobble_speed_mps = None;
        out.warnings
            .push("the rise of sigma with speed is not significant: only a lower bound".into());
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn kicks(points: &[(f64, f64)], sd: f64) -> Vec<KickPoint> {
        points
            .iter()
            .map(|&(u, s)| KickPoint {
                speed_mps: u,
                sigma_per_s: s,
                sigma_sd_per_s: sd,
                freq_hz: 7.0,
            })
            .collect()
    }

    /// Published reference: Student's t 97.5 % quantiles (Fisher and
    /// Yates tables): 2.571 (5), 2.228 (10), 2.086 (20), 2.042 (30).
    #[test]
    fn t_quantile_matches_the_tables() {
        for (dof, want) in [(5, 2.5706), (10, 2.2281), (20, 2.0860), (30, 2.0423)] {
            assert!((t_975(dof) - want).abs() < 0.005, "{dof}: {}", t_975(dof));
        }
    }

    /// Exact points on a line: both trends give the line's zero, the
    /// interval tight (the line assuming no bend).
    #[test]
    fn exact_line_gives_its_zero() {
        let pts: Vec<(f64, f64)> = (0..10)
            .map(|i| {
                let u = 2.0 + 0.2 * f64::from(i);
                (u, 1.5 * (u - 4.2))
            })
            .collect();
        for trend in [Trend::Line, Trend::Quadratic] {
            let m = predict_bent(&kicks(&pts, 0.05), trend, BendPrior::UNSIGNED);
            let w = m.wobble_speed_mps.unwrap();
            assert!((w - 4.2).abs() < 1e-6, "{m:?}");
            let [lo, hi] = m.ci95_mps;
            assert!(lo.unwrap() < 4.2 && hi.unwrap() > 4.2, "{m:?}");
            assert!(hi.unwrap() - lo.unwrap() < 0.5, "{m:?}");
            assert_eq!((m.kicks_used, m.kicks_rejected), (10, 0));
        }
    }

    /// Points on a bent trend, `sigma = -0.25 (u - 4.2)(u - 9)` (its slope
    /// falls by a third over the kicks): the quadratic finds its zero, the
    /// line crosses early and its interval misses it.
    #[test]
    fn a_bent_trend_needs_the_quadratic() {
        let pts: Vec<(f64, f64)> = (0..18)
            .map(|i| {
                let u = 1.9 + 0.1 * f64::from(i);
                (u, -0.25 * (u - 4.2) * (u - 9.0))
            })
            .collect();
        let q = predict_with(&kicks(&pts, 0.03), Trend::Quadratic);
        assert!((q.wobble_speed_mps.unwrap() - 4.2).abs() < 1e-6, "{q:?}");
        let c = q.coefficients.as_ref().unwrap();
        assert!((c[2] + 0.25).abs() < 1e-9, "{c:?}");
        let line = predict_with(&kicks(&pts, 0.03), Trend::Line);
        let w = line.wobble_speed_mps.unwrap();
        assert!(w < 4.1, "{line:?}");
    }

    /// Exact points on a trend bent as the prior says, `0.4 (u - 4.2) +
    /// (k/2) (u - 4.2)^2` with the prior's `k`, at 0.45-0.85 of its zero:
    /// the default line finds the zero, its coefficients are the trend's,
    /// and the interval holds it; a line assuming no bend crosses early,
    /// by the 2-3 % the model's bicycles show.
    #[test]
    fn the_prior_bend_takes_out_the_lines_bias() {
        let (zero, k) = (4.2, BEND_MEAN_PER_S_MPS2);
        let pts: Vec<(f64, f64)> = (0..18)
            .map(|i| {
                let u = zero * (0.45 + 0.4 * f64::from(i / 2) / 8.0);
                (u, 0.4 * (u - zero) + 0.5 * k * (u - zero).powi(2))
            })
            .collect();
        let m = predict(&kicks(&pts, 0.03));
        assert!((m.wobble_speed_mps.unwrap() - zero).abs() < 1e-6, "{m:?}");
        let c = m.coefficients.as_ref().unwrap();
        // Expanded: a = -0.4 zero + (k/2) zero^2, b = 0.4 - k zero, c = k/2.
        let want = [-0.4 * zero + 0.5 * k * zero * zero, 0.4 - k * zero, 0.5 * k];
        for (c, w) in c.iter().zip(want) {
            assert!((c - w).abs() < 1e-9, "{c} {w}");
        }
        assert!(matches!(m.ci95_mps, [Some(lo), Some(hi)] if lo < zero && zero < hi));
        assert_eq!(m.bend.as_ref().unwrap().prior_per_s_mps2, k);
        let straight = predict_bent(&kicks(&pts, 0.03), Trend::Line, BendPrior::UNSIGNED);
        let early = 1.0 - straight.wobble_speed_mps.unwrap() / zero;
        assert!((0.015..0.04).contains(&early), "{early}");
    }

    /// Fieller's closed form for a line `a + b u` with covariance
    /// `[Vaa, Vab, Vbb]`: the roots of
    /// `(b^2 - t^2 Vbb) u^2 + 2 (a b - t^2 Vab) u + a^2 - t^2 Vaa = 0`.
    fn fieller_closed_form(a: f64, b: f64, v: [f64; 3], t: f64) -> (f64, f64) {
        let t2 = t * t;
        let (qa, qb, qc) = (
            b * b - t2 * v[2],
            2.0 * (a * b - t2 * v[1]),
            a * a - t2 * v[0],
        );
        let r = (qb * qb - 4.0 * qa * qc).sqrt();
        let (x1, x2) = ((-qb - r) / (2.0 * qa), (-qb + r) / (2.0 * qa));
        (x1.min(x2), x1.max(x2))
    }

    /// For a line, the profile interval is Fieller's: both bounds as the
    /// closed form gives them, for several lines and covariances; and a
    /// slope within its noise leaves the interval open above.
    #[test]
    fn the_profile_interval_of_a_line_is_fiellers() {
        for (a, b, v) in [
            (-1.0, 1.0, [0.01, 0.0, 0.0025]),
            (-2.1, 0.5, [0.04, -0.008, 0.002]),
            (-0.9, 0.3, [0.02, -0.004, 0.001]),
        ] {
            let t = 2.1;
            let cov = vec![vec![v[0], v[1]], vec![v[1], v[2]]];
            let zero = -a / b;
            let (lo, hi) = profile_interval(&[a, b], |u| variance(&cov, u), t, zero, (0.01, 50.0));
            let (want_lo, want_hi) = fieller_closed_form(a, b, v, t);
            assert!((lo.unwrap() - want_lo).abs() < 1e-6, "{lo:?} {want_lo}");
            assert!((hi.unwrap() - want_hi).abs() < 1e-6, "{hi:?} {want_hi}");
        }
        let cov = vec![vec![0.01, 0.0], vec![0.0, 0.0025]];
        let (lo, hi) = profile_interval(
            &[-1.0, 0.05],
            |u| variance(&cov, u),
            2.0,
            20.0,
            (0.01, 50.0),
        );
        assert!(lo.is_some() && hi.is_none(), "{lo:?} {hi:?}");
        // An intercept within its noise: Fieller's lower root is at
        // -0.100 m/s, no speed, so the search stops at 0 with no lower end;
        // the upper is the closed form's.
        let v = [0.01, 0.0, 0.0025];
        let (lo, hi) =
            profile_interval(&[-0.1, 1.0], |u| variance(&cov, u), 2.0, 0.1, (0.01, 50.0));
        let (want_lo, want_hi) = fieller_closed_form(-0.1, 1.0, v, 2.0);
        assert!(want_lo < -0.1 && lo.is_none(), "{lo:?} {want_lo}");
        assert!((hi.unwrap() - want_hi).abs() < 1e-6, "{hi:?} {want_hi}");
    }

    /// Gaussian draws from a xorshift generator (Box-Muller).
    fn normals(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            let mut uniform = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let (u1, u2) = (uniform().max(1e-300), uniform());
            (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
        }
    }

    /// How often the interval holds the zero over 400 noisy draws of
    /// `trend_at(draw)`: 18 kicks at 0.45-0.85 of the zero (4.2 m/s) with
    /// Gaussian scatter as stated (0.05 1/s).
    fn coverage(trend: Trend, mut bend_of_draw: impl FnMut() -> f64) -> f64 {
        let mut normal = normals(0x2545_F491_4F6C_DD1D);
        let (zero, draws) = (4.2, 400);
        let mut covered = 0;
        for _ in 0..draws {
            // sigma = 0.4 (u - zero) + (k/2) (u - zero)^2: zero at `zero`.
            let k = bend_of_draw();
            let pts: Vec<(f64, f64)> = (0..18)
                .map(|i| {
                    let u = zero * (0.45 + 0.4 * f64::from(i / 2) / 8.0);
                    let d = u - zero;
                    (u, 0.4 * d + 0.5 * k * d * d + 0.05 * normal())
                })
                .collect();
            let m = predict_with(&kicks(&pts, 0.05), trend);
            // An interval open above holds the zero if its lower end is
            // below it.
            covered += usize::from(matches!(
                m.ci95_mps,
                [Some(lo), hi] if lo <= zero && hi.is_none_or(|hi| zero <= hi)
            ));
        }
        covered as f64 / f64::from(draws)
    }

    /// The interval's coverage is about its stated 95 % (400 draws: 1.1 %
    /// is one standard error) where its assumptions hold: a quadratic on
    /// a parabola, and the line with its bend allowance on trends whose
    /// curvature is drawn as the prior says (its mean, its SD). A trend
    /// bent far beyond the allowance is covered far less.
    #[test]
    fn the_interval_covers_at_its_stated_rate() {
        let quadratic = coverage(Trend::Quadratic, || -0.3);
        assert!((0.92..=0.98).contains(&quadratic), "{quadratic}");
        let mut normal = normals(0x9E37_79B9_7F4A_7C15);
        let line = coverage(Trend::Line, || {
            BEND_MEAN_PER_S_MPS2 + BEND_SD_PER_S_MPS2 * normal()
        });
        assert!((0.92..=0.99).contains(&line), "{line}");
        let bent = coverage(Trend::Line, || -0.3);
        assert!(bent < 0.5, "{bent}");
    }

    /// A weighted line worked by hand. Eight kicks at 2.0-3.4 m/s off
    /// `sigma = 0.8 (u - 4.5)` by `+e, -e, -e, +e, +e, -e, -e, +e` (a
    /// pattern orthogonal to 1 and to u, so the least-squares line is the
    /// true one), `e = 0.1` 1/s, stated SD 0.05 1/s, no bend assumed or
    /// allowed for. Every residual is 2 SD, so the median absolute
    /// deviation gives a scale of `1.4826 * 2`, Huber's weights are all 1
    /// (`2 / (1.345 * 2.965) < 1`), and Tukey's are all
    /// `q = (1 - (2 / (4.685 * 2.9652))^2)^2`: the fit stays on the line,
    /// each kick's weight is `q / 0.05^2`, the unit variance is
    /// `sum w e^2 / (n - 2) = 8 * 400 q * 0.01 / 6`, the covariance
    /// `(X^T W X)^-1` times it, and the interval Fieller's closed form
    /// with t of 6 degrees of freedom.
    #[test]
    fn a_weighted_line_worked_by_hand() {
        let m = hand_worked_line(&[]);
        assert_eq!((m.kicks_used, m.kicks_rejected), (8, 0));
    }

    /// The same eight kicks and a ninth at 3.0 m/s, 40 SD above the line:
    /// it leaves the MAD scale (the median residual is still 2 SD), gets no
    /// weight and no degree of freedom (the unit variance stays
    /// `sum w e^2 / 6` over the eight), so the fit and its interval are the
    /// eight's.
    #[test]
    fn a_rejected_kick_leaves_the_hand_worked_line_as_it_was() {
        let m = hand_worked_line(&[(3.0, 0.8 * (3.0 - 4.5) + 40.0 * 0.05)]);
        assert_eq!((m.kicks_used, m.kicks_rejected), (8, 1));
        assert_eq!(m.weights[8], 0.0);
    }

    /// The hand-worked line above with `extra` kicks after the eight, each
    /// of them to be rejected; every figure of the eight checked.
    fn hand_worked_line(extra: &[(f64, f64)]) -> Margin {
        let (e, sd, n) = (0.1, 0.05, 8);
        let pattern = [1.0, -1.0, -1.0, 1.0, 1.0, -1.0, -1.0, 1.0];
        let mut pts: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let u = 2.0 + 0.2 * f64::from(i as u8);
                (u, 0.8 * (u - 4.5) + e * pattern[i])
            })
            .collect();
        pts.extend_from_slice(extra);
        let m = predict_bent(&kicks(&pts, sd), Trend::Line, NO_BEND);
        let r = 2.0 / (BISQUARE_C * 1.482_6 * 2.0);
        let q = (1.0 - r * r).powi(2);
        let w = q / (sd * sd);
        for got in &m.weights[..n] {
            assert!((got - w).abs() < 1e-9 * w, "{got} {w}");
        }
        let pts = &pts[..n];
        let s2 = 8.0 * w * e * e / 6.0;
        assert!((m.unit_variance.unwrap() - s2).abs() < 1e-9, "{m:?}");
        let c = m.coefficients.as_ref().unwrap();
        assert!(
            (c[0] + 3.6).abs() < 1e-9 && (c[1] - 0.8).abs() < 1e-9,
            "{c:?}"
        );
        assert!((m.wobble_speed_mps.unwrap() - 4.5).abs() < 1e-6, "{m:?}");
        // X^T W X = w [[n, S1], [S1, S2]], S1 = sum u, S2 = sum u^2.
        let (s1, s2u) = pts
            .iter()
            .fold((0.0, 0.0), |(a, b), (u, _)| (a + u, b + u * u));
        let det = w * w * (8.0 * s2u - s1 * s1);
        let v = [w * s2u / det * s2, -w * s1 / det * s2, w * 8.0 / det * s2];
        let cov = m.covariance.as_ref().unwrap();
        for (got, want) in [cov[0][0], cov[0][1], cov[1][1]].iter().zip(v) {
            assert!((got - want).abs() < 1e-9 * want.abs(), "{got} {want}");
        }
        let (lo, hi) = fieller_closed_form(-3.6, 0.8, v, t_975(6));
        let [got_lo, got_hi] = m.ci95_mps;
        assert!((got_lo.unwrap() - lo).abs() < 1e-6, "{m:?} {lo}");
        assert!((got_hi.unwrap() - hi).abs() < 1e-6, "{m:?} {hi}");
        assert_eq!(m.dof, 6);
        assert_eq!(m.speed_range_mps, Some([pts[0].0, pts[7].0]));
        // The bend's lever: the kicks' mean speed, 2.7 m/s, and the mean
        // square of their distances from it, 2 (0.1^2 + 0.3^2 + 0.5^2 +
        // 0.7^2) / 8 = 0.21 (m/s)^2 (equal weights).
        let bend = m.bend.as_ref().unwrap();
        assert!((bend.mean_mps - 2.7).abs() < 1e-12, "{bend:?}");
        assert!((bend.variance_mps2 - 0.21).abs() < 1e-12, "{bend:?}");
        m
    }

    /// No bend assumed or allowed for.
    const NO_BEND: BendPrior = BendPrior {
        mean_per_s_mps2: 0.0,
        sd_per_s_mps2: 0.0,
    };

    /// A trend that does not reach zero within the search: eleven kicks at
    /// 2.0-3.25 m/s exactly on `sigma = 0.1 (u - 8.4)`, SD 0.02 1/s. The
    /// search ends at the fastest kick plus four ranges, 8.25 m/s, short of
    /// the zero: no wobble speed, and the lower bound is the first speed
    /// of the search's grid (a 400th of the range) from the fastest kick up
    /// where the line is within its noise: Fieller's lower root with the
    /// covariance `0.02^2 (X^T X)^-1` (an exact line: unit variance 0,
    /// scaled up to 1), at 6.91 m/s. A falling trend gives no bound.
    #[test]
    fn a_zero_beyond_the_search_leaves_a_lower_bound_only() {
        let (sd, step) = (0.02, 1.25 / 400.0);
        let us: Vec<f64> = (0..11).map(|i| 2.0 + 0.125 * f64::from(i)).collect();
        let pts: Vec<(f64, f64)> = us.iter().map(|&u| (u, 0.1 * (u - 8.4))).collect();
        let m = predict_bent(&kicks(&pts, sd), Trend::Line, NO_BEND);
        assert_eq!(m.wobble_speed_mps, None, "{m:?}");
        assert!(
            m.warnings[0].contains("does not reach zero within the speeds searched"),
            "{m:?}"
        );
        let (s1, s2) = us.iter().fold((0.0, 0.0), |(a, b), u| (a + u, b + u * u));
        let det = 11.0 * s2 - s1 * s1;
        let v = [
            sd * sd * s2 / det,
            -sd * sd * s1 / det,
            sd * sd * 11.0 / det,
        ];
        let (root, _) = fieller_closed_form(-0.84, 0.1, v, t_975(9));
        assert!((root - 6.91).abs() < 0.01, "{root}");
        let lower = m.ci95_mps[0].unwrap();
        assert!(lower >= root && lower < root + step, "{lower} {root}");
        let k = (lower - 3.25) / step;
        assert!((k - k.round()).abs() < 1e-6, "{lower} is off the grid");
        assert_eq!(m.ci95_mps[1], None);
        let falling: Vec<(f64, f64)> = us.iter().map(|&u| (u, -0.5 - 0.1 * (u - 2.0))).collect();
        let m = predict_bent(&kicks(&falling, sd), Trend::Line, NO_BEND);
        assert!(m.warnings[0].contains("does not rise"), "{m:?}");
        assert_eq!(m.ci95_mps, [None, None], "{m:?}");
    }

    /// The refusals' limits: seven kicks over exactly 0.75 m/s are not a
    /// narrow range, and a zero 0.45 m/s beyond the fastest (less than the
    /// range) is no long extrapolation: no warning, both ends bounded. At
    /// 1.25 m/s beyond (more than the range, less than 1 + the range) the
    /// upper end is left open.
    #[test]
    fn the_range_and_extrapolation_limits() {
        let us: Vec<f64> = (0..7).map(|i| 2.0 + 0.125 * f64::from(i)).collect();
        let line =
            |zero: f64| -> Vec<(f64, f64)> { us.iter().map(|&u| (u, 1.5 * (u - zero))).collect() };
        let m = predict_bent(&kicks(&line(3.2), 0.02), Trend::Line, NO_BEND);
        assert_eq!(m.speed_range_mps, Some([2.0, 2.75]));
        assert!(m.warnings.is_empty(), "{m:?}");
        assert!((m.wobble_speed_mps.unwrap() - 3.2).abs() < 1e-6, "{m:?}");
        assert!(m.ci95_mps.iter().all(Option::is_some), "{m:?}");
        let m = predict_bent(&kicks(&line(4.0), 0.02), Trend::Line, NO_BEND);
        assert!(m.warnings[0].contains("long extrapolation"), "{m:?}");
        assert!((m.wobble_speed_mps.unwrap() - 4.0).abs() < 1e-6, "{m:?}");
        assert!(m.ci95_mps[0].is_some() && m.ci95_mps[1].is_none(), "{m:?}");
    }

    /// Six kicks are enough, the limit included; rejected kicks do not
    /// count towards it: seven with one wild kick predict, six with one
    /// (five carrying weight) do not.
    #[test]
    fn six_kicks_that_carry_weight_are_needed_and_enough() {
        let line = |u: f64| 1.5 * (u - 3.6);
        let pts: Vec<(f64, f64)> = (0..6)
            .map(|i| 2.0 + 0.2 * f64::from(i))
            .map(|u| (u, line(u)))
            .collect();
        let six = predict(&kicks(&pts, 0.05));
        assert_eq!(six.kicks_used, 6, "{six:?}");
        assert!(six.wobble_speed_mps.is_some(), "{six:?}");
        let mut one_wild = pts.clone();
        one_wild.push((2.5, line(2.5) + 3.0));
        let m = predict(&kicks(&one_wild, 0.05));
        assert_eq!((m.kicks_used, m.kicks_rejected), (6, 1), "{m:?}");
        assert!(m.wobble_speed_mps.is_some(), "{m:?}");
        let mut five = one_wild;
        five.remove(5);
        let m = predict(&kicks(&five, 0.05));
        assert_eq!((m.kicks_used, m.kicks_rejected), (5, 1), "{m:?}");
        assert!(m.wobble_speed_mps.is_none(), "{m:?}");
        assert!(m.warnings[0].contains("5 carry weight"), "{m:?}");
    }

    /// The robust fit is a fixed point of its reweighting: from the final
    /// line, each kick's residual in units of its SD, the MAD scale and
    /// Tukey's weight give back the weights reported (a fit stopped after
    /// a pass or two would report the weights of an earlier line). Kicks
    /// scattered about a line, one of them 2 1/s off.
    #[test]
    fn the_robust_fit_is_a_fixed_point_of_its_weights() {
        let mut normal = normals(0x1234_5678_9ABC_DEF1);
        let sd = 0.05;
        let mut pts: Vec<(f64, f64)> = (0..16)
            .map(|i| {
                let u = 2.0 + 0.12 * f64::from(i);
                (u, 1.2 * (u - 4.5) + 1.5 * sd * normal())
            })
            .collect();
        pts[5].1 += 2.0;
        let m = predict_bent(&kicks(&pts, sd), Trend::Line, NO_BEND);
        let c = m.coefficients.as_ref().unwrap();
        let z: Vec<f64> = pts
            .iter()
            .map(|(u, y)| (y - c[0] - c[1] * u) / sd)
            .collect();
        let scale = (1.482_6 * median(z.iter().map(|z| z.abs()).collect())).max(1.0);
        for (z, got) in z.iter().zip(&m.weights) {
            let want = bisquare(z / (BISQUARE_C * scale)) / (sd * sd);
            assert!(
                (got - want).abs() < 1e-6 * (1.0 / (sd * sd)),
                "{got} {want}"
            );
        }
        assert_eq!(m.weights[5], 0.0);
    }

    /// Huber's and Tukey's weight functions of the residual in units of
    /// their constant (Huber 1964, `min(1, 1 / |r|)`; Beaton and Tukey
    /// 1974, `(1 - r^2)^2` inside 1, 0 outside).
    #[test]
    fn the_weight_functions_are_huber_and_tukey() {
        for (r, h, b) in [
            (0.0, 1.0, 1.0),
            (0.5, 1.0, 0.5625),
            (-1.0, 1.0, 0.0),
            (2.0, 0.5, 0.0),
            (-4.0, 0.25, 0.0),
        ] {
            assert_eq!((huber(r), bisquare(r)), (h, b), "{r}");
        }
    }

    /// The bend allowance by hand: kicks of mean speed 3 m/s and speed
    /// variance 0.25 (m/s)^2, a curvature SD of 0.02: at 5 m/s the trend
    /// is uncertain by `0.01 * |4 - 0.25| = 0.0375` 1/s more, at the mean
    /// by `0.01 * 0.25`; and the band at `u` is the trend's value plus and
    /// minus `t` times the square root of the fit's variance
    /// `Vaa + 2 u Vab + u^2 Vbb` and the bend's.
    #[test]
    fn the_bend_allowance_and_the_band_by_hand() {
        let bend = Bend {
            mean_mps: 3.0,
            variance_mps2: 0.25,
            prior_per_s_mps2: -0.04,
            sd_per_s_mps2: 0.02,
        };
        assert!((bend.sd_at(5.0) - 0.0375).abs() < 1e-12);
        assert!((bend.sd_at(3.0) - 0.0025).abs() < 1e-12);
        assert!((bend.sd_at(1.0) - 0.0375).abs() < 1e-12);
        let mut m = predict(&[]);
        m.coefficients = Some(vec![-2.0, 0.5, -0.02]);
        m.covariance = Some(vec![vec![0.04, -0.01], vec![-0.01, 0.003]]);
        m.bend = Some(bend);
        m.dof = 10;
        let (y, lo, hi) = m.band(5.0).unwrap();
        // -2 + 2.5 - 0.5; 0.04 - 0.1 + 0.075 = 0.015; plus 0.0375^2.
        let half = t_975(10) * (0.015_f64 + 0.0375 * 0.0375).sqrt();
        assert!((y - 0.0).abs() < 1e-12, "{y}");
        assert!(
            (lo + half).abs() < 1e-12 && (hi - half).abs() < 1e-12,
            "{lo} {hi}"
        );
        m.bend = None;
        let (_, lo, _) = m.band(5.0).unwrap();
        assert!((lo + t_975(10) * 0.015_f64.sqrt()).abs() < 1e-12, "{lo}");
    }

    /// Kicks it cannot use are left out and counted as rejected: a speed
    /// of zero or less, a non-finite growth rate or uncertainty, a
    /// negative uncertainty. What is left still gives the prediction.
    #[test]
    fn unusable_kicks_are_rejected() {
        let pts: Vec<(f64, f64)> = (0..10)
            .map(|i| {
                let u = 2.0 + 0.2 * f64::from(i);
                (u, 1.5 * (u - 4.2))
            })
            .collect();
        let clean = predict(&kicks(&pts, 0.05));
        let mut k = kicks(&pts, 0.05);
        let bad = |speed: f64, sigma: f64, sd: f64| KickPoint {
            speed_mps: speed,
            sigma_per_s: sigma,
            sigma_sd_per_s: sd,
            freq_hz: 7.0,
        };
        k.extend([
            bad(0.0, -6.0, 0.05),
            bad(-3.0, -1.0, 0.05),
            bad(f64::NAN, -1.0, 0.05),
            bad(3.0, f64::INFINITY, 0.05),
            bad(3.0, -1.0, f64::NAN),
            bad(3.0, 5.0, -0.05),
        ]);
        let m = predict(&k);
        assert_eq!((m.kicks_used, m.kicks_rejected), (10, 6), "{m:?}");
        assert!(m.weights[10..].iter().all(|w| *w == 0.0), "{m:?}");
        assert_eq!(m.wobble_speed_mps, clean.wobble_speed_mps);
        assert_eq!(m.ci95_mps, clean.ci95_mps);
        // Six kicks, one of them unusable: too few.
        let few: Vec<KickPoint> = k[5..10].iter().chain(&k[15..]).cloned().collect();
        let few = predict(&few);
        assert!(few.warnings[0].contains("5 usable"), "{few:?}");
        assert_eq!(few.kicks_rejected, 6);
    }

    /// The median of odd and even counts, in any order.
    #[test]
    fn the_median_of_odd_and_even_counts() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 3.0, 2.0]), 2.5);
        assert_eq!(median(Vec::new()), 0.0);
    }

    #[test]
    fn refuses_too_few_kicks() {
        let m = predict(&kicks(&[(2.0, -2.0), (2.5, -1.5), (3.0, -1.0)], 0.1));
        assert!(m.wobble_speed_mps.is_none());
        assert_eq!(m.ci95_mps, [None, None]);
        assert!(m.warnings[0].contains("too few kicks"), "{m:?}");
    }

    #[test]
    fn narrow_range_leaves_the_interval_open() {
        let pts: Vec<(f64, f64)> = (0..12)
            .map(|i| {
                let u = 3.0 + 0.04 * f64::from(i);
                (u, u - 4.0 + if i % 2 == 0 { 0.05 } else { -0.05 })
            })
            .collect();
        for trend in [Trend::Line, Trend::Quadratic] {
            let m = predict_with(&kicks(&pts, 0.05), trend);
            assert!(m.ci95_mps[1].is_none(), "{m:?}");
        }
        let m = predict_with(&kicks(&pts, 0.05), Trend::Line);
        assert!(m.warnings.iter().any(|w| w.contains("narrow")), "{m:?}");
    }

    #[test]
    fn long_extrapolation_is_said_and_left_open() {
        // Kicks at 1.5-2.1 m/s of a line crossing at 4.5 m/s.
        let pts: Vec<(f64, f64)> = (0..12)
            .map(|i| {
                let u = 1.5 + 0.06 * f64::from(i);
                (u, 0.8 * (u - 4.5) + if i % 3 == 0 { 0.04 } else { -0.02 })
            })
            .collect();
        for trend in [Trend::Line, Trend::Quadratic] {
            let m = predict_with(&kicks(&pts, 0.05), trend);
            assert!(m.ci95_mps[1].is_none(), "{m:?}");
        }
        let m = predict_with(&kicks(&pts, 0.05), Trend::Line);
        assert!(
            m.warnings.iter().any(|w| w.contains("extrapolation")),
            "{m:?}"
        );
    }

    #[test]
    fn flat_sigma_predicts_nothing() {
        let pts: Vec<(f64, f64)> = (0..10).map(|i| (2.0 + 0.2 * f64::from(i), -1.0)).collect();
        let mut k = kicks(&pts, 0.05);
        k[3].sigma_per_s = -1.02;
        for trend in [Trend::Line, Trend::Quadratic] {
            let m = predict_with(&k, trend);
            assert!(m.wobble_speed_mps.is_none(), "{m:?}");
            assert!(m.ci95_mps[1].is_none(), "{m:?}");
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// One kick anywhere, however wrong, moves the prediction by less
        /// than 2 % and is rejected when it is far off (the default line;
        /// a quadratic leans more on its end kicks).
        #[test]
        fn one_bad_kick_does_not_move_the_answer(
            bad in 0usize..16,
            wrong in prop_oneof![-6.0..-1.5f64, 1.5..6.0f64],
            jitter in proptest::collection::vec(-0.08..0.08f64, 16),
        ) {
            let trend = Trend::Line;
            let pts: Vec<(f64, f64)> = (0..16)
                .map(|i| {
                    let u = 2.0 + 0.12 * i as f64;
                    (u, 1.2 * (u - 4.5) + jitter[i])
                })
                .collect();
            let clean = predict_with(&kicks(&pts, 0.05), trend).wobble_speed_mps.unwrap();
            let mut spoiled = pts.clone();
            spoiled[bad].1 += wrong;
            let m = predict_with(&kicks(&spoiled, 0.05), trend);
            let w = m.wobble_speed_mps.unwrap();
            prop_assert!((w - clean).abs() < 0.02 * clean, "{clean} -> {w}");
            prop_assert!(m.kicks_rejected >= 1, "{m:?}");
            prop_assert!(m.weights[bad] == 0.0);
        }
    }
}
