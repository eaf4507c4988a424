//! Time-domain simulation of a linear model `x' = A x + B e`: the exact
//! zero-order-hold discretisation over a step `h` (the excitation `e` held
//! over the step), from one matrix exponential of the augmented system
//! `[[A, B], [0, 0]] h`, whose top blocks are `exp(A h)` and
//! `int_0^h exp(A s) ds B` (Van Loan 1978). Exact for any step, so a stiff
//! tyre lag needs no small step, and `A` may be singular.

use nalgebra::{DMatrix, DVector};

/// One step of a linear model, discretised.
#[derive(Clone, Debug, PartialEq)]
pub struct Discrete {
    /// State transition `exp(A h)`.
    pub phi: DMatrix<f64>,
    /// Input matrix of the held excitation.
    pub gamma: DMatrix<f64>,
}

impl Discrete {
    /// The discretisation of `x' = a x + b e` over `step_s`.
    ///
    /// # Panics
    /// If `a` is not square or `b` has not as many rows as `a`.
    #[must_use]
    pub fn new(a: &DMatrix<f64>, b: &DMatrix<f64>, step_s: f64) -> Self {
        let (n, m) = (a.nrows(), b.ncols());
        assert!(a.is_square() && b.nrows() == n, "A is n x n, B is n x m");
        let mut aug = DMatrix::zeros(n + m, n + m);
        aug.view_mut((0, 0), (n, n)).copy_from(&(a * step_s));
        aug.view_mut((0, n), (n, m)).copy_from(&(b * step_s));
        let e = aug.exp();
        Self {
            phi: e.view((0, 0), (n, n)).into_owned(),
            gamma: e.view((0, n), (n, m)).into_owned(),
        }
    }

    /// The state one step after `x` under the held excitation `e`.
    #[must_use]
    pub fn step(&self, x: &DVector<f64>, e: &DVector<f64>) -> DVector<f64> {
        &self.phi * x + &self.gamma * e
    }
}
