//! The seed paper's Figure 6: steering angle, roll angle, yaw rate and speed
//! stacked on one time axis, alert periods shaded, rider markers drawn, and
//! where the data are missing (lost blocks, forward time jumps) shaded too.

use plotters::coord::types::RangedCoordf64;
use plotters::coord::Shift;
use plotters::prelude::*;

use super::key::{self, Swatch};
use super::{padded_range, tick_label, titled_page, Decimator, Figure, FONT};
use crate::analysis::filter::follows;
use crate::analysis::roll::RollStream;
use crate::analysis::{Episode, KickMode, Run};
use crate::rows::Row;
use crate::summary::Summary;
use crate::time::{iso8601_unix_ms, utc_ms_at, SyncPair};

/// Panel titles (y-axis labels), top to bottom.
pub const PANELS: [&str; 4] = [
    "steering angle (deg)",
    "roll angle (deg)",
    "yaw rate (deg/s)",
    "speed (m/s)",
];
/// Colour of the signal lines.
pub const LINE_COLOUR: RGBColor = RGBColor(0x1f, 0x4e, 0x9a);
/// Colour of alert shading (drawn with transparency).
pub const ALERT_COLOUR: RGBColor = RGBColor(0xe0, 0x30, 0x30);
/// Colour of rider markers.
pub const MARKER_COLOUR: RGBColor = RGBColor(0x20, 0x90, 0x30);
/// Colour of stretches lost from the file (drawn with transparency).
pub const LOST_COLOUR: RGBColor = RGBColor(0x70, 0x70, 0x70);
/// Colour of forward jumps of the logger's clock (drawn with transparency).
pub const JUMP_COLOUR: RGBColor = RGBColor(0xe0, 0x90, 0x10);
/// Colour of the wobble episodes the host measured (with transparency).
pub const EPISODE_COLOUR: RGBColor = RGBColor(0x80, 0x30, 0xa0);
/// Colour of the weave's kick ring-downs the host measured.
pub const WEAVE_COLOUR: RGBColor = RGBColor(0x10, 0x90, 0xa0);
/// Colour of the board's kick records.
pub const KICK_COLOUR: RGBColor = RGBColor(0x90, 0x50, 0x10);
/// A shaded span is drawn at least this wide, px: a 3 s alert on an
/// hour's figure would otherwise be a hairline or nothing.
pub const MIN_SPAN_PX: f64 = 4.0;
/// Width of the y tick labels and axis title, px: room for `-1000.0`
/// beside a two-line-free title in 14 px text.
const Y_LABEL_AREA_PX: u32 = 84;

/// Figure 6 of one run over a time window.
pub struct TimePlot {
    title: String,
    window_s: std::ops::Range<f64>,
    /// One list of contiguous stretches per panel.
    series: [Vec<Vec<(f64, f64)>>; 4],
    alerts_s: Vec<(f64, f64)>,
    markers_s: Vec<f64>,
    /// The board's kick records, s.
    kicks_s: Vec<f64>,
    /// The wobble episodes the host measured (onset to end), s.
    episodes_s: Vec<(f64, f64)>,
    /// The weave's kick ring-downs the host measured, s.
    weave_s: Vec<(f64, f64)>,
    /// Stretches lost from the file (missing blocks), s.
    lost_s: Vec<(f64, f64)>,
    /// Forward jumps of the frame times, s: no data, and no time passed
    /// that the logger saw.
    jumps_s: Vec<(f64, f64)>,
    /// Sync pairs and the UTC midnight (ms since 1970) before the
    /// window's start, when the time axis is in UTC.
    utc: Option<(Vec<SyncPair>, i64)>,
    /// Figure width, px: the lines are kept at twice its resolution.
    width_px: u32,
}

/// The figure's own size, px: 220 px a panel below the title.
pub const SIZE_PX: (u32, u32) = (1200, 40 + 220 * PANELS.len() as u32);

/// Builds a [`TimePlot`] in one pass over the frames, in memory that does
/// not grow with the run: each panel keeps its lowest and highest point per
/// column of the figure, and the roll estimate streams (see
/// [`RollStream`]).
pub struct TimePlotBuilder {
    roll: RollStream,
    panels: Panels,
}

/// The figure being drawn, frame by frame.
struct Panels {
    plot: TimePlot,
    period_s: f64,
    lines: [Decimator; 4],
    /// Time of the last frame drawn.
    last_s: Option<f64>,
}

impl Panels {
    /// Adds frame `j` of `frames`, whose roll is `roll_deg`, if it falls in
    /// the figure's window.
    fn draw(&mut self, frames: &Run, j: usize, roll_deg: f64) {
        let t = frames.t_s[j];
        let window = &self.plot.window_s;
        if !(window.contains(&t) || t == window.end) {
            return;
        }
        let joins = self
            .last_s
            .is_some_and(|prev| follows(prev, t, self.period_s));
        self.last_s = Some(t);
        let values = [
            frames.steer_deg[j],
            roll_deg,
            frames.gyro_dps[j][2],
            frames.speed_mps[j],
        ];
        for (line, y) in self.lines.iter_mut().zip(values) {
            line.push(t, y, joins);
        }
    }
}

impl TimePlotBuilder {
    /// The figure of the run `name`, whose frames span `data_s` (first and
    /// last in file order) at `fs_hz`, between `from_s` and `to_s` (the whole
    /// run where absent), shading and marking what `summary` records, for
    /// a figure `width_px` wide. `None` if no frame can fall in the window.
    #[must_use]
    pub fn new(
        name: &str,
        summary: &Summary,
        data_s: (f64, f64),
        fs_hz: f64,
        (from_s, to_s): (Option<f64>, Option<f64>),
        width_px: u32,
    ) -> Option<Self> {
        let (first, last) = data_s;
        let window_s = from_s.unwrap_or(first).max(first)..to_s.unwrap_or(last).min(last);
        if window_s.start >= window_s.end {
            return None;
        }
        let overlaps = |a: f64, b: f64| a < window_s.end && b > window_s.start;
        let clip = |(a, b): (f64, f64)| (a.max(window_s.start), b.min(window_s.end));
        let alerts_s = summary
            .alerts
            .iter()
            .map(|a| (a.on_s, a.off_s.unwrap_or(last)))
            .filter(|&(a, b)| overlaps(a, b))
            .map(clip)
            .collect();
        let markers_s = summary
            .markers
            .iter()
            .copied()
            .filter(|t| window_s.contains(t))
            .collect();
        // One tick per pixel column at most: a log of 100 000 kick records
        // would otherwise draw each of them.
        let column_s = (window_s.end - window_s.start) / f64::from(width_px);
        let mut kicks_s: Vec<f64> = summary
            .kick_records
            .iter()
            .map(|k| k.t_us as f64 / 1e6)
            .filter(|t| window_s.contains(t))
            .collect();
        kicks_s.sort_by(f64::total_cmp);
        kicks_s.dedup_by(|b, a| *b - *a < column_s);
        let lost_s = summary
            .losses
            .lost_blocks
            .iter()
            .map(|g| (g.from_s.unwrap_or(first), g.to_s))
            .filter(|&(a, b)| overlaps(a, b))
            .map(clip)
            .collect();
        let jumps_s = summary
            .losses
            .time_jumps
            .iter()
            .copied()
            .filter(|&(a, b)| a < b && overlaps(a, b))
            .map(clip)
            .collect();
        let columns = 2 * width_px as usize;
        Some(Self {
            panels: Panels {
                lines: std::array::from_fn(|_| Decimator::new(&window_s, columns)),
                plot: TimePlot {
                    title: format!("{name}: {:.1} to {:.1} s", window_s.start, window_s.end),
                    window_s,
                    series: Default::default(),
                    alerts_s,
                    markers_s,
                    kicks_s,
                    episodes_s: Vec::new(),
                    weave_s: Vec::new(),
                    lost_s,
                    jumps_s,
                    utc: None,
                    width_px,
                },
                period_s: 1.0 / fs_hz,
                last_s: None,
            },
            roll: RollStream::new(fs_hz),
        })
    }

    /// Takes frame `i` of `source` (frames in file order).
    pub fn push(&mut self, source: &Run, i: usize) {
        let panels = &mut self.panels;
        self.roll
            .push(source, i, &mut |f, j, r| panels.draw(f, j, r));
    }

    /// Takes one frame as a row (frames in file order).
    pub fn push_row(&mut self, row: &Row) {
        let panels = &mut self.panels;
        self.roll.push_row(row, &mut |f, j, r| panels.draw(f, j, r));
    }

    /// The figure.
    #[must_use]
    pub fn finish(mut self) -> TimePlot {
        let panels = &mut self.panels;
        self.roll.finish(&mut |f, j, r| panels.draw(f, j, r));
        let mut plot = self.panels.plot;
        plot.series = self.panels.lines.each_ref().map(Decimator::lines);
        plot
    }
}

impl TimePlot {
    /// The figure of `run` (in memory) between `from_s` and `to_s` (the
    /// whole run where absent). `None` if no frame falls in the window.
    #[must_use]
    pub fn new(run: &Run, from_s: Option<f64>, to_s: Option<f64>) -> Option<Self> {
        let data_s = (*run.t_s.first()?, *run.t_s.last()?);
        let mut builder = TimePlotBuilder::new(
            &run.name(),
            &run.summary,
            data_s,
            run.sample_rate_hz(),
            (from_s, to_s),
            SIZE_PX.0,
        )?;
        for i in 0..run.len() {
            builder.push(run, i);
        }
        Some(builder.finish())
    }

    /// Whether no frame fell in the window.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.series.iter().all(Vec::is_empty)
    }

    /// Puts the time axis in UTC through the log's sync `pairs`: ticks at
    /// round UTC times (the axis is UTC seconds of the day), labelled to
    /// the tenth or hundredth of a second on short windows, and the UTC
    /// span in the title. Without a pair, nothing changes.
    pub fn label_utc(&mut self, pairs: Vec<SyncPair>) {
        const DAY_MS: i64 = 86_400_000;
        let Some(start_ms) = utc_ms_at(&pairs, self.window_s.start) else {
            return;
        };
        self.utc = Some((pairs, start_ms.div_euclid(DAY_MS) * DAY_MS));
        let (from, to) = (self.x(self.window_s.start), self.x(self.window_s.end));
        let day = iso8601_unix_ms(start_ms).map_or(String::new(), |iso| iso[..10].to_string());
        self.title = format!(
            "{} (UTC {day} {} to {})",
            self.title,
            clock_text(from, 3),
            clock_text(to, 3)
        );
    }

    /// Where `t_s` since boot sits on the time axis: itself, or its UTC
    /// in seconds since the midnight before the window (exact, not rounded
    /// to the millisecond).
    fn x(&self, t_s: f64) -> f64 {
        let Some((pairs, midnight_ms)) = &self.utc else {
            return t_s;
        };
        let at = pairs.partition_point(|p| p.0 <= t_s).saturating_sub(1);
        pairs.get(at).map_or(t_s, |&(pair_s, pair_ms)| {
            (pair_ms - midnight_ms) as f64 / 1000.0 + (t_s - pair_s)
        })
    }

    /// The time axis's ticks: on a UTC axis at round clock times (whole
    /// minutes or hours on long windows, 1-2-5 steps of a second on short
    /// ones, see [`clock_ticks`]), else where plotters puts them.
    fn x_ticks(&self) -> Vec<f64> {
        let (from, to) = (self.x(self.window_s.start), self.x(self.window_s.end));
        match &self.utc {
            Some(_) => clock_ticks(from, to, MAX_TIME_TICKS).0,
            None => RangedCoordf64::from(from..to).key_points(MAX_TIME_TICKS),
        }
    }

    /// Decimals of the UTC tick labels: those of the tick step.
    fn utc_decimals(&self) -> usize {
        let (from, to) = (self.x(self.window_s.start), self.x(self.window_s.end));
        clock_ticks(from, to, MAX_TIME_TICKS).1
    }

    /// Draws `episodes` (the host's, as `wobblog wobble` lists them): the
    /// wobble's and the weave's ring-downs each as a span of its own.
    pub fn set_episodes(&mut self, episodes: &[Episode]) {
        let window = &self.window_s;
        let spans = |mode: KickMode| {
            episodes
                .iter()
                .filter(|e| e.mode == mode && e.onset_s < window.end && e.end_s > window.start)
                .map(|e| (e.onset_s.max(window.start), e.end_s.min(window.end)))
                .collect()
        };
        self.episodes_s = spans(KickMode::Wobble);
        self.weave_s = spans(KickMode::Weave);
    }

    /// The spans drawn for the host's wobble episodes, s.
    #[must_use]
    pub fn episodes_s(&self) -> &[(f64, f64)] {
        &self.episodes_s
    }

    /// `span` widened about its middle to [`MIN_SPAN_PX`] of a plot
    /// `plot_px` wide when narrower, within the window.
    #[must_use]
    pub fn visible(&self, (a, b): (f64, f64), plot_px: f64) -> (f64, f64) {
        let w = &self.window_s;
        let min_s = (w.end - w.start) * MIN_SPAN_PX / plot_px;
        if b - a >= min_s {
            return (a, b);
        }
        let mid = 0.5 * (a + b);
        let a = (mid - 0.5 * min_s).max(w.start);
        (a, (a + min_s).min(w.end))
    }

    /// `spans` as drawn on a plot `plot_px` wide: each made [`Self::visible`],
    /// those that then overlap joined into one, in time order. One shape per
    /// stretch: a campaign's thousand kicks would otherwise be a thousand
    /// translucent boxes, darker where they overlap and slow to draw.
    #[must_use]
    pub fn visible_spans(&self, spans: &[(f64, f64)], plot_px: f64) -> Vec<(f64, f64)> {
        join_overlaps(spans.iter().map(|&s| self.visible(s, plot_px)).collect())
    }

    /// Stretches lost from the file drawn, s.
    #[must_use]
    pub fn lost_s(&self) -> &[(f64, f64)] {
        &self.lost_s
    }

    /// The time axis's label.
    fn x_desc(&self) -> String {
        match &self.utc {
            Some(_) => "UTC (hh:mm:ss)".into(),
            None => "time since boot (s)".into(),
        }
    }

    /// A time axis tick at `x` on the axis.
    fn x_tick(&self, x: f64) -> String {
        match &self.utc {
            Some(_) => clock_text(x, self.utc_decimals()),
            None => tick_label(x),
        }
    }

    /// Forward time jumps drawn, s.
    #[must_use]
    pub fn jumps_s(&self) -> &[(f64, f64)] {
        &self.jumps_s
    }

    /// Alert periods drawn, s.
    #[must_use]
    pub fn alerts_s(&self) -> &[(f64, f64)] {
        &self.alerts_s
    }

    /// Markers drawn, s.
    #[must_use]
    pub fn markers_s(&self) -> &[f64] {
        &self.markers_s
    }
}

impl Figure for TimePlot {
    fn size_px(&self) -> (u32, u32) {
        (self.width_px, SIZE_PX.1)
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), String> {
        let err = |e: DrawingAreaErrorKind<DB::ErrorType>| e.to_string();
        let root = titled_page(root, &self.title)?;
        // The shaded spans, each kind in the key if present.
        let shaded = [
            (
                &self.alerts_s,
                ALERT_COLOUR.mix(0.18),
                "wobble alert (on board)",
            ),
            (
                &self.lost_s,
                LOST_COLOUR.mix(0.35),
                "data lost (missing blocks)",
            ),
            (
                &self.jumps_s,
                JUMP_COLOUR.mix(0.3),
                "time jump (logger clock)",
            ),
            (
                &self.episodes_s,
                EPISODE_COLOUR.mix(0.22),
                "wobble episode (host)",
            ),
            (
                &self.weave_s,
                WEAVE_COLOUR.mix(0.22),
                "weave ring-down (host)",
            ),
        ];
        let entries: Vec<(String, Swatch)> = shaded
            .iter()
            .filter(|(spans, ..)| !spans.is_empty())
            .map(|&(_, colour, label)| (label.to_string(), Swatch::Fill(colour)))
            .chain(
                (!self.markers_s.is_empty())
                    .then(|| ("rider marker".into(), Swatch::Upright(MARKER_COLOUR, 2))),
            )
            .chain((!self.kicks_s.is_empty()).then(|| {
                (
                    "kick record (board)".into(),
                    Swatch::Upright(KICK_COLOUR, 3),
                )
            }))
            .collect();
        // The key stands beside the top panel; every panel leaves its
        // room so the time axes line up.
        let labels: Vec<&str> = entries.iter().map(|e| e.0.as_str()).collect();
        let key_px = key::width_px(&root, &labels)?;
        let panels = root.split_evenly((PANELS.len(), 1));
        let last = PANELS.len() - 1;
        for (k, ((area, label), series)) in panels.iter().zip(PANELS).zip(&self.series).enumerate()
        {
            let y = padded_range(series.iter().flatten().map(|p| p.1), 1.0);
            // The bottom panel also holds the time axis's title.
            let x_label_px = if k == last { 48 } else { 28 };
            let mut chart = ChartBuilder::on(area)
                .margin_right(20.max(key_px))
                .margin_left(10)
                .margin_top(6)
                .x_label_area_size(x_label_px)
                .y_label_area_size(Y_LABEL_AREA_PX)
                .build_cartesian_2d(
                    TimeAxis {
                        inner: (self.x(self.window_s.start)..self.x(self.window_s.end)).into(),
                        ticks: self.x_ticks(),
                    },
                    y.clone(),
                )
                .map_err(err)?;
            let x_desc = if k == last {
                self.x_desc()
            } else {
                String::new()
            };
            chart
                .configure_mesh()
                .y_desc(label)
                .x_desc(x_desc)
                .x_label_formatter(&|t| self.x_tick(*t))
                .y_label_formatter(&|v| tick_label(*v))
                .label_style((FONT, 13))
                .axis_desc_style((FONT, 14))
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(err)?;
            let plot_px = f64::from(chart.plotting_area().dim_in_pixel().0);
            for (spans, colour, _) in shaded {
                chart
                    .draw_series(
                        self.visible_spans(spans, plot_px)
                            .into_iter()
                            .map(|(a, b)| {
                                Rectangle::new(
                                    [(self.x(a), y.start), (self.x(b), y.end)],
                                    colour.filled(),
                                )
                            }),
                    )
                    .map_err(err)?;
            }
            chart
                .draw_series(self.markers_s.iter().map(|&t| {
                    PathElement::new(
                        vec![(self.x(t), y.start), (self.x(t), y.end)],
                        MARKER_COLOUR.stroke_width(2),
                    )
                }))
                .map_err(err)?;
            // The board's kick records: a tick along the top of each panel.
            let tick = (y.end - y.start) * 0.15;
            chart
                .draw_series(self.kicks_s.iter().map(|&t| {
                    PathElement::new(
                        vec![(self.x(t), y.end - tick), (self.x(t), y.end)],
                        KICK_COLOUR.stroke_width(3),
                    )
                }))
                .map_err(err)?;
            for points in series {
                let line =
                    LineSeries::new(points.iter().map(|&(t, v)| (self.x(t), v)), LINE_COLOUR);
                // A stretch of one sample has no line to draw: a dot shows it.
                let line = if points.len() == 1 {
                    line.point_size(2)
                } else {
                    line
                };
                chart.draw_series(line).map_err(err)?;
            }
            if k == 0 {
                key::draw(area, chart.plotting_area(), key_px, &entries)?;
            }
        }
        Ok(())
    }
}

/// A time axis with ticks of its own: plotters' f64 axis, whose ticks are
/// decimal (round multiples of 100 or 500 s, not minutes), and whose
/// `with_key_points` form cannot take a label formatter.
struct TimeAxis {
    inner: RangedCoordf64,
    ticks: Vec<f64>,
}

impl Ranged for TimeAxis {
    type FormatOption = plotters::coord::ranged1d::DefaultFormatting;
    type ValueType = f64;

    fn map(&self, value: &f64, limit: (i32, i32)) -> i32 {
        self.inner.map(value, limit)
    }

    fn key_points<Hint: plotters::coord::ranged1d::KeyPointHint>(&self, hint: Hint) -> Vec<f64> {
        // Light (minor) grid lines are not drawn.
        if hint.weight().allow_light_points() {
            Vec::new()
        } else {
            self.ticks.clone()
        }
    }

    fn range(&self) -> std::ops::Range<f64> {
        self.inner.range()
    }
}

/// Most ticks on the time axis (plotters' default count).
const MAX_TIME_TICKS: usize = 10;

/// Tick steps of a clock axis, s, with the decimals their labels need: 1-2-5
/// steps under a second, then the clock's own divisions (15 and 30 s,
/// minutes, quarter hours, hours).
const CLOCK_STEPS_S: [(f64, usize); 23] = [
    (0.01, 2),
    (0.02, 2),
    (0.05, 2),
    (0.1, 1),
    (0.2, 1),
    (0.5, 1),
    (1.0, 0),
    (2.0, 0),
    (5.0, 0),
    (10.0, 0),
    (15.0, 0),
    (30.0, 0),
    (60.0, 0),
    (120.0, 0),
    (300.0, 0),
    (600.0, 0),
    (900.0, 0),
    (1800.0, 0),
    (3600.0, 0),
    (7200.0, 0),
    (10_800.0, 0),
    (21_600.0, 0),
    (43_200.0, 0),
];

/// Ticks at the multiples of the finest clock step that puts at most `max`
/// of them in `from..=to` (seconds since a midnight), and their labels'
/// decimals.
fn clock_ticks(from: f64, to: f64, max: usize) -> (Vec<f64>, usize) {
    let (step, decimals) = CLOCK_STEPS_S
        .iter()
        .copied()
        .find(|&(step, _)| ((to / step).floor() - (from / step).ceil()) < max as f64)
        .unwrap_or((86_400.0, 0));
    let first = (from / step).ceil() as i64;
    let last = (to / step).floor() as i64;
    // Multiples of the step, not sums of it: no rounding creeps in.
    let ticks = (first..=last).map(|k| k as f64 * step).collect();
    (ticks, decimals)
}

/// Seconds since a midnight as `hh:mm:ss` with `decimals` of a second
/// (rounded; past 24 h it goes on into the next day's hours).
fn clock_text(s: f64, decimals: usize) -> String {
    let scale = 10f64.powi(decimals as i32);
    let units = (s * scale).round() as i64;
    let whole = units.div_euclid(scale as i64);
    let frac = units.rem_euclid(scale as i64);
    let (h, m, sec) = (whole / 3600 % 24, whole / 60 % 60, whole % 60);
    if decimals == 0 {
        format!("{h:02}:{m:02}:{sec:02}")
    } else {
        format!("{h:02}:{m:02}:{sec:02}.{frac:0decimals$}")
    }
}

/// `spans` in time order, those that overlap or touch joined into one.
fn join_overlaps(mut spans: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut joined: Vec<(f64, f64)> = Vec::with_capacity(spans.len());
    for (a, b) in spans {
        match joined.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => joined.push((a, b)),
        }
    }
    joined
}

#[cfg(test)]
mod tests {
    use super::{clock_text, clock_ticks, join_overlaps};

    #[test]
    fn overlapping_spans_are_joined_in_time_order() {
        let spans = vec![(3.0, 4.0), (0.0, 1.0), (0.5, 2.0), (2.0, 2.5), (0.2, 0.3)];
        assert_eq!(join_overlaps(spans), [(0.0, 2.5), (3.0, 4.0)]);
        assert_eq!(
            join_overlaps(vec![(1.0, 2.0), (2.5, 3.0)]),
            [(1.0, 2.0), (2.5, 3.0)]
        );
        assert!(join_overlaps(Vec::new()).is_empty());
    }

    #[test]
    fn clock_ticks_fall_on_round_clock_times() {
        // 40 minutes from 10:03:17: every 5 minutes.
        let (ticks, decimals) = clock_ticks(36_197.0, 38_597.0, 10);
        assert_eq!(decimals, 0);
        let labels: Vec<String> = ticks.iter().map(|&t| clock_text(t, 0)).collect();
        assert_eq!(
            labels,
            [
                "10:05:00", "10:10:00", "10:15:00", "10:20:00", "10:25:00", "10:30:00", "10:35:00",
                "10:40:00"
            ]
        );
        // 7 h: every hour.
        let (ticks, _) = clock_ticks(30_000.0, 55_200.0, 10);
        assert_eq!(ticks.first(), Some(&32_400.0));
        assert!(ticks.iter().all(|t| t % 3600.0 == 0.0), "{ticks:?}");
        // 1.5 s: every 0.2 s, to the tenth.
        let (ticks, decimals) = clock_ticks(37_816.05, 37_817.55, 10);
        assert_eq!(decimals, 1);
        assert_eq!(clock_text(ticks[0], decimals), "10:30:16.2");
        assert_eq!(ticks.len(), 7);
        // 8 minutes: every minute (not every 50 s or 100 s).
        let (ticks, _) = clock_ticks(36_000.0, 36_480.0, 10);
        assert_eq!(ticks.len(), 9);
        assert!(ticks.iter().all(|t| t % 60.0 == 0.0));
    }

    #[test]
    fn clock_text_rounds_to_its_decimals() {
        assert_eq!(clock_text(37_816.0, 0), "10:30:16");
        assert_eq!(clock_text(37_816.2, 1), "10:30:16.2");
        assert_eq!(clock_text(37_816.249_999, 2), "10:30:16.25");
        assert_eq!(clock_text(37_816.999_6, 3), "10:30:17.000");
        assert_eq!(clock_text(86_400.5, 1), "00:00:00.5");
    }
}
