//! Modes and critical speeds of BicycleParameters' six measured bicycles
//! (Moore 2012) and the benchmark, against the weave and capsize speeds
//! BicycleParameters' own matrices give (`scripts/bicycleparameters_reference.py`,
//! run once; the parameter files are as BicycleParameters wrote them).

use std::path::{Path, PathBuf};

use wobble_model::{critical_speeds, Mode, Model, ParamSet, Sweep};

fn data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bicycleparameters")
        .join(name)
}

/// (bicycle, weave speed, capsize speed), m/s.
fn references() -> Vec<(String, f64, f64)> {
    let text = std::fs::read_to_string(data("critical_speeds.csv")).unwrap();
    let rows: Vec<(String, String, f64)> = text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.starts_with("bicycle,"))
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            (c[0].to_owned(), c[1].to_owned(), c[2].parse().unwrap())
        })
        .collect();
    let speed = |b: &str, m: &str| {
        let found: Vec<f64> = rows
            .iter()
            .filter(|r| r.0 == b && r.1 == m)
            .map(|r| r.2)
            .collect();
        assert_eq!(found.len(), 1, "{b} {m}");
        found[0]
    };
    let mut names: Vec<String> = rows.iter().map(|r| r.0.clone()).collect();
    names.dedup();
    assert_eq!(names.len(), 7, "six measured bicycles and the benchmark");
    names
        .into_iter()
        .map(|b| {
            let (w, c) = (speed(&b, "weave"), speed(&b, "capsize"));
            (b, w, c)
        })
        .collect()
}

fn grid(step: f64, top: f64) -> Vec<f64> {
    let n = (top / step).round() as usize;
    (0..=n).map(|i| i as f64 * step).collect()
}

#[test]
fn weave_and_capsize_speeds_of_every_bicycle_on_every_grid() {
    for (bicycle, weave, capsize) in references() {
        let set = ParamSet::load(&data(&format!("{bicycle}Benchmark.txt"))).unwrap();
        let model = Model::from_set(&set).unwrap();
        for step in [0.5, 0.37, 0.25, 0.1, 0.05, 0.013] {
            let sweep = Sweep::run(&model, &grid(step, 10.0), |_| {}).unwrap();
            let found = critical_speeds(&model, &sweep);
            let what = format!("{bicycle}, {step} m/s grid: {found:?}");
            assert!(found.iter().all(|c| c.speed_mps > 0.1), "{what}");
            let weaves: Vec<_> = found.iter().filter(|c| c.mode == Mode::Weave).collect();
            let capsizes: Vec<_> = found.iter().filter(|c| c.mode == Mode::Capsize).collect();
            assert_eq!(weaves.len(), 1, "{what}");
            assert_eq!(capsizes.len(), 1, "{what}");
            assert_eq!(found.len(), 2, "nothing else crosses: {what}");
            let (w, c) = (weaves[0], capsizes[0]);
            assert!((w.speed_mps - weave).abs() < 1e-6, "{what}");
            assert!(!w.unstable_above && w.kind() == "oscillatory", "{what}");
            assert!(w.im_rad_per_s > 1.0, "{what}");
            assert!((c.speed_mps - capsize).abs() < 1e-6, "{what}");
            assert!(c.unstable_above && c.kind() == "real", "{what}");
        }
    }
}

/// Every bicycle has each Whipple mode once: the weave pair (oscillating
/// above its split into two real roots), capsize and castering, real at
/// standstill and at 10 m/s (on the Browser they meet near 1 m/s and part
/// again: still two modes).
#[test]
fn every_bicycle_has_the_four_whipple_branches_named() {
    for (bicycle, _, _) in references() {
        let set = ParamSet::load(&data(&format!("{bicycle}Benchmark.txt"))).unwrap();
        let model = Model::from_set(&set).unwrap();
        for step in [0.5, 0.01] {
            let sweep = Sweep::run(&model, &grid(step, 10.0), |_| {}).unwrap();
            let count = |m| sweep.of(m).count();
            assert_eq!(
                [
                    count(Mode::Weave),
                    count(Mode::Capsize),
                    count(Mode::Castering)
                ],
                [2, 1, 1],
                "{bicycle} {step}: {:?}",
                sweep.branches.iter().map(|b| b.mode).collect::<Vec<_>>()
            );
            let weave = sweep.upper(Mode::Weave).unwrap();
            assert!(
                weave.values[0].im.abs() < 1e-9,
                "{bicycle}: real at standstill"
            );
            assert!(
                weave.values.last().unwrap().im > 1.0,
                "{bicycle}: oscillating at 10 m/s"
            );
            for m in [Mode::Capsize, Mode::Castering] {
                let v = &sweep.upper(m).unwrap().values;
                assert!(
                    v[0].im.abs() < 1e-9 && v[v.len() - 1].im.abs() < 1e-9,
                    "{bicycle}"
                );
            }
        }
    }
}
