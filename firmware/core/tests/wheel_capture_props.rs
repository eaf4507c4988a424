//! Edge times from (counter, capture, now) triples as the board's wheel
//! interrupt reads them: exact across the 32-bit timer wrap, at the highest
//! edge rate (240 edges/s, 10 m/s on the 50-hole disc) with any interrupt
//! latency below one edge interval, with repeated reads of one capture mixed
//! in, and into the speed estimator.

use proptest::prelude::*;
use wobble_core::wheel::{WheelConfig, WheelSpeed};
use wobble_core::wheel_capture::{EdgeClock, RawCapture, Refused};

/// 240 edges per second.
const EDGE_INTERVAL_US: u64 = 1_000_000 / 240;

/// What the interrupt reads for an edge at `t_us` (system clock) handled
/// `latency_us` later, with the timer `offset` counts ahead of the clock.
fn read_at(t_us: u64, latency_us: u64, offset: u32) -> RawCapture {
    let count = |t: u64| (t as u32).wrapping_add(offset);
    RawCapture {
        counter: count(t_us + latency_us),
        capture: count(t_us),
        now_us: t_us + latency_us,
        overcapture: false,
    }
}

proptest! {
    #[test]
    fn edges_are_exact_across_the_wrap(
        // The timer wraps somewhere within the first few seconds of edges.
        to_wrap_us in 0u32..3_000_000,
        boot_us in 1_000_000u64..10_000_000_000,
        latencies in prop::collection::vec(0u64..EDGE_INTERVAL_US, 1_000),
        jitter in prop::collection::vec(0u64..200, 1_000),
    ) {
        // Timer count = clock + offset; at `boot_us + to_wrap_us` it wraps.
        let offset = (u32::MAX - to_wrap_us).wrapping_sub(boot_us as u32).wrapping_add(1);
        let mut clock = EdgeClock::new();
        let mut t_us = boot_us;
        for (latency, j) in latencies.iter().zip(&jitter) {
            t_us += EDGE_INTERVAL_US - 100 + j;
            prop_assert_eq!(clock.edge_time_us(read_at(t_us, *latency, offset)), Ok(t_us));
        }
        prop_assert_eq!(clock.stats().refused, 0);
    }

    #[test]
    fn repeated_reads_never_add_edges(
        offset in any::<u32>(),
        repeats in prop::collection::vec(any::<bool>(), 500),
    ) {
        let mut clock = EdgeClock::new();
        let mut accepted = Vec::new();
        for (k, repeat) in repeats.iter().enumerate() {
            let t_us = 5_000_000 + k as u64 * EDGE_INTERVAL_US;
            let r = read_at(t_us, 30, offset);
            if let Ok(t) = clock.edge_time_us(r) {
                accepted.push(t);
            }
            if *repeat {
                // The same capture again, read a little later.
                let again = RawCapture { counter: r.counter + 7, now_us: r.now_us + 7, ..r };
                prop_assert_eq!(clock.edge_time_us(again), Err(Refused::Repeated));
            }
        }
        let truth: Vec<u64> = (0..repeats.len() as u64).map(|k| 5_000_000 + k * EDGE_INTERVAL_US).collect();
        prop_assert_eq!(accepted, truth);
    }

    #[test]
    fn stale_captures_are_refused(
        offset in any::<u32>(),
        age_us in 1_000_001u32..=u32::MAX,
        now_us in 5_000_000_000u64..10_000_000_000,
    ) {
        let mut clock = EdgeClock::new();
        let counter = (now_us as u32).wrapping_add(offset);
        let r = RawCapture { counter, capture: counter.wrapping_sub(age_us), now_us, overcapture: false };
        prop_assert_eq!(clock.edge_time_us(r), Err(Refused::Stale));
    }
}

/// A burst of captures drained in one frame, as the sampler does, feeds the
/// speed estimator the true speed: 240 edges/s on a 2.18 m wheel with 50
/// holes is 10.464 m/s, across a timer wrap.
#[test]
fn captures_through_the_estimator_give_the_true_speed() {
    let mut clock = EdgeClock::new();
    let mut wheel = WheelSpeed::try_new(WheelConfig::DEFAULT).expect("default config");
    let pitch_m = f64::from(WheelConfig::DEFAULT.circumference_m) / 50.0;
    let offset = u32::MAX - 1_500_000;
    let mut queue = Vec::new();
    let mut t_us = 1_000_000;
    for frame in 1..=300u64 {
        let frame_end_us = 1_000_000 + frame * 10_000;
        while t_us + EDGE_INTERVAL_US <= frame_end_us {
            t_us += EDGE_INTERVAL_US;
            queue.push(read_at(t_us, 25, offset));
        }
        for raw in queue.drain(..) {
            let t = clock.edge_time_us(raw).expect("fresh capture");
            wheel.on_edge(t);
        }
    }
    let truth_mps = pitch_m * 1e6 / EDGE_INTERVAL_US as f64;
    let speed = f64::from(wheel.speed_mps(t_us));
    assert!(
        (speed - truth_mps).abs() < 1e-3 * truth_mps,
        "{speed} vs {truth_mps}"
    );
    assert_eq!(clock.stats().refused, 0);
}
