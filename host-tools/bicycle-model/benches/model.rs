//! The costs the model's users wait for: a 1000-speed eigenvalue sweep of
//! the 14-state wobble model, and a two-parameter fit to 11 episodes.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use wobble_model::fit::{fit, Observation, Weights};
use wobble_model::sweep::mode_at;
use wobble_model::{critical_speeds, Mode, Model, ParamSet, Sweep};

fn test_bicycle() -> ParamSet {
    ParamSet::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("params/test-bicycle.toml")).unwrap()
}

fn sweep_1000(c: &mut Criterion) {
    let model = Model::from_set(&test_bicycle()).unwrap();
    let speeds: Vec<f64> = (0..1000).map(|i| f64::from(i) * 0.01).collect();
    c.bench_function("wobble model, 1000-speed sweep", |b| {
        b.iter(|| Sweep::run(&model, black_box(&speeds), |_| {}).unwrap());
    });
    c.bench_function("wobble model, 1000-speed sweep with critical speeds", |b| {
        b.iter(|| {
            let sweep = Sweep::run(&model, black_box(&speeds), |_| {}).unwrap();
            critical_speeds(&model, &sweep)
        });
    });
    // The floor: the eigenvalues alone at the same 1000 speeds.
    let (a0, a1) = model.pencil().unwrap();
    c.bench_function("wobble model, 1000 eigenvalue calls", |b| {
        b.iter(|| {
            for &u in black_box(&speeds) {
                black_box(wobble_model::eig::eigenvalues(&(&a0 + &a1 * u)));
            }
        });
    });
}

fn two_parameter_fit(c: &mut Criterion) {
    let start = test_bicycle();
    let keys = vec![
        "steer_head.stiffness".to_string(),
        "steer_head.damping".to_string(),
    ];
    let mut truth = start.clone();
    truth.set_value(&keys[0], 3450.0, "truth").unwrap();
    truth.set_value(&keys[1], 1.6, "truth").unwrap();
    let speeds: Vec<f64> = (0..11).map(|i| 3.0 + 0.5 * f64::from(i)).collect();
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
        freq_sd_hz: 0.03,
        sigma_sd_per_s: 0.1,
    };
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    group.bench_function("two parameters, 11 episodes", |b| {
        b.iter(|| fit(&start, &keys, black_box(&obs), weights).unwrap());
    });
    group.finish();
}

criterion_group!(benches, sweep_1000, two_parameter_fit);
criterion_main!(benches);
