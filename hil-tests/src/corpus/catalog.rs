//! The corpus: every fixture's recipe. Seeds are fixed, so the output is the
//! same on every run and every machine.

use super::rng::Rng;
use super::signal::{wobble_mode_hz, Ride, WobbleSpec};

/// Typical wheel-harmonic ripple: well under 0.5 degrees, the 3rd and 4th
/// (5.6 and 7.5 Hz at 4 m/s) as large as the 1st.
pub(crate) const HARMONICS: [f64; 6] = [0.10, 0.05, 0.10, 0.10, 0.04, 0.02];
/// A wheel out of true with a worn tyre: ripple twice as strong.
const STRONG_HARMONICS: [f64; 6] = [0.20, 0.10, 0.20, 0.20, 0.08, 0.04];

/// A ride at `speed` with the ordinary background: weave, light pedalling,
/// wheel ripple, road texture.
fn cruise(name: &str, description: &str, seed: u64, duration_s: f64, speed: f64) -> Ride {
    let mut r = Ride::new(name, description, seed, duration_s, speed);
    r.weave(1.0);
    r.pedalling(1.2, 0.4, &[(0.0, duration_s)]);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.03);
    r
}

/// One unstable wobble in a 30 s cruise, onset at 12 s.
pub fn episode(name: &str, speed: f64, freq_hz: f64, growth: f64, peak: f64, seed: u64) -> Ride {
    let description = format!(
        "unstable wobble at {freq_hz} Hz growing at {growth}/s to {peak} deg, {speed} m/s cruise"
    );
    let mut r = cruise(name, &description, seed, 30.0, speed);
    r.wobble(WobbleSpec::growing(12.0, freq_hz, growth, peak));
    r
}

/// The committed wobble episodes.
fn wobble_rides() -> Vec<Ride> {
    let mut v = Vec::new();

    // The seed paper's Figure 6: 4 m/s, a 6.4 Hz wobble on a 0.65 Hz weave,
    // from nothing to a dangerous amplitude in about 3 s, then the rider
    // intervenes. The rider is coasting (no pedalling) and weaving a little
    // more than usual.
    let mut r = Ride::new(
        "wobble_fig6",
        "seed paper Figure 6: 6.4 Hz wobble on a 0.65 Hz weave at 4 m/s, ~3 s to 4 deg",
        6,
        30.0,
        4.0,
    );
    r.weave(1.5);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.03);
    r.wobble(WobbleSpec::growing(12.0, 6.4, 1.75, 4.0));
    v.push(r);

    // Frequencies across the band, at the speeds the mode model gives them.
    for (i, &(speed, growth, peak)) in [
        (3.2, 1.5, 3.0),
        (4.8, 1.5, 3.0),
        (6.4, 2.0, 3.0),
        (7.8, 1.5, 2.5),
        (9.0, 2.5, 3.0),
    ]
    .iter()
    .enumerate()
    {
        let f = wobble_mode_hz(speed);
        v.push(episode(
            &format!("wobble_f{f:.1}"),
            speed,
            f,
            growth,
            peak,
            10 + i as u64,
        ));
    }

    // Growth rates from barely unstable to violent.
    for (i, &(speed, f, growth)) in [
        (4.2, 6.5, 0.6),
        (5.0, 6.9, 1.0),
        (4.0, 6.4, 3.0),
        (5.6, 7.2, 4.0),
    ]
    .iter()
    .enumerate()
    {
        v.push(episode(
            &format!("wobble_g{growth:.1}"),
            speed,
            f,
            growth,
            3.0,
            20 + i as u64,
        ));
    }

    // A limit cycle: grows to 0.9 deg and stays there for 6 s.
    let mut r = cruise(
        "wobble_limit_cycle",
        "wobble at 6.6 Hz growing at 1.2/s to a 0.9 deg limit cycle held for 6 s",
        30,
        30.0,
        4.4,
    );
    r.wobble(WobbleSpec {
        hold_s: 6.0,
        decay_per_s: 3.0,
        ..WobbleSpec::growing(8.0, 6.6, 1.2, 0.9)
    });
    v.push(r);

    // Sensor noise four times the usual, strong wheel ripple.
    let mut r = Ride::new(
        "wobble_noisy",
        "6.4 Hz wobble growing at 1.5/s, 0.12 deg sensor noise, strong wheel ripple",
        31,
        30.0,
        4.0,
    );
    r.weave(1.0);
    r.pedalling(1.3, 0.5, &[(0.0, 30.0)]);
    r.wheel_harmonics(STRONG_HARMONICS);
    r.road_texture(0.05);
    r.noise(0.12);
    r.wobble(WobbleSpec::growing(12.0, 6.4, 1.5, 3.0));
    v.push(r);

    // A wobble on top of a wheel harmonic: at 5.1 m/s the firmware's wheel
    // (2.18 m) turns at 2.34 Hz and its 3rd harmonic sits at 7.02 Hz.
    let mut r = cruise(
        "wobble_on_harmonic",
        "7.0 Hz wobble growing at 1.5/s at 5.1 m/s, on the wheel's 3rd harmonic (7.02 Hz)",
        32,
        30.0,
        5.1,
    );
    r.wobble(WobbleSpec::growing(12.0, 7.0, 1.5, 3.0));
    v.push(r);

    // Two episodes in a ride with corners and speed changes between them.
    let mut r = Ride::new(
        "ride_two_wobbles",
        "90 s ride: corners and speed changes, wobbles at 6.6 Hz (1.5/s) and 7.3 Hz (2.2/s)",
        33,
        90.0,
        4.4,
    );
    r.speed_profile(&[
        (0.0, 3.0),
        (20.0, 4.4),
        (45.0, 4.4),
        (55.0, 5.8),
        (90.0, 5.8),
    ]);
    r.weave(1.0);
    r.pedalling(1.2, 0.5, &[(0.0, 25.0), (40.0, 55.0), (75.0, 90.0)]);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.03);
    r.corner(6.0, 3.0, 12.0);
    r.corner(40.0, 4.0, -8.0);
    r.corner(80.0, 3.0, 6.0);
    r.wobble(WobbleSpec::growing(27.0, 6.6, 1.5, 3.0));
    r.wobble(WobbleSpec::growing(60.0, 7.3, 2.2, 3.5));
    v.push(r);
    v
}

/// Kicks at low speed: the stable wobble mode rings and decays.
pub fn kicks_ride(name: &str, seed: u64, duration_s: f64, committed_note: &str) -> Ride {
    let mut r = Ride::new(
        name,
        &format!(
            "low-speed ride (2.2-3.8 m/s) with lateral kicks on the handlebar{committed_note}"
        ),
        seed,
        duration_s,
        3.0,
    );
    let mut rng = Rng::new(seed ^ 0x6b69_636b);
    let knots: Vec<(f64, f64)> = (0..=(duration_s / 10.0) as usize)
        .map(|k| (k as f64 * 10.0, rng.range(2.2, 3.8)))
        .collect();
    r.speed_profile(&knots);
    r.weave(1.2);
    r.pedalling(1.1, 0.5, &[(0.0, duration_s)]);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.03);
    let mut t = 4.0;
    while t < duration_s - 4.0 {
        let v = r.speed_at(t);
        let f = wobble_mode_hz(v) + rng.range(-0.2, 0.4);
        r.kick(t, rng.range(0.8, 4.0) * rng.sign(), f, rng.range(2.5, 8.0));
        t += rng.range(5.0, 11.0);
    }
    r
}

/// Potholes and kerbs over a range of speeds.
pub fn road_ride(name: &str, seed: u64, duration_s: f64) -> Ride {
    let mut r = Ride::new(
        name,
        "3-7 m/s ride over potholes and kerbs (jolts that ring the steering mode)",
        seed,
        duration_s,
        4.0,
    );
    let mut rng = Rng::new(seed ^ 0x726f_6164);
    let knots: Vec<(f64, f64)> = (0..=(duration_s / 15.0) as usize)
        .map(|k| (k as f64 * 15.0, rng.range(3.0, 7.0)))
        .collect();
    r.speed_profile(&knots);
    r.weave(1.0);
    r.pedalling(1.3, 0.4, &[(0.0, duration_s)]);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.04);
    let mut t = 3.0;
    while t < duration_s - 3.0 {
        if rng.uniform() < 0.7 {
            r.pothole(t, rng.range(1.0, 4.0) * rng.sign(), rng.range(3.0, 8.0));
        } else {
            r.kerb(t, rng.range(1.0, 3.0) * rng.sign(), rng.range(3.0, 8.0));
        }
        t += rng.range(4.0, 9.0);
    }
    r
}

/// Cornering at low and moderate speed.
fn corner_ride(name: &str, seed: u64, duration_s: f64) -> Ride {
    let mut r = Ride::new(
        name,
        "2.5-6 m/s ride with corners of 5-25 deg steering, pedalling on and off",
        seed,
        duration_s,
        4.0,
    );
    let mut rng = Rng::new(seed ^ 0x636f_726e);
    let knots: Vec<(f64, f64)> = (0..=(duration_s / 12.0) as usize)
        .map(|k| (k as f64 * 12.0, rng.range(2.5, 6.0)))
        .collect();
    r.speed_profile(&knots);
    r.weave(1.2);
    let spans: Vec<(f64, f64)> = (0..(duration_s / 20.0) as usize)
        .map(|k| (k as f64 * 20.0, k as f64 * 20.0 + 12.0))
        .collect();
    r.pedalling(1.2, 0.6, &spans);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.03);
    let mut t = 2.0;
    while t < duration_s - 8.0 {
        let v = r.speed_at(t);
        let angle = rng.range(5.0, 25.0) * (3.0 / v).min(1.0) * rng.sign();
        let dur = rng.range(2.0, 6.0);
        r.corner(t, dur, angle);
        t += dur + rng.range(2.0, 6.0);
    }
    r
}

/// Speed sweeps so the wheel harmonics cross the whole band.
pub fn harmonics_ride(name: &str, seed: u64) -> Ride {
    let mut r = Ride::new(
        name,
        "speed sweeps 2-10 m/s and back with strong wheel ripple (0.2 deg at harmonics 1, 3, 4): \
         harmonics 2-5 cross 6-9 Hz",
        seed,
        180.0,
        2.0,
    );
    r.speed_profile(&[
        (0.0, 2.0),
        (60.0, 10.0),
        (90.0, 10.0),
        (150.0, 2.0),
        (180.0, 2.0),
    ]);
    r.weave(0.8);
    r.pedalling(1.2, 0.3, &[(0.0, 180.0)]);
    r.wheel_harmonics(STRONG_HARMONICS);
    r.road_texture(0.03);
    r
}

/// A long cruise with four times the usual sensor noise.
fn noisy_ride(name: &str, seed: u64) -> Ride {
    let mut r = Ride::new(
        name,
        "4-6 m/s cruise with 0.12 deg sensor noise",
        seed,
        120.0,
        4.0,
    );
    r.speed_profile(&[(0.0, 4.0), (40.0, 6.0), (80.0, 5.0), (120.0, 4.0)]);
    r.noise(0.12);
    r.weave(1.0);
    r.pedalling(1.4, 0.6, &[(0.0, 120.0)]);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.05);
    r
}

/// A long mixed ride: stops, speed changes, corners, kicks, potholes, kerbs.
pub fn commute(name: &str, seed: u64, duration_s: f64) -> Ride {
    let mut r = Ride::new(
        name,
        "long mixed ride (generated at test time): stops, 2-9 m/s, corners, kicks at low \
         speed, potholes, kerbs, pedalling on and off",
        seed,
        duration_s,
        4.0,
    );
    let mut rng = Rng::new(seed ^ 0x636f_6d6d);
    let mut knots = vec![(0.0, 0.0)];
    let mut t = 5.0;
    while t < duration_s {
        let v = if rng.uniform() < 0.08 {
            0.0
        } else {
            rng.range(2.0, 9.0)
        };
        knots.push((t, v));
        let hold = rng.range(8.0, 30.0);
        knots.push((t + hold, v));
        t += hold + rng.range(3.0, 8.0);
    }
    r.speed_profile(&knots);
    r.weave(rng.range(0.8, 1.3));
    let mut spans = Vec::new();
    let mut t = 0.0;
    while t < duration_s {
        let on = rng.range(10.0, 60.0);
        spans.push((t, t + on));
        t += on + rng.range(5.0, 20.0);
    }
    r.pedalling(rng.range(1.0, 1.5), rng.range(0.3, 0.8), &spans);
    r.wheel_harmonics(HARMONICS);
    r.road_texture(0.03);
    let mut t = 3.0;
    while t < duration_s - 10.0 {
        let v = r.speed_at(t);
        let u = rng.uniform();
        if v < 1.0 {
            t += 5.0;
            continue;
        }
        if u < 0.35 {
            let dur = rng.range(2.0, 6.0);
            r.corner(
                t,
                dur,
                rng.range(5.0, 25.0) * (3.0 / v).min(1.0) * rng.sign(),
            );
        } else if u < 0.6 && v < 4.0 {
            let f = wobble_mode_hz(v) + rng.range(-0.2, 0.4);
            r.kick(t, rng.range(0.8, 4.0) * rng.sign(), f, rng.range(2.5, 8.0));
        } else if u < 0.85 {
            r.pothole(t, rng.range(1.0, 4.0) * rng.sign(), rng.range(3.0, 8.0));
        } else {
            r.kerb(t, rng.range(1.0, 3.0) * rng.sign(), rng.range(3.0, 8.0));
        }
        t += rng.range(6.0, 20.0);
    }
    r
}

/// Every fixture's ride, and whether its CSV is committed.
#[must_use]
pub fn rides() -> Vec<(Ride, bool)> {
    let mut v: Vec<(Ride, bool)> = wobble_rides().into_iter().map(|r| (r, true)).collect();
    v.push((kicks_ride("ride_kicks", 40, 120.0, ""), true));
    v.push((road_ride("ride_potholes_kerbs", 41, 120.0), true));
    v.push((corner_ride("ride_cornering", 42, 120.0), true));
    v.push((harmonics_ride("ride_wheel_harmonics", 43), true));
    v.push((noisy_ride("ride_noisy", 44), true));
    for (i, seed) in [50, 51, 52].into_iter().enumerate() {
        v.push((
            commute(&format!("long_commute_{}", i + 1), seed, 600.0),
            false,
        ));
    }
    v.push((
        kicks_ride("long_kicks", 53, 300.0, " (generated at test time)"),
        false,
    ));
    v
}
