//! The robust weighted fit of sigma against speed with the kicks'
//! scatter about the bicycle's mean damping as its own variance.
//!
//! A kick's sigma differs from the trend by its measurement error (its
//! stated SD) and by how much that kick's true damping differs from the
//! bicycle's mean at its speed: the rider's kick, the road, the lean. The
//! second is the same for every kick, a between-kick variance `tau^2`
//! (the random effect of a meta-regression), so each kick's variance is
//! `sd^2 + tau^2`. The fit alternates two steps until neither changes:
//!
//! 1. outliers, with `tau^2` fixed: from Siegel's repeated-median line
//!    ([`repeated_median`]; a quadratic from Huber's reweighting), Tukey's bisquare
//!    reweighting on residuals in units of `sqrt(sd^2 + tau^2)`, the scale
//!    the median absolute deviation of those (never below 1); a kick
//!    beyond [`BISQUARE_C`] scales is rejected;
//! 2. `tau^2` from the kicks kept (Paule and Mandel 1982): the value at
//!    which the weighted residuals' chi-square, refitted with weights
//!    `1 / (sd^2 + tau^2)`, equals its degrees of freedom (0 when the
//!    kicks scatter no more than their SDs say). The rejected kicks take
//!    no part, so an outlier cannot inflate it.
//!
//! The final trend is the weighted least-squares fit to the kicks kept
//! with weights `1 / (sd^2 + tau^2)`, its covariance `(X^T W X)^-1`
//! scaled by the residuals' variance of unit weight when above 1 (Knapp
//! and Hartung 2003; with Paule and Mandel's `tau^2` that is 1 unless the
//! kicks scatter less than stated), for Student's t with `n - p` degrees of
//! freedom (`n` kicks kept, `p` coefficients).

use nalgebra::{DMatrix, DVector};

use super::interval::value;

/// Tukey's bisquare constant (95 % efficiency for Gaussian scatter).
pub const BISQUARE_C: f64 = 4.685;
/// Huber's constant (95 % efficiency), for the robust start.
const HUBER_K: f64 = 1.345;
/// Floor of a kick's uncertainty, 1/s: no kick is weighted as exact.
pub const MIN_SD_PER_S: f64 = 0.02;
/// IRLS iterations of each stage (each converges in a handful).
const ITERATIONS: usize = 50;
/// Rounds of outliers then `tau^2` (two or three settle it).
const ROUNDS: usize = 10;

/// Weighted least squares polynomial of `terms` coefficients through
/// `(u, y)` with weights `w`: the coefficients and `(X^T W X)^-1`. Speeds
/// are centred and scaled for the solve (so the normal matrix is well
/// conditioned), then mapped back.
pub(super) fn weighted_poly(
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

pub(super) fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => 0.0,
        _ if n % 2 == 1 => v[n / 2],
        _ => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}

/// The robust fit with the between-kick variance.
#[derive(Debug)]
pub(super) struct RobustFit {
    /// Coefficients of `(1, u, u^2, ...)`.
    pub coef: Vec<f64>,
    /// Their covariance, scaled as the module says.
    pub cov: Vec<Vec<f64>>,
    /// The between-kick variance, (1/s)^2.
    pub tau2: f64,
    /// The kicks' scatter about the trend over their stated SDs alone
    /// (chi-square with weights `1 / sd^2` over the degrees of freedom).
    pub unit_variance: f64,
    /// Each kick's final weight, `1 / (sd^2 + tau^2)`, 0 when rejected.
    pub weights: Vec<f64>,
}

/// IRLS from `coef` with the weight function `rho` of the residual in
/// units of `c` robust scales; `base` the weights of a kick in full.
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
        w = reweighted(data, &coef, c, rho);
        let (next, _) = weighted_poly(u, y, &w, terms)?;
        let moved: f64 = next.iter().zip(&coef).map(|(a, b)| (a - b).abs()).sum();
        coef = next;
        if moved < 1e-10 {
            break;
        }
    }
    Some((coef, w))
}

/// One reweighting: residuals in units of each kick's own SD (`base`
/// its inverse variance), the MAD scale (consistent for Gaussian scatter,
/// never below 1: a trend through the points is no reason to trust them
/// more than they say), and `rho` of the residual over `c` scales.
pub(super) fn reweighted(
    (u, y, base): (&[f64], &[f64], &[f64]),
    coef: &[f64],
    c: f64,
    rho: fn(f64) -> f64,
) -> Vec<f64> {
    let z: Vec<f64> = (0..u.len())
        .map(|i| (y[i] - value(coef, u[i])) * base[i].sqrt())
        .collect();
    let scale = (1.482_6 * median(z.iter().map(|v| v.abs()).collect())).max(1.0);
    z.iter()
        .zip(base)
        .map(|(z, b)| b * rho(z / (c * scale)))
        .collect()
}

pub(super) fn huber(r: f64) -> f64 {
    if r.abs() <= 1.0 {
        1.0
    } else {
        1.0 / r.abs()
    }
}

pub(super) fn bisquare(r: f64) -> f64 {
    if r.abs() < 1.0 {
        (1.0 - r * r).powi(2)
    } else {
        0.0
    }
}

/// A weighted fit: its chi-square, coefficients, `(X^T W X)^-1` and
/// weights.
type Weighted = (f64, Vec<f64>, DMatrix<f64>, Vec<f64>);

/// The weighted chi-square of the least-squares fit to the kept kicks with
/// weights `1 / (var + tau2)`, and that fit.
fn chi_square(
    (u, y, var): (&[f64], &[f64], &[f64]),
    kept: &[bool],
    tau2: f64,
    terms: usize,
) -> Option<Weighted> {
    let w: Vec<f64> = var
        .iter()
        .zip(kept)
        .map(|(v, k)| if *k { 1.0 / (v + tau2) } else { 0.0 })
        .collect();
    let (coef, inv) = weighted_poly(u, y, &w, terms)?;
    let chi2 = (0..u.len())
        .map(|i| w[i] * (y[i] - value(&coef, u[i])).powi(2))
        .sum();
    Some((chi2, coef, inv, w))
}

/// Paule and Mandel's between-kick variance of the kept kicks: 0 when
/// their chi-square at 0 is within its `dof`, else the `tau^2` at which it
/// equals `dof` (the chi-square falls as `tau^2` grows), by bisection.
pub(super) fn paule_mandel(
    data: (&[f64], &[f64], &[f64]),
    kept: &[bool],
    terms: usize,
) -> Option<f64> {
    let dof = kept.iter().filter(|k| **k).count().saturating_sub(terms) as f64;
    if dof < 1.0 {
        return Some(0.0);
    }
    let excess = |tau2: f64| chi_square(data, kept, tau2, terms).map(|c| c.0 - dof);
    if excess(0.0)? <= 0.0 {
        return Some(0.0);
    }
    let (mut lo, mut hi) = (0.0, 1e-4);
    while excess(hi)? > 0.0 {
        lo = hi;
        hi *= 4.0;
        if hi > 1e12 {
            return None;
        }
    }
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if excess(mid)? > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 + 1e-7 * hi {
            break;
        }
    }
    Some(0.5 * (lo + hi))
}

/// Most kicks [`repeated_median`] takes.
pub(super) const MEDIAN_START_KICKS: usize = 1000;

/// Siegel's repeated-median line through `(u, y)`: for each kick the
/// median of the slopes to every other kick at another speed, the
/// slope the median of those, the intercept the median of `y - b u`. It
/// stands until half the kicks are outliers, where least squares falls to
/// one kick far out at the end of the speed range (a hand on the bar at
/// the slowest kick), so the reweighting starts from it. Written here as
/// it is a few lines over [`median`] and no maintained crate offers it.
///
/// It is quadratic in the kicks, and only where the reweighting starts:
/// above [`MEDIAN_START_KICKS`] kicks it is the line of that many, taken
/// evenly along the kicks in speed order (a hostile log holds 131 000).
pub(super) fn repeated_median(u: &[f64], y: &[f64]) -> Option<[f64; 2]> {
    if u.len() <= MEDIAN_START_KICKS {
        return siegel(u, y);
    }
    let mut order: Vec<usize> = (0..u.len()).collect();
    order.sort_by(|&i, &j| u[i].total_cmp(&u[j]));
    let step = u.len().div_ceil(MEDIAN_START_KICKS);
    let (u, y): (Vec<f64>, Vec<f64>) = order.iter().step_by(step).map(|&i| (u[i], y[i])).unzip();
    siegel(&u, &y)
}

/// [`repeated_median`] of every kick.
fn siegel(u: &[f64], y: &[f64]) -> Option<[f64; 2]> {
    let slopes: Vec<f64> = (0..u.len())
        .filter_map(|i| {
            let to_others: Vec<f64> = (0..u.len())
                .filter(|&j| (u[j] - u[i]).abs() > 1e-9)
                .map(|j| (y[j] - y[i]) / (u[j] - u[i]))
                .collect();
            (!to_others.is_empty()).then(|| median(to_others))
        })
        .collect();
    if slopes.len() < 2 {
        return None;
    }
    let b = median(slopes);
    let a = median(u.iter().zip(y).map(|(u, y)| y - b * u).collect());
    (a.is_finite() && b.is_finite()).then_some([a, b])
}

/// The fit of `terms` coefficients to the kicks at speeds `u` with growth
/// rates `y` and stated SDs `sd`, as the module says.
pub(super) fn robust_fit(u: &[f64], y: &[f64], sd: &[f64], terms: usize) -> Option<RobustFit> {
    let var: Vec<f64> = sd.iter().map(|s| s.max(MIN_SD_PER_S).powi(2)).collect();
    let mut tau2 = 0.0;
    let mut kept = vec![true; u.len()];
    for _ in 0..ROUNDS {
        let base: Vec<f64> = var.iter().map(|v| 1.0 / (v + tau2)).collect();
        // A line starts from the repeated median (high breakdown: Huber's
        // reweighting from least squares follows a kick far out at the end
        // of the speed range); a quadratic from least squares and Huber.
        let start = match repeated_median(u, y) {
            Some(line) if terms == 2 => line.to_vec(),
            _ => {
                let (ls, _) = weighted_poly(u, y, &base, terms)?;
                irls((u, y, &base), ls, HUBER_K, huber)?.0
            }
        };
        let (_, w) = irls((u, y, &base), start, BISQUARE_C, bisquare)?;
        let now: Vec<bool> = w.iter().map(|w| *w > 0.0).collect();
        let next = paule_mandel((u, y, &var), &now, terms)?;
        let settled = now == kept && (next - tau2).abs() <= 1e-10 + 1e-6 * tau2;
        kept = now;
        tau2 = next;
        if settled {
            break;
        }
    }
    let (chi2, coef, inv, weights) = chi_square((u, y, &var), &kept, tau2, terms)?;
    let used = kept.iter().filter(|k| **k).count();
    let dof = used.saturating_sub(terms).max(1) as f64;
    let scale = (chi2 / dof).max(1.0);
    let cov = (0..terms)
        .map(|r| (0..terms).map(|c| inv[(r, c)] * scale).collect())
        .collect();
    let (fixed, ..) = chi_square((u, y, &var), &kept, 0.0, terms)?;
    Some(RobustFit {
        coef,
        cov,
        tau2,
        unit_variance: fixed / dof,
        weights,
    })
}
