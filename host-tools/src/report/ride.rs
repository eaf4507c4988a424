//! One run as the ride view shows it: the analyses every command makes of
//! it (the summary `info` gives, the episodes `wobble` measures, the roll
//! estimate `plot` draws, the events `events` lists), and its signals
//! thinned for display.

use std::path::Path;

use serde::Serialize;

use super::series::{Series, SeriesBuilder, Values, CHANNELS};
use super::spectrogram::{steer_spectrogram, Spectrogram};
use super::track::{track_svg, Fix};
use crate::analysis::run::stream_rows;
use crate::analysis::{estimate_roll_deg, Episode, Ride, Run, Stability};
use crate::cmd::detect::log_config;
use crate::cmd::summary::RunRow;
use crate::rows::Row;
use crate::summary::Summary;
use crate::CliError;

/// Events listed per run, at most: a log damaged all through has
/// thousands, and `wobblog events` lists them all.
pub const MAX_EVENTS: usize = 2000;
/// Seconds kept at full rate around each episode, alert and marker.
const DETAIL_PAD_S: f64 = 2.0;

/// One listed event: a wobble episode or an event of the log.
#[derive(Clone, Debug, Serialize)]
pub struct EventLine {
    /// Time since boot, s.
    pub t_s: f64,
    /// End, for what lasts (episodes, alerts, lost stretches), s.
    pub end_s: Option<f64>,
    /// UTC, as `events` gives it.
    pub utc: Option<String>,
    /// The kind, as `events` names it (`episode` for a wobble episode).
    pub kind: String,
    /// The details in words.
    pub text: String,
}

/// What the ride view shows of one run.
#[derive(Debug, Serialize)]
pub struct RideView {
    /// The log's name.
    pub name: String,
    /// The log as given, as `margin` names its kicks' logs.
    pub path: String,
    /// The row `wobblog summary` gives it.
    pub row: RunRow,
    /// Lowest wheel speed, m/s.
    pub min_speed_mps: f64,
    /// What `wobblog info --json` says.
    pub summary: Summary,
    /// The episodes `wobblog wobble` measures.
    pub episodes: Vec<Episode>,
    /// Episodes and log events in time order (at most [`MAX_EVENTS`] of
    /// the log's).
    pub events: Vec<EventLine>,
    /// The log's events, all of them.
    pub events_total: usize,
    /// Signals for display.
    pub series: Series,
    /// Names of the series' columns.
    pub channels: [&'static str; CHANNELS.len()],
    /// The steering spectrogram.
    pub spectrogram: Option<Spectrogram>,
    /// The wheel's circumference from the log's configuration, m.
    pub wheel_m: Option<f64>,
    /// The detector's band from the log's configuration, Hz.
    pub band_hz: Option<(f64, f64)>,
    /// The GPS track drawn.
    #[serde(skip)]
    pub track_svg: Option<String>,
    /// The damage in words, as `info` and `margin` warn.
    pub damage: Vec<String>,
}

/// The frames of a run with its GPS fixes.
#[derive(Default)]
struct Frames {
    run: Run,
    fixes: Vec<Fix>,
}

impl RideView {
    /// Reads and analyses the log at `path`.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let (summary, frames) = stream_rows(path, |_| Frames::default(), collect)?;
        let Frames { mut run, fixes } = frames;
        run.path = path.to_path_buf();
        run.summary = summary;
        let ride = Ride::of(&run);
        let roll = estimate_roll_deg(&run);
        let config = log_config(&run.summary.config, &[]).ok();
        let events = events_of(path, &ride)?;
        let fs_hz = run.sample_rate_hz();
        let series = display_series(&run, &roll, &ride);
        let (t_ordered, steer_ordered) = ordered(&run);
        let onsets: Vec<f64> = ride
            .episodes
            .iter()
            .filter(|e| e.stability == Stability::Unstable)
            .map(|e| e.onset_s)
            .collect();
        Ok(Self {
            name: ride.name(),
            path: path.display().to_string(),
            row: RunRow::of(&ride),
            min_speed_mps: run.speed_mps.iter().copied().fold(f64::INFINITY, f64::min),
            spectrogram: steer_spectrogram(&t_ordered, &steer_ordered, fs_hz),
            wheel_m: config.as_ref().map(|c| f64::from(c.wheel.circumference_m)),
            band_hz: config.as_ref().map(|c| {
                (
                    f64::from(c.detector.band_lo_hz),
                    f64::from(c.detector.band_hi_hz),
                )
            }),
            track_svg: track_svg(&fixes, &onsets),
            damage: ride.summary.losses.describe(),
            events: events.0,
            events_total: events.1,
            series,
            channels: CHANNELS,
            episodes: ride.episodes,
            summary: ride.summary,
        })
    }
}

fn collect(frames: &mut Frames, row: &Row) {
    frames.run.push(row);
    if let Some(g) = &row.gps {
        let fix = (row.t_s, g.lat_deg, g.lon_deg);
        // Rows hold a fix until the next one: one point per fix.
        if frames
            .fixes
            .last()
            .is_none_or(|l| (l.1, l.2) != (fix.1, fix.2))
        {
            frames.fixes.push(fix);
        }
    }
}

/// The frames whose time is after every earlier frame's: what the
/// display and the spectrogram can place on a time axis.
fn ordered(run: &Run) -> (Vec<f64>, Vec<f64>) {
    let mut last = f64::NEG_INFINITY;
    run.t_s
        .iter()
        .zip(&run.steer_deg)
        .filter(|(&t, _)| {
            let later = t > last;
            last = last.max(t);
            later
        })
        .map(|(&t, &s)| (t, s))
        .unzip()
}

/// The signals thinned for display, every frame kept around the episodes,
/// alerts and markers.
fn display_series(run: &Run, roll_deg: &[f64], ride: &Ride) -> Series {
    let s = &ride.summary;
    let mut detail: Vec<(f64, f64)> = ride
        .episodes
        .iter()
        .map(|e| (e.onset_s, e.end_s))
        .chain(s.alerts.iter().map(|a| (a.on_s, a.off_s.unwrap_or(a.on_s))))
        .chain(s.markers.iter().map(|&m| (m, m)))
        .collect();
    for d in &mut detail {
        *d = (d.0 - DETAIL_PAD_S, d.1 + DETAIL_PAD_S);
    }
    let span = s.frame_range_s.unwrap_or((0.0, 0.0));
    let mut builder = SeriesBuilder::new(run.len(), 1.0 / run.sample_rate_hz(), span, &detail);
    for i in 0..run.len() {
        let (g, a) = (run.gyro_dps[i], run.accel_g[i]);
        let values: Values = [
            run.steer_deg[i],
            roll_deg.get(i).copied().unwrap_or(f64::NAN),
            g[2],
            run.speed_mps[i],
            g[0],
            g[1],
            a[0],
            a[1],
            a[2],
        ];
        builder.push(run.t_s[i], &values);
    }
    builder.finish()
}

/// The episodes and the log's events (the first [`MAX_EVENTS`]) in time
/// order, and how many events the log has.
fn events_of(path: &Path, ride: &Ride) -> Result<(Vec<EventLine>, usize), CliError> {
    let pairs = &ride.summary.utc_syncs;
    let mut lines: Vec<EventLine> = ride
        .episodes
        .iter()
        .map(|e| EventLine {
            t_s: e.onset_s,
            end_s: Some(e.end_s),
            utc: crate::time::utc_text_at(pairs, e.onset_s),
            kind: "episode".into(),
            text: episode_text(e),
        })
        .collect();
    let mut total = 0usize;
    let walked = crate::cmd::events::walk(path, |e, utc| {
        total += 1;
        if total <= MAX_EVENTS {
            let end_s = match &e.kind {
                crate::events::EventKind::LostBlocks { to_s, .. } => Some(*to_s),
                _ => None,
            };
            lines.push(EventLine {
                t_s: e.t_s,
                end_s,
                utc,
                kind: e.kind.name().into(),
                text: e.kind.describe(),
            });
        }
        Ok::<(), std::convert::Infallible>(())
    })?;
    if let Err(never) = walked {
        match never {}
    }
    lines.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
    Ok((lines, total))
}

/// An episode in words, with the numbers `wobble` prints.
fn episode_text(e: &Episode) -> String {
    let stability = match e.stability {
        Stability::Stable => "stable",
        Stability::Unstable => "unstable",
    };
    let cut = e.cuts_text();
    format!(
        "{stability} {:.2} Hz, sigma {:+.2} 1/s, peak {:.2} deg, {:.2} m/s at onset ({}){}",
        e.freq_hz,
        e.sigma_per_s,
        e.peak_amp_deg,
        e.speed_at_onset_mps,
        e.source.as_str(),
        if cut.is_empty() {
            String::new()
        } else {
            format!(", {cut}")
        }
    )
}
