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

/// A tense rider, whose 4 Hz torso lean oscillation carries much steer, and
/// a start 40 % below the true head stiffness: the fit follows the wobble,
/// not the lean, and lands on the truth.
#[test]
fn fit_from_far_with_a_tense_rider_finds_the_wobble() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/test-bicycle.toml");
    let mut truth = ParamSet::load(&path).unwrap();
    truth
        .set_value("hip.stiffness", 2000.0, "tense rider")
        .unwrap();
    let key = "steer_head.stiffness".to_string();
    let k_true = truth.value(&key).unwrap();
    let mut start = truth.clone();
    start.set_value(&key, 0.6 * k_true, "far start").unwrap();
    let speeds: Vec<f64> = (0..8).map(|i| 2.0 + f64::from(i)).collect();
    let wobble = mode_at(&Model::from_set(&truth).unwrap(), Mode::Wobble, &speeds)
        .unwrap()
        .unwrap();
    let obs: Vec<Observation> = speeds
        .iter()
        .zip(&wobble)
        .map(|(&u, w)| Observation {
            speed_mps: u,
            freq_hz: w.im / std::f64::consts::TAU,
            sigma_per_s: w.re,
        })
        .collect();
    let weights = Weights {
        freq_sd_hz: 0.05,
        sigma_sd_per_s: 0.2,
    };
    let result = fit(&start, std::slice::from_ref(&key), &obs, weights).unwrap();
    let est = &result.estimates[0];
    assert!(
        (est.value - k_true).abs() < 1e-3 * k_true,
        "{est:?}, truth {k_true}"
    );
}

/// A model without a wobble mode cannot be fitted to wobble episodes: an
/// error, not an estimate.
#[test]
fn a_model_without_wobble_cannot_be_fitted() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/benchmark.toml");
    let set = ParamSet::load(&path).unwrap();
    let obs = [Observation {
        speed_mps: 4.0,
        freq_hz: 6.0,
        sigma_per_s: -1.0,
    }; 3];
    let weights = Weights {
        freq_sd_hz: 0.05,
        sigma_sd_per_s: 0.2,
    };
    // The Whipple bicycle has no wobble at all.
    let err = fit(&set, &["geometry.trail".to_string()], &obs, weights).unwrap_err();
    assert!(err.to_string().contains("no wobble mode"), "{err}");
}
