//! From a tense to a rigid rider (hip stiffness 500 to 50 000 N m/rad on
//! the first test bicycle): one `lean`, one `sway` and one `wobble` pair at
//! every stiffness, checked against the eigenvectors of the state matrix.
//! The lean is the pair rolling the upper body most on the hip: the torso's
//! low-frequency oscillation on a soft hip, and on a stiff one (12 000 N m/rad
//! and more) the torso against the frame at 19-31 Hz. The sway is the frame
//! sliding sideways on the rear tyre: under a held upper body on a soft hip,
//! with the upper body rolling along on a stiff one.

mod support;

use support::bundled;

use wobble_model::eig::eigen;
use wobble_model::{Complex, Mode, Model, Sweep};

const HIPS: [f64; 10] = [
    500.0, 1000.0, 2000.0, 5000.0, 8000.0, 12000.0, 16000.0, 20000.0, 30000.0, 50000.0,
];

/// A pair's upper member at 5 m/s, from the state matrix: its value and the
/// shares of `phi_r`, `alpha2'` among its angles and tyre lags, and `phi_r / phi`.
struct Pair {
    value: Complex<f64>,
    torso: f64,
    rear_slip: f64,
    torso_per_roll: Complex<f64>,
}

fn pairs_at_5(model: &Model) -> Vec<Pair> {
    let names = model.state_names();
    let at = |n: &str| names.iter().position(|m| *m == n).unwrap();
    let kept = [
        "phi", "delta", "phi_r", "beta", "alpha1'", "gamma1'", "alpha2'", "gamma2'",
    ];
    eigen(&model.state_matrix(5.0))
        .unwrap()
        .into_iter()
        .filter(|e| e.value.im > 1e-6)
        .map(|e| {
            let x = &e.vector;
            let total: f64 = kept.iter().map(|n| x[at(n)].norm_sqr()).sum();
            Pair {
                value: e.value,
                torso: x[at("phi_r")].norm_sqr() / total,
                rear_slip: x[at("alpha2'")].norm_sqr() / total,
                torso_per_roll: x[at("phi_r")] / x[at("phi")],
            }
        })
        .collect()
}

fn hz(v: Complex<f64>) -> f64 {
    v.im / std::f64::consts::TAU
}

#[test]
fn lean_and_sway_from_a_tense_to_a_rigid_rider() {
    let mut set = bundled("test-bicycle.toml");
    let speeds: Vec<f64> = (0..=28).map(|i| f64::from(i) * 0.5).collect();
    let mut lean_hz = Vec::new();
    for hip in HIPS {
        set.set_value("hip.stiffness", hip, "test").unwrap();
        let model = Model::from_set(&set).unwrap();
        let sweep = Sweep::run(&model, &speeds, |_| {}).unwrap();
        for mode in [Mode::Lean, Mode::Sway, Mode::Wobble] {
            assert_eq!(sweep.of(mode).count(), 2, "hip {hip}: one {mode} pair");
        }
        let named = |mode| sweep.upper(mode).unwrap().values[10];
        let pairs = pairs_at_5(&model);
        let pair = |v: Complex<f64>| {
            pairs
                .iter()
                .min_by(|a, b| (a.value - v).norm().total_cmp(&(b.value - v).norm()))
                .unwrap()
        };
        let (lean, sway) = (pair(named(Mode::Lean)), pair(named(Mode::Sway)));
        // The lean rolls the upper body on the hip most of all pairs.
        let most_torso = pairs.iter().map(|p| p.torso).fold(0.0, f64::max);
        assert_eq!(lean.torso, most_torso, "hip {hip}: lean {}", lean.value);
        lean_hz.push(hz(lean.value));
        // The sway is carried by the rear tyre's slip lag, more than by any
        // other pair but the lean.
        assert!(sway.rear_slip > 0.5, "hip {hip}: sway {}", sway.value);
        for p in pairs.iter().filter(|p| p.value != lean.value) {
            assert!(
                p.rear_slip <= sway.rear_slip,
                "hip {hip}: {} beside the sway",
                p.value
            );
        }
        // A soft hip holds the upper body while the frame rolls under it; a
        // stiff one rolls it along with the frame, and its lean is the
        // upper body against the frame, faster than the sway.
        let along = sway.torso_per_roll.re > 0.0;
        assert_eq!(
            along,
            hip >= 12000.0,
            "hip {hip}: phi_r / phi {}",
            sway.torso_per_roll
        );
        if hip >= 12000.0 {
            assert!(
                lean.torso_per_roll.re < -1.0,
                "hip {hip}: lean phi_r / phi {}",
                lean.torso_per_roll
            );
            assert!(hz(lean.value) > hz(sway.value), "hip {hip}");
        }
    }
    // The lean stiffens with the hip.
    assert!(
        lean_hz.windows(2).all(|w| w[1] > w[0]),
        "lean frequencies {lean_hz:?}"
    );
}
