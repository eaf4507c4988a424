//! The episode fit only calls a wobble unstable when one growing sinusoid
//! explains the signal: a swelling of motion at two frequencies at once
//! grows in envelope just as
//! a wobble does, but no single mode explains it, so it is no unstable
//! episode (a fit that accepted any residual would call it one). The same
//! envelope on one tone is one.

use std::f64::consts::TAU;

use wobblog::analysis::{find_episodes, Run, Stability};

/// A 30 s run at 100 Hz with steering `x(t)` at 4.5 m/s.
fn run(x: impl Fn(f64) -> f64) -> Run {
    let mut run = Run::default();
    for i in 0..3000 {
        let t = f64::from(i) / 100.0;
        run.t_s.push(t);
        run.steer_deg.push(x(t));
        run.speed_mps.push(4.5);
        run.gyro_dps.push([0.0; 3]);
        run.accel_g.push([0.0; 3]);
    }
    run
}

/// Grows at 1.5/s from 0.02 deg at 8 s to 2 deg, holds, gone at 16 s.
fn envelope(t: f64) -> f64 {
    if (8.0..=16.0).contains(&t) {
        (0.02 * (1.5 * (t - 8.0)).exp()).min(2.0)
    } else {
        0.0
    }
}

#[test]
fn a_swelling_of_two_tones_is_no_unstable_wobble() {
    // Two equal tones 2 Hz or more apart: one sinusoid explains half the
    // power at best (an RMS residual of 71 %).
    for (f1, f2) in [(6.0, 8.0), (6.2, 8.6), (6.5, 8.9), (5.8, 8.2)] {
        let r = run(|t| envelope(t) * ((TAU * f1 * t).sin() + (TAU * f2 * t + 1.0).sin()));
        // Big enough to be an episode's size (0.5 deg of envelope) many
        // times over: only the fit can turn it down.
        let peak = r.steer_deg.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(peak > 2.0, "{f1}+{f2} Hz: peak {peak}");
        let unstable: Vec<_> = find_episodes(&r)
            .into_iter()
            .filter(|e| e.stability == Stability::Unstable)
            .collect();
        assert!(unstable.is_empty(), "{f1}+{f2} Hz: {unstable:?}");
    }
}

#[test]
fn the_same_swelling_on_one_tone_is_an_unstable_wobble() {
    let r = run(|t| envelope(t) * (TAU * 6.8 * t).sin());
    let episodes = find_episodes(&r);
    assert_eq!(episodes.len(), 1, "{episodes:?}");
    let e = &episodes[0];
    assert_eq!(e.stability, Stability::Unstable);
    assert!((e.sigma_per_s - 1.5).abs() < 0.3, "{e:?}");
    assert!((e.freq_hz - 6.8).abs() < 0.1, "{e:?}");
}
