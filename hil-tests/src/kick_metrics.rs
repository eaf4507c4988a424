//! How the on-board detector treats kicks with a known answer
//! ([`crate::corpus::kicks`]): whether its alert fired on a ring-down, and
//! how well it measured the ring.

use wobble_core::config::Config;
use wobble_core::detector::{AlertEvent, Kick};

use crate::corpus::Fixture;

/// A kick measured more than this far from a true kick is matched to none, s.
const MATCH_S: f64 = 0.5;

/// One kick of a ride and what the detector made of it.
#[derive(Clone, Debug, PartialEq)]
pub struct KickScore {
    /// Ride name.
    pub fixture: String,
    /// Kick time, s.
    pub t_s: f64,
    /// Speed, m/s.
    pub speed_mps: f64,
    /// True ring frequency, Hz.
    pub freq_hz: f64,
    /// True growth rate of the ring, 1/s (negative: it decays).
    pub sigma_per_s: f64,
    /// True initial amplitude of the ring, degrees.
    pub amp_deg: f64,
    /// Times of the `alert_on`s from the kick to the next kick (or the end).
    pub alerts_s: Vec<f64>,
    /// The detector's measurement of it, with the time it put the kick at.
    pub measured: Option<(f64, Kick)>,
}

impl KickScore {
    /// Whether the measurement is within `sigma_tol` (1/s) and `freq_tol`
    /// (Hz) of the truth.
    #[must_use]
    pub fn within(&self, sigma_tol: f64, freq_tol: f64) -> bool {
        self.measured.is_some_and(|(_, k)| {
            (f64::from(k.sigma_per_s) - self.sigma_per_s).abs() <= sigma_tol
                && (f64::from(k.freq_hz) - self.freq_hz).abs() <= freq_tol
        })
    }
}

/// What one replay saw: the times of the alert-ons, and each measured kick
/// with the time the detector puts it at.
pub type Replayed = (Vec<f64>, Vec<(f64, Kick)>);

/// A ride's replay with the speed column, as `config` sets the detector up.
///
/// # Errors
/// An invalid `config` or a ride whose CSV does not parse.
pub fn replay(fx: &Fixture, config: &Config) -> Result<Replayed, String> {
    let rows = fx.rows()?;
    let mut det = config.detector().map_err(|e| e.to_string())?;
    let fs = f64::from(det.config().sample_rate_hz);
    let (mut ons, mut kicks) = (Vec::new(), Vec::new());
    for r in &rows {
        if let Some(AlertEvent::On { .. }) = det.push(r.steer_deg, Some(r.speed_mps)) {
            ons.push(r.t_s);
        }
        if let Some(k) = det.take_kick() {
            kicks.push((r.t_s - f64::from(k.samples_ago) / fs, k));
        }
    }
    Ok((ons, kicks))
}

/// Replays every ride through the detector and scores each of its kicks.
///
/// # Errors
/// An invalid `config` or a ride whose CSV does not parse.
pub fn score(fixtures: &[Fixture], config: &Config) -> Result<Vec<KickScore>, String> {
    let mut out = Vec::new();
    for fx in fixtures {
        let (ons, measured) = replay(fx, config)?;
        let mut kicks: Vec<_> = fx
            .truth
            .events
            .iter()
            .filter(|e| e.kind == "kick")
            .collect();
        kicks.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        for (i, k) in kicks.iter().enumerate() {
            let until = kicks.get(i + 1).map_or(f64::INFINITY, |n| n.t_s);
            out.push(KickScore {
                fixture: fx.truth.name.clone(),
                t_s: k.t_s,
                speed_mps: k.speed_mps,
                freq_hz: k.freq_hz,
                sigma_per_s: -k.decay_per_s,
                amp_deg: k.amp_deg.abs(),
                alerts_s: ons
                    .iter()
                    .copied()
                    .filter(|&t| t >= k.t_s && t < until)
                    .collect(),
                measured: measured
                    .iter()
                    .copied()
                    .filter(|(t, _)| (t - k.t_s).abs() <= MATCH_S)
                    .min_by(|a, b| (a.0 - k.t_s).abs().total_cmp(&(b.0 - k.t_s).abs())),
            });
        }
    }
    Ok(out)
}
