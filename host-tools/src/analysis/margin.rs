//! The wobble speed predicted from kicks below it, by damping
//! extrapolation (the flutter-margin idea of flight testing): each kick's
//! ring-down gives the wobble mode's growth rate sigma at its speed, sigma
//! rises towards zero as the speed approaches the wobble speed, and the
//! trend's zero is the prediction.
//!
//! - **Fit**: a straight line `sigma = a + b u`, weighted by each kick's
//!   uncertainty (`1 / sd^2`) and made robust by Tukey's bisquare
//!   (iteratively reweighted least squares, scale from the median absolute
//!   deviation of the standardised residuals): a kick more than
//!   [`BISQUARE_C`] scales off the line gets no weight and is counted as
//!   rejected, so one bad kick cannot move the answer.
//! - **Interval**: the 95 % interval of the zero `u* = -a / b` is
//!   Fieller's: the speeds `u` at which the line's value `a + b u` is not
//!   significantly different from zero (t test with `n - 2` degrees of
//!   freedom on the fit's covariance). For a straight line with Gaussian
//!   scatter this is the profile-likelihood interval of `u*`; it is
//!   bounded only when the slope itself is significantly positive, so
//!   data that cannot bound the wobble speed give an open interval rather
//!   than a made-up one.
//! - **Refusals**: fewer than [`MIN_KICKS`] kicks, a speed range narrower
//!   than [`MIN_SPAN_MPS`], or an extrapolation beyond the fastest kick
//!   longer than [`MAX_EXTRAPOLATION`] times the measured range: the
//!   result says so (`warnings`), and the interval's upper end is open.
//!
//! Assumption: sigma is smooth and close to linear in speed over the
//! measured range and the extrapolation. The model crate's wobble mode
//! bends little over the upper half of the range below the wobble speed;
//! that is why the campaign protocol steps the speed up towards it.

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
    /// The fitted line: `[a (1/s), b (1/s per m/s)]`, if any.
    pub line: Option<[f64; 2]>,
    /// The fit's covariance of `(a, b)`: `[Vaa, Vab, Vbb]`.
    pub covariance: Option<[f64; 3]>,
    /// Degrees of freedom of the t quantile.
    pub dof: usize,
    /// Speeds of the kicks used, slowest and fastest, m/s.
    pub speed_range_mps: Option<[f64; 2]>,
    /// Why the answer is weaker than it looks, in words.
    pub warnings: Vec<String>,
    /// Each input kick's final weight (0: rejected).
    pub weights: Vec<f64>,
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
/// Floor of a kick's uncertainty, 1/s: no kick is weighted as exact.
const MIN_SD_PER_S: f64 = 0.02;
/// IRLS iterations (it converges in a handful).
const ITERATIONS: usize = 50;

/// The method, in words, as `wobblog margin` reports it.
pub const METHOD: &str = "damping extrapolation: robust straight line of sigma against speed \
(weights 1/sd^2, Tukey bisquare IRLS), its zero; 95 % interval by profile likelihood \
(Fieller's interval of the zero, t with n-2 dof)";

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

/// Weighted least squares line through `(u, y)` with weights `w`:
/// `(a, b)` and `(X^T W X)^-1` as `[Vaa, Vab, Vbb]`.
fn weighted_line(u: &[f64], y: &[f64], w: &[f64]) -> Option<([f64; 2], [f64; 3])> {
    let (mut s, mut su, mut suu, mut sy, mut suy) = (0.0, 0.0, 0.0, 0.0, 0.0);
    for ((&u, &y), &w) in u.iter().zip(y).zip(w) {
        s += w;
        su += w * u;
        suu += w * u * u;
        sy += w * y;
        suy += w * u * y;
    }
    let det = s * suu - su * su;
    if det.is_nan() || det <= 1e-12 * s * suu {
        return None;
    }
    let b = (s * suy - su * sy) / det;
    let a = (sy - b * su) / s;
    Some(([a, b], [suu / det, -su / det, s / det]))
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

/// The robust fit: line, covariance and final weights.
struct RobustFit {
    line: [f64; 2],
    cov: [f64; 3],
    weights: Vec<f64>,
}

fn robust_line(u: &[f64], y: &[f64], sd: &[f64]) -> Option<RobustFit> {
    let base: Vec<f64> = sd
        .iter()
        .map(|s| 1.0 / s.max(MIN_SD_PER_S).powi(2))
        .collect();
    let (mut line, _) = weighted_line(u, y, &base)?;
    let mut w = base.clone();
    for _ in 0..ITERATIONS {
        // Residuals in units of each kick's own uncertainty.
        let z: Vec<f64> = (0..u.len())
            .map(|i| (y[i] - line[0] - line[1] * u[i]) * base[i].sqrt())
            .collect();
        // MAD scale (consistent for Gaussian scatter), never below the
        // stated uncertainties: a line through the points is no reason to
        // trust them more than they say.
        let scale = (1.482_6 * median(z.iter().map(|v| v.abs()).collect())).max(1.0);
        w = z
            .iter()
            .zip(&base)
            .map(|(z, b)| {
                let r = z / (BISQUARE_C * scale);
                if r.abs() < 1.0 {
                    b * (1.0 - r * r).powi(2)
                } else {
                    0.0
                }
            })
            .collect();
        let (next, _) = weighted_line(u, y, &w)?;
        let moved = (next[0] - line[0]).abs() + (next[1] - line[1]).abs();
        line = next;
        if moved < 1e-10 {
            break;
        }
    }
    let (_, inv) = weighted_line(u, y, &w)?;
    // Residual variance of unit weight from the weighted residuals, with
    // the degrees of freedom of the kicks that carry weight.
    let used = w.iter().filter(|w| **w > 0.0).count();
    let dof = used.saturating_sub(2).max(1) as f64;
    let s2 = (0..u.len())
        .map(|i| w[i] * (y[i] - line[0] - line[1] * u[i]).powi(2))
        .sum::<f64>()
        / dof;
    // Never below what the kicks' own uncertainties give (unit weight).
    let s2 = s2.max(1.0);
    Some(RobustFit {
        line,
        cov: inv.map(|v| v * s2),
        weights: w,
    })
}

/// Fieller's interval of the zero of `a + b u`: the `u` where
/// `(a + b u)^2 <= t^2 (Vaa + 2 u Vab + u^2 Vbb)`. Returns `(lo, hi)` with
/// `hi = None` when the set is unbounded above (slope not significant).
fn fieller(line: [f64; 2], cov: [f64; 3], t: f64) -> Option<(f64, Option<f64>)> {
    let [a, b] = line;
    let [vaa, vab, vbb] = cov;
    let t2 = t * t;
    let qa = b * b - t2 * vbb;
    let qb = 2.0 * (a * b - t2 * vab);
    let qc = a * a - t2 * vaa;
    let disc = qb * qb - 4.0 * qa * qc;
    if qa > 0.0 && disc >= 0.0 {
        let r = disc.sqrt();
        let (x1, x2) = ((-qb - r) / (2.0 * qa), (-qb + r) / (2.0 * qa));
        Some((x1.min(x2), Some(x1.max(x2))))
    } else if b > 0.0 {
        // The slope is not significant: every speed above some bound is
        // consistent with the data (or every speed at all).
        let lo = if qa < 0.0 && disc >= 0.0 {
            let r = disc.sqrt();
            let (x1, x2) = ((-qb - r) / (2.0 * qa), (-qb + r) / (2.0 * qa));
            // The complement of (x1, x2) holds the zero: its upper part.
            x1.max(x2)
        } else {
            f64::NEG_INFINITY
        };
        Some((lo, None))
    } else {
        None
    }
}

/// Predicts the wobble speed from `kicks`.
#[must_use]
pub fn predict(kicks: &[KickPoint]) -> Margin {
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
        method: METHOD.into(),
        line: None,
        covariance: None,
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
    let Some(fit) = robust_line(&u, &y, &sd) else {
        out.warnings
            .push("the kicks' speeds do not spread: no line can be fitted".into());
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
    out.line = Some(fit.line);
    out.covariance = Some(fit.cov);
    out.dof = used.len().saturating_sub(2).max(1);
    if used.len() < MIN_KICKS {
        out.warnings.push(format!(
            "too few kicks: {} carry weight, a prediction needs at least {MIN_KICKS}",
            used.len()
        ));
        return out;
    }
    let [a, b] = fit.line;
    if b.is_nan() || b <= 0.0 {
        out.warnings.push(format!(
            "sigma does not rise with speed ({b:.3} 1/s per m/s): no wobble speed ahead"
        ));
        return out;
    }
    let zero = -a / b;
    out.wobble_speed_mps = Some(zero);
    let span = hi_u - lo_u;
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
    if zero < lo_u {
        out.warnings.push(format!(
            "the predicted wobble speed {zero:.2} m/s is below the kicks' speeds: \
             the kicks contradict a stable bicycle"
        ));
    }
    match fieller(fit.line, fit.cov, t_975(out.dof)) {
        Some((lo, hi)) => {
            out.ci95_mps = [lo.is_finite().then_some(lo), hi.filter(|_| !open)];
            if hi.is_none() {
                // A slope within its noise puts the zero anywhere beyond
                // the lower bound: no point estimate is given.
                out.wobble_speed_mps = None;
                out.warnings.push(
                    "the rise of sigma with speed is not significant: only a lower bound".into(),
                );
            }
        }
        None => out.ci95_mps = [None, None],
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

    /// Exact points on a line: the zero is the line's, the interval tight.
    #[test]
    fn exact_line_gives_its_zero() {
        let pts: Vec<(f64, f64)> = (0..10)
            .map(|i| {
                let u = 2.0 + 0.2 * f64::from(i);
                (u, 1.5 * (u - 4.2))
            })
            .collect();
        let m = predict(&kicks(&pts, 0.05));
        let w = m.wobble_speed_mps.unwrap();
        assert!((w - 4.2).abs() < 1e-9, "{m:?}");
        let [lo, hi] = m.ci95_mps;
        assert!(lo.unwrap() < 4.2 && hi.unwrap() > 4.2, "{m:?}");
        assert!(hi.unwrap() - lo.unwrap() < 0.3, "{m:?}");
        assert_eq!((m.kicks_used, m.kicks_rejected), (10, 0));
    }

    /// Hand check of Fieller's interval: line through (0, -1) with slope 1
    /// and a diagonal covariance: the bounds solve
    /// `(u - 1)^2 = t^2 (Vaa + u^2 Vbb)`.
    #[test]
    fn fieller_bounds_solve_the_test() {
        let (t, vaa, vbb) = (2.0, 0.01, 0.0025);
        let (lo, hi) = fieller([-1.0, 1.0], [vaa, 0.0, vbb], t).unwrap();
        for u in [lo, hi.unwrap()] {
            let lhs = (u - 1.0f64).powi(2);
            let rhs = t * t * (vaa + u * u * vbb);
            assert!((lhs - rhs).abs() < 1e-12, "{u}");
        }
        assert!(lo < 1.0 && hi.unwrap() > 1.0);
        // A slope within its noise: open above.
        let (_, hi) = fieller([-1.0, 0.05], [vaa, 0.0, vbb], t).unwrap();
        assert!(hi.is_none());
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
        let m = predict(&kicks(&pts, 0.05));
        assert!(m.ci95_mps[1].is_none(), "{m:?}");
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
        let m = predict(&kicks(&pts, 0.05));
        assert!(m.ci95_mps[1].is_none(), "{m:?}");
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
        let m = predict(&k);
        assert!(m.wobble_speed_mps.is_none(), "{m:?}");
        assert!(m.ci95_mps[1].is_none(), "{m:?}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(64))]

        /// One kick anywhere, however wrong, moves the prediction by less
        /// than 2 % and is rejected when it is far off.
        #[test]
        fn one_bad_kick_does_not_move_the_answer(
            bad in 0usize..16,
            wrong in prop_oneof![-6.0..-1.5f64, 1.5..6.0f64],
            jitter in proptest::collection::vec(-0.08..0.08f64, 16),
        ) {
            let pts: Vec<(f64, f64)> = (0..16)
                .map(|i| {
                    let u = 2.0 + 0.12 * i as f64;
                    (u, 1.2 * (u - 4.5) + jitter[i])
                })
                .collect();
            let clean = predict(&kicks(&pts, 0.05)).wobble_speed_mps.unwrap();
            let mut spoiled = pts.clone();
            spoiled[bad].1 += wrong;
            let m = predict(&kicks(&spoiled, 0.05));
            let w = m.wobble_speed_mps.unwrap();
            prop_assert!((w - clean).abs() < 0.02 * clean, "{clean} -> {w}");
            prop_assert!(m.kicks_rejected >= 1, "{m:?}");
            prop_assert!(m.weights[bad] == 0.0);
        }
    }
}
