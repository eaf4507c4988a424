//! Eigenvalues and eigenvectors of a real state matrix.
//!
//! Eigenvalues come from the eigenvalues-only Hessenberg QR iteration of
//! [`crate::hessenberg_qr`] (a sweep computes nothing else at most speeds).
//! nalgebra has no eigenvectors for a non-symmetric matrix, so each one is found by two
//! steps of inverse iteration on `A - lambda I` in complex arithmetic (LU):
//! the vectors only serve to tell modes apart, so that is accurate enough.

use nalgebra::{Complex, DMatrix, DVector};

use crate::model::Pencil;

/// One eigenvalue with its (unit-norm) eigenvector.
#[derive(Clone, Debug, PartialEq)]
pub struct Eigen {
    /// The eigenvalue, 1/s (real part) and rad/s (imaginary part).
    pub value: Complex<f64>,
    /// The right eigenvector, unit Euclidean norm.
    pub vector: DVector<Complex<f64>>,
}

/// The eigenvalues of `a`, or `None` if they cannot be computed (a matrix
/// with NaN or infinite entries, or an iteration that does not converge).
#[must_use]
pub fn eigenvalues(a: &DMatrix<f64>) -> Option<Vec<Complex<f64>>> {
    eigenvalues_near(a, &[])
}

/// [`eigenvalues`], given approximations of them (a sweep's previous
/// speed's, extrapolated): the same values, found in fewer steps when the
/// guesses are close.
#[must_use]
pub fn eigenvalues_near(a: &DMatrix<f64>, guesses: &[Complex<f64>]) -> Option<Vec<Complex<f64>>> {
    crate::hessenberg_qr::eigenvalues(a, guesses)
}

/// [`eigenvalues_near`] of `pencil` at `speed_mps`, evaluated straight into
/// the solver's storage.
#[must_use]
pub fn pencil_eigenvalues_near(
    pencil: &Pencil,
    speed_mps: f64,
    guesses: &[Complex<f64>],
) -> Option<Vec<Complex<f64>>> {
    let fill = |rows: &mut [f64]| pencil.write_rows(speed_mps, rows);
    crate::hessenberg_qr::eigenvalues_of(pencil.a0.nrows(), fill, guesses)
}

/// Every eigenvalue of `a` with its eigenvector.
#[must_use]
pub fn eigen(a: &DMatrix<f64>) -> Option<Vec<Eigen>> {
    let values = eigenvalues(a)?;
    let ac = complex(a);
    Some(
        values
            .into_iter()
            .map(|value| Eigen {
                value,
                vector: eigenvector_of(&ac, value),
            })
            .collect(),
    )
}

/// The (unit-norm) eigenvector of `a` for its eigenvalue `value`.
#[must_use]
pub fn eigenvector(a: &DMatrix<f64>, value: Complex<f64>) -> DVector<Complex<f64>> {
    eigenvector_of(&complex(a), value)
}

fn complex(a: &DMatrix<f64>) -> DMatrix<Complex<f64>> {
    a.map(|v| Complex::new(v, 0.0))
}

/// Two steps of inverse iteration on `ac - value I`.
fn eigenvector_of(ac: &DMatrix<Complex<f64>>, value: Complex<f64>) -> DVector<Complex<f64>> {
    let n = ac.nrows();
    let scale = ac.iter().fold(1.0_f64, |m, v| m.max(v.norm()));
    // A shift just off the eigenvalue keeps the LU regular.
    let shift = value + Complex::new(1e-10 * scale, 1e-10 * scale);
    let lu = (ac - DMatrix::from_diagonal_element(n, n, shift)).lu();
    let mut x = DVector::from_fn(n, |i, _| Complex::new(1.0 + 0.1 * i as f64, 0.0));
    for _ in 0..2 {
        if let Some(y) = lu.solve(&x) {
            let norm = y.norm();
            if norm.is_finite() && norm > 0.0 {
                x = y / Complex::new(norm, 0.0);
            }
        }
    }
    x
}
