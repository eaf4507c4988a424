//! The episode search over a stream of frames, in memory that does not grow
//! with the run: the frames of the current stretch (between gaps) are held
//! in a window that is analysed every [`CHUNK_FRAMES`] frames and then
//! forgets what lies well before anything still open.
//!
//! Each analysis of the window sees at least [`MARGIN_S`] of frames before
//! any episode it measures (the 8 s background and the filters' settling)
//! and after it (the tone fit's 4 s and settling), so an episode is
//! measured as if the whole stretch were in memory; the band-pass filters'
//! edge effects die out within a second. Where the steering stays above the
//! quiet level for longer than the window holds ([`MAX_WINDOW_FRAMES`]),
//! the stretch is measured in pieces, each censored
//! [`super::Cut::Overlong`].

use super::censor::Edge;
use super::episodes::{Found, Frames, Place, Span, MIN_SPAN_S};
use super::filter::follows;
use super::kicks::Kick;
use super::Episode;
use crate::losses::Losses;

/// New frames between two analyses of the window.
pub const CHUNK_FRAMES: usize = 1 << 16;
/// Most frames the window holds (43.7 min at 100 Hz).
pub const MAX_WINDOW_FRAMES: usize = 4 * CHUNK_FRAMES;
/// Frames kept around what is measured, s.
pub const MARGIN_S: f64 = 30.0;

/// Wobble episodes of a stream of frames.
pub struct EpisodeSearch {
    fs_hz: f64,
    chunk: usize,
    max_window: usize,
    margin: usize,
    window: Window,
    found: Vec<Found>,
    /// The host's kicks of the run, in time order: a stable episode that
    /// is one of them takes its values instead of being fitted.
    kicks: Vec<Kick>,
    /// Most frames the window has held.
    most_held: usize,
}

/// The frames held of the current stretch.
#[derive(Default)]
struct Window {
    t_s: Vec<f64>,
    steer_deg: Vec<f64>,
    speed_mps: Vec<f64>,
    /// Where the window lies in its stretch (`None` before the first frame).
    place: Option<Place>,
    /// Frames of the stretch so far, including those forgotten.
    stretch_frames: usize,
    /// Frames before this one are measured or cannot start an episode.
    scan_from: usize,
    /// The window is analysed when it holds this many frames.
    analyse_at: usize,
}

impl Window {
    fn len(&self) -> usize {
        self.t_s.len()
    }

    fn forget(&mut self, n: usize) {
        self.t_s.drain(..n);
        self.steer_deg.drain(..n);
        self.speed_mps.drain(..n);
        self.scan_from = self.scan_from.saturating_sub(n);
        self.analyse_at = self.analyse_at.saturating_sub(n);
    }
}

impl EpisodeSearch {
    /// A search over frames nominally `fs_hz` apart.
    #[must_use]
    pub fn new(fs_hz: f64) -> Self {
        Self::with_chunk(fs_hz, CHUNK_FRAMES)
    }

    /// A search analysing the window every `chunk` frames (tests use short
    /// chunks to show that the result does not depend on them).
    #[must_use]
    pub fn with_chunk(fs_hz: f64, chunk: usize) -> Self {
        let margin = (MARGIN_S * fs_hz).ceil() as usize;
        let chunk = chunk.max(2 * margin);
        Self {
            fs_hz,
            chunk,
            max_window: 4 * chunk,
            margin,
            window: Window::default(),
            found: Vec::new(),
            kicks: Vec::new(),
            most_held: 0,
        }
    }

    /// Takes the next of the host's kicks of the run, in time order (as
    /// [`super::kicks::KickSearch`] finds them): every kick that rose up to
    /// [`super::campaign_kicks::MATCH_S`] after a frame must be given
    /// before the frame is [`Self::push`]ed, for a stable episode that is
    /// one of them to take its values instead of being fitted.
    pub fn add_kicks(&mut self, kicks: &[Kick]) {
        self.kicks.extend_from_slice(kicks);
    }

    /// Takes the next frame in file order: time, steering angle, speed.
    pub fn push(&mut self, t_s: f64, steer_deg: f64, speed_mps: f64) {
        let period_s = 1.0 / self.fs_hz;
        match self.window.t_s.last() {
            None if self.window.place.is_none() => self.start_stretch(t_s, Edge::DataStart),
            Some(&last) if !follows(last, t_s, period_s) => {
                let edge = Edge::Between(last, t_s);
                self.analyse(Some(edge));
                self.start_stretch(t_s, edge);
            }
            _ => {}
        }
        let w = &mut self.window;
        w.t_s.push(t_s);
        w.steer_deg.push(steer_deg);
        w.speed_mps.push(speed_mps);
        w.stretch_frames += 1;
        self.most_held = self.most_held.max(w.len());
        if w.len() >= w.analyse_at {
            self.analyse(None);
        }
    }

    /// Most frames held at once so far: at most four chunks, whatever the
    /// run's length.
    #[must_use]
    pub fn most_held(&self) -> usize {
        self.most_held
    }

    /// Every episode, in file order, its cuts named from the log's `losses`.
    #[must_use]
    pub fn finish(mut self, losses: &Losses) -> Vec<Episode> {
        if !self.window.t_s.is_empty() {
            self.analyse(Some(Edge::DataEnd));
        }
        self.found.into_iter().map(|f| f.resolve(losses)).collect()
    }

    fn start_stretch(&mut self, first_s: f64, edge: Edge) {
        self.window = Window {
            place: Some(Place {
                first_s,
                stretch_start: edge,
                window_start: Some(edge),
            }),
            analyse_at: self.chunk + self.margin,
            ..Window::default()
        };
    }

    /// Measures every episode the window shows whole; `end` is what ends the
    /// stretch when it is over. Then forgets what no later episode needs.
    fn analyse(&mut self, end: Option<Edge>) {
        let w = &mut self.window;
        let Some(place) = w.place else { return };
        w.analyse_at = w.len() + self.chunk;
        let over = end.is_some();
        if over && (w.stretch_frames as f64) < MIN_SPAN_S * self.fs_hz {
            return;
        }
        let frames = Frames {
            t_s: &w.t_s,
            steer_deg: &w.steer_deg,
            speed_mps: &w.speed_mps,
        };
        let span = Span::new(frames, self.fs_hz, place, &self.kicks);
        let len = w.len();
        // Regions that end before this are measured with all they need.
        let settled = if over { len } else { len - self.margin };
        let mut from = w.scan_from;
        let mut open = None;
        while let Some(hit) = span.next_hit(from, settled) {
            let region = span.region(hit);
            if !over && region.end > settled {
                open = Some(region);
                break;
            }
            let cut = (region.end >= len).then_some(end).flatten();
            from = region.end;
            self.found.extend(span.measure(region, cut));
        }
        if over {
            return;
        }
        if open.is_none() {
            from = from.max(settled);
        }
        // A later episode starts after the last quiet frame before `from`.
        let keep_from = span.last_quiet(from).unwrap_or(0);
        let forget = keep_from.saturating_sub(self.margin);
        if len - forget + self.chunk <= self.max_window {
            w.scan_from = from;
            if forget > 0 {
                w.forget(forget);
                w.place = Some(Place {
                    window_start: None,
                    ..place
                });
            }
            return;
        }
        // Above quiet for longer than the window holds: measure what is
        // open up to here, and go on from a window cut at this point.
        if let Some(region) = open {
            self.found
                .extend(span.measure(region.start..len, Some(Edge::Overlong)));
        }
        let keep = self.margin.min(len);
        w.forget(len - keep);
        w.scan_from = keep;
        w.place = Some(Place {
            window_start: Some(Edge::Overlong),
            ..place
        });
    }
}
