//! Handlebar kicks found in a run's steering angle, each ring-down fitted
//! for the wobble mode's eigenvalue at the speed of the kick: the data of
//! a kick-test campaign (`wobblog margin`).
//!
//! 1. The steering angle is band-passed around the wobble band (zero
//!    phase, as for episodes) and its envelope taken as a moving RMS over
//!    [`ENVELOPE_WINDOW_S`]. The background is the envelope's median over
//!    the stretch.
//! 2. A kick is a stretch where the envelope exceeds [`KICK_MIN_DEG`] and
//!    [`KICK_OVER_BACKGROUND`] times the background, reached within
//!    [`MAX_RISE_S`] of rising above it: a struck mode rises within a
//!    cycle or two, a wobble that grows by itself takes longer and is not a
//!    kick; and out of at least [`QUIET_BEFORE_S`] below it (a ring's
//!    tail crossing the threshold again is no new kick).
//! 3. The push (the hand's short, large transient, and the filter's
//!    answer to it) is skipped: the fit starts [`SKIP_AFTER_PEAK_S`] after
//!    the envelope's peak.
//! 4. The samples of the ring-down (not their envelope) are fitted with a
//!    decaying sinusoid plus, when one of the wheel's harmonics lies within
//!    [`TONE_SEARCH_HZ`] and the fit spans [`MIN_TONE_BEATS`] beats with
//!    it, a steady tone for it (see [`super::sinefit`]),
//!    until the envelope is back at [`FIT_END_OVER_BACKGROUND`] times the
//!    background or [`MAX_FIT_S`] has passed.
//! 5. sigma's uncertainty starts from the fit's standard error, corrected
//!    for what the residuals hold near the ring's frequency (the band-pass
//!    colours them): see [`super::sinefit::SineFit::sigma_se_per_s`]. That
//!    error still understates the kicks' actual errors by a factor of 2-3:
//!    the road keeps the mode ringing through the whole ring-down, and what
//!    it rings in at the mode's own frequency and decay the fit cannot tell
//!    from the kick's ring, so the residuals do not show it. The stated
//!    uncertainty is the fit's error calibrated against the truth of the
//!    simulated campaigns ([`stated_sd`]).
//!
//! Why this is not the board's measurement refined (the board's is
//! `wobble_core::detector::ringdown`, the same physics in `f32`): the two
//! share only the idea (skip the push, measure a decaying sinusoid in the
//! wobble band), not a step. The board must decide causally, in one pass,
//! in 300 bytes: it starts at the impulse detector's trigger (which is held
//! off for 1 s after every impulse and off during an alert and below
//! walking speed), skips a fixed 0.15 s, demodulates at a fixed frequency
//! and fits `ln |X|` of Hann segments it cannot revisit. The host has the
//! whole record: it finds kicks in a zero-phase band (no group delay, the
//! push's answer on both sides of it), starts the fit after the envelope's
//! peak (which the board cannot know when it starts), fits the samples
//! themselves with a wheel harmonic beside the ring, and corrects sigma's
//! error for the residuals' colour. Starting from the board's kicks would
//! lose the kicks it misses (a kick inside another's hold-off, a log
//! without kick records) and gain nothing the host's own start values
//! lack: the board's sigma is biased (-0.023 1/s) and its error a third
//! larger (`host-tools/docs/kick-testing.md`). The board's values are kept
//! beside the host's instead (`campaign_kicks`).

use std::f64::consts::TAU;

use serde::Serialize;

use super::filter::{band_pass, band_pass_causal, follows, WOBBLE_BAND_HZ};
use super::run::Run;
use super::sinefit::{fit_mode, fit_mode_on_trend};

/// The mode a kick is searched for and measured in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum KickMode {
    /// The 4-12 Hz steering oscillation, in the steering angle.
    #[default]
    Wobble,
    /// The 0.15-3 Hz roll and steer oscillation, in the roll rate
    /// ([`super::weave`]).
    Weave,
}

impl KickMode {
    /// The signal the mode's kicks are searched in, at frame `i` of `run`:
    /// the steering angle (degrees) for the wobble, the roll rate (deg/s,
    /// the gyroscope's forward axis) for the weave.
    #[must_use]
    pub fn signal(self, run: &Run, i: usize) -> f64 {
        match self {
            Self::Wobble => run.steer_deg[i],
            Self::Weave => run.gyro_dps[i][0],
        }
    }

    /// Lower case, as in the command line and the outputs.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::Wobble => "wobble",
            Self::Weave => "weave",
        }
    }
}

/// How kicks of one mode are found and fitted: the steps of the module
/// documentation, each with its number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Band {
    /// The zero-phase band-pass the signal goes through, Hz.
    pub pass_hz: (f64, f64),
    /// Moving-RMS window of the envelope, s.
    pub envelope_window_s: f64,
    /// Whether the envelope is taken of the signal band-passed causally
    /// (forwards only) rather than with zero phase: a slow band's
    /// zero-phase filter answers a kick seconds before it, so the kick
    /// would seem to rise slowly, and be placed early.
    pub causal_envelope: bool,
    /// Envelope a kick's ring must reach, in the signal's unit...
    pub kick_min: f64,
    /// ... and this many times the stretch's background.
    pub kick_over_background: f64,
    /// A kick rises out of at least this long below the threshold, s.
    pub quiet_before_s: f64,
    /// A kick's envelope reaches its peak within this of rising above the
    /// threshold, s.
    pub max_rise_s: f64,
    /// The fit starts this long after the envelope's peak, s.
    pub skip_after_peak_s: f64,
    /// The fit ends where the envelope is back at this many times the
    /// background...
    pub fit_end_over_background: f64,
    /// ... or at this share of its value where the fit starts (what is
    /// left of a ring that has decayed this far is mostly not the ring:
    /// a slow drift's share through the band-pass)...
    pub fit_end_of_start: f64,
    /// ... and lasts no longer than this, s.
    pub max_fit_s: f64,
    /// A fit spans at least this long, s.
    pub min_fit_s: f64,
    /// The first guess of the frequency counts zero crossings over this
    /// much of the fit's start, s.
    pub head_s: f64,
    /// Fits are trusted for frequencies in this band, Hz.
    pub freq_band_hz: (f64, f64),
    /// Whether a wheel harmonic near the ring is fitted as a tone.
    pub wheel_tones: bool,
    /// Whether a straight trend is fitted beside the ring instead (see
    /// [`super::sinefit::fit_mode_on_trend`]).
    pub fit_trend: bool,
    /// Whether the signal is a rate (deg/s): a kick's amplitude is then
    /// that of its integral (degrees), the rate's over the frequency.
    pub rate_signal: bool,
    /// Frames searched at once, at most ([`PIECE_FRAMES`] for the wobble).
    pub piece_frames: usize,
    /// The fit's standard error of sigma is scaled by this...
    pub se_factor: f64,
    /// ... and an error this large (1/s) is added in quadrature.
    pub sd_floor_per_s: f64,
}

/// The wobble's kicks, in the steering angle (degrees).
pub const WOBBLE: Band = Band {
    pass_hz: WOBBLE_BAND_HZ,
    envelope_window_s: ENVELOPE_WINDOW_S,
    causal_envelope: false,
    kick_min: KICK_MIN_DEG,
    kick_over_background: KICK_OVER_BACKGROUND,
    quiet_before_s: QUIET_BEFORE_S,
    max_rise_s: MAX_RISE_S,
    skip_after_peak_s: SKIP_AFTER_PEAK_S,
    fit_end_over_background: FIT_END_OVER_BACKGROUND,
    fit_end_of_start: 0.0,
    max_fit_s: MAX_FIT_S,
    min_fit_s: MIN_FIT_S,
    head_s: 1.0,
    freq_band_hz: WOBBLE_BAND_HZ,
    wheel_tones: true,
    fit_trend: false,
    rate_signal: false,
    piece_frames: PIECE_FRAMES,
    se_factor: SE_FACTOR,
    sd_floor_per_s: SD_FLOOR_PER_S,
};

impl Band {
    /// The band of `mode`.
    #[must_use]
    pub const fn of(mode: KickMode) -> Self {
        match mode {
            KickMode::Wobble => WOBBLE,
            KickMode::Weave => super::weave::WEAVE,
        }
    }

    /// The standard uncertainty of a kick's sigma from the fit's standard
    /// error `se`: `sqrt((se_factor se)^2 + sd_floor^2)`.
    #[must_use]
    pub fn stated_sd(&self, se: f64) -> f64 {
        (self.se_factor * se).hypot(self.sd_floor_per_s)
    }

    /// Consecutive pieces of a stretch share this much, s: more than a
    /// kick's rise, skip and longest fit, and the band-pass's settling at
    /// the piece's end; at least [`PIECE_OVERLAP_S`].
    #[must_use]
    pub fn piece_overlap_s(&self) -> f64 {
        (self.max_rise_s + self.skip_after_peak_s + self.max_fit_s + 1.0 / self.pass_hz.0)
            .max(PIECE_OVERLAP_S)
    }
}

/// Envelope a kick's ring must reach, degrees.
pub const KICK_MIN_DEG: f64 = 0.3;
/// ... and this many times the stretch's background.
const KICK_OVER_BACKGROUND: f64 = 4.0;
/// A kick rises out of at least this long below the threshold, s.
const QUIET_BEFORE_S: f64 = 0.5;
/// A kick's envelope reaches its peak within this of rising above the
/// threshold, s.
const MAX_RISE_S: f64 = 0.4;
/// Moving-RMS window of the envelope, s (about a cycle at 7 Hz).
const ENVELOPE_WINDOW_S: f64 = 0.15;
/// The fit starts this long after the envelope's peak, s: past a push of
/// up to 0.15 s and the band-pass's answer to its edges (the zero-phase
/// 4 Hz high-pass rings down at about 18/s on either side of an edge).
const SKIP_AFTER_PEAK_S: f64 = 0.3;
/// The background is this quantile of the stretch's envelope (the quiet
/// between kicks, not their long ring-downs).
const BACKGROUND_QUANTILE: f64 = 0.2;
/// The fit ends where the envelope is back at this many times the
/// background...
const FIT_END_OVER_BACKGROUND: f64 = 2.0;
/// ... and lasts no longer than this, s.
const MAX_FIT_S: f64 = 5.0;
/// A wheel harmonic is fitted as a tone only if the fit spans this many
/// beats between it and the ring (fewer cannot tell them apart).
const MIN_TONE_BEATS: f64 = 1.5;
/// A fit spans at least this long, s (three cycles at 6 Hz).
const MIN_FIT_S: f64 = 0.5;
/// Stretches shorter than this (between gaps) are not searched, s.
const MIN_STRETCH_S: f64 = 2.0;
/// Largest unexplained share (RMS) of the samples for a fit to count.
const MAX_RESIDUAL_REL: f64 = 0.6;
/// A wheel harmonic within this of the ring's frequency is fitted beside
/// it, Hz.
const TONE_SEARCH_HZ: f64 = 1.0;

/// The fit's standard error of sigma is scaled by this...
pub const SE_FACTOR: f64 = 1.6;
/// ... and an error this large (1/s) that no single fit can see is added
/// to it in quadrature.
pub const SD_FLOOR_PER_S: f64 = 0.0275;

/// The standard uncertainty of a kick's sigma from the fit's standard
/// error `se`: `sqrt((SE_FACTOR se)^2 + SD_FLOOR_PER_S^2)`. Calibrated on
/// the simulated campaigns of seeds 100-111 (864 kicks on four bicycles:
/// the median |error| / SD is 0.674, the normal distribution's, in each
/// fifth of the kicks sorted by `se`), and checked on seeds 200-249 (3600
/// kicks): 67.7 % of the errors within one stated SD and 92.0 % within two
/// (68.3 % and 95.4 % for a normal distribution); with the fit's error
/// alone, 57 % within two (`host-tools/docs/kick-testing.md`).
#[must_use]
pub fn stated_sd(se: f64) -> f64 {
    WOBBLE.stated_sd(se)
}

/// One kick's ring-down.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Kick {
    /// When the ring rose above the threshold, s since boot.
    pub t_s: f64,
    /// Mean wheel speed over the fit, m/s.
    pub speed_mps: f64,
    /// Frequency of the ring, Hz.
    pub freq_hz: f64,
    /// Growth rate of the ring (negative: it decays), 1/s.
    pub sigma_per_s: f64,
    /// Standard uncertainty of `sigma_per_s`, 1/s ([`stated_sd`] of the
    /// fit's standard error).
    pub sigma_sd_per_s: f64,
    /// The fit's own standard error of `sigma_per_s`, 1/s.
    pub sigma_se_fit_per_s: f64,
    /// Amplitude at the fit's start, degrees: the steering angle's (wobble),
    /// the roll angle's (weave: the roll rate's over the angular frequency).
    pub amp_deg: f64,
    /// The stretch fitted, s since boot.
    pub fit_s: [f64; 2],
    /// Unexplained share (RMS) of the fitted samples.
    pub residual_rel: f64,
}

/// Frames a stretch is searched in at most: a longer one (between gaps) is
/// searched in pieces of this many frames, each overlapping the one before
/// by [`PIECE_OVERLAP_S`], so that the search holds no more than this
/// however long the log (43.7 min at 100 Hz).
pub const PIECE_FRAMES: usize = super::search::MAX_WINDOW_FRAMES;
/// Consecutive pieces of a stretch share this much, s: more than a kick's
/// rise, skip and longest fit ([`MAX_RISE_S`] + [`SKIP_AFTER_PEAK_S`] +
/// [`MAX_FIT_S`]) and the band-pass's settling at the piece's end. A piece
/// gives the kicks rising before its shared end; the next one, those
/// rising after. Each piece has its own background.
pub const PIECE_OVERLAP_S: f64 = 10.0;

/// Every wobble kick of `run`, in time order: the frames go through a
/// [`KickSearch`], as when a command streams a log.
#[must_use]
pub fn find_kicks(run: &Run, wheel_circumference_m: f64) -> Vec<Kick> {
    find_mode_kicks(run, wheel_circumference_m, KickMode::Wobble)
}

/// Every kick of `mode` in `run`, in time order.
#[must_use]
pub fn find_mode_kicks(run: &Run, wheel_circumference_m: f64, mode: KickMode) -> Vec<Kick> {
    let mut search = KickSearch::for_mode(mode, run.sample_rate_hz(), wheel_circumference_m);
    for i in 0..run.len() {
        search.push(run.t_s[i], mode.signal(run, i), run.speed_mps[i]);
    }
    search.finish()
}

/// The kicks of a stream of frames, in memory that does not grow with the
/// run: each evenly sampled stretch between gaps is searched alone (no fit
/// reaches across a gap), in pieces of at most [`PIECE_FRAMES`].
pub struct KickSearch {
    band: Band,
    fs: f64,
    circumference_m: f64,
    piece: usize,
    overlap: usize,
    t_s: Vec<f64>,
    signal: Vec<f64>,
    speed_mps: Vec<f64>,
    kicks: Vec<Kick>,
    /// Every kick rising before this is in `kicks`, s.
    settled_s: f64,
    /// Most frames held at once.
    most_held: usize,
}

impl KickSearch {
    /// A search for wobble kicks over frames nominally `fs_hz` apart, on
    /// a wheel of `wheel_circumference_m` (its harmonics are fitted beside
    /// a ring).
    #[must_use]
    pub fn new(fs_hz: f64, wheel_circumference_m: f64) -> Self {
        Self::for_mode(KickMode::Wobble, fs_hz, wheel_circumference_m)
    }

    /// A search for kicks of `mode`: [`Self::push`] takes the mode's
    /// [`KickMode::signal`].
    #[must_use]
    pub fn for_mode(mode: KickMode, fs_hz: f64, wheel_circumference_m: f64) -> Self {
        let band = Band::of(mode);
        Self::with_piece(band, fs_hz, wheel_circumference_m, band.piece_frames)
    }

    /// A search of `band` in pieces of `piece` frames (at least twice the
    /// overlap; tests use short pieces).
    #[must_use]
    pub fn with_piece(band: Band, fs_hz: f64, wheel_circumference_m: f64, piece: usize) -> Self {
        let overlap = if fs_hz.is_finite() && fs_hz > 0.0 {
            (band.piece_overlap_s() * fs_hz).ceil() as usize
        } else {
            0
        };
        Self {
            band,
            fs: fs_hz,
            circumference_m: wheel_circumference_m,
            piece: piece.max(2 * overlap).max(1),
            overlap,
            t_s: Vec::new(),
            signal: Vec::new(),
            speed_mps: Vec::new(),
            kicks: Vec::new(),
            settled_s: f64::NEG_INFINITY,
            most_held: 0,
        }
    }

    /// Takes the next frame in file order: time, the mode's signal
    /// (steering angle, degrees, for the wobble), speed.
    pub fn push(&mut self, t_s: f64, signal: f64, speed_mps: f64) {
        if !(self.fs.is_finite() && self.fs > 0.0) {
            return;
        }
        if let Some(&last) = self.t_s.last() {
            if !follows(last, t_s, 1.0 / self.fs) {
                self.search(None);
                self.clear(self.t_s.len());
                self.settled_s = t_s;
            }
        }
        self.t_s.push(t_s);
        self.signal.push(signal);
        self.speed_mps.push(speed_mps);
        self.most_held = self.most_held.max(self.t_s.len());
        if self.t_s.len() >= self.piece {
            let shared = self.t_s.len() - self.overlap;
            self.search(Some(shared));
            self.settled_s = self.t_s[shared];
            self.clear(shared);
        }
    }

    /// Most frames held at once so far: at most a piece, whatever the
    /// run's length.
    #[must_use]
    pub fn most_held(&self) -> usize {
        self.most_held
    }

    /// The kicks found so far, in time order: every kick rising before
    /// [`Self::settled_s`], none after it.
    #[must_use]
    pub fn found(&self) -> &[Kick] {
        &self.kicks
    }

    /// Every kick rising before this time (s since boot) is
    /// [`Self::found`]: those of the stretches before the last gap, and
    /// those of the pieces searched.
    #[must_use]
    pub fn settled_s(&self) -> f64 {
        self.settled_s
    }

    /// Every kick, in time order.
    #[must_use]
    pub fn finish(mut self) -> Vec<Kick> {
        self.search(None);
        self.kicks
    }

    /// Searches the frames held, keeping the kicks that rise before frame
    /// `until` (all of them without it).
    fn search(&mut self, until: Option<usize>) {
        let stretch = Stretch {
            band: &self.band,
            t_s: &self.t_s,
            signal: &self.signal,
            speed_mps: &self.speed_mps,
            fs: self.fs,
        };
        let until_s = until.map_or(f64::INFINITY, |i| self.t_s[i]);
        self.kicks.extend(
            stretch
                .kicks(self.circumference_m)
                .into_iter()
                .filter(|k| k.t_s < until_s),
        );
    }

    /// Forgets the first `n` frames held.
    fn clear(&mut self, n: usize) {
        self.t_s.drain(..n);
        self.signal.drain(..n);
        self.speed_mps.drain(..n);
    }
}

/// One evenly sampled stretch.
struct Stretch<'a> {
    band: &'a Band,
    t_s: &'a [f64],
    signal: &'a [f64],
    speed_mps: &'a [f64],
    fs: f64,
}

/// Moving RMS over `window` samples (centred), times sqrt 2: the amplitude
/// of a sinusoid.
fn envelope(x: &[f64], window: usize) -> Vec<f64> {
    let half = window / 2;
    let mut prefix = Vec::with_capacity(x.len() + 1);
    prefix.push(0.0);
    for v in x {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + v * v);
    }
    (0..x.len())
        .map(|i| {
            let (lo, hi) = (i.saturating_sub(half), (i + half + 1).min(x.len()));
            (2.0 * (prefix[hi] - prefix[lo]).max(0.0) / (hi - lo) as f64).sqrt()
        })
        .collect()
}

/// The `q` quantile of `v` (the element at `q` of the way through it in
/// order), by selection rather than a sort: the search takes one of each
/// piece of up to [`PIECE_FRAMES`] frames, where sorting was a fifth of
/// the time an analysis of a kick campaign took.
fn quantile(mut v: Vec<f64>, q: f64) -> f64 {
    let i = ((v.len() as f64 - 1.0) * q).round() as usize;
    if i >= v.len() {
        return 0.0;
    }
    *v.select_nth_unstable_by(i, f64::total_cmp).1
}

impl Stretch<'_> {
    fn samples(&self, s: f64) -> usize {
        (s * self.fs).round() as usize
    }

    fn kicks(&self, circumference_m: f64) -> Vec<Kick> {
        let n = self.t_s.len();
        let b = self.band;
        if n < self.samples(MIN_STRETCH_S.max(2.0 * b.min_fit_s)) {
            return Vec::new();
        }
        let band = band_pass(self.signal, b.pass_hz, self.fs);
        let window = self.samples(b.envelope_window_s).max(3);
        let env = if b.causal_envelope {
            envelope(&band_pass_causal(self.signal, b.pass_hz, self.fs), window)
        } else {
            envelope(&band, window)
        };
        let background = quantile(env.clone(), BACKGROUND_QUANTILE);
        let threshold = b.kick_min.max(b.kick_over_background * background);
        let mut kicks = Vec::new();
        let mut i = 0;
        let mut last_end: Option<usize> = None;
        while i < n {
            if env[i] <= threshold {
                i += 1;
                continue;
            }
            // A stretch above the threshold: where it rose, its peak, its end.
            let rise = i;
            let end = (rise..n).find(|&k| env[k] <= threshold).unwrap_or(n);
            let peak = (rise..end)
                .max_by(|&a, &b| env[a].total_cmp(&env[b]))
                .unwrap_or(rise);
            i = end;
            let quiet_before = last_end.is_none_or(|e| rise >= e + self.samples(b.quiet_before_s));
            last_end = Some(end);
            if peak - rise > self.samples(b.max_rise_s) || rise == 0 || !quiet_before {
                // Grew by itself, was already ringing at the start, or is
                // the tail of the last ring rising out of the noise again.
                continue;
            }
            let next_rise = (end..n).find(|&k| env[k] > threshold).unwrap_or(n);
            if let Some(kick) = self.fit(
                &band,
                &env,
                background,
                (rise, peak, next_rise),
                circumference_m,
            ) {
                kicks.push(kick);
            }
        }
        kicks
    }

    /// Fits the ring-down of the kick that rose at `rise`, peaked at `peak`;
    /// the next kick rises at `next`.
    fn fit(
        &self,
        band: &[f64],
        env: &[f64],
        background: f64,
        (rise, peak, next): (usize, usize, usize),
        circumference_m: f64,
    ) -> Option<Kick> {
        let b = self.band;
        let start = peak + self.samples(b.skip_after_peak_s);
        let floor = (b.fit_end_over_background * background)
            .max(b.fit_end_of_start * env.get(start).copied().unwrap_or(0.0));
        let last = (start + self.samples(b.max_fit_s)).min(next.saturating_sub(1));
        let stop = (start..last).find(|&k| env[k] <= floor).unwrap_or(last);
        if stop < start + self.samples(b.min_fit_s) {
            return None;
        }
        let t = &self.t_s[start..stop];
        let x = &band[start..stop];
        let duration = t[t.len() - 1] - t[0];
        let sigma0 = ((env[stop].max(1e-3) / env[start].max(1e-3)).ln() / duration).min(-0.05);
        // Zero crossings of the fit's start, where the ring stands well
        // above the noise.
        let head = &x[..x.len().min(self.samples(b.head_s))];
        let crossings = head
            .windows(2)
            .filter(|w| (w[0] < 0.0) != (w[1] < 0.0))
            .count();
        let freq0 = crossings as f64 * self.fs / (2.0 * head.len() as f64);
        if !(b.freq_band_hz.0..b.freq_band_hz.1).contains(&freq0) {
            return None;
        }
        let speed = self.speed_mps[start..stop].iter().sum::<f64>() / t.len() as f64;
        let wheel_hz = speed / circumference_m;
        let tone = (1..=8)
            .map(|h| f64::from(h) * wheel_hz)
            .filter(|f| {
                let beat = (f - freq0).abs();
                beat < TONE_SEARCH_HZ && beat * duration >= MIN_TONE_BEATS
            })
            .min_by(|a, b| (a - freq0).abs().total_cmp(&(b - freq0).abs()))
            .filter(|_| b.wheel_tones && wheel_hz > 0.0);
        let fit = if b.fit_trend {
            fit_mode_on_trend(t, x, sigma0, TAU * freq0)?
        } else {
            fit_mode(t, x, sigma0, TAU * freq0, tone.map(|f| TAU * f))?
        };
        let freq = fit.omega_rad_s / TAU;
        let plausible = fit.residual_rel <= MAX_RESIDUAL_REL
            && (b.freq_band_hz.0..b.freq_band_hz.1).contains(&freq)
            && fit.sigma_se_per_s.is_finite();
        plausible.then(|| Kick {
            t_s: self.t_s[rise],
            speed_mps: speed,
            freq_hz: freq,
            sigma_per_s: fit.sigma_per_s,
            sigma_sd_per_s: b.stated_sd(fit.sigma_se_per_s),
            sigma_se_fit_per_s: fit.sigma_se_per_s,
            amp_deg: if b.rate_signal {
                fit.log_amp.exp() / fit.omega_rad_s
            } else {
                fit.log_amp.exp()
            },
            fit_s: [t[0], t[t.len() - 1]],
            residual_rel: fit.residual_rel,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Frames at a rate that is not a positive finite number are not
    /// searched (and not held): a run without a usable rate has no kicks.
    #[test]
    fn no_rate_no_search() {
        for fs in [0.0, -100.0, f64::NAN, f64::INFINITY] {
            let mut search = KickSearch::new(fs, 2.18);
            for i in 0..500 {
                let t = f64::from(i) / 100.0;
                search.push(t, 2.0 * (TAU * 7.0 * t).sin() * (-t).exp(), 3.0);
            }
            assert_eq!(search.most_held(), 0, "{fs}");
            assert!(search.finish().is_empty(), "{fs}");
        }
    }

    /// The quantile is the element at its place in sorted order, worked
    /// out here by sorting; nothing for no values.
    #[test]
    fn quantile_is_the_sorted_element() {
        let v: Vec<f64> = (0..1001).map(|i| f64::from((i * 7919) % 1001)).collect();
        let mut sorted = v.clone();
        sorted.sort_by(f64::total_cmp);
        for q in [0.0_f64, 0.2, 0.5, 0.999, 1.0] {
            let i = (1000.0 * q).round() as usize;
            assert_eq!(quantile(v.clone(), q), sorted[i], "{q}");
        }
        assert_eq!(quantile(vec![3.0, 1.0, 2.0], 0.2), 1.0);
        assert_eq!(quantile(Vec::new(), 0.2), 0.0);
    }
}
