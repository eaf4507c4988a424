//! Critical speeds straight from the affine pencil `A(u) = A0 + u A1`,
//! without a grid: an eigenvalue on the imaginary axis.
//!
//! - A real root through zero: `det A(u) = 0`, the real `u` of the pencil
//!   `(A0, A1)` (a generalised eigenproblem of the model's size).
//! - A pair through the imaginary axis: `lambda_i + lambda_j = 0`, i.e.
//!   `det B(u) = 0` with `B(u) = B(A0) + u B(A1)` the bialternate sum
//!   `2 A (.) I`, whose eigenvalues are every `lambda_i + lambda_j`, `i < j`
//!   (Govaerts 2000, *Numerical methods for bifurcations of dynamical
//!   equilibria*, ch. 4). It is `n(n-1)/2` square: 91 for the 14-state model.
//!
//! Each pencil is solved as the standard eigenproblem `M(s)^-1 M1` about a
//! shift `s` where `M(s)` is regular (`u = s - 1/mu`), by nalgebra's Schur
//! decomposition. A root of `B` is also `lambda_i = -lambda_j` for two real
//! eigenvalues (a neutral saddle, no crossing): each root is kept only if
//! `A(u)` has an eigenvalue on the imaginary axis there.

use nalgebra::{DMatrix, Schur};

use crate::eig::eigenvalues;
use crate::model::Pencil;
use crate::sweep::REAL_TOL;

/// A speed where an eigenvalue of the pencil lies on the imaginary axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neutral {
    /// The speed, m/s.
    pub speed_mps: f64,
    /// The eigenvalue's imaginary part there, rad/s (0: a real root at zero).
    pub im_rad_per_s: f64,
}

/// The bialternate sum `2 M (.) I` of a square matrix, in the index pairs
/// `(p, q)`, `p > q`, taken row-major.
#[must_use]
pub fn bialternate(m: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    let pairs: Vec<(usize, usize)> = (1..n).flat_map(|p| (0..p).map(move |q| (p, q))).collect();
    DMatrix::from_fn(pairs.len(), pairs.len(), |i, j| {
        let ((p, q), (r, s)) = (pairs[i], pairs[j]);
        let mut v = 0.0;
        if r == q {
            v -= m[(p, s)];
        }
        if r != p && s == q {
            v += m[(p, r)];
        }
        if r == p && s == q {
            v += m[(p, p)] + m[(q, q)];
        }
        if r == p && s != q {
            v += m[(q, s)];
        }
        if s == p {
            v -= m[(q, r)];
        }
        v
    })
}

/// The real `u` in `[lo, hi]` with `det(m0 + u m1) = 0`, about the shift `s`.
fn pencil_roots(m0: &DMatrix<f64>, m1: &DMatrix<f64>, s: f64, (lo, hi): (f64, f64)) -> Vec<f64> {
    let Some(inv) = (m0 + m1 * s).try_inverse() else {
        return Vec::new();
    };
    let Some(schur) = Schur::try_new(inv * m1, f64::EPSILON, 10_000) else {
        return Vec::new();
    };
    schur
        .complex_eigenvalues()
        .iter()
        .filter(|mu| mu.im == 0.0 && mu.re != 0.0)
        .map(|mu| s - 1.0 / mu.re)
        .filter(|u| (lo..=hi).contains(u))
        .collect()
}

/// The eigenvalue of `a` nearest the imaginary axis, if it is on it (within
/// `tol` of the spectrum's scale): its `|im|`.
fn on_axis(a: &DMatrix<f64>, tol: f64) -> Option<f64> {
    let values = eigenvalues(a)?;
    let scale = values.iter().fold(1.0_f64, |m, v| m.max(v.norm()));
    let v = values
        .iter()
        .min_by(|a, b| a.re.abs().total_cmp(&b.re.abs()))?;
    (v.re.abs() <= tol * scale).then_some(v.im.abs())
}

/// Every speed in `range` where the pencil has an eigenvalue on the
/// imaginary axis, in order: real roots through zero and pairs through the
/// axis. The shift is the range's golden-section point, away from any round
/// speed a model is likely to be singular at.
#[must_use]
pub fn neutral_speeds(pencil: &Pencil, range: (f64, f64)) -> Vec<Neutral> {
    let s = range.0 + 0.618_033_988_749_895 * (range.1 - range.0);
    let mut out: Vec<Neutral> = Vec::new();
    // A zero root of A(u) appears as a real root of det A and, doubled, of
    // det B; the imaginary part tells them apart.
    for u in pencil_roots(&pencil.a0, &pencil.a1, s, range) {
        if on_axis(&pencil.at(u), 1e-8).is_some_and(|im| im <= REAL_TOL) {
            out.push(Neutral {
                speed_mps: u,
                im_rad_per_s: 0.0,
            });
        }
    }
    let (b0, b1) = (bialternate(&pencil.a0), bialternate(&pencil.a1));
    for u in pencil_roots(&b0, &b1, s, range) {
        if let Some(im) = on_axis(&pencil.at(u), 1e-8).filter(|&im| im > REAL_TOL) {
            out.push(Neutral {
                speed_mps: u,
                im_rad_per_s: im,
            });
        }
    }
    out.sort_by(|a, b| a.speed_mps.total_cmp(&b.speed_mps));
    out
}
