//! A crossing refined by Newton's method on the real part of one eigenvalue,
//! `Re lambda(u) = 0`, without a full eigenvalue solution per step.
//!
//! At each speed the eigenvalue near a predicted one comes from two steps of
//! inverse iteration on `A(u) - s I` for the right eigenvector `x` and on its
//! adjoint for the left one `y` (one complex LU each), and its derivative in
//! speed from them: `dlambda/du = y^H A'(u) x / y^H x` (first-order
//! perturbation of a simple eigenvalue). The value is the two-sided Rayleigh
//! quotient `y^H A x / y^H x`, accurate to the square of the vectors' error.
//! The next step's shift is the value moved along that derivative, so it is
//! already close and two steps of inverse iteration suffice.

use nalgebra::{Complex, DMatrix, DVector};

use super::SPEED_TOL_MPS;

/// Newton steps before giving up (the test bicycle's crossings take 3).
const MAX_STEPS: usize = 12;

/// One eigenvalue at one speed and its derivative in speed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Local {
    /// The eigenvalue, 1/s and rad/s.
    pub value: Complex<f64>,
    /// Its derivative in speed, per m.
    pub slope: Complex<f64>,
}

/// Right and left eigenvector estimates, carried from one speed to the next.
struct Vectors {
    right: DVector<Complex<f64>>,
    left: DVector<Complex<f64>>,
}

impl Vectors {
    /// A start with a component along every eigenvector in practice.
    fn generic(n: usize) -> Self {
        let v = DVector::from_fn(n, |i, _| Complex::new(1.0 + 0.1 * i as f64, 0.0));
        Self {
            right: v.clone(),
            left: v,
        }
    }
}

fn complex(a: &DMatrix<f64>) -> DMatrix<Complex<f64>> {
    a.map(|v| Complex::new(v, 0.0))
}

/// Two steps of inverse iteration on `m` from `v` (left unchanged where a
/// solve fails); `None` if `m` is exactly singular.
fn inverse_iteration(m: DMatrix<Complex<f64>>, v: &mut DVector<Complex<f64>>) -> Option<()> {
    let lu = m.lu();
    for _ in 0..2 {
        let w = lu.solve(v)?;
        let norm = w.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        *v = w.unscale(norm);
    }
    Some(())
}

/// The cosine between the unit left and right vectors below which a root
/// counts as double: its condition number (the cosine's inverse) above
/// 1e4. A Jordan block's root gives about 4e-8 after the shifted inverse
/// iteration; the bicycles' simple roots 0.03 and more (`cargo test -p
/// wobble-model --lib`, 1429 evaluations).
const DEFECTIVE_COS: f64 = 1e-4;

/// The eigenvalue of `a` nearest `shift` and its derivative for the speed
/// derivative `da` of `a`, from the vectors `v` (updated).
fn local(
    a: &DMatrix<f64>,
    da: &DMatrix<f64>,
    shift: Complex<f64>,
    v: &mut Vectors,
) -> Option<Local> {
    let n = a.nrows();
    let ac = complex(a);
    // A shift just off the eigenvalue keeps the LU regular once the shift
    // has converged; inverse iteration then gains ten digits per step.
    let off = 1e-10 * a.amax().max(1.0);
    let m = &ac - DMatrix::from_diagonal_element(n, n, shift + Complex::new(off, off));
    let adjoint = m.adjoint();
    inverse_iteration(m, &mut v.right)?;
    inverse_iteration(adjoint, &mut v.left)?;
    let (x, y) = (&v.right, &v.left);
    let yx = y.dotc(x);
    if yx.norm() <= DEFECTIVE_COS {
        // Left and right vectors (unit length) all but orthogonal: a
        // defective (double) root, whose slope would be round-off over
        // round-off.
        return None;
    }
    let value = y.dotc(&(&ac * x)) / yx;
    let slope = y.dotc(&(complex(da) * x)) / yx;
    (value.is_finite() && slope.is_finite()).then_some(Local { value, slope })
}

/// The speed in `[lo, hi]` where the eigenvalue starting as `guess` at
/// speed `start` has a zero real part, by Newton's method on
/// `Re lambda(u)`; with the eigenvalue there (as the last step predicts it).
/// `None` if an iterate leaves the interval, a slope is flat or the steps
/// do not converge.
pub(super) fn crossing(
    matrix: &dyn Fn(f64) -> DMatrix<f64>,
    slope: &dyn Fn(f64) -> DMatrix<f64>,
    (lo, hi): (f64, f64),
    (start, guess): (f64, Complex<f64>),
) -> Option<(f64, Complex<f64>)> {
    let a = matrix(start);
    let mut vectors = Vectors::generic(a.nrows());
    let (mut u, mut shift, mut a) = (start, guess, a);
    for _ in 0..MAX_STEPS {
        let at = local(&a, &slope(u), shift, &mut vectors)?;
        let step = -at.value.re / at.slope.re;
        if !step.is_finite() {
            return None;
        }
        let next = u + step;
        if !(lo..=hi).contains(&next) {
            return None;
        }
        // The next iterate and its eigenvalue predicted along the slope.
        (u, shift) = (next, at.value + at.slope * step);
        if step.abs() <= SPEED_TOL_MPS {
            return Some((u, shift));
        }
        a = matrix(u);
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The companion matrix of `l^3 + c2 l^2 + c1 l + c0`.
    fn companion(c2: f64, c1: f64, c0: f64) -> DMatrix<f64> {
        DMatrix::from_row_slice(3, 3, &[0.0, 1.0, 0.0, 0.0, 0.0, 1.0, -c0, -c1, -c2])
    }

    /// `(l + p)(l^2 - 2 r l + r^2 + w^2)`: roots `-p` and `r +- i w`,
    /// expanded by hand.
    fn with_roots(p: f64, r: f64, w: f64) -> DMatrix<f64> {
        let q = r * r + w * w;
        companion(p - 2.0 * r, q - 2.0 * r * p, p * q)
    }

    #[test]
    fn the_local_eigenvalue_and_its_slope_are_the_known_roots() {
        // Roots moving with u as -1, (u - 1) +- 2i (r = u - 1): at u = 0.5
        // the pair is -0.5 +- 2i and moves with slope 1 in its real part.
        let matrix = |u: f64| with_roots(1.0, u - 1.0, 2.0);
        let h = 1e-6;
        let da = (matrix(0.5 + h) - matrix(0.5 - h)) / (2.0 * h);
        let mut v = Vectors::generic(3);
        let got = local(&matrix(0.5), &da, Complex::new(-0.4, 2.1), &mut v).unwrap();
        let got = local(&matrix(0.5), &da, got.value, &mut v).unwrap();
        assert!(
            (got.value - Complex::new(-0.5, 2.0)).norm() < 1e-12,
            "{got:?}"
        );
        assert!(
            (got.slope - Complex::new(1.0, 0.0)).norm() < 1e-8,
            "{got:?}"
        );
    }

    /// `(l + 1)^2 (l + 2)`, its double root -1 a single Jordan block (a
    /// companion matrix is non-derogatory): the left and right vectors there
    /// are orthogonal and no eigenvalue slope exists, so no local value.
    #[test]
    fn a_defective_double_root_has_no_local_value() {
        let a = companion(4.0, 5.0, 2.0);
        let da = companion(1.0, 0.0, 0.0) - companion(0.0, 0.0, 0.0);
        let mut v = Vectors::generic(3);
        assert_eq!(local(&a, &da, Complex::new(-1.0, 0.0), &mut v), None);
        // Beside it, the simple root -2 is found.
        let mut v = Vectors::generic(3);
        let simple = local(&a, &da, Complex::new(-2.0, 0.0), &mut v).unwrap();
        assert!((simple.value + 2.0).norm() < 1e-9, "{simple:?}");
    }

    #[test]
    fn a_hopf_point_of_a_cubic_is_where_hurwitz_puts_it() {
        // l^3 + u l^2 + 2 l + 3: the Hurwitz determinant c2 c1 - c0 = 2u - 3
        // is zero at u = 1.5, where the roots are -1.5 and +-i sqrt 2.
        let matrix = |u: f64| companion(u, 2.0, 3.0);
        let slope = |_: f64| companion(1.0, 0.0, 0.0) - companion(0.0, 0.0, 0.0);
        // A start as a 0.1 m/s grid's straight line gives it.
        let (u, value) = crossing(&matrix, &slope, (1.4, 1.6), (1.5, Complex::new(0.01, 1.41)))
            .expect("converges");
        assert!((u - 1.5).abs() < 1e-13, "{u}");
        assert!(
            (value - Complex::new(0.0, 2f64.sqrt())).norm() < 1e-12,
            "{value}"
        );
    }

    #[test]
    fn a_real_root_through_zero_is_where_the_constant_term_vanishes() {
        // l^3 + 3 l^2 + 2 l + (u^2 - 2): a root through zero at u = sqrt 2.
        let matrix = |u: f64| companion(3.0, 2.0, u * u - 2.0);
        let slope = |u: f64| companion(0.0, 0.0, 2.0 * u) - companion(0.0, 0.0, 0.0);
        let (u, value) = crossing(&matrix, &slope, (1.0, 2.0), (1.5, Complex::new(-0.08, 0.0)))
            .expect("converges");
        assert!((u - 2f64.sqrt()).abs() < 1e-13, "{u}");
        assert!(value.norm() < 1e-12, "{value}");
    }

    #[test]
    fn an_iterate_outside_the_interval_is_no_crossing() {
        let matrix = |u: f64| companion(u, 2.0, 3.0);
        let slope = |_: f64| companion(1.0, 0.0, 0.0) - companion(0.0, 0.0, 0.0);
        assert_eq!(
            crossing(
                &matrix,
                &slope,
                (1.6, 1.7),
                (1.65, Complex::new(-0.01, 1.41))
            ),
            None
        );
    }
}
