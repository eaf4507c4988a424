//! The costs the model's users wait for: a 1000-speed eigenvalue sweep of
//! the 14-state wobble model, and a two-parameter fit to 11 episodes.

use std::hint::black_box;
use std::path::Path;

use criterion::{criterion_group, criterion_main, Criterion};
use wobble_model::fit::fit;
use wobble_model::neutral::neutral_speeds;
use wobble_model::synthetic::Synthetic;
use wobble_model::{critical_speeds, Model, ParamSet, Sweep};

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
    // The critical speeds alone: bracketed on the sweep and refined by
    // Newton's method, against solving the pencil (bialternate sum, 91 x 91).
    let sweep = Sweep::run(&model, &speeds, |_| {}).unwrap();
    c.bench_function(
        "wobble model, critical speeds by Newton on the sweep",
        |b| {
            b.iter(|| critical_speeds(&model, black_box(&sweep)));
        },
    );
    let pencil = model.pencil().unwrap();
    c.bench_function("wobble model, critical speeds from the pencil", |b| {
        b.iter(|| neutral_speeds(black_box(&pencil), (0.0, 10.0)));
    });
    // The floor: the eigenvalues alone at the same 1000 speeds, and the same
    // from nalgebra's Schur decomposition (the solver used before).
    c.bench_function("wobble model, 1000 eigenvalue calls", |b| {
        b.iter(|| {
            for &u in black_box(&speeds) {
                black_box(wobble_model::eig::eigenvalues(&pencil.at(u)));
            }
        });
    });
    c.bench_function("wobble model, 1000 nalgebra Schur eigenvalue calls", |b| {
        b.iter(|| {
            for &u in black_box(&speeds) {
                let schur = nalgebra::Schur::try_new(pencil.at(u), f64::EPSILON, 10_000);
                black_box(schur.map(|s| s.complex_eigenvalues()));
            }
        });
    });
}

fn two_parameter_fit(c: &mut Criterion) {
    let start = test_bicycle();
    let case = Synthetic::steering_head(&start).unwrap();
    let mut group = c.benchmark_group("fit");
    group.sample_size(10);
    group.bench_function("two parameters, 11 episodes", |b| {
        b.iter(|| {
            fit(
                &start,
                &case.keys,
                black_box(&case.observations),
                case.weights,
            )
            .unwrap()
        });
    });
    group.finish();
}

criterion_group!(benches, sweep_1000, two_parameter_fit);
criterion_main!(benches);
