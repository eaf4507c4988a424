//! A fit on synthetic episodes generated from the model with known
//! parameters recovers them within its stated confidence.

use std::path::Path;

use wobble_model::fit::{fit, Observation, Weights};
use wobble_model::sweep::mode_at;
use wobble_model::{Mode, Model, ParamSet};

#[test]
fn fit_recovers_known_steering_head_parameters() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/test-bicycle.toml");
    let start = ParamSet::load(&path).unwrap();
    let keys = vec![
        "steer_head.stiffness".to_string(),
        "steer_head.damping".to_string(),
    ];
    let mut truth = start.clone();
    let (k_true, c_true) = (
        1.15 * start.value(&keys[0]).unwrap(),
        0.8 * start.value(&keys[1]).unwrap(),
    );
    truth.set_value(&keys[0], k_true, "truth").unwrap();
    truth.set_value(&keys[1], c_true, "truth").unwrap();
    let speeds: Vec<f64> = (0..11).map(|i| 3.0 + 0.5 * f64::from(i)).collect();
    let model = Model::from_set(&truth).unwrap();
    let wobble = mode_at(&model, Mode::Wobble, &speeds).unwrap().unwrap();
    let weights = Weights {
        freq_sd_hz: 0.03,
        sigma_sd_per_s: 0.1,
    };
    // Deterministic scatter of about one standard deviation.
    let obs: Vec<Observation> = speeds
        .iter()
        .zip(&wobble)
        .enumerate()
        .map(|(i, (&u, w))| {
            let e = (1.7 * i as f64).sin();
            Observation {
                speed_mps: u,
                freq_hz: w.im / std::f64::consts::TAU + weights.freq_sd_hz * e,
                sigma_per_s: w.re - weights.sigma_sd_per_s * (2.3 * i as f64).cos(),
            }
        })
        .collect();
    let result = fit(&start, &keys, &obs, weights).unwrap();
    for (est, truth) in result.estimates.iter().zip([k_true, c_true]) {
        println!(
            "{}: {} +/- {} (truth {truth})",
            est.key, est.value, est.ci95
        );
        assert!(
            (est.value - truth).abs() <= est.ci95,
            "{} = {} +/- {}, truth {truth}",
            est.key,
            est.value,
            est.ci95
        );
        assert!(
            est.ci95 < 0.5 * truth,
            "{} interval {} is not informative",
            est.key,
            est.ci95
        );
    }
    assert!(result.rms_freq_hz < 2.0 * weights.freq_sd_hz);
    let written = result.set.quantity(&keys[0]).unwrap();
    assert!((written.value - result.estimates[0].value).abs() < 1e-12);
}
