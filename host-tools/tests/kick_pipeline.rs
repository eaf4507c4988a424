//! The host's kick extractor (`find_kicks`) on its own, on rides whose
//! answer is written down: a ring beside a wheel harmonic, a slow push
//! before the ring.

use std::f64::consts::TAU;

use wobblog::analysis::{find_kicks, Run};

/// The wheel's circumference, m.
const CIRCUMFERENCE_M: f64 = 2.18;

/// A 12 s ride at `speed` whose steering is `steer(t)`, 100 Hz.
fn ride(speed: f64, steer: impl Fn(f64) -> f64) -> Run {
    let mut run = Run::default();
    for i in 0..1200 {
        let t = f64::from(i) / 100.0;
        run.t_s.push(t);
        run.steer_deg.push(steer(t));
        run.speed_mps.push(speed);
        run.gyro_dps.push([0.0; 3]);
        run.accel_g.push([0.0, 0.0, 1.0]);
    }
    run
}

/// A ring of `amp` degrees at `freq` Hz decaying at `sigma` from `t0`.
fn ring(t: f64, t0: f64, amp: f64, freq: f64, sigma: f64) -> f64 {
    let r = t - t0;
    if r < 0.0 {
        0.0
    } else {
        amp * (sigma * r).exp() * (TAU * freq * r).sin()
    }
}

#[test]
fn a_ring_beside_a_wheel_harmonic_is_fitted_with_the_harmonic() {
    // The wheel turns at 2.1 Hz: its third harmonic, 6.3 Hz, rides
    // 0.7 Hz from the ring at 7.0 Hz for all of the ride.
    let speed = 2.1 * CIRCUMFERENCE_M;
    let run = ride(speed, |t| {
        ring(t, 3.0, 1.5, 7.0, -0.4) + 0.2 * (TAU * 6.3 * t + 0.4).sin()
    });
    let kicks = find_kicks(&run, CIRCUMFERENCE_M);
    assert_eq!(kicks.len(), 1, "{kicks:?}");
    let k = &kicks[0];
    assert!((k.freq_hz - 7.0).abs() < 0.05, "{k:?}");
    // Noise-free, the ring and the harmonic fitted together give sigma
    // exactly; the ring alone takes the harmonic's steady share for a
    // slower decay (-0.31 1/s).
    assert!((k.sigma_per_s + 0.4).abs() < 0.02, "{k:?}");
}

#[test]
fn a_slow_push_is_left_out_of_the_fit() {
    // The bar driven over and back by 12 degrees in 0.15 s, then the ring.
    let run = ride(3.0, |t| {
        let tau = t - 3.0;
        let push = if (0.0..0.15).contains(&tau) {
            12.0 * (TAU / 0.3 * tau).sin()
        } else {
            0.0
        };
        push + ring(t, 3.15, 1.5, 7.0, -1.2)
    });
    let kicks = find_kicks(&run, CIRCUMFERENCE_M);
    assert_eq!(kicks.len(), 1, "{kicks:?}");
    let k = &kicks[0];
    assert!((k.freq_hz - 7.0).abs() < 0.05, "{k:?}");
    assert!((k.sigma_per_s + 1.2).abs() < 0.1, "{k:?}");
}
