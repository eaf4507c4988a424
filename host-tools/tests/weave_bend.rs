//! The weave's bend in the reciprocal speed `w = 1/u`, on the benchmark
//! and BicycleParameters' six measured bicycles: the shape `beta = k w*^2
//! / D` (`k` the curvature of sigma against `w` at the weave speed's `w*`,
//! `D` the damping at `w*/2`, twice the weave speed) lies within two SDs
//! of the weave's bend prior (`BendPrior::WEAVE`), and is worked out here
//! from the model's eigenvalues by finite differences, not from the
//! margin's code.

use wobble_model::eig::eigenvalues;
use wobble_model::params::{measured_bicycle_file, MEASURED_BICYCLES};
use wobble_model::{Model, ParamSet};
use wobblog::analysis::margin::BendPrior;

/// sigma of the weave (the oscillatory pair) at speed `u`.
fn weave_sigma(model: &Model, u: f64) -> f64 {
    eigenvalues(&model.state_matrix(u))
        .unwrap()
        .iter()
        .filter(|l| l.im > 1e-6)
        .max_by(|a, b| a.im.total_cmp(&b.im))
        .map(|l| l.re)
        .unwrap()
}

#[test]
fn the_weaves_bend_in_reciprocal_speed_lies_within_the_prior() {
    let mut betas = Vec::new();
    for b in MEASURED_BICYCLES {
        let set = ParamSet::load(&measured_bicycle_file(b)).unwrap();
        let model = Model::whipple_of(&set).unwrap();
        // The weave speed by bisection on sigma (stable above it).
        let (mut lo, mut hi) = (2.0, 8.0);
        assert!(
            weave_sigma(&model, lo) > 0.0 && weave_sigma(&model, hi) < 0.0,
            "{b}"
        );
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if weave_sigma(&model, mid) > 0.0 {
                lo = mid
            } else {
                hi = mid
            }
        }
        let w_star = 1.0 / lo;
        let s = |w: f64| weave_sigma(&model, 1.0 / w);
        let h = 0.01 * w_star;
        let k = (s(w_star + h) - 2.0 * s(w_star) + s(w_star - h)) / (h * h);
        let damping = -s(0.5 * w_star);
        let beta = k * w_star * w_star / damping;
        eprintln!("{b}: weave speed {lo:.3} m/s, beta {beta:.2}");
        assert!(damping > 0.0, "{b}");
        let p = BendPrior::WEAVE;
        assert!(
            (p.mean - 2.0 * p.sd_concave..p.mean + 2.0 * p.sd_convex).contains(&beta),
            "{b}: beta {beta}"
        );
        betas.push(beta);
    }
    // Each lies within 1.3 SDs of the prior's mean, which is within half
    // an SD of theirs (9.1).
    let p = BendPrior::WEAVE;
    assert!(
        betas.iter().all(|b| (b - p.mean).abs() < 1.3 * p.sd_convex),
        "{betas:?}"
    );
    let mean = betas.iter().sum::<f64>() / betas.len() as f64;
    assert!((mean - p.mean).abs() < 0.5 * p.sd_concave, "{mean}");
}
