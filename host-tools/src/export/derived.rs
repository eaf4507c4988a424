//! Signals derived from the decoded rows, for `decode --columns`: the roll
//! angle the plot draws, the steering angle band-passed to the wobble band,
//! and that band's envelope. Each is computed only when its column is
//! chosen, as the rows stream by, in bounded memory.
//!
//! - `roll_deg`: the plot's roll estimate ([`crate::analysis::roll`]: the
//!   complementary filter run forwards and backwards and averaged), zero
//!   phase, so no delay; the rows are held until it is final (up to
//!   [`crate::analysis::roll::BACKWARD_LEAD_S`] and a chunk, about 4 min).
//! - `steer_bp_deg`: the steering angle through the wobble band's filter
//!   run forwards only ([`crate::analysis::filter::band_pass_causal`]: two
//!   second-order Butterworth high-passes at 4 Hz and two low-passes at
//!   12 Hz), as a filter on the bicycle would: nothing shows before it
//!   happened. At 7 Hz it passes [`BAND_GAIN_7HZ`] of the oscillation, in
//!   phase, and a change of its amplitude (a wobble growing) shows
//!   [`GROUP_DELAY_7HZ_S`] late (tests measure both).
//! - `wobble_env_deg`: the wobble's amplitude: `sqrt 2` times the band's
//!   RMS over the [`ENVELOPE_WINDOW_S`] before each row, over
//!   [`BAND_GAIN_7HZ`]; a steady 6-8 Hz oscillation reads within 4 % of its
//!   amplitude, and a change shows the group delay and half the window late
//!   (340 ms at 7 Hz).
//!
//! Each restarts after a gap in the frames (from the first frame after it),
//! as the analyses do.

use std::collections::VecDeque;

use crate::analysis::filter::{follows, Biquad, Pass, Streaming, WOBBLE_BAND_HZ};
use crate::analysis::roll::RollStream;
use crate::rows::Row;

/// The trailing window of the envelope, s: whole cycles at 6 and 8 Hz
/// (3 and 4), so a steady wobble reads without ripple there.
pub const ENVELOPE_WINDOW_S: f64 = 0.5;
/// The causal band's gain at 7 Hz (0.80 at 6 and 8 Hz).
pub const BAND_GAIN_7HZ: f64 = 0.824;
/// Its group delay at 7 Hz, s (105 ms at 6 Hz, 80 ms at 8 Hz).
pub const GROUP_DELAY_7HZ_S: f64 = 0.090;

/// The names of the derived columns.
pub const NAMES: [&str; 3] = ["roll_deg", "steer_bp_deg", "wobble_env_deg"];

/// The derived values of one row (`None` where not asked for).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Derived {
    /// Roll angle, degrees, positive leaning right.
    pub roll_deg: Option<f64>,
    /// Steering angle in the wobble band, degrees.
    pub steer_bp_deg: Option<f64>,
    /// Amplitude of the wobble band, degrees.
    pub wobble_env_deg: Option<f64>,
}

/// The causal wobble band and its envelope over the current span.
struct Band {
    sections: [Streaming; 4],
    window: VecDeque<f64>,
    sum_sq: f64,
}

/// Adds the chosen derived values to rows in file order.
pub struct Deriver {
    fs_hz: f64,
    last_t: Option<f64>,
    /// With `steer_bp_deg` or `wobble_env_deg` chosen.
    band: Option<Option<Band>>,
    /// With `roll_deg` chosen: the estimate and the rows it still holds.
    roll: Option<(RollStream, VecDeque<Row>)>,
    window_frames: usize,
}

impl Deriver {
    /// A deriver of the columns among `chosen` (column names) for rows
    /// nominally `fs_hz` apart; `None` when no derived column is chosen.
    #[must_use]
    pub fn for_columns(chosen: &[&str], fs_hz: f64) -> Option<Self> {
        let wants = |name: &str| chosen.contains(&name);
        if !NAMES.iter().any(|n| wants(n)) {
            return None;
        }
        Some(Self {
            fs_hz,
            last_t: None,
            band: (wants("steer_bp_deg") || wants("wobble_env_deg")).then_some(None),
            roll: wants("roll_deg").then(|| (RollStream::new(fs_hz), VecDeque::new())),
            window_frames: ((ENVELOPE_WINDOW_S * fs_hz).round() as usize).max(1),
        })
    }

    /// Takes the next row; `emit` gets every row whose values are final,
    /// in order.
    pub fn push(&mut self, row: &Row, emit: &mut impl FnMut(&Row)) {
        let joins = self
            .last_t
            .is_some_and(|t| follows(t, row.t_s, 1.0 / self.fs_hz));
        self.last_t = Some(row.t_s);
        let mut row = *row;
        if let Some(state) = &mut self.band {
            let band = match state {
                Some(band) if joins => band,
                _ => state.insert(Band::new(row.steer_deg, self.fs_hz)),
            };
            let bp = band.next(row.steer_deg, self.window_frames);
            row.derived.steer_bp_deg = Some(bp.0);
            row.derived.wobble_env_deg = Some(bp.1);
        }
        let Some((stream, held)) = &mut self.roll else {
            emit(&row);
            return;
        };
        held.push_back(row);
        stream.push_row(&row, &mut |_, _, roll| Self::give(held, roll, emit));
    }

    /// Gives every row still held.
    pub fn finish(&mut self, emit: &mut impl FnMut(&Row)) {
        if let Some((stream, held)) = &mut self.roll {
            stream.finish(&mut |_, _, roll| Self::give(held, roll, emit));
        }
    }

    /// The roll stream gives estimates in the order its rows came: the
    /// oldest row held takes the next one.
    fn give(held: &mut VecDeque<Row>, roll_deg: f64, emit: &mut impl FnMut(&Row)) {
        if let Some(mut row) = held.pop_front() {
            row.derived.roll_deg = Some(roll_deg);
            emit(&row);
        }
    }
}

impl Band {
    fn new(x0: f64, fs_hz: f64) -> Self {
        let high = Biquad::butterworth(Pass::High, WOBBLE_BAND_HZ.0, fs_hz);
        let low = Biquad::butterworth(Pass::Low, WOBBLE_BAND_HZ.1, fs_hz);
        // Each section starts settled to the first sample: the high-passes
        // pass nothing of a constant, so the low-passes start from zero.
        Self {
            sections: [
                high.stream(x0),
                high.stream(0.0),
                low.stream(0.0),
                low.stream(0.0),
            ],
            window: VecDeque::new(),
            sum_sq: 0.0,
        }
    }

    /// The band's value for the next sample `x`, and its envelope over the
    /// last `window` values.
    fn next(&mut self, x: f64, window: usize) -> (f64, f64) {
        let y = self.sections.iter_mut().fold(x, |v, s| s.next(v));
        self.window.push_back(y);
        self.sum_sq += y * y;
        if self.window.len() > window {
            let old = self.window.pop_front().unwrap_or(0.0);
            self.sum_sq -= old * old;
        }
        // Summed as it goes: rounding can leave a hair below zero.
        let mean_sq = self.sum_sq.max(0.0) / self.window.len() as f64;
        (y, (2.0 * mean_sq).sqrt() / BAND_GAIN_7HZ)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::filter::band_pass_causal;
    use std::f64::consts::TAU;

    /// The steady response of the causal band to a sine at `f` Hz after 3 s
    /// of settling: gain and phase (radians, against the input's).
    fn response(f: f64) -> (f64, f64) {
        let fs = 100.0;
        let x: Vec<f64> = (0..1000)
            .map(|i| (TAU * f * f64::from(i) / fs).sin())
            .collect();
        let y = band_pass_causal(&x, WOBBLE_BAND_HZ, fs);
        let (mut s, mut c) = (0.0, 0.0);
        for (i, v) in y.iter().enumerate().skip(300) {
            let w = TAU * f * i as f64 / fs;
            s += v * w.sin();
            c += v * w.cos();
        }
        let n = (y.len() - 300) as f64 / 2.0;
        ((s / n).hypot(c / n), c.atan2(s))
    }

    /// The stated gain and group delay at 7 Hz, measured on steady sines
    /// (the delay from the phase at 6.95 and 7.05 Hz); in phase at 7 Hz.
    #[test]
    fn the_band_has_the_stated_gain_and_delay_at_7hz() {
        let (gain, phase) = response(7.0);
        assert!((gain - BAND_GAIN_7HZ).abs() < 0.002, "{gain}");
        assert!(phase.abs() < 0.01, "{phase}");
        let (lo, hi) = (response(6.95).1, response(7.05).1);
        let delay = -(hi - lo) / (TAU * 0.1);
        assert!((delay - GROUP_DELAY_7HZ_S).abs() < 0.003, "{delay}");
    }

    /// The envelope reads a steady 6-8 Hz oscillation's amplitude within
    /// 4 % (of 2 degrees).
    #[test]
    fn the_envelope_reads_the_amplitude() {
        let fs = 100.0;
        for f in [6.0, 7.0, 8.0] {
            let mut d = Deriver::for_columns(&["wobble_env_deg"], fs).unwrap();
            let mut env = Vec::new();
            for i in 0..600 {
                let t = f64::from(i) / fs;
                let row = Row {
                    t_s: t,
                    steer_deg: 2.0 * (TAU * f * t).sin(),
                    ..Row::default()
                };
                d.push(&row, &mut |r: &Row| {
                    env.push(r.derived.wobble_env_deg.unwrap())
                });
            }
            assert!(
                env[300..].iter().all(|e| (e / 2.0 - 1.0).abs() < 0.04),
                "{f}: {:?}",
                &env[300..305]
            );
        }
    }

    /// No derived column chosen, no deriver.
    #[test]
    fn nothing_chosen_nothing_derived() {
        assert!(Deriver::for_columns(&["t_s", "steer_deg"], 100.0).is_none());
        assert!(Deriver::for_columns(&["roll_deg"], 100.0).is_some());
    }
}
