//! Wobble episodes found offline in the steering angle, each measured the
//! way the seed paper measures its eigenvalues: the free oscillation fitted
//! as `A e^(sigma t) sin(2 pi f t + phi)`, giving the real part sigma and the
//! imaginary part 2 pi f of the mode.
//!
//! 1. The steering angle is band-passed around the wobble band (zero phase)
//!    and its envelope taken from the smoothed signal energy. An episode is
//!    a stretch where that envelope exceeds [`DETECT_AMP_DEG`], extended on
//!    both sides to where it is back below [`QUIET_AMP_DEG`].
//! 2. Its frequency comes from zero crossings around the peak; the signal
//!    is then demodulated at that frequency (narrow, zero-phase) for a clean
//!    envelope, and the background in that narrow band (sensor noise, wheel
//!    ripple) is measured before the episode and removed in power.
//! 3. If the envelope climbs to the peak for long enough, the samples of
//!    that climb are fitted directly (not their envelope) with a growing
//!    sinusoid, plus a steady tone for a wheel harmonic beside it (see
//!    [`super::sinefit`]), looked for up to 4 s before the climb but not
//!    before the previous episode has rung down. If that explains the signal, the wobble is
//!    **unstable** and sigma is the fitted growth rate. Otherwise the
//!    oscillation was struck (a kick, a pothole) and rings down: the fall
//!    from its largest swing is fitted the same way (the tone looked for up
//!    to 4 s after it, but not into the next episode), the mode is
//!    **stable**, and sigma is the (negative) decay rate.
//! 4. An unstable episode's onset is where the fitted exponential is
//!    [`ONSET_AMP_DEG`]: the wobble's start "from nothing", independent of
//!    where the noise floor happens to be. A stable episode starts where it
//!    was struck.
//! 5. An oscillation whose frequency lies outside [`WOBBLE_BAND_HZ`] is
//!    not a wobble, however strongly it shows through the band-pass's
//!    skirts: a weave of several degrees at 1-2.5 Hz, pedalling, a
//!    rider's shimmy of the bar. It is no episode (the weave's kicks are
//!    measured in their own band: [`super::weave`]).
//! 6. Each stretch between gaps is analysed alone, so no fit reaches across
//!    a gap. An episode that reaches a lost block, a dropout, a time jump or
//!    an end of the data is **censored** (see [`super::censor`]): its onset
//!    is not placed before the cut, its peak and end are only what was seen,
//!    and one that starts at a cut is never called stable (its strike was
//!    not seen: a ring-down from a gap's edge would be a mode made up).

use std::f64::consts::TAU;
use std::ops::Range;

use serde::Serialize;

use super::campaign_kicks::{Source, MATCH_S};
use super::censor::{Cut, Edge};
use super::filter::{wobble_band, wobble_band_causal, Biquad, Pass, WOBBLE_BAND_HZ};
use super::kicks::{Kick, KickMode};
use super::run::Run;
use super::search::EpisodeSearch;
use super::sinefit::{fit_mode, Grid, SineFit};
use crate::losses::Losses;

/// Envelope at which an unstable wobble is said to start, degrees: below
/// every sensor's noise, so onsets compare across runs and bicycles.
pub const ONSET_AMP_DEG: f64 = 0.02;
/// Envelope that makes an episode, degrees (the size the rider feels).
pub const DETECT_AMP_DEG: f64 = 0.5;
/// Envelope below which an episode is over, degrees.
pub const QUIET_AMP_DEG: f64 = 0.25;

/// Smoothing of the signal energy for detection, Hz.
const ENERGY_SMOOTHING_HZ: f64 = 2.0;
/// Low-pass after demodulation, Hz: the envelope only bounds the fits, so it
/// needs to follow a growth of 4/s and to reject what lies a few hertz off.
const DEMOD_LOWPASS_HZ: f64 = 2.0;
/// Background is measured over this long before an episode, s.
const BACKGROUND_WINDOW_S: f64 = 8.0;
/// Envelope fits use the range from this many times the background...
const FIT_FLOOR_OVER_BACKGROUND: f64 = 3.0;
/// ...and never start below this, degrees...
const FIT_FLOOR_MIN_DEG: f64 = 0.1;
/// ...up to this fraction of the peak, where the envelope still follows the
/// free oscillation rather than the rider's intervention.
const FIT_TOP_OF_PEAK: f64 = 0.85;
/// A growth fit must span this long to call the wobble unstable, s:
/// a struck oscillation rises within a cycle or two.
const MIN_GROWTH_FIT_S: f64 = 0.3;
/// A decay fit must span at least this long, s.
const MIN_DECAY_FIT_S: f64 = 0.15;
/// Largest unexplained share (RMS) of the signal for a mode fit to count:
/// a struck oscillation fitted as growth leaves most of it.
const MAX_RESIDUAL_REL: f64 = 0.5;
/// A growth must show in the causally filtered signal: its RMS over
/// [`CAUSAL_WINDOW_S`] before the climb's last [`CAUSAL_TRIM_S`] at least
/// this share of the zero-phase band's there.
const CAUSAL_SHARE: f64 = 0.5;
/// See [`CAUSAL_SHARE`], s.
const CAUSAL_WINDOW_S: f64 = 0.3;
/// The causal check of a growth leaves out this much of the climb's end, s.
const CAUSAL_TRIM_S: f64 = 0.15;
/// The longest push on the bar, s: the climb before it is its answer
/// alone (see [`CAUSAL_SHARE`]).
const SLOW_PUSH_S: f64 = 0.3;
/// A decay fit the largest swing cannot start (a push there) starts this
/// much later in turn...
const PUSH_STEP_S: f64 = 0.05;
/// ... up to this long after it, s.
const PUSH_MAX_S: f64 = 0.5;
/// A growth fit starts this long before the wobble rises, s.
const TONE_LOOKBACK_S: f64 = 4.0;
/// A steady tone is looked for within this of the wobble's frequency, Hz.
const TONE_SEARCH_HZ: f64 = 1.5;
/// Speed at onset is the mean over onset ± this, s.
const SPEED_HALF_WIDTH_S: f64 = 0.25;

/// Spans shorter than this (between gaps in the data) are not analysed, s.
pub(super) const MIN_SPAN_S: f64 = 2.0;

/// Whether the wobble mode grew or decayed.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Stability {
    /// Struck and ringing down: sigma < 0.
    Stable,
    /// Growing by itself: sigma > 0.
    Unstable,
}

/// Where an episode's frequency and growth rate come from; written as its
/// name ([`Measured::as_str`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Measured {
    /// The episode's own fit (below): an unstable episode, or a stable one
    /// that is no kick `wobblog margin` uses.
    Episode,
    /// A stable episode that is a kick: the kick's values as `wobblog
    /// margin` takes them (see [`super::kick_episodes`]), measured as this
    /// says (`host`, `card-host` or `card`).
    Kick(Source),
}

impl Measured {
    /// The name JSON and the tables use: `episode`, or the kick's source
    /// (`host`, `card-host`, `card`) as `wobblog margin` names it.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Episode => "episode",
            Self::Kick(source) => source.as_str(),
        }
    }
}

impl Serialize for Measured {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_str(self.as_str())
    }
}

/// One episode: a wobble's, or a weave's ring-down after a kick
/// ([`Episode::of_weave_kick`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Episode {
    /// The mode: `wobble` (in the steering angle) or `weave` (a kick's
    /// ring-down in the roll rate).
    pub mode: KickMode,
    /// Start, s since boot (see the module notes).
    pub onset_s: f64,
    /// Envelope back below [`QUIET_AMP_DEG`], s since boot.
    pub end_s: f64,
    /// Time of the largest envelope, s since boot.
    pub peak_s: f64,
    /// Dominant frequency, Hz.
    pub freq_hz: f64,
    /// Real part of the mode: growth (> 0) or decay (< 0) rate of the
    /// envelope, 1/s.
    pub sigma_per_s: f64,
    /// Standard uncertainty of `sigma_per_s`, 1/s: the kick's where the
    /// episode is a kick (see `source`); `None` for the episode's own fit.
    pub sigma_sd_per_s: Option<f64>,
    /// Where `freq_hz`, `sigma_per_s` and `sigma_sd_per_s` come from.
    pub source: Measured,
    /// Largest envelope (zero to peak), degrees: of the steering angle for
    /// the wobble, of the roll angle at the fit's start for the weave.
    pub peak_amp_deg: f64,
    /// Wheel speed at onset, m/s.
    pub speed_at_onset_mps: f64,
    /// Stable or unstable.
    pub stability: Stability,
    /// The stretch the envelope fit used, s since boot.
    pub fit_s: [f64; 2],
    /// Whether the data do not show the whole episode: it reaches a cut
    /// (below). Its onset, peak or end are then bounds only.
    pub censored: bool,
    /// What cuts it at its start, if the data do not show it starting.
    pub cut_at_start: Option<Cut>,
    /// What cuts it at its end, if the data do not show it ending.
    pub cut_at_end: Option<Cut>,
}

impl Episode {
    /// The weave's ring-down after `kick` (found in the roll rate,
    /// [`super::weave`]) as an episode: it starts where the kick rose, ends
    /// with its fit, peaks at the fit's start with the roll angle's
    /// amplitude; stable if it decays.
    #[must_use]
    pub fn of_weave_kick(kick: &Kick) -> Self {
        Self {
            mode: KickMode::Weave,
            onset_s: kick.t_s,
            end_s: kick.fit_s[1],
            peak_s: kick.fit_s[0],
            freq_hz: kick.freq_hz,
            sigma_per_s: kick.sigma_per_s,
            sigma_sd_per_s: Some(kick.sigma_sd_per_s),
            source: Measured::Kick(Source::Host),
            peak_amp_deg: kick.amp_deg,
            speed_at_onset_mps: kick.speed_mps,
            stability: if kick.sigma_per_s < 0.0 {
                Stability::Stable
            } else {
                Stability::Unstable
            },
            fit_s: kick.fit_s,
            censored: false,
            cut_at_start: None,
            cut_at_end: None,
        }
    }

    /// What cuts the episode, in words (`start: lost_blocks, end:
    /// data_end`); empty when the data show it whole.
    #[must_use]
    pub fn cuts_text(&self) -> String {
        let parts: Vec<String> = [("start", self.cut_at_start), ("end", self.cut_at_end)]
            .into_iter()
            .filter_map(|(edge, cut)| cut.map(|c| format!("{edge}: {}", c.as_str())))
            .collect();
        parts.join(", ")
    }

    /// Imaginary part of the mode, `2 pi f`, rad/s.
    #[must_use]
    pub fn omega_rad_s(&self) -> f64 {
        TAU * self.freq_hz
    }
}

/// The wobble speed: the lowest speed at onset of an unstable wobble
/// episode whose onset the data show (not cut at its start), m/s (a
/// weave's is no wobble's).
#[must_use]
pub fn wobble_speed_mps(episodes: &[Episode]) -> Option<f64> {
    episodes
        .iter()
        .filter(|e| {
            e.mode == KickMode::Wobble
                && e.stability == Stability::Unstable
                && e.cut_at_start.is_none()
        })
        .map(|e| e.speed_at_onset_mps)
        .min_by(f64::total_cmp)
}

/// Every episode of `run`, in time order.
#[must_use]
pub fn find_episodes(run: &Run) -> Vec<Episode> {
    let mut search = EpisodeSearch::new(run.sample_rate_hz());
    for i in 0..run.len() {
        search.push(run.t_s[i], run.steer_deg[i], run.speed_mps[i]);
    }
    search.finish(&run.summary.losses)
}

/// Where an episode's frequency and growth rate come from.
enum Rate<'k> {
    /// Its own fit over a range of the samples.
    Fit(Range<usize>, SineFit),
    /// The host's measurement of the kick that struck it.
    Kick(&'k Kick),
}

/// An episode as found while the frames stream by: what cuts it is known
/// once the whole log has been read.
pub(super) struct Found {
    pub episode: Episode,
    pub start: Option<Edge>,
    pub end: Option<Edge>,
}

impl Found {
    /// The episode, its cuts named from the log's `losses`.
    pub fn resolve(self, losses: &Losses) -> Episode {
        let cut_at_start = self.start.map(|e| e.cut(losses));
        let cut_at_end = self.end.map(|e| e.cut(losses));
        Episode {
            censored: cut_at_start.is_some() || cut_at_end.is_some(),
            cut_at_start,
            cut_at_end,
            ..self.episode
        }
    }
}

/// Frames of one evenly sampled stretch (all of it or a window onto it).
pub(super) struct Frames<'a> {
    pub t_s: &'a [f64],
    pub steer_deg: &'a [f64],
    pub speed_mps: &'a [f64],
}

/// Where a window of frames lies in its stretch.
#[derive(Clone, Copy)]
pub(super) struct Place {
    /// Time of the stretch's first frame, s.
    pub first_s: f64,
    /// What cuts the stretch at its start.
    pub stretch_start: Edge,
    /// What cuts the window at its first frame: the stretch's start, or
    /// the analysis window's limit; `None` if frames before it were seen.
    pub window_start: Option<Edge>,
}

/// One evenly sampled stretch of a run, band-passed.
pub(super) struct Span<'a> {
    frames: Frames<'a>,
    t_s: &'a [f64],
    band: Vec<f64>,
    /// The same band filtered causally: a growth must show in it too.
    causal: Vec<f64>,
    pub energy: Vec<f64>,
    fs_hz: f64,
    place: Place,
    /// The host's kicks of the run, in time order (see [`Self::kick_struck`]).
    kicks: &'a [Kick],
}

impl<'a> Span<'a> {
    pub fn new(frames: Frames<'a>, fs_hz: f64, place: Place, kicks: &'a [Kick]) -> Self {
        let band = wobble_band(frames.steer_deg, fs_hz);
        let causal = wobble_band_causal(frames.steer_deg, fs_hz);
        let mut energy: Vec<f64> = band.iter().map(|v| 2.0 * v * v).collect();
        Biquad::butterworth(Pass::Low, ENERGY_SMOOTHING_HZ, fs_hz).filtfilt(&mut energy);
        let energy = energy.into_iter().map(|e| e.max(0.0).sqrt()).collect();
        Self {
            t_s: frames.t_s,
            frames,
            band,
            causal,
            energy,
            fs_hz,
            place,
            kicks,
        }
    }

    fn samples(&self, s: f64) -> usize {
        (s * self.fs_hz).round() as usize
    }

    /// The first frame at or after `from` (and before `to`) whose
    /// envelope makes an episode.
    pub fn next_hit(&self, from: usize, to: usize) -> Option<usize> {
        let to = to.min(self.energy.len());
        let from = from.min(to);
        self.energy[from..to]
            .iter()
            .position(|&e| e > DETECT_AMP_DEG)
            .map(|i| from + i)
    }

    /// The frames around `hit` where the envelope is above quiet: from the
    /// first after the last quiet one before it, to the first quiet one
    /// after it (or the end of the frames).
    pub fn region(&self, hit: usize) -> Range<usize> {
        let start = self.energy[..hit]
            .iter()
            .rposition(is_quiet)
            .map_or(0, |q| q + 1);
        let end = self.energy[hit..]
            .iter()
            .position(is_quiet)
            .map_or(self.energy.len(), |q| hit + q);
        start..end
    }

    /// The last frame at or before `i` whose envelope is quiet: no episode
    /// found later can start before it.
    pub fn last_quiet(&self, i: usize) -> Option<usize> {
        let end = (i + 1).min(self.energy.len());
        self.energy[..end].iter().rposition(is_quiet)
    }

    /// Measures the episode whose energy envelope is above quiet over
    /// `region`; `end_cut` is what cuts the frames where it ends, if they do.
    pub fn measure(&self, region: Range<usize>, end_cut: Option<Edge>) -> Option<Found> {
        let peak = region.start + argmax(&self.energy[region.clone()])?;
        let half_s = self.samples(0.5);
        let around = peak.saturating_sub(half_s).max(region.start)..(peak + half_s).min(region.end);
        let f0_hz = crossing_freq_hz(&self.t_s[around.clone()], &self.band[around])?;

        // No fit reaches into a neighbouring episode: the tone looked for
        // before a growth or after a decay would be that episode.
        let (prev_end, next_start) = self.neighbours(region.clone());
        let window = region
            .start
            .saturating_sub(self.samples(BACKGROUND_WINDOW_S))
            ..(region.end + self.samples(TONE_LOOKBACK_S)).min(next_start);
        let t = &self.t_s[window.clone()];
        let env = demod_envelope(&self.band[window.clone()], t, f0_hz, self.fs_hz);
        let before = region.start.saturating_sub(self.samples(0.3)) - window.start;
        let background_sq = median(env[..before].iter().map(|e| e * e).collect());
        let clean: Vec<f64> = env
            .iter()
            .map(|e| (e * e - background_sq).max(0.0).sqrt())
            .collect();

        let local = region.start - window.start..region.end - window.start;
        let top = local.start + argmax(&clean[local.clone()])?;
        let peak_amp_deg = clean[top];
        let floor = (FIT_FLOOR_OVER_BACKGROUND * background_sq.sqrt()).max(FIT_FLOOR_MIN_DEG);
        let ceiling = FIT_TOP_OF_PEAK * peak_amp_deg;
        if ceiling <= floor {
            return None;
        }

        let band = &self.band[window.clone()];
        let causal = &self.causal[window.clone()];
        // The mode fitted over `range` if it grows (or decays) as asked and
        // explains the signal there.
        let fit = |range: Range<usize>, growing: bool| {
            let min_s = if growing {
                MIN_GROWTH_FIT_S
            } else {
                MIN_DECAY_FIT_S
            };
            if t[range.end - 1] - t[range.start] < min_s {
                return None;
            }
            let slope = log_slope(&t[range.clone()], &clean[range.clone()])?;
            let f1_hz = crossing_freq_hz(&t[range.clone()], &band[range.clone()]).unwrap_or(f0_hz);
            // The fit reaches beyond the rise or the fall, to where a steady
            // tone near the wobble (a wheel harmonic) shows alone, and fits
            // that tone alongside: before a growth, after a decay.
            let lookback = self.samples(TONE_LOOKBACK_S);
            let (fitted, alone) = if growing {
                // Not before the previous episode's ring-down is over.
                let prev_gone = prev_end.map_or(0, |end| {
                    let end = end.saturating_sub(window.start).min(range.start);
                    clean[end..range.start]
                        .iter()
                        .position(|&e| e < floor)
                        .map_or(range.start, |i| end + i)
                });
                let from = range.start.saturating_sub(lookback).max(prev_gone);
                (from..range.end, from..range.start)
            } else {
                let to = (range.end + lookback).min(t.len());
                (range.start..to, range.end..to)
            };
            // A growth must also be there in the causally filtered signal:
            // the zero-phase band answers a push on the bar before the push
            // itself, with an oscillation growing towards it that is no
            // wobble. A real growth is as large in either filter (the same
            // magnitude response); the push's answer before the push is
            // only in the zero-phase one. Compared over
            // [`CAUSAL_WINDOW_S`] ending [`CAUSAL_TRIM_S`] before the top
            // of the climb (a short push may fill the last moments), and
            // over the part of the climb before [`SLOW_PUSH_S`] from its top
            // (a slow push fills more than the trim).
            let causal_ok = !growing || {
                let rms = |x: &[f64]| {
                    let n = x.len().max(1) as f64;
                    (x.iter().map(|v| v * v).sum::<f64>() / n).sqrt()
                };
                let shows = |w: Range<usize>| {
                    w.end > w.start && rms(&causal[w.clone()]) >= CAUSAL_SHARE * rms(&band[w])
                };
                let width = self.samples(CAUSAL_WINDOW_S);
                let end = fitted.end.saturating_sub(self.samples(CAUSAL_TRIM_S));
                let late = end.saturating_sub(width).max(fitted.start)..end;
                let before_push = fitted.end.saturating_sub(self.samples(SLOW_PUSH_S));
                let early = before_push.saturating_sub(width).max(range.start)..before_push;
                shows(late) && (early.len() < 2 || shows(early))
            };
            if !causal_ok {
                return None;
            }
            let tone = strongest_tone(&t[alone.clone()], &band[alone], f1_hz, self.fs_hz);
            let mode = fit_mode(
                &t[fitted.clone()],
                &band[fitted.clone()],
                slope,
                TAU * f1_hz,
                tone,
            )?;
            let ok = (mode.sigma_per_s > 0.0) == growing && mode.residual_rel <= MAX_RESIDUAL_REL;
            ok.then_some((fitted, mode))
        };
        // Quiet before it within the stretch, or it reaches the cut.
        let starts_at_cut = region.start == 0;
        let (stability, rate) =
            match growth_range(&clean, local.clone(), floor, ceiling).and_then(|r| fit(r, true)) {
                Some((r, mode)) => (Stability::Unstable, Rate::Fit(r, mode)),
                None if starts_at_cut => return None,
                None => {
                    let fall = decay_range(&clean, band, local.clone(), floor)?;
                    // A ring the kick search measured is not fitted again:
                    // the episode takes the kick's values in the end
                    // (`super::kick_episodes`), and its own fits (up to
                    // eleven starts, each with its tone search) were most
                    // of the time a kick campaign's analysis took.
                    let rate = match self.kick_struck(self.t_s[region.start], t[fall.start]) {
                        Some(kick) => Rate::Kick(kick),
                        None => {
                            // A push before the ring-down leaves the fall
                            // from the largest swing unexplained: the fit
                            // starts later, past the push, until it
                            // explains the ring.
                            let step = self.samples(PUSH_STEP_S).max(1);
                            let (r, mode) = (0..=self.samples(PUSH_MAX_S) / step)
                                .map(|k| fall.start + k * step..fall.end)
                                .take_while(|r| r.end > r.start + 2)
                                .find_map(|r| fit(r, false))?;
                            Rate::Fit(r, mode)
                        }
                    };
                    (Stability::Stable, rate)
                }
            };
        let onset_s = match (&rate, stability) {
            (Rate::Fit(range, mode), Stability::Unstable) => {
                let level = mode.log_amp - self.level_bias(t, top, mode, range.clone());
                mode.t0_s + (ONSET_AMP_DEG.ln() - level) / mode.sigma_per_s
            }
            _ => self.t_s[region.start],
        };
        let (freq_hz, sigma_per_s, sigma_sd_per_s, source, fit_s) = match rate {
            Rate::Fit(range, mode) => (
                mode.omega_rad_s / TAU,
                mode.sigma_per_s,
                None,
                Measured::Episode,
                [t[range.start], t[range.end - 1]],
            ),
            Rate::Kick(kick) => (
                kick.freq_hz,
                kick.sigma_per_s,
                Some(kick.sigma_sd_per_s),
                Measured::Kick(Source::Host),
                kick.fit_s,
            ),
        };
        if !(WOBBLE_BAND_HZ.0..=WOBBLE_BAND_HZ.1).contains(&freq_hz) {
            return None;
        }
        // An onset before the stretch began would be extrapolated across
        // the cut: the first frame after it is all the data say.
        let start = if starts_at_cut {
            Some(self.place.window_start.unwrap_or(Edge::Overlong))
        } else {
            (onset_s < self.place.first_s).then_some(self.place.stretch_start)
        };
        let onset_s = onset_s.max(self.place.first_s);
        let end = region.end.min(self.t_s.len() - 1);
        let episode = Episode {
            mode: KickMode::Wobble,
            onset_s,
            end_s: self.t_s[end],
            peak_s: t[top],
            freq_hz,
            sigma_per_s,
            sigma_sd_per_s,
            source,
            peak_amp_deg,
            speed_at_onset_mps: speed_around(&self.frames, onset_s, SPEED_HALF_WIDTH_S),
            stability,
            fit_s,
            censored: false,
            cut_at_start: None,
            cut_at_end: None,
        };
        Some(Found {
            episode,
            start,
            end: end_cut,
        })
    }

    /// The last of the host's kicks that rose from [`MATCH_S`] before
    /// `onset_s` (where a stable episode was struck) to [`MATCH_S`] after
    /// `swing_s` (its largest swing): the kick the episode is
    /// (`super::kick_episodes::kick_of` pairs them the same way).
    fn kick_struck(&self, onset_s: f64, swing_s: f64) -> Option<&'a Kick> {
        let last = self.kicks.partition_point(|k| k.t_s <= swing_s + MATCH_S);
        self.kicks[..last]
            .last()
            .filter(|k| k.t_s >= onset_s - MATCH_S)
    }

    /// Where the episodes either side of `region` end and start: the end
    /// of the one before (if any) and the first frame of the one after (the
    /// end of the frames if none).
    fn neighbours(&self, region: Range<usize>) -> (Option<usize>, usize) {
        let before = self.energy[..region.start]
            .iter()
            .rposition(|&e| e > DETECT_AMP_DEG)
            .map(|hit| self.region(hit).end);
        let after = self
            .next_hit(region.end, self.energy.len())
            .map_or(self.energy.len(), |hit| self.region(hit).start);
        (before, after)
    }

    /// How much the band-pass changes the fitted log amplitude of `mode`
    /// over `range`: a synthetic wobble with that mode, growing up to `top`
    /// and caught as fast, goes through the same filter and fit.
    fn level_bias(&self, t: &[f64], top: usize, mode: &SineFit, range: Range<usize>) -> f64 {
        let t_top = t[top];
        let t0 = mode.t0_s;
        let sigma = mode.sigma_per_s.abs();
        let log_env =
            |ts: f64| mode.log_amp + mode.sigma_per_s * (t_top - t0) - sigma * (ts - t_top).abs();
        let synthetic: Vec<f64> = t
            .iter()
            .map(|&ts| log_env(ts).exp() * (mode.omega_rad_s * (ts - t0)).sin())
            .collect();
        let filtered = wobble_band(&synthetic, self.fs_hz);
        fit_mode(
            &t[range.clone()],
            &filtered[range],
            mode.sigma_per_s,
            mode.omega_rad_s,
            None,
        )
        .map_or(0.0, |f| f.log_amp - mode.log_amp)
    }
}

fn is_quiet(e: &f64) -> bool {
    *e <= QUIET_AMP_DEG
}

/// Mean wheel speed of `frames` over `t_s ± half_width_s`, m/s (the
/// nearest frame's speed if none falls inside).
fn speed_around(frames: &Frames<'_>, t_s: f64, half_width_s: f64) -> f64 {
    let lo = frames.t_s.partition_point(|&t| t < t_s - half_width_s);
    let hi = frames.t_s.partition_point(|&t| t <= t_s + half_width_s);
    if hi > lo {
        return frames.speed_mps[lo..hi].iter().sum::<f64>() / (hi - lo) as f64;
    }
    let i = lo.min(frames.t_s.len().saturating_sub(1));
    frames.speed_mps.get(i).copied().unwrap_or(0.0)
}

/// Within `region`, the climb to the first time the envelope reaches
/// `ceiling`, from the last time before it was under `floor`.
fn growth_range(
    env: &[f64],
    region: Range<usize>,
    floor: f64,
    ceiling: f64,
) -> Option<Range<usize>> {
    let end = region.start + env[region.clone()].iter().position(|&e| e >= ceiling)?;
    let start = env[..end]
        .iter()
        .rposition(|&e| e < floor)
        .map_or(0, |i| i + 1);
    (end > start + 2).then_some(start..end)
}

/// Within `region`, the fall from the largest swing of the band-passed
/// signal (where the oscillation was struck) to the first time after it
/// that the envelope is under `floor`.
fn decay_range(
    env: &[f64],
    band: &[f64],
    region: Range<usize>,
    floor: f64,
) -> Option<Range<usize>> {
    let swings: Vec<f64> = band[region.clone()].iter().map(|v| v.abs()).collect();
    let start = region.start + argmax(&swings)?;
    let end = env[start..]
        .iter()
        .position(|&e| e < floor)
        .map_or(env.len(), |i| start + i);
    (end > start + 2).then_some(start..end)
}

/// Slope of the least-squares line through `(t, ln env)`, 1/s: the
/// starting guess of a mode fit. `None` without two distinct times or with
/// a non-positive envelope.
fn log_slope(t: &[f64], env: &[f64]) -> Option<f64> {
    let n = t.len() as f64;
    let ys: Vec<f64> = env.iter().map(|e| e.ln()).collect();
    if n < 2.0 || ys.iter().any(|y| !y.is_finite()) {
        return None;
    }
    let mean_t = t.iter().sum::<f64>() / n;
    let mean_y = ys.iter().sum::<f64>() / n;
    let (stt, sty) = t.iter().zip(&ys).fold((0.0, 0.0), |(stt, sty), (tv, y)| {
        let dt = tv - mean_t;
        (stt + dt * dt, sty + dt * (y - mean_y))
    });
    (stt > 0.0).then(|| sty / stt)
}

/// Envelope of `band` at `freq_hz`: mixed down to 0 Hz and low-passed
/// (zero phase), so only what lies within the low-pass of `freq_hz` counts.
fn demod_envelope(band: &[f64], t: &[f64], freq_hz: f64, fs_hz: f64) -> Vec<f64> {
    let Some(&t0) = t.first() else {
        return Vec::new();
    };
    let (mut i, mut q): (Vec<f64>, Vec<f64>) = band
        .iter()
        .zip(t)
        .map(|(x, ts)| {
            let (sin, cos) = (TAU * freq_hz * (ts - t0)).sin_cos();
            (2.0 * x * cos, 2.0 * x * sin)
        })
        .unzip();
    let lowpass = Biquad::butterworth(Pass::Low, DEMOD_LOWPASS_HZ, fs_hz);
    lowpass.filtfilt(&mut i);
    lowpass.filtfilt(&mut q);
    i.iter().zip(&q).map(|(a, b)| a.hypot(*b)).collect()
}

/// Frequency from the zero crossings of `x` (at least four), Hz.
fn crossing_freq_hz(t: &[f64], x: &[f64]) -> Option<f64> {
    let mut crossings = (1..x.len())
        .filter(|&i| (x[i - 1] < 0.0) != (x[i] < 0.0))
        .map(|i| t[i - 1] + (t[i] - t[i - 1]) * x[i - 1] / (x[i - 1] - x[i]));
    let first = crossings.next()?;
    let (count, last) = crossings.fold((1usize, first), |(n, _), c| (n + 1, c));
    (count >= 4 && last > first).then(|| (count - 1) as f64 / (2.0 * (last - first)))
}

/// The frequency of the strongest steady tone in `x` within
/// [`TONE_SEARCH_HZ`] of `near_hz`, rad/s (a periodogram peak in 0.02 Hz
/// steps); `None` on less than a second of samples.
fn strongest_tone(t: &[f64], x: &[f64], near_hz: f64, fs_hz: f64) -> Option<f64> {
    if (x.len() as f64) < fs_hz {
        return None;
    }
    let steps = (2.0 * TONE_SEARCH_HZ / 0.02).round() as usize;
    // The power does not depend on the time origin: the grid's own.
    let grid = Grid::of(t);
    (0..=steps)
        .map(|k| TAU * (near_hz - TONE_SEARCH_HZ + 0.02 * k as f64))
        .map(|omega| {
            let (mut re, mut im) = (0.0, 0.0);
            grid.for_each_sin_cos(t, omega, |i, s, c| {
                re += x[i] * c;
                im += x[i] * s;
            });
            (omega, re * re + im * im)
        })
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(omega, _)| omega)
}

fn argmax(x: &[f64]) -> Option<usize> {
    x.iter()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(b.1))
        .map(|(i, _)| i)
}

/// Median of `v` (0 if empty).
fn median(mut v: Vec<f64>) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    let mid = v.len() / 2;
    *v.select_nth_unstable_by(mid, f64::total_cmp).1
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(32))]

        /// Any steering signal, with gaps and repeated times, gives episodes
        /// (or none) without panicking, each ordered and finite.
        #[test]
        fn any_signal_is_analysed(
            steps in proptest::collection::vec((-300.0..300.0f64, 0u8..40), 0..3000),
            tone_deg in 0.0..5.0f64,
        ) {
            let mut run = Run::default();
            let mut t = 0.0;
            for (i, &(noise, step)) in steps.iter().enumerate() {
                // Mostly 10 ms, sometimes a gap or a repeat.
                t += match step { 0 => 0.0, 1 => 0.37, _ => 0.01 };
                let x = tone_deg * (TAU * 7.0 * t).sin() * (i as f64 / 300.0).sin()
                    + if step == 2 { noise } else { 0.0 };
                run.t_s.push(t);
                run.steer_deg.push(x);
                run.speed_mps.push(4.0);
                run.gyro_dps.push([0.0; 3]);
                run.accel_g.push([0.0; 3]);
            }
            for e in find_episodes(&run) {
                prop_assert!(e.onset_s <= e.peak_s && e.peak_s <= e.end_s, "{e:?}");
                prop_assert!(e.sigma_per_s.is_finite() && e.freq_hz > 0.0, "{e:?}");
            }
        }
    }

    #[test]
    fn crossings_give_the_tone_frequency() {
        let t: Vec<f64> = (0..200).map(|i| f64::from(i) / 100.0).collect();
        let x: Vec<f64> = t.iter().map(|t| (TAU * 6.37 * t + 0.3).sin()).collect();
        let f = crossing_freq_hz(&t, &x).unwrap();
        assert!((f - 6.37).abs() < 0.01, "{f}");
        assert_eq!(crossing_freq_hz(&t[..10], &x[..10]), None);
    }

    #[test]
    fn log_slope_of_an_exponential() {
        let t: Vec<f64> = (0..100).map(|i| 3.0 + f64::from(i) / 100.0).collect();
        let env: Vec<f64> = t.iter().map(|t| 0.1 * (1.7 * (t - 3.0)).exp()).collect();
        let slope = log_slope(&t, &env).unwrap();
        assert!((slope - 1.7).abs() < 1e-9);
        assert_eq!(log_slope(&t[..1], &env[..1]), None);
    }
}
