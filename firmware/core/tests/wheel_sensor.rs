//! Wheel speed from simulated hall edges: constant speed, acceleration, stop,
//! bounce and glitches, and the accuracy report quoted in
//! firmware/docs/sensors.md:
//!
//! ```text
//! cargo test -p wobble-core --test wheel_sensor -- --nocapture accuracy_report
//! ```

use wobble_core::wheel::{Edge, WheelConfig, WheelSpeed};

const CIRCUMFERENCE_M: f64 = 2.180;
const HOLES: usize = 50;
const PITCH_M: f64 = CIRCUMFERENCE_M / HOLES as f64;

/// Imperfections of a real disc and timer, all zero for the exact tests.
#[derive(Clone, Copy, Default)]
struct Errors {
    /// Each hole's position error is uniform in ±this, metres of arc.
    hole_m: f64,
    /// Disc eccentricity: once-per-revolution position error amplitude, m.
    eccentricity_m: f64,
    /// Capture jitter, uniform in ±this, µs (sensor rise time, thresholds).
    jitter_us: f64,
}

/// A deterministic generator (xorshift64*), so the report is reproducible.
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
    /// Uniform in ±1.
    fn sym(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }
}

/// Motion from t = 0: speed `v0` m/s until `t_change`, then constant
/// acceleration `a` m/s² until the wheel stops (if it does), for `duration_s`.
#[derive(Clone, Copy)]
struct Motion {
    v0: f64,
    a: f64,
    t_change: f64,
    duration_s: f64,
}

impl Motion {
    fn steady(v: f64, duration_s: f64) -> Self {
        Self::accelerating(v, 0.0, duration_s)
    }
    fn accelerating(v0: f64, a: f64, duration_s: f64) -> Self {
        Self {
            v0,
            a,
            t_change: 0.0,
            duration_s,
        }
    }
    fn speed(&self, t: f64) -> f64 {
        (self.v0 + self.a * (t - self.t_change).max(0.0)).max(0.0)
    }
    /// Time at which the wheel has rolled `x` metres, if it does.
    fn time_at(&self, x: f64) -> Option<f64> {
        let x_change = self.v0 * self.t_change;
        let t = if x <= x_change || self.a == 0.0 {
            x / self.v0
        } else {
            let x = x - x_change;
            let disc = self.v0 * self.v0 + 2.0 * self.a * x;
            if disc < 0.0 {
                return None;
            }
            self.t_change + (disc.sqrt() - self.v0) / self.a
        };
        (t.is_finite() && t >= 0.0 && t <= self.duration_s).then_some(t)
    }

    /// Edge times in whole µs (a 1 MHz capture timer), the first hole
    /// `offset_m` ahead of the sensor.
    fn edges(&self, offset_m: f64, errors: Errors, rng: &mut Rng) -> Vec<u64> {
        let hole_err: Vec<f64> = (0..HOLES).map(|_| errors.hole_m * rng.sym()).collect();
        let mut out = Vec::new();
        for k in 0.. {
            let nominal = offset_m + k as f64 * PITCH_M;
            let angle = nominal / CIRCUMFERENCE_M * std::f64::consts::TAU;
            let x = nominal + hole_err[k % HOLES] + errors.eccentricity_m * angle.sin();
            if x < 0.0 {
                continue; // that hole passed the sensor before t = 0
            }
            let Some(t) = self.time_at(x) else { break };
            let t_us = (t * 1e6 + errors.jitter_us * rng.sym()).max(0.0);
            out.push(t_us.round() as u64);
        }
        out.sort_unstable();
        out.dedup();
        out
    }
}

fn wheel() -> WheelSpeed {
    WheelSpeed::try_new(WheelConfig::default()).unwrap()
}

/// Feeds `edges` and samples the speed every 10 ms (the frame rate),
/// returning (t_s, estimate_mps).
fn run(w: &mut WheelSpeed, edges: &[u64], until_us: u64) -> Vec<(f64, f32)> {
    let mut out = Vec::new();
    let mut next = edges.iter().peekable();
    for tick in (10_000..=until_us).step_by(10_000) {
        while let Some(&&e) = next.peek() {
            if e > tick {
                break;
            }
            w.on_edge(e);
            next.next();
        }
        out.push((tick as f64 / 1e6, w.speed_mps(tick)));
    }
    out
}

#[test]
fn constant_speed_is_exact() {
    // Speeds whose edge period is a whole number of µs (43.6 mm pitch).
    for v in [2.0, 4.0, 5.0, 8.0, 10.0, 16.0] {
        let m = Motion::steady(v, 3.0);
        let edges = m.edges(0.0, Errors::default(), &mut Rng(1));
        let mut w = wheel();
        let samples = run(&mut w, &edges, 3_000_000);
        // From the second edge on, every estimate is the true speed: the
        // period of exactly-timed edges (integer µs at these speeds).
        for &(t, est) in samples.iter().filter(|(t, _)| *t > 2.0 * PITCH_M / v) {
            assert!(
                (f64::from(est) - v).abs() < 1e-5 * v,
                "{v} m/s at {t} s: {est}"
            );
        }
        assert_eq!(w.pulses() as usize, edges.len());
        let distance = edges.len() as f64 * PITCH_M;
        assert!((w.distance_m() - distance).abs() < 1e-6 * distance);
    }
}

#[test]
fn constant_acceleration_is_tracked_without_lag() {
    for a in [1.0, -1.5] {
        let m = Motion::accelerating(5.0, a, 2.0);
        let edges = m.edges(0.0, Errors::default(), &mut Rng(1));
        let mut w = wheel();
        for (i, &e) in edges.iter().enumerate() {
            assert_eq!(w.on_edge(e), Edge::Accepted);
            let est = f64::from(w.speed_mps(e));
            let truth = m.speed(e as f64 / 1e6);
            if i >= 2 * HOLES {
                // Two revolutions known: the speed at the newest edge.
                assert!(
                    (est - truth).abs() < 2e-3,
                    "a = {a}, edge {i}: {est} vs {truth}"
                );
            } else if i >= HOLES {
                // One revolution: its mean, the speed at its middle.
                let mid = (edges[i - HOLES] + e) as f64 / 2e6;
                assert!(
                    (est - m.speed(mid)).abs() < 2e-3,
                    "a = {a}, edge {i}: {est}"
                );
            }
        }
    }
}

#[test]
fn stop_decays_to_zero_and_counts_every_hole() {
    // 4 m/s for 2 s, then braking at 2 m/s²: stops 2 s and 4 m later.
    let m = Motion {
        v0: 4.0,
        a: -2.0,
        t_change: 2.0,
        duration_s: 6.0,
    };
    let edges = m.edges(0.01, Errors::default(), &mut Rng(1));
    let mut w = wheel();
    let samples = run(&mut w, &edges, 6_000_000);
    assert_eq!(edges.len(), ((12.0 - 0.01) / PITCH_M) as usize + 1);
    assert_eq!(w.pulses() as usize, edges.len());
    // While braking: monotone non-increasing...
    let start = samples.iter().position(|(t, _)| *t >= 2.0).unwrap();
    for pair in samples[start..].windows(2) {
        assert!(pair[1].1 <= pair[0].1 + 1e-6, "{pair:?}");
    }
    // ... and close to the truth: the step into braking takes about 1.5
    // revolutions to show in the acceleration estimate (peak error 0.4 m/s
    // at 2 m/s²), after which the estimate converges.
    for &(t, est) in samples[start..].iter().filter(|(t, _)| *t < 3.5) {
        let err = (f64::from(est) - m.speed(t)).abs();
        assert!(err < 0.45, "{t}: {est}");
        if t > 3.2 {
            assert!(err < 0.15, "{t}: {est}");
        }
    }
    // ... and zero, flagged, once no edge came for the timeout.
    let last_edge = *edges.last().unwrap();
    let after = last_edge + u64::from(WheelConfig::DEFAULT.timeout_us) + 1;
    let s = w.sample(after);
    assert!(s.stopped);
    assert_eq!(s.speed_mps, 0.0);
    assert!(!w.sample(last_edge + 1000).stopped);
}

#[test]
fn restart_after_a_stop_does_not_average_across_it() {
    let mut w = wheel();
    let period = 10_900; // 4 m/s
    for i in 0..60 {
        w.on_edge(i * period);
    }
    let resume = 59 * period + 5_000_000;
    for i in 0..3 {
        w.on_edge(resume + i * 2 * period); // 2 m/s
    }
    let v = w.speed_mps(resume + 2 * 2 * period);
    assert!((v - 2.0).abs() < 1e-4, "{v}");
}

#[test]
fn contact_bounce_is_rejected() {
    let m = Motion::steady(6.0, 2.0);
    let edges = m.edges(0.0, Errors::default(), &mut Rng(1));
    let mut w = wheel();
    for &e in &edges {
        assert_eq!(w.on_edge(e), Edge::Accepted);
        assert_eq!(w.on_edge(e + 15), Edge::Bounce);
        assert_eq!(w.on_edge(e + 140), Edge::Bounce);
    }
    assert_eq!(w.pulses() as usize, edges.len());
    assert_eq!(w.rejected() as usize, 2 * edges.len());
    let last = *edges.last().unwrap();
    assert!((w.speed_mps(last) - 6.0).abs() < 1e-4);
}

#[test]
fn a_single_glitch_never_changes_the_count() {
    // 5 m/s: period 8720 µs. A spurious edge at every fraction of a period.
    let period = 8_720u64;
    for frac in [0.05, 0.2, 0.45, 0.55, 0.8, 0.95] {
        let mut w = wheel();
        let glitch_after = 20;
        for i in 0..40u64 {
            w.on_edge(i * period);
            if i == glitch_after {
                w.on_edge(i * period + (frac * period as f64) as u64);
            }
        }
        assert_eq!(w.pulses(), 40, "glitch at {frac} of a period");
        assert_eq!(w.rejected(), 1);
        // And the speed has recovered exactly once the window is past it.
        for i in 40..100u64 {
            w.on_edge(i * period);
        }
        assert!((w.speed_mps(99 * period) - 5.0).abs() < 1e-4);
    }
}

#[test]
fn acceleration_from_rest_is_not_mistaken_for_glitches() {
    // The first intervals from rest shrink fastest when a hole is right at
    // the sensor: 1, 0.41, 0.32, 0.27... of the first.
    for a in [0.5, 2.0, 5.0] {
        for offset in [0.0, 0.001, 0.02] {
            let m = Motion::accelerating(0.0, a, 3.0);
            let edges = m.edges(offset, Errors::default(), &mut Rng(1));
            let mut w = wheel();
            for &e in &edges {
                assert_eq!(w.on_edge(e), Edge::Accepted, "a = {a}, at {e}");
            }
        }
    }
}

/// Error statistics of estimates against the true speed.
fn stats(samples: &[(f64, f64)], truth: impl Fn(f64) -> f64) -> (f64, f64) {
    let errs: Vec<f64> = samples.iter().map(|&(t, v)| v - truth(t)).collect();
    let max = errs.iter().fold(0.0f64, |m, e| m.max(e.abs()));
    let rms = (errs.iter().map(|e| e * e).sum::<f64>() / errs.len() as f64).sqrt();
    (max, rms)
}

/// The naive alternative: edges counted per 10 ms frame.
fn counts_per_frame(edges: &[u64], from_us: u64, until_us: u64) -> Vec<(f64, f64)> {
    (from_us..=until_us)
        .step_by(10_000)
        .map(|tick| {
            let n = edges
                .iter()
                .filter(|&&e| e > tick - 10_000 && e <= tick)
                .count();
            (tick as f64 / 1e6, n as f64 * PITCH_M / 0.01)
        })
        .collect()
}

#[test]
fn accuracy_report() {
    // Disc laser-cut to ±0.1 mm, mounted 0.3 mm off-centre (0.5 % at a
    // 60 mm radius), sensor/threshold jitter ±2 µs, 1 µs capture timer.
    let errors = Errors {
        hole_m: 0.1e-3,
        eccentricity_m: 0.3e-3 * CIRCUMFERENCE_M / (std::f64::consts::TAU * 0.06),
        jitter_us: 2.0,
    };
    println!(
        "wheel speed accuracy at 100 Hz samples: steady cases over 10 s after the first second"
    );
    println!("(disc ±0.1 mm, 0.3 mm eccentric, ±2 µs jitter, 1 µs timer)");
    println!("{:<34} {:>14} {:>14}", "case", "max |err|", "rms err");
    let mut rng = Rng(0x5eed);
    for v in [4.0, 10.0] {
        let m = Motion::steady(v, 11.0);
        let edges = m.edges(0.0, errors, &mut rng);
        let from = 1_000_000;
        let mut w = wheel();
        let ours: Vec<(f64, f64)> = run(&mut w, &edges, 11_000_000)
            .into_iter()
            .filter(|(t, _)| *t >= from as f64 / 1e6)
            .map(|(t, s)| (t, f64::from(s)))
            .collect();
        let (max, rms) = stats(&ours, |t| m.speed(t));
        println!(
            "{:<34} {:>9.2} mm/s {:>9.2} mm/s   ({:.4} % max)",
            format!("{v} m/s, period over 1 revolution"),
            1e3 * max,
            1e3 * rms,
            100.0 * max / v
        );
        assert!(max / v < 0.001, "{v} m/s: {max}");
        // A window of 5 intervals, to show what the revolution buys.
        let mut short = WheelSpeed::try_new(WheelConfig {
            window_edges: 5,
            ..WheelConfig::DEFAULT
        })
        .unwrap();
        let short: Vec<(f64, f64)> = run(&mut short, &edges, 11_000_000)
            .into_iter()
            .filter(|(t, _)| *t >= from as f64 / 1e6)
            .map(|(t, s)| (t, f64::from(s)))
            .collect();
        let (max, rms) = stats(&short, |t| m.speed(t));
        println!(
            "{:<34} {:>9.2} mm/s {:>9.2} mm/s",
            format!("{v} m/s, period over 5 intervals"),
            1e3 * max,
            1e3 * rms
        );
        let naive = counts_per_frame(&edges, from, 11_000_000);
        let (max, rms) = stats(&naive, |t| m.speed(t));
        println!(
            "{:<34} {:>9.0} mm/s {:>9.0} mm/s",
            format!("{v} m/s, edges counted per 10 ms"),
            1e3 * max,
            1e3 * rms
        );
    }
    // Steady 7 m/s for 1 s, then 1 s of acceleration or braking.
    for a in [0.5, -2.0] {
        let m = Motion {
            v0: 7.0,
            a,
            t_change: 1.0,
            duration_s: 2.0,
        };
        let edges = m.edges(0.0, errors, &mut rng);
        let mut w = wheel();
        let ours: Vec<(f64, f64)> = run(&mut w, &edges, 2_000_000)
            .into_iter()
            .filter(|(t, _)| *t >= 1.0)
            .map(|(t, s)| (t, f64::from(s)))
            .collect();
        let (max, rms) = stats(&ours, |t| m.speed(t));
        println!(
            "{:<34} {:>9.1} mm/s {:>9.1} mm/s",
            format!("7 m/s, then {a:+} m/s² for 1 s"),
            1e3 * max,
            1e3 * rms
        );
    }
}
