//! The ride's signals as the page draws them: one shared time column and
//! one column per channel, thinned for display only. Outside the stretches
//! worth a close look (episodes, alerts, markers) each time bucket keeps
//! its lowest and highest value per channel, so a spike of one frame is
//! still drawn; inside them every frame is kept. The analyses never see
//! these columns.

use serde::Serialize;

use crate::analysis::filter::follows;

/// The channels, in column order: the seed paper's Figure 6 first, then
/// the rest of the IMU.
pub const CHANNELS: [&str; 9] = [
    "steer_deg",
    "roll_deg",
    "yaw_rate_dps",
    "speed_mps",
    "gyro_x_dps",
    "gyro_y_dps",
    "accel_x_g",
    "accel_y_g",
    "accel_z_g",
];

/// Rows kept outside the close-look stretches, at most (two per bucket):
/// about ten per pixel of a wide screen, so a zoom by ten still shows the
/// envelope at screen resolution.
pub const OVERVIEW_ROWS: usize = 16_000;
/// Time in close-look stretches kept at full rate, at most, s: beyond it
/// the later stretches are thinned like the rest.
pub const DETAIL_BUDGET_S: f64 = 300.0;

/// The display columns. `None` breaks the line (a gap in the data).
#[derive(Clone, Debug, Default, Serialize)]
pub struct Series {
    /// Time since boot, s, strictly increasing.
    pub t: Vec<f64>,
    /// One column per [`CHANNELS`] entry.
    pub columns: Vec<Vec<Option<f64>>>,
    /// Frames not drawn because their time was not after the previous
    /// frame's (a log whose clock jumped back).
    pub frames_out_of_order: usize,
}

/// One frame's values, in [`CHANNELS`] order.
pub type Values = [f64; CHANNELS.len()];

/// A bucket of frames being thinned: per channel the lowest and highest
/// value and the index of the frame it came from.
struct Bucket {
    index: i64,
    first_s: f64,
    last_s: f64,
    frames: usize,
    /// Whether the frames have a gap between them.
    broken: bool,
    low: Vec<(f64, usize)>,
    high: Vec<(f64, usize)>,
}

/// Builds a [`Series`] frame by frame.
pub struct SeriesBuilder {
    out: Series,
    period_s: f64,
    origin_s: f64,
    bucket_s: f64,
    /// The close-look stretches, in time order, apart.
    detail_s: Vec<(f64, f64)>,
    /// The first of `detail_s` not over before the last frame taken.
    detail_at: usize,
    bucket: Option<Bucket>,
    /// Whether the lines break before the next row with a value (after a
    /// bucket with a gap in it).
    broken: bool,
    last_s: Option<f64>,
    frame: usize,
}

/// Rounds to `decimals` places: the page needs no more, and shorter
/// numbers keep the file small.
fn round(v: f64, scale: f64) -> f64 {
    (v * scale).round() / scale
}

impl SeriesBuilder {
    /// A builder for `frames` frames `period_s` apart spanning `span_s`,
    /// keeping every frame inside `detail_s` (sorted or not, overlapping
    /// or not).
    #[must_use]
    pub fn new(frames: usize, period_s: f64, span_s: (f64, f64), detail_s: &[(f64, f64)]) -> Self {
        let all = frames <= OVERVIEW_ROWS;
        let buckets = (OVERVIEW_ROWS / 2).max(1);
        let bucket_s = if all {
            0.0
        } else {
            (span_s.1 - span_s.0) / buckets as f64
        };
        Self {
            out: Series {
                columns: vec![Vec::new(); CHANNELS.len()],
                ..Series::default()
            },
            period_s,
            origin_s: span_s.0,
            bucket_s,
            detail_s: if all { Vec::new() } else { budgeted(detail_s) },
            detail_at: 0,
            bucket: None,
            broken: false,
            last_s: None,
            frame: 0,
        }
    }

    /// Takes the next frame in file order.
    pub fn push(&mut self, t_s: f64, values: &Values) {
        self.frame += 1;
        let last = self.last_s;
        if last.is_some_and(|last| t_s <= last) {
            self.out.frames_out_of_order += 1;
            return;
        }
        self.last_s = Some(t_s);
        let thinned = self.bucket_s > 0.0 && !self.in_detail(t_s);
        let index = ((t_s - self.origin_s) / self.bucket_s).floor() as i64;
        if let Some(last) = last.filter(|&last| !follows(last, t_s, self.period_s)) {
            match &mut self.bucket {
                // A gap within a bucket being thinned breaks the lines
                // after the bucket: however many gaps a bucket spans, it
                // makes at most three rows.
                Some(b) if thinned && b.index == index => b.broken = true,
                _ => {
                    self.flush();
                    // A row of nothing between the two frames breaks the
                    // lines.
                    self.row(0.5 * (last + t_s), &[None; CHANNELS.len()]);
                }
            }
        }
        if !thinned {
            self.flush();
            self.row(t_s, &values.map(Some));
            return;
        }
        if self.bucket.as_ref().is_some_and(|b| b.index != index) {
            self.flush();
        }
        let frame = self.frame;
        let bucket = self.bucket.get_or_insert_with(|| Bucket {
            index,
            first_s: t_s,
            last_s: t_s,
            frames: 0,
            broken: false,
            low: values.iter().map(|&v| (v, frame)).collect(),
            high: values.iter().map(|&v| (v, frame)).collect(),
        });
        bucket.last_s = t_s;
        bucket.frames += 1;
        for (c, &v) in values.iter().enumerate() {
            // NaN never replaces a value: the comparisons are false.
            if v < bucket.low[c].0 {
                bucket.low[c] = (v, frame);
            }
            if v > bucket.high[c].0 {
                bucket.high[c] = (v, frame);
            }
        }
    }

    /// Whether `t_s` is in a close-look stretch; the times asked about
    /// only increase.
    fn in_detail(&mut self, t_s: f64) -> bool {
        while self
            .detail_s
            .get(self.detail_at)
            .is_some_and(|&(_, b)| b < t_s)
        {
            self.detail_at += 1;
        }
        self.detail_s
            .get(self.detail_at)
            .is_some_and(|&(a, _)| a <= t_s)
    }

    /// The display columns.
    #[must_use]
    pub fn finish(mut self) -> Series {
        self.flush();
        self.out
    }

    fn row(&mut self, t_s: f64, values: &[Option<f64>; CHANNELS.len()]) {
        if std::mem::take(&mut self.broken) && values.iter().any(Option::is_some) {
            if let Some(&before) = self.out.t.last() {
                self.row(0.5 * (before + t_s), &[None; CHANNELS.len()]);
            }
        }
        self.out.t.push(round(t_s, 1e5));
        for (column, v) in self.out.columns.iter_mut().zip(values) {
            column.push(v.map(|v| round(v, 1e3)).filter(|v| v.is_finite()));
        }
    }

    /// Writes the open bucket: one row for one frame, else two (at its
    /// first and last frame's times), each channel's extremes in the order
    /// they came.
    fn flush(&mut self) {
        let Some(b) = self.bucket.take() else {
            return;
        };
        if b.frames == 1 {
            let values: Vec<Option<f64>> = b.low.iter().map(|l| Some(l.0)).collect();
            let row: [Option<f64>; CHANNELS.len()] = std::array::from_fn(|c| values[c]);
            self.row(b.first_s, &row);
            self.broken = b.broken;
            return;
        }
        let (mut first, mut second) = ([None; CHANNELS.len()], [None; CHANNELS.len()]);
        for c in 0..CHANNELS.len() {
            let (lo, hi) = (b.low[c], b.high[c]);
            let (a, z) = if lo.1 <= hi.1 {
                (lo.0, hi.0)
            } else {
                (hi.0, lo.0)
            };
            first[c] = Some(a);
            second[c] = Some(z);
        }
        self.row(b.first_s, &first);
        self.row(b.last_s, &second);
        self.broken = b.broken;
    }
}

/// The close-look stretches in time order, merged where they overlap,
/// up to [`DETAIL_BUDGET_S`] in all.
fn budgeted(stretches: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut sorted: Vec<(f64, f64)> = stretches
        .iter()
        .copied()
        .filter(|(a, b)| a.is_finite() && b.is_finite() && a <= b)
        .collect();
    sorted.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut merged: Vec<(f64, f64)> = Vec::new();
    for (a, b) in sorted {
        match merged.last_mut() {
            Some(last) if a <= last.1 => last.1 = last.1.max(b),
            _ => merged.push((a, b)),
        }
    }
    let mut total = 0.0;
    merged
        .into_iter()
        .take_while(|(a, b)| {
            total += b - a;
            total <= DETAIL_BUDGET_S
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn frame(v: f64) -> Values {
        [v; CHANNELS.len()]
    }

    #[test]
    fn a_short_ride_keeps_every_frame_and_breaks_at_gaps() {
        let mut b = SeriesBuilder::new(5, 0.01, (0.0, 0.05), &[]);
        for (t, v) in [
            (0.0, 1.0),
            (0.01, 2.0),
            (0.02, 3.0),
            (0.05, 4.0),
            (0.06, 5.0),
        ] {
            b.push(t, &frame(v));
        }
        let s = b.finish();
        assert_eq!(s.t, [0.0, 0.01, 0.02, 0.035, 0.05, 0.06]);
        let steer: Vec<Option<f64>> = s.columns[0].clone();
        assert_eq!(
            steer,
            [Some(1.0), Some(2.0), Some(3.0), None, Some(4.0), Some(5.0)]
        );
    }

    #[test]
    fn a_long_ride_keeps_each_buckets_extremes_in_order_and_details_whole() {
        let n = 10 * OVERVIEW_ROWS;
        let period = 0.01;
        let span = (0.0, (n - 1) as f64 * period);
        // Every 97th frame a spike, which thinning must keep.
        let value = |i: usize| {
            if i.is_multiple_of(97) {
                100.0
            } else {
                (i % 7) as f64
            }
        };
        let detail = [(50.0, 51.0)];
        let mut b = SeriesBuilder::new(n, period, span, &detail);
        for i in 0..n {
            b.push(i as f64 * period, &frame(value(i)));
        }
        let s = b.finish();
        assert!(s.t.len() <= OVERVIEW_ROWS + 4 + 101, "{} rows", s.t.len());
        assert!(s.t.windows(2).all(|w| w[0] < w[1]));
        let spikes = (0..n).filter(|i| i.is_multiple_of(97)).count();
        let drawn = s.columns[0].iter().filter(|v| **v == Some(100.0)).count();
        assert_eq!(drawn, spikes);
        // Inside the detail stretch every frame is there.
        let inside = s.t.iter().filter(|t| (50.0..=51.0).contains(*t)).count();
        assert_eq!(inside, 101);
    }

    #[test]
    fn gaps_in_a_long_ride_break_the_lines_in_rows_bounded_by_the_buckets() {
        // A frame missing after every 20th: 50 000 gaps, 6 per bucket.
        let n = 1_000_000;
        let period = 0.01;
        let times: Vec<f64> = (0..n)
            .filter(|i| i % 21 != 20)
            .map(|i| i as f64 * period)
            .collect();
        let span = (0.0, times[times.len() - 1]);
        let mut b = SeriesBuilder::new(times.len(), period, span, &[]);
        for (i, &t) in times.iter().enumerate() {
            b.push(t, &frame((i % 5) as f64));
        }
        let s = b.finish();
        let breaks = s.columns[0].iter().filter(|v| v.is_none()).count();
        assert!(
            s.t.len() <= 3 * OVERVIEW_ROWS / 2 + 10,
            "{} rows",
            s.t.len()
        );
        assert!(breaks > OVERVIEW_ROWS / 4, "{breaks} breaks");
        assert!(s.t.windows(2).all(|w| w[0] < w[1]));
        // Every bucket still has its extremes.
        let highs = s.columns[0].iter().filter(|v| **v == Some(4.0)).count();
        assert!(highs >= OVERVIEW_ROWS / 2 - 1, "{highs}");
    }

    #[test]
    fn frames_going_back_in_time_are_counted_not_drawn() {
        let mut b = SeriesBuilder::new(3, 0.01, (0.0, 0.02), &[]);
        for t in [0.0, 0.01, 0.005, 0.02] {
            b.push(t, &frame(t));
        }
        let s = b.finish();
        assert_eq!(s.frames_out_of_order, 1);
        assert!(s.t.windows(2).all(|w| w[0] < w[1]));
    }
}
