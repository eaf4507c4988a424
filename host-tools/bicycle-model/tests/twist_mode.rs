//! The `twist` is the front assembly twisting on the fork's lateral
//! compliance. Its name is checked here against its eigenvectors computed
//! directly from the state matrix at every speed of the sweep, not against
//! the naming's own participation sums.

mod support;

use support::bundled;

use wobble_model::eig::eigenvector;
use wobble_model::multibody::BETA;
use wobble_model::wobble::WobbleModel;
use wobble_model::{Mode, Model, StateRole, Sweep};

/// Mean shares of roll, steer, torso, twist and the tyre lags (squared
/// moduli over their sum, rates left out) of the eigenvectors of `values`.
fn mean_shares(model: &Model, speeds: &[f64], values: &[wobble_model::Complex<f64>]) -> [f64; 5] {
    let slots: Vec<Option<usize>> = model
        .state_roles()
        .into_iter()
        .map(|role| match role {
            StateRole::Roll => Some(0),
            StateRole::Steer => Some(1),
            StateRole::Torso => Some(2),
            StateRole::Twist => Some(3),
            StateRole::Tyre => Some(4),
            _ => None,
        })
        .collect();
    let mut mean = [0.0; 5];
    for (u, v) in speeds.iter().zip(values) {
        let x = eigenvector(&model.state_matrix(*u), *v);
        let mut s = [0.0; 5];
        for (slot, c) in slots.iter().zip(x.iter()) {
            if let Some(i) = slot {
                s[*i] += c.norm_sqr();
            }
        }
        let total: f64 = s.iter().sum();
        for (m, x) in mean.iter_mut().zip(s) {
            *m += x / total / speeds.len() as f64;
        }
    }
    mean
}

/// The twist's undamped angular frequency on the head's compliance alone,
/// the rest of the bicycle held and the tyre free: `sqrt((k_head + K) / I)`
/// with `K` the twist's gravity stiffness, rad/s.
fn head_alone_rad_s(set: &wobble_model::ParamSet) -> f64 {
    let m = WobbleModel::from_set(set).unwrap();
    let (inertia, gravity) = (m.lin.m[(2 + BETA, 2 + BETA)], m.lin.k[(2 + BETA, BETA)]);
    ((m.params.head_stiffness + gravity) / inertia).sqrt()
}

/// The twist's share of the four angles.
fn of_angles(s: &[f64; 5]) -> f64 {
    s[3] / s[..4].iter().sum::<f64>()
}

/// On each bicycle with a fork compliance, one branch pair is named `twist`;
/// averaged over 1-14 m/s its eigenvectors move the twist more than any other
/// angle (more than 80 % of the four), and it oscillates faster than the
/// head's compliance alone would let the fork twist with the frame held: the
/// front tyre's lateral stiffness is its second spring (its lags, 37 times
/// the twist on the paper's bicycle with its 0.08 m front relaxation length,
/// say how much it takes).
#[test]
fn the_twist_is_the_pair_that_twists_the_fork_most() {
    let speeds: Vec<f64> = (2..=28).map(|i| f64::from(i) * 0.5).collect();
    for file in [
        "paper-test-bicycle.toml",
        "paper-test-bicycle-light-rider.toml",
        "test-bicycle.toml",
    ] {
        let model = Model::from_set(&bundled(file)).unwrap();
        let sweep = Sweep::run(&model, &speeds, |_| {}).unwrap();
        assert_eq!(sweep.of(Mode::Twist).count(), 2, "{file}: one twist pair");
        let twist = sweep.upper(Mode::Twist).unwrap();
        let s = mean_shares(&model, &speeds, &twist.values);
        let head_alone = head_alone_rad_s(&bundled(file));
        assert!(
            twist.values.iter().all(|v| v.im > head_alone),
            "{file}: twist {:?} below {head_alone} rad/s",
            twist.values
        );
        assert!(of_angles(&s) > 0.8, "{file}: twist shares {s:?}");
        // Every other oscillating pair moves the other angles more than the
        // twist (the wobble twists the fork too, under its steer).
        for b in sweep.branches.iter().filter(|b| b.mode != Mode::Twist) {
            if b.values.iter().all(|v| v.im > 1e-6) {
                let o = mean_shares(&model, &speeds, &b.values);
                assert!(of_angles(&o) < 0.5, "{file}: {} twists {o:?}", b.mode);
            }
        }
    }
}
