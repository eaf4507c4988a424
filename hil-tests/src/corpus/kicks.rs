//! Kick tests below the wobble speed: rides on which a handlebar kick rings
//! the *stable* wobble mode down, generated at test time (nothing here is
//! committed), in both corpus families.
//!
//! - [`signal_rides`]: signal models. Each kick rings at the mode's frequency
//!   for the speed ([`super::signal::wobble_mode_hz`]) and decays at a growth
//!   rate drawn from -3 to -0.3 1/s, from 1.2-2.6 degrees, on weave, road
//!   texture (0.05-0.1 deg RMS), wheel ripple and sensor noise, at 1.5-6 m/s;
//!   every other kick starts with a visible push (a large, short steering
//!   transient before the ring). The truth is the recipe's own numbers.
//! - [`simulated_rides`]: the bicycle model (`super::simulated`), ridden at
//!   constant speeds between 0.6 and 0.85 of its wobble speed and knocked on
//!   the bar; the truth of each kick is the closed loop's wobble eigenvalue at
//!   that speed.
//!
//! What they are for: the on-board alert must never fire on a ring-down that
//! decays, and the on-board kick measurement is scored against their truth
//! (`hil-tests/tests/kick_rides.rs`).

use super::catalog::HARMONICS;
use super::rng::Rng;
use super::signal::{wobble_mode_hz, Ride};
use super::simulated::{catalog::TEST_BIKE, road::RoadClass, Recipe, KICK_S};
use super::Fixture;

/// Kicks per signal-model ride.
const KICKS_PER_RIDE: usize = 10;
/// Time between two kicks, s: a ring at -0.3 1/s from 2.6 degrees falls
/// below 0.25 degrees in 7.8 s.
const KICK_SPACING_S: f64 = 9.0;

/// The signal-model kick rides: `rides` rides of 10 kicks each, at speeds
/// spread over 1.5-6 m/s, from `seed`.
#[must_use]
pub fn signal_rides(seed: u64, rides: usize) -> Vec<Fixture> {
    let mut rng = Rng::new(seed ^ 0x6b69_636b_7321);
    (0..rides)
        .map(|k| {
            let lo = 1.5 + 4.5 * k as f64 / rides as f64;
            let speed = rng.range(lo, lo + 4.5 / rides as f64);
            let duration_s = KICK_SPACING_S * (KICKS_PER_RIDE + 1) as f64;
            let mut r = Ride::new(
                &format!("kicks_signal_{seed}_{k}"),
                "signal-model kick test below the wobble speed",
                seed.wrapping_mul(1000).wrapping_add(k as u64),
                duration_s,
                speed,
            );
            r.speed_profile(&[(0.0, speed), (duration_s, speed * rng.range(0.95, 1.05))]);
            r.weave(1.0);
            r.wheel_harmonics(HARMONICS);
            r.road_texture(rng.range(0.05, 0.1));
            for i in 0..KICKS_PER_RIDE {
                let t = KICK_SPACING_S * (i + 1) as f64 + rng.range(-1.0, 1.0);
                let v = r.speed_at(t);
                let ring = (
                    rng.range(1.2, 2.6) * rng.sign(),
                    wobble_mode_hz(v) + rng.range(-0.2, 0.2),
                    rng.range(0.3, 3.0),
                );
                if i % 2 == 0 {
                    r.kick(t, ring.0, ring.1, ring.2);
                } else {
                    let push = ring.0.signum() * rng.range(2.0, 5.0);
                    r.pushed_kick(t, push, rng.range(0.05, 0.12), ring);
                }
            }
            let (csv, truth) = r.finish(false);
            Fixture { csv, truth }
        })
        .collect()
}

/// The wobble speed of the test bicycle with its rider's balance loop, m/s
/// (`firmware/docs/detector.md`, the simulated family).
pub const TEST_BIKE_WOBBLE_MPS: f64 = 4.1;

/// Speeds of the bicycle-model kick rides, fractions of the wobble speed:
/// below about 0.55 (2.3 m/s) the simulated rider's balance loop no longer
/// holds the weave (the simulation diverges), so the family starts at 0.6.
pub const SIMULATED_SPEEDS: [f64; 6] = [0.6, 0.65, 0.7, 0.75, 0.8, 0.85];

/// A visible push: the torque held this long, over and back, s.
const PUSH_S: f64 = 0.12;
/// Wheel ripple on the steering of the bicycle-model rides, degrees per
/// harmonic (a clean-ish wheel).
const RIPPLE_DEG: f64 = 0.05;

/// Knock on the bar, N m for 30 ms: rings the mode at 1-2.5 degrees at
/// these speeds.
const KNOCK_NM: (f64, f64) = (8.0, 16.0);

/// The bicycle-model kick rides: one ride per speed of `speeds_rel` (fractions
/// of the wobble speed), each 8 kicks 8 s apart, from `seed`.
#[must_use]
pub fn simulated_recipes(seed: u64, speeds_rel: &[f64]) -> Vec<Recipe> {
    let mut rng = Rng::new(seed ^ 0x6b69_636b_6d31);
    speeds_rel
        .iter()
        .enumerate()
        .map(|(k, rel)| {
            let speed = rel * TEST_BIKE_WOBBLE_MPS;
            let kicks = (1..=8)
                .map(|i| {
                    let t = 8.0 * f64::from(i) + rng.range(-1.0, 1.0);
                    // A push holds its torque four times as long.
                    let scale = if k % 2 == 0 { 1.0 } else { 0.3 };
                    (t, scale * rng.range(KNOCK_NM.0, KNOCK_NM.1) * rng.sign())
                })
                .collect();
            Recipe {
                name: format!("kicks_sim_{seed}_{k}"),
                description: format!("knocks on the bar at {speed:.2} m/s"),
                bike: TEST_BIKE,
                changes: Vec::new(),
                seed: seed.wrapping_mul(1000).wrapping_add(500 + k as u64),
                duration_s: 75.0,
                road: if k % 2 == 0 {
                    RoadClass::A
                } else {
                    RoadClass::B
                },
                speed: vec![(0.0, speed)],
                grip_at_deg: None,
                rider_nm: (0.05, 0.1),
                kicks,
                // Every other ride pushes the bar over and back before it
                // rings (a visible push), the others knock it.
                kick_s: if k % 2 == 0 { KICK_S } else { PUSH_S },
                ripple_deg: RIPPLE_DEG,
                committed: false,
            }
        })
        .collect()
}

/// [`simulated_recipes`] simulated.
///
/// # Errors
/// A ride the model cannot simulate.
pub fn simulated_rides(seed: u64, speeds_rel: &[f64]) -> Result<Vec<Fixture>, String> {
    simulated_recipes(seed, speeds_rel)
        .iter()
        .map(|r| r.simulate().map(|s| s.fixture))
        .collect()
}
