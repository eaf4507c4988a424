//! The trend as a polynomial in speed, its zero, and the profile-likelihood
//! interval of that zero.

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
pub(super) fn powers(u: f64, terms: usize) -> impl Iterator<Item = f64> {
    std::iter::successors(Some(1.0), move |p| Some(p * u)).take(terms)
}

/// The polynomial `coef` at `u`.
pub(super) fn value(coef: &[f64], u: f64) -> f64 {
    coef.iter()
        .zip(powers(u, coef.len()))
        .map(|(c, p)| c * p)
        .sum()
}

/// Its slope at `u`.
pub(super) fn slope(coef: &[f64], u: f64) -> f64 {
    coef.iter()
        .enumerate()
        .skip(1)
        .map(|(k, c)| k as f64 * c * u.powi(k as i32 - 1))
        .sum()
}

/// `x(u)^T V x(u)`: the variance of the fitted value at `u`.
pub(super) fn variance(cov: &[Vec<f64>], u: f64) -> f64 {
    let x: Vec<f64> = powers(u, cov.len()).collect();
    cov.iter()
        .zip(&x)
        .map(|(row, xi)| xi * row.iter().zip(&x).map(|(v, xj)| v * xj).sum::<f64>())
        .sum()
}

/// The lowest speed above `from` where `coef` crosses zero upwards, if it
/// does below `to`.
pub(super) fn upward_zero(coef: &[f64], from: f64, to: f64) -> Option<f64> {
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
pub(super) fn bisect(inside: impl Fn(f64) -> bool, mut lo: f64, mut hi: f64) -> f64 {
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
/// speeds `inside` (where the trend is not significantly non-zero) that
/// holds it, searched down to 0 and up to `cap` on a grid of `step`; an
/// end not found is `None`.
pub(super) fn profile_interval(
    inside: impl Fn(f64) -> bool,
    zero: f64,
    (step, cap): (f64, f64),
) -> (Option<f64>, Option<f64>) {
    let walk = |dir: f64, limit: f64| {
        let mut u = zero;
        loop {
            let next = u + dir * step;
            if (dir < 0.0 && next <= limit) || (dir > 0.0 && next >= limit) {
                return None;
            }
            if !inside(next) {
                return Some(bisect(&inside, u, next));
            }
            u = next;
        }
    };
    (walk(-1.0, 0.0), walk(1.0, cap))
}
