//! The time-domain simulation against the eigenvalues: a free oscillation
//! started on a mode follows `Re(v e^(lambda t))` exactly, and a held
//! excitation settles where `A x + B e = 0` puts it.

use std::path::Path;

use nalgebra::{Complex, DMatrix, DVector};
use proptest::prelude::*;
use wobble_model::eig::eigen;
use wobble_model::simulate::Discrete;
use wobble_model::wobble::{WobbleModel, INPUTS, STATES};
use wobble_model::ParamSet;

fn model() -> WobbleModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/test-bicycle.toml");
    WobbleModel::from_set(&ParamSet::load(&path).unwrap()).unwrap()
}

/// Started on the wobble mode (above the wobble speed, growing) and on the
/// castering mode (stiff, decaying at 16/s), the state after every 10 ms
/// step for 1 s is the mode's own motion, to 1e-9 of its size (or of its
/// start, once it has decayed).
#[test]
fn free_motion_on_a_mode_is_the_eigen_solution() {
    let m = model();
    let a = m.state_matrix(5.0);
    let d = Discrete::new(&a, &DMatrix::zeros(STATES.len(), 1), 0.01);
    let none = DVector::zeros(1);
    let modes = eigen(&a).unwrap();
    let wobble = modes
        .iter()
        .find(|e| e.value.im > 30.0 && e.value.im < 45.0)
        .expect("a 5-7 Hz mode");
    let castering = modes
        .iter()
        .find(|e| e.value.re < -10.0 && e.value.im > 0.0 && e.value.im < 10.0)
        .expect("the castering mode");
    assert!(wobble.value.re > 0.0, "{}", wobble.value);
    for mode in [wobble, castering] {
        let at = |t: f64| -> DVector<f64> {
            (&mode.vector * (mode.value * t).exp()).map(|c: Complex<f64>| c.re)
        };
        let mut x = at(0.0);
        for k in 1..=100 {
            x = d.step(&x, &none);
            let want = at(f64::from(k) * 0.01);
            let size = want.norm().max(at(0.0).norm());
            let err = (&x - &want).norm() / size;
            assert!(err < 1e-9, "{} at step {k}: {err:e}", mode.value);
        }
    }
}

/// The excitation columns act where they should: a steer torque moves the
/// steer acceleration first, a hip torque the torso's, a path slope only
/// the slip lag of its own tyre.
#[test]
fn each_excitation_enters_its_own_equation() {
    let m = model();
    let b = m.input_matrix(4.0);
    assert_eq!(b.ncols(), INPUTS.len());
    let row = |name: &str| STATES.iter().position(|s| *s == name).unwrap();
    let biggest = |col: usize| {
        (0..STATES.len())
            .max_by(|&i, &j| b[(i, col)].abs().total_cmp(&b[(j, col)].abs()))
            .unwrap()
    };
    assert_eq!(biggest(0), row("ddelta"));
    assert_eq!(biggest(1), row("dphi_r"));
    for (col, lag) in [(2, "alpha1'"), (3, "alpha2'")] {
        let touched: Vec<usize> = (0..STATES.len()).filter(|&i| b[(i, col)] != 0.0).collect();
        assert_eq!(touched, [row(lag)]);
        // alpha' relaxes to the slip with time constant sigma / u.
        let sigma = if col == 2 {
            m.params.front_tyre.relaxation_length
        } else {
            m.params.rear_tyre.relaxation_length
        };
        assert!((b[(row(lag), col)] - 4.0 / sigma).abs() < 1e-12);
    }
}

proptest! {
    /// A held excitation on a stable system ends at the equilibrium
    /// `x = -A^-1 B e`, whatever the step.
    #[test]
    fn held_excitation_settles_at_the_equilibrium(
        diag in proptest::collection::vec(-30.0..-2.0f64, 4),
        off in proptest::collection::vec(-0.3..0.3f64, 12),
        b in proptest::collection::vec(-2.0..2.0f64, 8),
        e in proptest::collection::vec(-1.0..1.0f64, 2),
        step_s in 0.001..0.05f64,
    ) {
        // Gershgorin: every eigenvalue has a real part below -1.1/s.
        let mut k = 0;
        let a = DMatrix::from_fn(4, 4, |i, j| if i == j { diag[i] } else { k += 1; off[k - 1] });
        let b = DMatrix::from_row_slice(4, 2, &b);
        let e = DVector::from_row_slice(&e);
        let d = Discrete::new(&a, &b, step_s);
        let mut x = DVector::zeros(4);
        let steps = (40.0 / step_s) as usize;
        for _ in 0..steps {
            x = d.step(&x, &e);
        }
        let want = -a.clone().lu().solve(&(&b * &e)).unwrap();
        prop_assert!((&x - &want).norm() <= 1e-9 * (1.0 + want.norm()), "{x} vs {want}");
    }
}
