//! Kick tests below the wobble speed (`wobble_hil::corpus::kicks`, generated
//! here): the on-board alert never fires on a ring-down that decays, and the
//! on-board kick measurement meets its accuracy goal against the truth.

use std::sync::OnceLock;

use wobble_core::config::Config;
use wobble_hil::corpus::kicks;
use wobble_hil::kick_metrics::{self, KickScore};

/// The issue's threshold: a ring decaying faster than this never alerts.
const DECAYING_PER_S: f64 = -0.3;

/// Seeds of the signal-model rides (90 kicks each) and of the simulated
/// bicycle's (48 each). Seeds 4 (signal) and 3 (simulated) hold slow rings
/// that alerted on their tail before the envelope trend.
const SIGNAL_SEEDS: core::ops::RangeInclusive<u64> = 1..=4;
const SIMULATED_SEEDS: core::ops::RangeInclusive<u64> = 1..=3;

/// The signal-model kick rides of [`SIGNAL_SEEDS`], each seed's scores.
fn signal_seeds() -> &'static [Vec<KickScore>] {
    static S: OnceLock<Vec<Vec<KickScore>>> = OnceLock::new();
    S.get_or_init(|| {
        SIGNAL_SEEDS
            .map(|seed| {
                let rides = kicks::signal_rides(seed, 9);
                kick_metrics::score(&rides, &Config::default()).expect("scores")
            })
            .collect()
    })
}

fn signal() -> Vec<KickScore> {
    signal_seeds().concat()
}

fn simulated() -> &'static [KickScore] {
    static S: OnceLock<Vec<KickScore>> = OnceLock::new();
    S.get_or_init(|| {
        let rides: Vec<_> = SIMULATED_SEEDS
            .flat_map(|seed| {
                kicks::simulated_rides(seed, &kicks::SIMULATED_SPEEDS).expect("simulates")
            })
            .collect();
        kick_metrics::score(&rides, &Config::default()).expect("scores")
    })
}

fn alerted(scores: &[KickScore]) -> Vec<String> {
    scores
        .iter()
        .filter(|k| k.sigma_per_s < DECAYING_PER_S && !k.alerts_s.is_empty())
        .map(|k| {
            format!(
                "{} kick at {:.2} s (sigma {:.2}/s, {:.2} deg, {:.2} m/s): alert at {:?}",
                k.fixture, k.t_s, k.sigma_per_s, k.amp_deg, k.speed_mps, k.alerts_s
            )
        })
        .collect()
}

#[test]
fn the_rides_hold_the_kicks_the_issue_describes() {
    let s = signal();
    assert_eq!(s.len(), 90 * SIGNAL_SEEDS.count());
    assert!(s.iter().all(|k| (-3.0..=-0.3).contains(&k.sigma_per_s)));
    assert!(s.iter().all(|k| (1.2..=2.6).contains(&k.amp_deg)));
    assert!(s.iter().any(|k| k.speed_mps < 2.0) && s.iter().any(|k| k.speed_mps > 5.5));
    let m = simulated();
    assert_eq!(m.len(), 48 * SIMULATED_SEEDS.count());
    // The model's wobble decays ever more slowly towards the wobble speed.
    assert!(m.iter().all(|k| k.sigma_per_s < 0.0
        && k.speed_mps < kicks::TEST_BIKE_WOBBLE_MPS
        && k.amp_deg < 3.5));
}

#[test]
fn no_decaying_ring_down_alerts_on_signal_model_kicks() {
    let bad = alerted(&signal());
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn no_decaying_ring_down_alerts_on_the_simulated_bicycle() {
    let bad = alerted(simulated());
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The share of kicks at 1.5-6 m/s measured within the issue's accuracy:
/// sigma within 0.3 1/s and the frequency within 0.2 Hz of the truth.
fn accurate_share<'a>(scores: impl IntoIterator<Item = &'a KickScore>) -> f64 {
    let band: Vec<_> = scores
        .into_iter()
        .filter(|k| (1.5..=6.0).contains(&k.speed_mps))
        .collect();
    band.iter().filter(|k| k.within(0.3, 0.2)).count() as f64 / band.len() as f64
}

#[test]
fn at_least_80_percent_of_kicks_are_measured_within_the_goal() {
    // Measured (firmware/docs/detector.md): 88 and 92 % of the signal-model
    // kicks of seeds 1 and 2 (rings down to -3 1/s, half of them behind a
    // push), 81 % of their rings faster than 1.5 1/s, and 96 % of the
    // simulated bicycle's.
    for (seed, scores) in (1..).zip(signal_seeds()) {
        let share = accurate_share(scores);
        assert!(share >= 0.8, "signal seed {seed}: {:.0} %", 100.0 * share);
    }
    let signal = signal();
    let fast = accurate_share(signal.iter().filter(|k| k.sigma_per_s < -1.5));
    assert!(
        fast >= 0.8,
        "rings faster than 1.5 1/s: {:.0} %",
        100.0 * fast
    );
    let share = accurate_share(simulated());
    assert!(share >= 0.9, "simulated: {:.0} %", 100.0 * share);
}
