//! A kick below the wobble speed is a stable episode, never an unstable
//! one: with and without a visible push (the hand's large, short steering
//! transient before the ring-down), over ring-downs decaying at 0.3-3 1/s
//! from 1.2-2.6 degrees, on a weave, noise and wheel ripple. The push's
//! edges ring through the zero-phase band-pass before the push itself, as
//! an oscillation near the band's centre that grows towards the kick; an
//! analysis that takes that for a wobble growing by itself calls a stable
//! bicycle unstable.

use std::f64::consts::TAU;

use proptest::prelude::*;
use wobblog::analysis::{find_episodes, Run, Stability};

/// A 12 s ride at 3 m/s with one kick at 5 s: optionally a push of
/// `push_deg` over `push_s` (raised and released as a half sine), then a
/// ring of `amp_deg` decaying at `sigma`, at `freq_hz`; a 0.8 Hz weave of
/// 1 degree, 0.03 degrees of wheel ripple at 4x and 3x the wheel and
/// small noise.
fn kick_run(push: Option<(f64, f64)>, amp_deg: f64, sigma: f64, freq_hz: f64, seed: u64) -> Run {
    let fs = 100.0;
    let speed = 3.0;
    let wheel_hz = speed / 2.18;
    let mut state = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1;
    let mut run = Run::default();
    for i in 0..1200 {
        let t = f64::from(i) / fs;
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let noise = 0.03 * ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5);
        let weave = 1.0 * (TAU * 0.8 * t).sin();
        let ripple =
            0.03 * ((TAU * 4.0 * wheel_hz * t).sin() + (TAU * 3.0 * wheel_hz * t + 1.0).sin());
        let (push_deg, push_s) = push.unwrap_or((0.0, 0.0));
        let tau = t - 5.0;
        let push = if (0.0..push_s).contains(&tau) {
            push_deg * (TAU / (2.0 * push_s) * tau).sin()
        } else {
            0.0
        };
        let r = tau - push_s;
        let ring = if r >= 0.0 {
            amp_deg * (sigma * r).exp() * (TAU * freq_hz * r).sin()
        } else {
            0.0
        };
        run.t_s.push(t);
        run.steer_deg.push(weave + ripple + noise + push + ring);
        run.speed_mps.push(speed);
        run.gyro_dps.push([0.0; 3]);
        run.accel_g.push([0.0, 0.0, 1.0]);
    }
    run
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// No kick is called unstable, whatever its push.
    #[test]
    fn a_kick_is_never_unstable(
        push in prop_oneof![Just(None), (2.0..15.0f64, 0.02..0.3f64).prop_map(Some)],
        amp_deg in 1.2..2.6f64,
        sigma in -3.0..-0.3f64,
        freq_hz in 6.0..8.5f64,
        seed in 0u64..1000,
    ) {
        let run = kick_run(push, amp_deg, sigma, freq_hz, seed);
        let episodes = find_episodes(&run);
        for e in &episodes {
            prop_assert_eq!(e.stability, Stability::Stable, "{:?}", e);
        }
    }

    /// Without a push the ring is measured as the stable episode it is.
    #[test]
    fn a_knock_is_measured(
        amp_deg in 1.2..2.6f64,
        sigma in -3.0..-0.3f64,
        freq_hz in 6.0..8.5f64,
        seed in 0u64..1000,
    ) {
        let episodes = find_episodes(&kick_run(None, amp_deg, sigma, freq_hz, seed));
        let ring = episodes.iter().find(|e| (e.freq_hz - freq_hz).abs() < 0.2);
        prop_assert!(ring.is_some_and(|e| (e.sigma_per_s - sigma).abs() < 0.3), "{:?}", episodes);
    }
}

/// A case the property test above once drew (exact values kept): a slow,
/// small push, then a ring decaying at -1.77 1/s.
#[test]
fn a_slow_small_push_then_a_decaying_ring_is_stable() {
    let run = kick_run(Some((2.0, 0.2481)), 1.2, -1.7653, 6.0, 0);
    let episodes = find_episodes(&run);
    for e in &episodes {
        assert_eq!(e.stability, Stability::Stable, "{e:?}");
    }
}
