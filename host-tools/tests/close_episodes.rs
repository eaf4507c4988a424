//! Episodes a few seconds apart are measured apart: the fits look up to 4 s
//! before a growth and after a decay for a steady tone beside the wobble,
//! and there they must not take up the neighbouring episode (a growth fit
//! that starts in the previous episode's ring-down finds no growth, a decay
//! fit that runs into the next kick explains neither).

mod analysis_support;

use std::f64::consts::TAU;

use analysis_support::{limits, wobble, Ride};
use wobblog::analysis::{find_episodes, Episode, Stability};

/// The standard wobble (7 Hz, growing at 2/s from 0.02 degrees at 14 s to
/// 2 degrees, caught at 5/s), `after_s` later and at `freq_hz`.
fn later_wobble(t: f64, after_s: f64, freq_hz: f64) -> f64 {
    wobble::envelope_deg(t - after_s) * (TAU * freq_hz * t).sin()
}

/// A kick on the handlebar at `t0_s`: the stable mode ringing down.
#[derive(Clone, Copy, Debug)]
struct Kick {
    t0_s: f64,
    amp_deg: f64,
    freq_hz: f64,
    decay_per_s: f64,
}

impl Kick {
    fn at(&self, t: f64) -> f64 {
        let tau = t - self.t0_s;
        if tau < 0.0 {
            return 0.0;
        }
        self.amp_deg * (-self.decay_per_s * tau).exp() * (TAU * self.freq_hz * tau).sin()
    }
}

/// A 30 s ride at 5 m/s with the standard wobble at 14 s (or none), a wheel
/// whose 3rd harmonic (0.08 degrees) lies 0.1 Hz from that wobble, and
/// `extra` added to the steering.
fn ride(with_wobble: bool, extra: impl Fn(f64) -> f64) -> Ride {
    let mut ride = Ride::new(30.0, 5.0, 0.0, 0.0, 0.0);
    let harmonic_hz = 3.0 * 5.0 / 2.18;
    for (t, steer) in ride.t_s.iter().zip(&mut ride.steer_deg) {
        if !with_wobble {
            *steer -= wobble::envelope_deg(*t) * (TAU * wobble::FREQ_HZ * t).sin();
        }
        *steer += 0.08 * (TAU * harmonic_hz * t + 0.7).sin() + extra(*t);
    }
    ride
}

/// The unstable episode whose span holds `peak_s`.
fn unstable_at(found: &[Episode], peak_s: f64) -> &Episode {
    found
        .iter()
        .filter(|e| e.stability == Stability::Unstable)
        .find(|e| e.onset_s - 1.0 <= peak_s && peak_s <= e.end_s + 0.5)
        .unwrap_or_else(|| panic!("no unstable episode at {peak_s} s: {found:#?}"))
}

/// `e` is the standard wobble moved `after_s` later and set to `freq_hz`,
/// within the corpus's acceptance limits; its peak within a tenth of a
/// second.
fn assert_is_wobble(e: &Episode, after_s: f64, freq_hz: f64) {
    let onset_s = wobble::ONSET_S + after_s;
    let peak_s = wobble::peak_s() + after_s;
    let sigma_rel = e.sigma_per_s / wobble::SIGMA_PER_S - 1.0;
    println!(
        "wobble at {onset_s:5.2} s: f {:+.3} Hz, sigma {:+.1} %, onset {:+.3} s, peak {:+.3} s",
        e.freq_hz - freq_hz,
        100.0 * sigma_rel,
        e.onset_s - onset_s,
        e.peak_s - peak_s
    );
    assert!((e.freq_hz - freq_hz).abs() < limits::FREQ_TOL_HZ, "{e:?}");
    assert!(sigma_rel.abs() < limits::SIGMA_TOL_REL, "{e:?}");
    assert!((e.onset_s - onset_s).abs() < limits::ONSET_TOL_S, "{e:?}");
    assert!((e.peak_s - peak_s).abs() < 0.1, "{e:?}");
}

/// The stable episode struck at `kick`, measured as the corpus's kicks are.
fn assert_is_kick(found: &[Episode], kick: Kick) {
    let e = found
        .iter()
        .find(|e| (e.onset_s - kick.t0_s).abs() < 0.5)
        .unwrap_or_else(|| panic!("no episode at the kick {kick:?}: {found:#?}"));
    assert_eq!(e.stability, Stability::Stable, "{kick:?}: {e:?}");
    let decay_rel = -e.sigma_per_s / kick.decay_per_s - 1.0;
    println!(
        "kick at {:5.2} s: f {:+.3} Hz, decay {:+.1} %",
        kick.t0_s,
        e.freq_hz - kick.freq_hz,
        100.0 * decay_rel
    );
    assert!(
        (e.freq_hz - kick.freq_hz).abs() < limits::KICK_FREQ_TOL_HZ,
        "{kick:?}: {e:?}"
    );
    assert!(
        decay_rel.abs() < limits::KICK_SIGMA_TOL_REL,
        "{kick:?}: {e:?}"
    );
}

#[test]
fn two_wobbles_seconds_apart_are_each_measured() {
    // The second starts growing 2.2-3.8 s after the first is caught: its
    // growth fit's 4 s look-back would reach into the first.
    for (after_s, freq_hz) in [(4.5, 7.0), (5.0, 6.4), (6.0, 7.8)] {
        let found = find_episodes(&ride(true, |t| later_wobble(t, after_s, freq_hz)).run());
        assert_is_wobble(unstable_at(&found, wobble::peak_s()), 0.0, wobble::FREQ_HZ);
        let second = unstable_at(&found, wobble::peak_s() + after_s);
        assert_is_wobble(second, after_s, freq_hz);
    }
}

#[test]
fn a_kick_just_before_a_wobble_is_measured_apart_from_it() {
    for t0_s in [11.5, 12.5] {
        let kick = Kick {
            t0_s,
            amp_deg: 3.0,
            freq_hz: 6.2,
            decay_per_s: 6.0,
        };
        let found = find_episodes(&ride(true, |t| kick.at(t)).run());
        assert_is_kick(&found, kick);
        assert_is_wobble(unstable_at(&found, wobble::peak_s()), 0.0, wobble::FREQ_HZ);
    }
}

#[test]
fn kicks_in_a_row_are_each_a_stable_mode() {
    // 2.5 s apart: each ring's decay fit would reach 4 s into the next.
    let kicks = [(8.0, 6.0, 5.0), (10.5, 7.2, 7.0), (13.0, 6.6, 4.0)].map(
        |(t0_s, freq_hz, decay_per_s)| Kick {
            t0_s,
            amp_deg: 3.0,
            freq_hz,
            decay_per_s,
        },
    );
    let found = find_episodes(&ride(false, |t| kicks.iter().map(|k| k.at(t)).sum()).run());
    for kick in kicks {
        assert_is_kick(&found, kick);
    }
    assert!(
        found.iter().all(|e| e.stability == Stability::Stable),
        "{found:#?}"
    );
}
