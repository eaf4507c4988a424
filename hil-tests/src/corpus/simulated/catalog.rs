//! The simulated rides. Seeds are fixed, so every run gives the same rides.

use super::road::RoadClass;
use super::Recipe;

/// The seed paper's test bicycle with its 83 kg rider (wobble speed 3.8 m/s).
const TEST_BIKE: &str = "test-bicycle.toml";
/// A knock on the handlebar, N m for 30 ms. Near the wobble speed the
/// wobble mode is barely damped, and a harder knock rings it like a wobble:
/// with 3 N m at 3.4-3.6 m/s on a class B road the ring reaches 0.6-0.7
/// degrees, decays at only 0.1-0.2/s, and the default detector alerts on
/// it (once in 11 minutes; see `firmware/docs/detector.md`).
const KICK_NM: f64 = 2.0;
/// Rider's steering wander and hip torque, N m RMS.
const RIDER_NM: (f64, f64) = (0.05, 0.1);

/// A ride that speeds up from `from` to `to` m/s between 5 and 7 s, holds
/// it until the wobble frightens the rider at `grip_deg`, who then grips and
/// brakes back to `from`.
fn through(
    name: &str,
    road: RoadClass,
    from: f64,
    to: f64,
    grip_deg: f64,
    seed: u64,
    committed: bool,
) -> Recipe {
    Recipe {
        name: name.into(),
        description: format!(
            "speeds up from {from} to {to} m/s through the wobble speed; grips the bar at {grip_deg} deg and brakes"
        ),
        bike: TEST_BIKE,
        changes: Vec::new(),
        seed,
        duration_s: 45.0,
        road,
        speed: vec![(5.0, from), (7.0, to)],
        grip_at_deg: Some((grip_deg, from)),
        rider_nm: RIDER_NM,
        kicks: Vec::new(),
        kick_s: super::KICK_S,
        ripple_deg: 0.0,
        committed,
    }
}

/// A ride below the wobble speed: `knots` of speed, kicks every
/// `kick_every_s`, kept at or below 3.4 m/s.
fn below(
    name: &str,
    road: RoadClass,
    knots: Vec<(f64, f64)>,
    duration_s: f64,
    kick_every_s: f64,
    seed: u64,
    committed: bool,
) -> Recipe {
    let kicks = (1..)
        .map(|k| f64::from(k) * kick_every_s)
        .take_while(|&t| t < duration_s - 3.0)
        .enumerate()
        .map(|(i, t)| (t, if i % 2 == 0 { KICK_NM } else { -KICK_NM }))
        .collect();
    Recipe {
        name: name.into(),
        description: format!("below the wobble speed, a handlebar kick every {kick_every_s} s"),
        bike: TEST_BIKE,
        changes: Vec::new(),
        seed,
        duration_s,
        road,
        speed: knots,
        grip_at_deg: None,
        rider_nm: RIDER_NM,
        kicks,
        kick_s: super::KICK_S,
        ripple_deg: 0.0,
        committed,
    }
}

/// Every ride of the family.
#[must_use]
pub fn recipes() -> Vec<Recipe> {
    use RoadClass::{A, B};
    vec![
        through("sim_wobble_5.5", A, 3.0, 5.5, 3.0, 101, true),
        through("sim_wobble_6.5", B, 3.0, 6.5, 3.0, 102, false),
        through("sim_wobble_7.0", A, 3.5, 7.0, 2.5, 103, false),
        through("sim_wobble_8.0", B, 3.5, 8.0, 4.0, 104, false),
        below(
            "sim_ride_below",
            B,
            vec![(0.0, 2.5), (30.0, 3.4), (60.0, 3.0)],
            60.0,
            6.0,
            201,
            true,
        ),
        below(
            "sim_commute_below",
            B,
            vec![
                (0.0, 2.8),
                (120.0, 3.4),
                (240.0, 3.0),
                (360.0, 3.4),
                (480.0, 2.6),
                (600.0, 3.2),
            ],
            600.0,
            15.0,
            202,
            false,
        ),
    ]
}
