//! The extended wobble model: its Whipple limits, and the first test
//! bicycle's wobble (the simulated corpus's; the seed paper's claims on the
//! re-derived test bicycle are in `paper_claims.rs`).

mod support;

use support::bundled;

use nalgebra::Complex;
use wobble_model::multibody::{self, constrained_whipple};
use wobble_model::wobble::{WobbleModel, WobbleParams};
use wobble_model::{critical_speeds, Mode, Model, ParamSet, Sweep};

fn speeds() -> Vec<f64> {
    (5..=100).map(|i| f64::from(i) * 0.1).collect()
}

/// The wobble eigenvalue (upper member) at every speed of `speeds()`.
fn wobble(set: &ParamSet) -> (Vec<Complex<f64>>, Option<f64>) {
    let model = Model::from_set(set).unwrap();
    let sweep = Sweep::run(&model, &speeds(), |_| {}).unwrap();
    let branch = sweep
        .upper(Mode::Wobble)
        .expect("a wobble mode")
        .values
        .clone();
    let speed = critical_speeds(&model, &sweep)
        .into_iter()
        .find(|c| c.mode == Mode::Wobble && c.unstable_above)
        .map(|c| c.speed_mps);
    (branch, speed)
}

fn hz(v: Complex<f64>) -> f64 {
    v.im / std::f64::consts::TAU
}

#[test]
fn constrained_limit_is_the_lumped_whipple_bicycle_exactly() {
    for file in [
        "test-bicycle.toml",
        "paper-test-bicycle.toml",
        "paper-test-bicycle-light-rider.toml",
    ] {
        let p = WobbleParams::from_set(&bundled(file)).unwrap();
        let (geo, bodies) = p.description();
        let [m, c1, k0g, k2] = constrained_whipple(&multibody::linearise(&geo, &bodies));
        let want = p.to_benchmark().matrices();
        for (got, want, what) in [
            (m, want.m, "M"),
            (c1, want.c1, "C1"),
            (k0g / p.gravity, want.k0, "K0"),
            (k2, want.k2, "K2"),
        ] {
            for i in 0..2 {
                for j in 0..2 {
                    assert!(
                        (got[(i, j)] - want[(i, j)]).abs() < 1e-10,
                        "{file} {what}: {got} vs {want}"
                    );
                }
            }
        }
    }
}

/// Stiffer by `k`: tyres (cornering up, relaxation down: towards no
/// relaxation), torso and twist springs; the tyre moments off (the
/// Whipple wheel is a knife edge).
fn stiffened(p: &WobbleParams, k: f64) -> WobbleParams {
    let mut s = *p;
    for t in [&mut s.front_tyre, &mut s.rear_tyre] {
        t.cornering_stiffness *= k;
        t.relaxation_length /= k;
        t.camber_relaxation_length /= k;
        t.camber_stiffness = 0.0;
        t.aligning_coefficient = 0.0;
        t.twisting_coefficient = 0.0;
        t.overturning_coefficient = 0.0;
    }
    s.hip_stiffness = 1e3 * k * k;
    s.head_stiffness *= k * k;
    s
}

#[test]
fn stiff_tyres_rigid_head_and_locked_torso_converge_to_whipple() {
    let p = WobbleParams::from_set(&bundled("test-bicycle.toml")).unwrap();
    let whipple = p.to_benchmark().matrices();
    let mut last = f64::INFINITY;
    for k in [10.0, 100.0, 1000.0] {
        let model = WobbleModel::new(stiffened(&p, k));
        let mut worst: f64 = 0.0;
        for u in [1.0, 3.0, 5.0, 8.0] {
            let ext = wobble_model::eig::eigenvalues(&model.state_matrix(u)).unwrap();
            for w in wobble_model::eig::eigenvalues(&whipple.state_matrix(u)).unwrap() {
                let nearest = ext
                    .iter()
                    .map(|e| (e - w).norm())
                    .fold(f64::INFINITY, f64::min);
                worst = worst.max(nearest / w.norm().max(1.0));
            }
        }
        println!("stiffness x{k}: worst relative distance {worst:.3e}");
        assert!(
            worst < last / 5.0,
            "x{k}: {worst} does not converge (before {last})"
        );
        last = worst;
    }
    assert!(last < 1e-3, "{last}");
}

#[test]
fn test_bicycle_wobbles_near_6_hz_unstable_from_about_4_mps() {
    let (w, speed) = wobble(&bundled("test-bicycle.toml"));
    let f_low = hz(w[5]); // 1 m/s
    let f_high = hz(w[95]); // 10 m/s
    assert!((5.5..6.5).contains(&f_low), "{f_low} Hz at 1 m/s");
    assert!(
        f_high > f_low,
        "frequency rises with speed: {f_low} -> {f_high} Hz"
    );
    let speed = speed.expect("a wobble speed");
    assert!((3.5..4.5).contains(&speed), "wobble speed {speed}");
    assert!(w[5].re < 0.0 && w[95].re > 0.0);
}

fn scaled(file: &str, key: &str, factor: f64) -> ParamSet {
    let mut s = bundled(file);
    let v = s.value(key).unwrap();
    s.set_value(key, v * factor, "scaled in a test").unwrap();
    s
}

#[test]
fn more_front_cornering_stiffness_raises_wobble_frequency_and_growth() {
    let (base, _) = wobble(&bundled("test-bicycle.toml"));
    let (stiff, _) = wobble(&scaled(
        "test-bicycle.toml",
        "front_tyre.cornering_stiffness",
        1.5,
    ));
    for k in 0..base.len() {
        assert!(
            hz(stiff[k]) > hz(base[k]),
            "frequency at {} m/s",
            speeds()[k]
        );
        assert!(stiff[k].re > base[k].re, "growth at {} m/s", speeds()[k]);
    }
}

#[test]
fn steering_head_damping_stabilises_wobble() {
    let (base, base_speed) = wobble(&bundled("test-bicycle.toml"));
    let (damped, damped_speed) = wobble(&scaled("test-bicycle.toml", "steer_head.damping", 2.0));
    for k in 0..base.len() {
        assert!(damped[k].re < base[k].re, "at {} m/s", speeds()[k]);
    }
    assert!(damped_speed.is_none_or(|s| s > base_speed.unwrap()));
}

/// A tense rider (hip stiffness over the range where the torso lean mode
/// moves from below to far above the wobble, through 5-6 Hz where it carries
/// much steer): the wobble keeps its name, the lean stays the lean, and a
/// coarse grid follows the same branch as a fine one.
#[test]
fn wobble_keeps_its_name_whatever_the_hip_stiffness() {
    let mut set = bundled("test-bicycle.toml");
    for hip in [
        500.0, 1000.0, 2000.0, 3000.0, 5000.0, 8000.0, 12000.0, 20000.0, 30000.0, 50000.0,
    ] {
        set.set_value("hip.stiffness", hip, "test").unwrap();
        let model = Model::from_set(&set).unwrap();
        let grid = |step: f64| -> Vec<f64> {
            let n = (14.0 / step).round() as usize;
            (0..=n).map(|i| i as f64 * step).collect()
        };
        let (coarse, fine) = (grid(0.5), grid(0.05));
        let wobble_on = |speeds: &[f64]| {
            let sweep = Sweep::run(&model, speeds, |_| {}).unwrap();
            assert_eq!(
                sweep.of(Mode::Wobble).count(),
                2,
                "hip {hip}: one wobble pair"
            );
            assert!(sweep.of(Mode::Lean).count() >= 2, "hip {hip}: a lean mode");
            sweep.upper(Mode::Wobble).unwrap().values.clone()
        };
        let (c, f) = (wobble_on(&coarse), wobble_on(&fine));
        for (k, v) in c.iter().enumerate() {
            assert!(
                (4.5..7.0).contains(&hz(*v)),
                "hip {hip}: {} Hz at {} m/s",
                hz(*v),
                coarse[k]
            );
            assert!(
                (v - f[10 * k]).norm() < 1e-9,
                "hip {hip}: grids differ at {} m/s",
                coarse[k]
            );
        }
    }
}

/// The state matrix is affine in the speed: the pencil the sweep evaluates
/// equals the assembled equations.
#[test]
fn state_matrix_is_the_affine_pencil() {
    let model = Model::from_set(&bundled("test-bicycle.toml")).unwrap();
    let pencil = model.pencil().expect("the wobble model is affine in u");
    for u in [0.3, 2.0, 7.5, 14.0, 40.0] {
        let a = model.state_matrix(u);
        let scale = a.amax();
        assert!((pencil.at(u) - &a).amax() < 1e-12 * scale, "at {u} m/s");
    }
    assert!(Model::from_set(&bundled("benchmark.toml"))
        .unwrap()
        .pencil()
        .is_none());
}

/// The non-holonomic counterpart: with the steering head made rigid its
/// eigenvalues are those of the independent constrained description that
/// keeps roll, torso and steer (the one checked against BicycleParameters'
/// rider-lean model), with the same hip spring-damper.
#[test]
fn no_slip_counterpart_with_a_rigid_head_is_the_rider_lean_bicycle() {
    let mut set = bundled("test-bicycle.toml");
    set.set_value("steer_head.stiffness", 1e9, "rigid").unwrap();
    let model = Model::no_slip_of(&set).unwrap();
    assert_eq!(model.state_names().len(), 8);
    let wobble = WobbleModel::from_set(&set).unwrap();
    let [m, c1, k0g, k2] = multibody::constrained(
        &wobble.lin,
        &[multibody::PHI, multibody::PHI_R, multibody::DELTA],
    );
    let p = &wobble.params;
    for u in [1.0, 4.0, 8.0] {
        let mut k = &k0g + &k2 * (u * u);
        let mut c = &c1 * u;
        k[(1, 1)] += p.hip_stiffness;
        c[(1, 1)] += p.hip_damping;
        c[(2, 2)] += p.steer_damping;
        let mi = m.clone().try_inverse().unwrap();
        let mut a = nalgebra::DMatrix::zeros(6, 6);
        a.view_mut((0, 3), (3, 3)).fill_with_identity();
        a.view_mut((3, 0), (3, 3)).copy_from(&(-&mi * k));
        a.view_mut((3, 3), (3, 3)).copy_from(&(-&mi * c));
        let got = wobble_model::eig::eigenvalues(&model.state_matrix(u)).unwrap();
        for want in wobble_model::eig::eigenvalues(&a).unwrap() {
            let d = got
                .iter()
                .map(|g| (g - want).norm())
                .fold(f64::INFINITY, f64::min);
            assert!(d < 1e-4 * want.norm().max(1.0), "{want} at {u} m/s: {d}");
        }
    }
}

/// Writes the test bicycle's pencil `A0`, `A1` (14 rows each) to the file
/// `PENCIL_OUT` names, for `scripts/lapack_batch_reference.py` (run by hand).
#[test]
#[ignore = "writes a file for the LAPACK comparison"]
fn write_pencil() {
    let out = std::env::var("PENCIL_OUT").expect("PENCIL_OUT names the file to write");
    let pencil = Model::from_set(&bundled("test-bicycle.toml"))
        .unwrap()
        .pencil()
        .unwrap();
    let mut text = String::new();
    for m in [pencil.a0, pencil.a1] {
        for r in m.row_iter() {
            let cells: Vec<String> = r.iter().map(|v| format!("{v:e}")).collect();
            text.push_str(&cells.join(","));
            text.push('\n');
        }
    }
    std::fs::write(out, text).unwrap();
}

/// The critical speeds the sweep brackets on a grid and refines by Brent's
/// method are the speeds the affine pencil puts an eigenvalue on the
/// imaginary axis (bialternate sum, no grid), to 1e-9 m/s, with the same
/// frequency; on the test bicycle with its standard and a tense rider.
#[test]
fn critical_speeds_are_the_pencils_neutral_speeds() {
    use wobble_model::neutral::neutral_speeds;
    for hip in [None, Some(2000.0)] {
        let mut s = bundled("test-bicycle.toml");
        if let Some(k) = hip {
            s.set_value("hip.stiffness", k, "tense rider").unwrap();
        }
        let model = Model::from_set(&s).unwrap();
        let speeds: Vec<f64> = (1..=120).map(|i| f64::from(i) * 0.1).collect();
        let sweep = Sweep::run(&model, &speeds, |_| {}).unwrap();
        let brent = critical_speeds(&model, &sweep);
        let neutral = neutral_speeds(&model.pencil().unwrap(), (0.1, 12.0));
        println!("hip {hip:?}: brent {brent:?}\n  pencil {neutral:?}");
        assert!(!brent.is_empty());
        for c in &brent {
            let n = neutral
                .iter()
                .min_by(|a, b| {
                    (a.speed_mps - c.speed_mps)
                        .abs()
                        .total_cmp(&(b.speed_mps - c.speed_mps).abs())
                })
                .unwrap();
            assert!(
                (n.speed_mps - c.speed_mps).abs() < 1e-9,
                "{c:?} against the pencil's {n:?}"
            );
            assert!((n.im_rad_per_s - c.im_rad_per_s).abs() < 1e-6 * c.im_rad_per_s.max(1.0));
        }
    }
}
