//! Signal models of the steering angle and wheel speed, and the [`Ride`]
//! builder that sums them into one fixture.
//!
//! Every component is a closed-form function of time (or, for the random
//! ones, of a seeded [`Rng`]), computed in `f64`; only the finished signal is
//! noised, quantised to the steering ADC's resolution and rounded to the
//! card's hundredths of a degree.

use super::rng::Rng;
use super::truth::{Episode, Event, FixtureTruth};
use libm::{cos, exp, log, sin};
use wobble_core::wheel::WheelConfig;

use core::f64::consts::{PI, TAU};

/// Sample rate of every fixture.
pub const FS_HZ: f64 = 100.0;
/// Wheel rolling circumference: the firmware's default wheel (28", 2.18 m),
/// the one its wheel-speed estimator and detector use. 4 m/s turns it at
/// 1.83 Hz, putting the 3rd and 4th harmonics at 5.5 and 7.3 Hz, inside the
/// wobble band.
pub const WHEEL_CIRCUMFERENCE_M: f64 = WheelConfig::DEFAULT.circumference_m as f64;
/// Steering ADC resolution.
pub const ADC_BITS: u32 = 12;
/// Steering angle span of the ADC's full scale (+-60 degrees): 0.029 deg/LSB.
pub const ADC_SPAN_DEG: f64 = 120.0;
/// Envelope amplitude from which alert latency is measured.
pub const LATENCY_REFERENCE_DEG: f64 = 0.5;
/// Envelope amplitude below which an episode has ended.
pub const EPISODE_END_DEG: f64 = 0.25;

/// Frequency of the (stable or unstable) wobble mode at speed `v`: 6.4 Hz at
/// 4 m/s as in the seed paper's Figure 6, rising 0.5 Hz per m/s.
#[must_use]
pub fn wobble_mode_hz(v_mps: f64) -> f64 {
    (6.4 + 0.5 * (v_mps - 4.0)).clamp(5.8, 9.2)
}

/// Weave frequency at speed `v` (0.65 Hz at 4 m/s, within 0.5-1.7 Hz).
#[must_use]
pub fn weave_hz(v_mps: f64) -> f64 {
    (0.29 + 0.09 * v_mps).clamp(0.5, 1.7)
}

/// 0 below `lo`, 1 above `hi`, smooth in between.
fn smoothstep(x: f64, lo: f64, hi: f64) -> f64 {
    let u = ((x - lo) / (hi - lo)).clamp(0.0, 1.0);
    u * u * (3.0 - 2.0 * u)
}

/// Rounds for the manifest (4 decimals).
pub(crate) fn r4(x: f64) -> f64 {
    libm::round(x * 1e4) / 1e4
}

/// Parameters of one unstable-wobble episode.
#[derive(Clone, Copy, Debug)]
pub struct WobbleSpec {
    /// Time the envelope is `onset_amp_deg`.
    pub onset_s: f64,
    /// Wobble frequency.
    pub freq_hz: f64,
    /// Envelope growth rate, 1/s.
    pub growth_per_s: f64,
    /// Largest envelope.
    pub peak_amp_deg: f64,
    /// How long the envelope stays at its peak (limit cycle) before the rider
    /// intervenes.
    pub hold_s: f64,
    /// Envelope decay after the intervention, 1/s.
    pub decay_per_s: f64,
}

impl WobbleSpec {
    /// Envelope at onset: "nothing", below the sensor noise.
    pub const ONSET_AMP_DEG: f64 = 0.02;

    /// A growing wobble the rider stops as soon as it peaks.
    #[must_use]
    pub fn growing(onset_s: f64, freq_hz: f64, growth_per_s: f64, peak_amp_deg: f64) -> Self {
        Self {
            onset_s,
            freq_hz,
            growth_per_s,
            peak_amp_deg,
            hold_s: 0.0,
            decay_per_s: 4.0,
        }
    }

    fn peak_s(&self) -> f64 {
        self.onset_s + log(self.peak_amp_deg / Self::ONSET_AMP_DEG) / self.growth_per_s
    }

    /// Envelope at `t`.
    #[must_use]
    pub fn envelope(&self, t: f64) -> f64 {
        let peak_s = self.peak_s();
        let release_s = peak_s + self.hold_s;
        if t <= peak_s {
            Self::ONSET_AMP_DEG * exp(self.growth_per_s * (t - self.onset_s))
        } else if t <= release_s {
            self.peak_amp_deg
        } else {
            self.peak_amp_deg * exp(-self.decay_per_s * (t - release_s))
        }
    }
}

/// A ride under construction: speed and clean steering angle per sample, and
/// the ground truth of what was added.
#[derive(Clone, Debug)]
pub struct Ride {
    name: String,
    description: String,
    seed: u64,
    rng: Rng,
    /// Wheel speed per sample, m/s.
    speed: Vec<f64>,
    /// Clean steering angle per sample, degrees.
    steer: Vec<f64>,
    noise_deg: f64,
    episodes: Vec<Episode>,
    events: Vec<Event>,
}

impl Ride {
    /// An empty ride of `duration_s` at a constant `speed_mps`.
    #[must_use]
    pub fn new(name: &str, description: &str, seed: u64, duration_s: f64, speed_mps: f64) -> Self {
        let n = libm::round(duration_s * FS_HZ) as usize;
        Self {
            name: name.to_owned(),
            description: description.to_owned(),
            seed,
            rng: Rng::new(seed),
            speed: vec![speed_mps; n],
            steer: vec![0.0; n],
            noise_deg: 0.03,
            episodes: Vec::new(),
            events: Vec::new(),
        }
    }

    /// Number of samples.
    #[must_use]
    pub fn len(&self) -> usize {
        self.steer.len()
    }

    /// Whether the ride has no samples.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.steer.is_empty()
    }

    /// Duration, seconds.
    #[must_use]
    pub fn duration_s(&self) -> f64 {
        self.len() as f64 / FS_HZ
    }

    /// The fixture's random stream for component `stream`.
    pub fn rng(&mut self, stream: u64) -> Rng {
        self.rng.fork(stream)
    }

    /// Speed at time `t`.
    #[must_use]
    pub fn speed_at(&self, t: f64) -> f64 {
        let i = (libm::round(t * FS_HZ) as usize).min(self.len().saturating_sub(1));
        self.speed.get(i).copied().unwrap_or(0.0)
    }

    /// Sets the speed profile: linear between `(t_s, v_mps)` knots, constant
    /// before the first and after the last.
    pub fn speed_profile(&mut self, knots: &[(f64, f64)]) {
        for (i, v) in self.speed.iter_mut().enumerate() {
            let t = i as f64 / FS_HZ;
            *v = match knots.iter().position(|&(tk, _)| tk > t) {
                None => knots.last().map_or(*v, |k| k.1),
                Some(0) => knots[0].1,
                Some(j) => {
                    let (t0, v0) = knots[j - 1];
                    let (t1, v1) = knots[j];
                    v0 + (v1 - v0) * (t - t0) / (t1 - t0)
                }
            };
        }
    }

    /// Sets the white sensor noise, degrees RMS.
    pub fn noise(&mut self, noise_deg: f64) {
        self.noise_deg = noise_deg;
    }

    /// Weave: a narrow-band oscillation at [`weave_hz`] of the current speed,
    /// larger at low speed, scaled by `scale` (1 is a relaxed rider).
    pub fn weave(&mut self, scale: f64) {
        let mut rng = self.rng(1);
        let parts: Vec<(f64, f64, f64)> = [(1.0, 0.6), (1.07, 0.3), (0.93, 0.25)]
            .iter()
            .map(|&(rel, a)| (rel * rng.range(0.97, 1.03), a, rng.range(0.0, TAU)))
            .collect();
        let mut phase = vec![0.0; parts.len()];
        for i in 0..self.len() {
            let v = self.speed[i];
            let amp = scale * (3.2 / v.max(0.5)).clamp(0.3, 2.0) * smoothstep(v, 0.5, 1.5);
            for (p, &(rel, a, ph0)) in phase.iter_mut().zip(&parts) {
                *p += TAU * rel * weave_hz(v) / FS_HZ;
                self.steer[i] += amp * a * sin(*p + ph0);
            }
        }
    }

    /// Pedalling at `cadence_hz` with steering amplitude `amp_deg` at the
    /// cadence (and harmonics 2-4 smaller), during the `(start, end)` spans.
    pub fn pedalling(&mut self, cadence_hz: f64, amp_deg: f64, spans: &[(f64, f64)]) {
        let mut rng = self.rng(2);
        let phases: [f64; 4] = core::array::from_fn(|_| rng.range(0.0, TAU));
        const HARMONICS: [f64; 4] = [1.0, 0.3, 0.1, 0.03];
        let mut phase = 0.0;
        for i in 0..self.len() {
            let t = i as f64 / FS_HZ;
            let gate: f64 = spans
                .iter()
                .map(|&(a, b)| smoothstep(t, a, a + 0.5) * (1.0 - smoothstep(t, b - 0.5, b)))
                .fold(0.0, f64::max);
            // Cadence wanders by a few percent over tens of seconds.
            phase += TAU * cadence_hz * (1.0 + 0.04 * sin(TAU * t / 23.0)) / FS_HZ;
            for (k, (&h, &ph)) in HARMONICS.iter().zip(&phases).enumerate() {
                self.steer[i] += gate * amp_deg * h * sin((k + 1) as f64 * phase + ph);
            }
        }
    }

    /// Ripple at the wheel-rotation harmonics 1..=6 with amplitudes
    /// `amps_deg`, phase-locked to the wheel (speed / circumference).
    pub fn wheel_harmonics(&mut self, amps_deg: [f64; 6]) {
        let mut rng = self.rng(3);
        let phases: [f64; 6] = core::array::from_fn(|_| rng.range(0.0, TAU));
        let mut theta = 0.0;
        for i in 0..self.len() {
            theta += TAU * self.speed[i] / WHEEL_CIRCUMFERENCE_M / FS_HZ;
            for (k, (&a, &ph)) in amps_deg.iter().zip(&phases).enumerate() {
                self.steer[i] += a * sin((k + 1) as f64 * theta + ph);
            }
        }
    }

    /// Road texture: white noise through a first-order 8 Hz low-pass,
    /// `rms_deg` RMS.
    pub fn road_texture(&mut self, rms_deg: f64) {
        let mut rng = self.rng(4);
        let alpha = 1.0 - exp(-TAU * 8.0 / FS_HZ);
        let drive = rms_deg * libm::sqrt((2.0 - alpha) / alpha);
        let mut y = 0.0;
        for s in &mut self.steer {
            y += alpha * (drive * rng.normal() - y);
            *s += y;
        }
    }

    fn add_ring(&mut self, t0: f64, amp: f64, freq_hz: f64, decay_per_s: f64) {
        let start = libm::ceil(t0 * FS_HZ) as usize;
        let len = libm::ceil(10.0 / decay_per_s * FS_HZ) as usize;
        for i in start..(start + len).min(self.len()) {
            let tau = i as f64 / FS_HZ - t0;
            self.steer[i] += amp * exp(-decay_per_s * tau) * sin(TAU * freq_hz * tau);
        }
    }

    fn event(&mut self, kind: &str, t_s: f64, amp_deg: f64, freq_hz: f64, decay_per_s: f64) {
        let speed_mps = r4(self.speed_at(t_s));
        self.events.push(Event {
            kind: kind.to_owned(),
            t_s: r4(t_s),
            amp_deg: r4(amp_deg),
            freq_hz: r4(freq_hz),
            decay_per_s: r4(decay_per_s),
            speed_mps,
        });
    }

    /// A lateral kick on the handlebar: it excites the (stable) wobble mode,
    /// which rings at `freq_hz` from `amp_deg` and decays at `decay_per_s`.
    pub fn kick(&mut self, t_s: f64, amp_deg: f64, freq_hz: f64, decay_per_s: f64) {
        self.add_ring(t_s, amp_deg, freq_hz, decay_per_s);
        self.event("kick", t_s, amp_deg, freq_hz, decay_per_s);
    }

    /// A kick whose push shows: the bar is first pushed aside, a half-sine of
    /// `push_deg` lasting `push_s`, then the wobble mode rings as in
    /// [`Ride::kick`] from the end of the push. The truth's time is the
    /// push's start.
    pub fn pushed_kick(&mut self, t_s: f64, push_deg: f64, push_s: f64, ring: (f64, f64, f64)) {
        let (amp_deg, freq_hz, decay_per_s) = ring;
        let start = libm::ceil(t_s * FS_HZ) as usize;
        let end = libm::ceil((t_s + push_s) * FS_HZ) as usize;
        for i in start..end.min(self.len()) {
            let tau = i as f64 / FS_HZ - t_s;
            self.steer[i] += push_deg * sin(core::f64::consts::PI * tau / push_s);
        }
        self.add_ring(t_s + push_s, amp_deg, freq_hz, decay_per_s);
        self.event("kick", t_s, amp_deg, freq_hz, decay_per_s);
    }

    /// A pothole: a sharp jolt of `amp_deg` when the front wheel drops in
    /// (40 ms), ringing of the steering mode, and a smaller second hit when
    /// the rear wheel follows one wheelbase (1.1 m) later.
    pub fn pothole(&mut self, t_s: f64, amp_deg: f64, decay_per_s: f64) {
        let v = self.speed_at(t_s).max(1.0);
        let f = wobble_mode_hz(v);
        for (t0, a) in [(t_s, amp_deg), (t_s + 1.1 / v, 0.4 * amp_deg)] {
            let start = libm::ceil(t0 * FS_HZ) as usize;
            for i in start..(start + 4).min(self.len()) {
                let tau = i as f64 / FS_HZ - t0;
                self.steer[i] += a * sin(PI * tau / 0.04);
            }
            self.add_ring(t0 + 0.04, 0.5 * a, f, decay_per_s);
        }
        self.event("pothole", t_s, amp_deg, f, decay_per_s);
    }

    /// A kerb or edge: the bar is knocked by `amp_deg` within 60 ms and the
    /// rider brings it back over 0.6 s; the knock rings the steering mode.
    pub fn kerb(&mut self, t_s: f64, amp_deg: f64, decay_per_s: f64) {
        let v = self.speed_at(t_s).max(1.0);
        let f = wobble_mode_hz(v);
        let start = libm::ceil(t_s * FS_HZ) as usize;
        for i in start..(start + 70).min(self.len()) {
            let tau = i as f64 / FS_HZ - t_s;
            self.steer[i] +=
                amp_deg * smoothstep(tau, 0.0, 0.06) * (1.0 - smoothstep(tau, 0.1, 0.7));
        }
        self.add_ring(t_s + 0.03, 0.6 * amp_deg, f, decay_per_s);
        self.event("kerb", t_s, amp_deg, f, decay_per_s);
    }

    /// A corner: the steering angle rises to `angle_deg` and back as a raised
    /// cosine over `duration_s`, after a small countersteer.
    pub fn corner(&mut self, t_s: f64, duration_s: f64, angle_deg: f64) {
        for (i, s) in self.steer.iter_mut().enumerate() {
            let t = i as f64 / FS_HZ;
            let u = (t - t_s) / duration_s;
            if (0.0..=1.0).contains(&u) {
                *s += angle_deg * 0.5 * (1.0 - cos(TAU * u));
            }
            let c = (t - t_s + 0.3) / 0.3;
            if (0.0..1.0).contains(&c) {
                *s -= 0.15 * angle_deg * sin(PI * c);
            }
        }
        self.event("corner", t_s, angle_deg, 0.0, 0.0);
    }

    /// An unstable wobble episode (see [`WobbleSpec`]).
    pub fn wobble(&mut self, w: WobbleSpec) {
        let mut rng = self.rng(100 + self.episodes.len() as u64);
        let phase0 = rng.range(0.0, TAU);
        for (i, s) in self.steer.iter_mut().enumerate() {
            let t = i as f64 / FS_HZ;
            let e = w.envelope(t);
            if e > 1e-4 {
                *s += e * sin(TAU * w.freq_hz * t + phase0);
            }
        }
        let peak_s = w.peak_s();
        let release_s = peak_s + w.hold_s;
        let end_s = release_s + log(w.peak_amp_deg / EPISODE_END_DEG) / w.decay_per_s;
        let t_ref_s =
            w.onset_s + log(LATENCY_REFERENCE_DEG / WobbleSpec::ONSET_AMP_DEG) / w.growth_per_s;
        let speed_mps = r4(self.speed_at(t_ref_s));
        self.episodes.push(Episode {
            onset_s: r4(w.onset_s),
            onset_amp_deg: WobbleSpec::ONSET_AMP_DEG,
            freq_hz: r4(w.freq_hz),
            growth_per_s: r4(w.growth_per_s),
            t_ref_s: r4(t_ref_s),
            peak_amp_deg: r4(w.peak_amp_deg),
            peak_s: r4(peak_s),
            intervention_s: r4(release_s),
            decay_per_s: r4(w.decay_per_s),
            end_s: r4(end_s),
            speed_mps,
            alert_expected: true,
        });
    }

    /// Adds calibration offset, sensor noise and ADC quantisation, and renders
    /// the fixture CSV (`t_s,steer_deg,speed_mps`) and its ground truth.
    #[must_use]
    pub fn finish(mut self, committed: bool) -> (String, FixtureTruth) {
        let mut rng = self.rng(5);
        let offset_deg = rng.range(-1.5, 1.5);
        let lsb = ADC_SPAN_DEG / f64::from(1u32 << ADC_BITS);
        let half_span = ADC_SPAN_DEG / 2.0;
        let mut csv = String::with_capacity(self.len() * 20 + 32);
        csv.push_str("t_s,steer_deg,speed_mps\n");
        for i in 0..self.len() {
            let x = self.steer[i] + offset_deg + self.noise_deg * rng.normal();
            let q = (libm::round(x / lsb) * lsb).clamp(-half_span, half_span - lsb);
            let v = (self.speed[i] + 0.01 * rng.normal()).max(0.0);
            push_fixed2(&mut csv, i as f64 / FS_HZ);
            csv.push(',');
            push_fixed2(&mut csv, q);
            csv.push(',');
            push_fixed2(&mut csv, v);
            csv.push('\n');
        }
        let truth = FixtureTruth {
            file: format!("{}.csv", self.name),
            name: self.name,
            committed,
            description: self.description,
            seed: self.seed,
            duration_s: r4(self.steer.len() as f64 / FS_HZ),
            noise_deg: r4(self.noise_deg),
            episodes: self.episodes,
            events: self.events,
        };
        (csv, truth)
    }
}

/// Appends `x` with exactly two decimals and no `-0.00`.
fn push_fixed2(out: &mut String, x: f64) {
    use core::fmt::Write as _;
    let c = libm::round(x * 100.0) as i64;
    let sign = if c < 0 { "-" } else { "" };
    let c = c.unsigned_abs();
    let _ = write!(out, "{sign}{}.{:02}", c / 100, c % 100);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fixed2_formatting() {
        let mut s = String::new();
        for x in [0.0, -0.001, 1.004, -2.5, 12.346, 0.07] {
            push_fixed2(&mut s, x);
            s.push(' ');
        }
        assert_eq!(s, "0.00 0.00 1.00 -2.50 12.35 0.07 ");
    }

    #[test]
    fn wobble_envelope_hits_its_truth() {
        let w = WobbleSpec::growing(10.0, 6.4, 1.8, 4.0);
        let mut r = Ride::new("x", "", 1, 20.0, 4.0);
        r.wobble(w);
        let e = &r.episodes[0];
        assert!((w.envelope(e.t_ref_s) - 0.5).abs() < 1e-3);
        assert!((w.envelope(e.peak_s) - 4.0).abs() < 1e-3);
        assert!((w.envelope(e.end_s) - 0.25).abs() < 1e-3);
    }
}
