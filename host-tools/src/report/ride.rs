//! One run as the ride view shows it: the analyses every command makes of
//! it (the summary `info` gives, the episodes `wobble` measures, the roll
//! estimate `plot` draws, the events `events` lists), and its signals
//! thinned for display.

use std::convert::Infallible;
use std::path::Path;

use serde::Serialize;
use wobble_core::format::{Event, Record};

use super::series::{Series, SeriesBuilder, Values, CHANNELS};
use super::spectrogram::{Spectrogram, SpectrogramBuilder};
use super::track::TrackBuilder;
use crate::analysis::campaign_kicks::{ride_campaign_kicks, CampaignKick, Prefer, SpeedsAfter};
use crate::analysis::roll::RollStream;
use crate::analysis::run::read_rows;
use crate::analysis::{Episode, Ride, Run, Stability};
use crate::cmd::detect::log_config;
use crate::cmd::summary::RunRow;
use crate::events::{EventConverter, EventKind, LogEvent, TimeOrder};
use crate::rows::Row;
use crate::summary::Summary;
use crate::time::SyncPair;
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
    /// The run's kicks as `margin` takes them (`Prefer::Best`), until the
    /// campaign takes them over ([`super::Campaign::load`]).
    #[serde(skip)]
    pub kicks: Vec<CampaignKick>,
}

impl RideView {
    /// Reads and analyses the log at `path` in two passes over it, neither
    /// holding the run: the first finds the episodes (the `Ride` analysis
    /// every command makes), the second draws the frames around them
    /// ([`Drawing`]), lists the log's events and gives the speeds after
    /// the card's kick records that have none, so the kicks `margin` takes
    /// need no pass of their own.
    ///
    /// # Errors
    /// The log cannot be read or has no frames, or its config is refused.
    pub fn load(path: &Path) -> Result<Self, CliError> {
        let ride = Ride::load(path)?;
        let mut drawing = Drawing::new(&ride);
        let mut listing = EventListing::new(&ride.summary.utc_syncs);
        let mut speeds = SpeedsAfter::for_records(&ride.summary.kick_records);
        let need_speeds = !speeds.is_empty();
        read_rows(
            path,
            |event| listing.observe(event),
            |row| {
                drawing.push(row);
                if need_speeds {
                    speeds.push(row.t_s, row.speed_mps);
                }
            },
        )?;
        let kicks = ride_campaign_kicks(&ride, Prefer::Best, &speeds)?;
        let drawn = drawing.finish();
        let events = listing.finish(&ride);
        let config = log_config(&ride.summary.config, &[]).ok();
        Ok(Self {
            name: ride.name(),
            path: path.display().to_string(),
            row: RunRow::of(&ride),
            min_speed_mps: drawn.min_speed_mps,
            spectrogram: drawn.spectrogram,
            wheel_m: config.as_ref().map(|c| f64::from(c.wheel.circumference_m)),
            band_hz: config.as_ref().map(|c| {
                (
                    f64::from(c.detector.band_lo_hz),
                    f64::from(c.detector.band_hi_hz),
                )
            }),
            track_svg: drawn.track_svg,
            damage: ride.summary.losses.describe(),
            events: events.0,
            events_total: events.1,
            series: drawn.series,
            channels: CHANNELS,
            episodes: ride.episodes,
            summary: ride.summary,
            kicks,
        })
    }
}

/// What the ride view draws of a run's frames, built as they go by (in
/// file order) in memory that does not grow with the run: the signals
/// thinned for display, every frame kept around the episodes, alerts and
/// markers ([`SeriesBuilder`]), the roll estimate `plot` draws
/// ([`RollStream`]), the steering spectrogram ([`SpectrogramBuilder`]) and
/// the GPS track ([`TrackBuilder`]).
pub struct Drawing {
    roll: RollStream,
    series: SeriesBuilder,
    spectrogram: Option<SpectrogramBuilder>,
    track: TrackBuilder,
    /// Position of the last fix drawn.
    last_fix: Option<(f64, f64)>,
    min_speed_mps: f64,
}

/// What [`Drawing`] made.
pub struct Drawn {
    /// The signals for display.
    pub series: Series,
    /// The steering spectrogram.
    pub spectrogram: Option<Spectrogram>,
    /// The GPS track, SVG.
    pub track_svg: Option<String>,
    /// Lowest wheel speed, m/s.
    pub min_speed_mps: f64,
}

impl Drawing {
    /// The drawing of the run `ride` analysed (its episodes, alerts and
    /// markers, frame count, span and rate).
    #[must_use]
    pub fn new(ride: &Ride) -> Self {
        let s = &ride.summary;
        let fs_hz = s.frame_rate_hz();
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
        let frames = usize::try_from(s.samples).unwrap_or(usize::MAX);
        let onsets: Vec<f64> = ride
            .episodes
            .iter()
            .filter(|e| e.stability == Stability::Unstable)
            .map(|e| e.onset_s)
            .collect();
        Self {
            roll: RollStream::new(fs_hz),
            series: SeriesBuilder::new(frames, 1.0 / fs_hz, span, &detail),
            spectrogram: SpectrogramBuilder::new(fs_hz, span.1),
            track: TrackBuilder::new(&onsets),
            last_fix: None,
            min_speed_mps: f64::INFINITY,
        }
    }

    /// Takes the next frame, in file order.
    pub fn push(&mut self, row: &Row) {
        self.min_speed_mps = self.min_speed_mps.min(row.speed_mps);
        if let Some(s) = &mut self.spectrogram {
            s.push(row.t_s, row.steer_deg);
        }
        if let Some(g) = &row.gps {
            // Rows hold a fix until the next one: one point per fix.
            let at = (g.lat_deg, g.lon_deg);
            if self.last_fix != Some(at) {
                self.last_fix = Some(at);
                self.track.push((row.t_s, at.0, at.1));
            }
        }
        let series = &mut self.series;
        self.roll
            .push_row(row, &mut |f, j, roll| draw(series, f, j, roll));
    }

    /// The drawings.
    #[must_use]
    pub fn finish(mut self) -> Drawn {
        let series = &mut self.series;
        self.roll.finish(&mut |f, j, roll| draw(series, f, j, roll));
        Drawn {
            series: self.series.finish(),
            spectrogram: self.spectrogram.and_then(SpectrogramBuilder::finish),
            track_svg: self.track.finish(),
            min_speed_mps: self.min_speed_mps,
        }
    }
}

/// Adds frame `j` of `frames`, whose roll estimate is `roll_deg`, to the
/// display columns.
fn draw(series: &mut SeriesBuilder, frames: &Run, j: usize, roll_deg: f64) {
    let (g, a) = (frames.gyro_dps[j], frames.accel_g[j]);
    let values: Values = [
        frames.steer_deg[j],
        roll_deg,
        g[2],
        frames.speed_mps[j],
        g[0],
        g[1],
        a[0],
        a[1],
        a[2],
    ];
    series.push(frames.t_s[j], &values);
}

/// The log's events as `wobblog events` lists them (the first
/// [`MAX_EVENTS`]), gathered from the decoder's events as they go by: the
/// same conversion, time order and UTC text as `events`, which places each
/// event with the sync pairs read before it is handed on.
struct EventListing<'a> {
    /// The log's sync pairs, in file order.
    syncs: &'a [SyncPair],
    /// How many of `syncs` have been read.
    read: usize,
    converter: EventConverter,
    order: TimeOrder,
    lines: Vec<EventLine>,
    total: usize,
}

impl<'a> EventListing<'a> {
    /// A listing of a log whose sync pairs are `syncs` (its summary's).
    fn new(syncs: &'a [SyncPair]) -> Self {
        Self {
            syncs,
            read: 0,
            converter: EventConverter::new(),
            order: TimeOrder::new(),
            lines: Vec::new(),
            total: 0,
        }
    }

    /// Takes the next decoder event.
    fn observe(&mut self, event: &Event<'_>) {
        // The summary keeps the pairs it can place, as `events` does.
        if let Event::Record(Record::UtcSync(pair)) = event {
            if i64::try_from(pair.unix_ms).is_ok() {
                self.read = (self.read + 1).min(self.syncs.len());
            }
        }
        if let Some(e) = self.converter.convert(event) {
            let pairs = &self.syncs[..self.read];
            let (lines, total) = (&mut self.lines, &mut self.total);
            let Ok(()) = self.order.push(e, &mut |e| {
                list(lines, total, e, pairs);
                Ok::<(), Infallible>(())
            });
        }
    }

    /// The episodes of `ride` and the events listed, in time order, and
    /// how many events the log has.
    fn finish(self, ride: &Ride) -> (Vec<EventLine>, usize) {
        let Self {
            syncs,
            read,
            order,
            mut lines,
            mut total,
            ..
        } = self;
        let pairs = &syncs[..read];
        let Ok(()) = order.finish(&mut |e| {
            list(&mut lines, &mut total, e, pairs);
            Ok::<(), Infallible>(())
        });
        let all = &ride.summary.utc_syncs;
        let mut listed: Vec<EventLine> = ride
            .episodes
            .iter()
            .map(|e| EventLine {
                t_s: e.onset_s,
                end_s: Some(e.end_s),
                utc: crate::time::utc_text_at(all, e.onset_s),
                kind: "episode".into(),
                text: episode_text(e),
            })
            .collect();
        listed.append(&mut lines);
        // A stable sort: an episode before an event at the same time.
        listed.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        (listed, total)
    }
}

/// Counts event `e` and lists it among the first [`MAX_EVENTS`], its UTC
/// from `pairs`.
fn list(lines: &mut Vec<EventLine>, total: &mut usize, e: LogEvent, pairs: &[SyncPair]) {
    *total += 1;
    if *total > MAX_EVENTS {
        return;
    }
    let end_s = match &e.kind {
        EventKind::LostBlocks { to_s, .. } => Some(*to_s),
        _ => None,
    };
    lines.push(EventLine {
        t_s: e.t_s,
        end_s,
        utc: crate::time::utc_text_at(pairs, e.t_s),
        kind: e.kind.name().into(),
        text: e.kind.describe(),
    });
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
