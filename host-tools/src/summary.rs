//! What `wobblog info` reports about a log.

use std::collections::BTreeMap;

use serde::Serialize;
use wobble_core::format::{DecodeStats, Event, KickRingDown, Record};

use crate::losses::Losses;
use crate::rows::{Row, RowAssembler};
use crate::time::iso8601_unix_us;

/// One wobble alert, from its switching on to its switching off.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct AlertSpan {
    /// Time the alert switched on, s.
    pub on_s: f64,
    /// Time it switched off, s (absent if the log ends first).
    pub off_s: Option<f64>,
    /// Dominant frequency when it switched on, Hz.
    pub freq_hz: f32,
    /// Steering amplitude when it switched on, degrees.
    pub amp_deg: f32,
}

/// How many records of one kind a log holds, and how often they came.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RecordCount {
    /// Records of the kind.
    pub count: u64,
    /// Records per second of the time the frames cover (`duration_s`);
    /// absent when the frames cover no time.
    pub rate_hz: Option<f64>,
}

/// The names `info` gives the kinds of records, in [`kind_index`]'s order.
const KIND_NAMES: [&str; 14] = [
    "frame",
    "gps_fix",
    "gps_no_position",
    "utc_sync",
    "alert_on",
    "alert_off",
    "marker",
    "dropout",
    "fault",
    "kick",
    "margin",
    "log_info",
    "channel",
    "config",
];

/// The place of `record`'s kind in [`KIND_NAMES`] (counted in an array
/// while decoding: a map entry per record would cost more than the record).
fn kind_index(record: &Record<'_>) -> usize {
    match record {
        Record::Frame(_) => 0,
        Record::Gps(g) if g.lat_e7.is_some() && g.lon_e7.is_some() => 1,
        Record::Gps(_) => 2,
        Record::UtcSync(_) => 3,
        Record::Alert(a) if a.on => 4,
        Record::Alert(_) => 5,
        Record::Marker(_) => 6,
        Record::Dropout(_) => 7,
        Record::Fault(_) => 8,
        Record::Kick(_) => 9,
        Record::Margin(_) => 10,
        Record::LogInfo(_) => 11,
        Record::Channel(_) => 12,
        Record::Config(_) => 13,
    }
}

/// Summary of one log.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Summary {
    /// Firmware that wrote the log.
    pub firmware: Option<String>,
    /// Device id, hex.
    pub device_id: Option<String>,
    /// Run number on the card.
    pub run: Option<u32>,
    /// Nominal frame rate, Hz.
    pub sample_rate_hz: Option<u16>,
    /// Configuration in force, as `key=value` lines.
    pub config: Vec<String>,
    /// Time of the first frame, s since boot.
    pub start_s: Option<f64>,
    /// Time of the last frame, s since boot.
    pub end_s: Option<f64>,
    /// Time the frames cover: over each segment, first to last frame plus
    /// one frame period, s. Time jumps between segments are not in it (they
    /// are listed in `losses.time_jumps`).
    pub duration_s: f64,
    /// Stretches of the run between time jumps.
    pub segments: u64,
    /// Frames decoded.
    pub samples: u64,
    /// Dropout records: frames the logger could not write, by reason.
    pub dropouts: BTreeMap<&'static str, u64>,
    /// Frames the logger reported as dropped (sum of dropout records).
    pub frames_dropped: u64,
    /// Blocks missing from the file.
    pub lost_blocks: u64,
    /// Frames those blocks held.
    pub frames_lost: u64,
    /// Damaged blocks skipped.
    pub damaged_blocks: u64,
    /// Bytes that were not valid blocks.
    pub bytes_skipped: u64,
    /// Whole blocks of zeros: space reserved or never written, no loss
    /// (a block missing from the sequence is counted in `lost_blocks`).
    pub unwritten_blocks: u64,
    /// Records in valid blocks that could not be read.
    pub bad_records: u64,
    /// Frames whose time went backwards.
    pub time_jumps: u64,
    /// Frames whose time went forwards by more than missing frames explain.
    pub forward_time_jumps: u64,
    /// Blocks whose sequence number went backwards (stale data).
    pub out_of_order_blocks: u64,
    /// Of those, repeats and stale copies, decoded once.
    pub repeated_blocks: u64,
    /// Values the firmware cannot have written, dropped or replaced.
    pub out_of_range: u64,
    /// GPS fix records.
    pub gps_fixes: u64,
    /// Share of frames with a GPS position, percent.
    pub gps_coverage_pct: f64,
    /// UTC of the first frame that has one (through the GPS sync pairs,
    /// as `decode`'s `utc` column), ISO 8601.
    pub first_utc: Option<String>,
    /// UTC of the last frame that has one, ISO 8601.
    pub last_utc: Option<String>,
    /// [`Self::first_utc`] in µs since 1970.
    #[serde(skip)]
    pub first_utc_us: Option<i64>,
    /// Wobble alerts.
    pub alerts: Vec<AlertSpan>,
    /// Rider markers, s.
    pub markers: Vec<f64>,
    /// Kick ring-downs measured on board (kick records; `wobblog events`
    /// lists them, `wobblog margin` uses them).
    pub kicks: u64,
    /// The kick records themselves, in file order.
    #[serde(skip)]
    pub kick_records: Vec<KickRingDown>,
    /// Fault records by source: number of faults counted.
    pub faults: BTreeMap<&'static str, u64>,
    /// Records by kind (`frame`, `gps_fix`, `utc_sync`, ...): the log's
    /// channels, as `ulog_info` lists a log's messages.
    pub records: BTreeMap<&'static str, RecordCount>,
    /// Everything lost, in detail.
    pub losses: Losses,
    /// The GPS sync pairs (s since boot, UTC ms since 1970), in time order:
    /// what places a UTC time on the log's clock.
    #[serde(skip)]
    pub utc_syncs: Vec<crate::time::SyncPair>,
    /// Earliest and latest frame time, s (whatever their order in the file).
    #[serde(skip)]
    pub frame_range_s: Option<(f64, f64)>,
    /// The stretch between time jumps with the most frames: first and last
    /// frame time, s, and its frames.
    #[serde(skip)]
    pub longest_segment: Option<((f64, f64), u64)>,
}

impl Summary {
    /// Nominal frame rate, Hz: the header's, or the documented default of
    /// 100 Hz.
    #[must_use]
    pub fn frame_rate_hz(&self) -> f64 {
        f64::from(self.sample_rate_hz.unwrap_or(100).max(1))
    }

    /// The span a plot of the whole run covers: the earliest to the latest
    /// frame, unless time jumps leave most of that span empty (more than
    /// twice the time the frames cover: a stray block with absurd times, a
    /// clock that leapt by days), then the stretch between jumps with the
    /// most frames. The flag says the span was narrowed so.
    #[must_use]
    pub fn plot_span_s(&self) -> Option<((f64, f64), bool)> {
        let (lo, hi) = self.frame_range_s?;
        let covered = self.duration_s.max(1.0);
        match self.longest_segment {
            Some((stretch, _)) if hi - lo > 2.0 * covered => Some((stretch, true)),
            _ => Some(((lo, hi), false)),
        }
    }
}

/// Builds a [`Summary`] from decoder events.
#[derive(Default)]
pub struct SummaryBuilder {
    summary: Summary,
    /// Records of each kind of [`KIND_NAMES`].
    kinds: [u64; KIND_NAMES.len()],
    /// First and last frame times of the current segment, µs.
    span_us: Option<(u64, u64)>,
    /// Time covered by the segments before it, µs.
    closed_us: u64,
    /// Frames of the current segment.
    segment_frames: u64,
    /// The frames' times, in µs until the summary is finished.
    frame_times: FrameTimes,
    /// The rows, assembled here unless the caller assembles them
    /// ([`SummaryBuilder::rows_elsewhere`]).
    rows: Option<RowAssembler>,
    row_stats: RowStats,
}

/// The first, last, earliest and latest frame time, µs.
#[derive(Default)]
struct FrameTimes(Option<[u64; 4]>);

impl FrameTimes {
    fn take(&mut self, t_us: u64) {
        let [first, _, min, max] = self.0.unwrap_or([t_us; 4]);
        self.0 = Some([first, t_us, min.min(t_us), max.max(t_us)]);
    }

    /// Sets the summary's start, end and range of frame times, s.
    fn fill(&self, s: &mut Summary) {
        let seconds = |t_us: u64| t_us as f64 / 1e6;
        if let Some([first, last, min, max]) = self.0 {
            s.start_s = Some(seconds(first));
            s.end_s = Some(seconds(last));
            s.frame_range_s = Some((seconds(min), seconds(max)));
        }
    }
}

/// What the summary takes from the decoded rows: GPS coverage and the UTC
/// span. Given every row of the log in order (whatever part of it an
/// output keeps).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RowStats {
    pub(crate) with_gps: u64,
    /// The `utc` of the first and last row that has one, µs since 1970.
    pub(crate) first_utc_us: Option<i64>,
    pub(crate) last_utc_us: Option<i64>,
}

impl RowStats {
    /// Takes the log's next row.
    pub fn take(&mut self, row: &Row) {
        self.take_parts(row.gps.is_some(), row.utc_us);
    }

    /// Takes the log's next row, given whether it has GPS columns and its
    /// UTC.
    pub(crate) fn take_parts(&mut self, has_gps: bool, utc_us: Option<i64>) {
        self.with_gps += u64::from(has_gps);
        if let Some(us) = utc_us {
            self.first_utc_us.get_or_insert(us);
            self.last_utc_us = Some(us);
        }
    }
}

impl SummaryBuilder {
    /// An empty builder.
    #[must_use]
    pub fn new() -> Self {
        Self {
            rows: Some(RowAssembler::new()),
            ..Self::default()
        }
    }

    /// An empty builder for a caller that assembles the log's rows itself
    /// (from the same records): it hands their [`RowStats`] to
    /// [`SummaryBuilder::finish_with_rows`] rather than having every row
    /// assembled twice.
    #[must_use]
    pub fn rows_elsewhere() -> Self {
        Self::default()
    }

    /// Takes one decoder event.
    pub fn observe(&mut self, event: &Event<'_>) {
        let Event::Record(record) = event else {
            self.summary.losses.observe(event);
            if let Event::TimeJump { .. } = event {
                self.close_segment();
            }
            return;
        };
        let s = &mut self.summary;
        // Not for frames, nearly every record, which keep integer times.
        let t_s = || record.t_us() as f64 / 1e6;
        self.kinds[kind_index(record)] += 1;
        match record {
            Record::Frame(f) => {
                s.samples += 1;
                self.frame_times.take(f.t_us);
                self.segment_frames += 1;
                let first = self.span_us.map_or(f.t_us, |(first, _)| first);
                self.span_us = Some((first, f.t_us));
            }
            Record::Gps(_) => s.gps_fixes += 1,
            Record::UtcSync(sync) => {
                if let Ok(ms) = i64::try_from(sync.unix_ms) {
                    s.utc_syncs.push((t_s(), ms));
                }
            }
            Record::Alert(a) if a.on => s.alerts.push(AlertSpan {
                on_s: t_s(),
                off_s: None,
                freq_hz: f32::from(a.freq_chz) / 100.0,
                amp_deg: f32::from(a.amp_cdeg) / 100.0,
            }),
            Record::Alert(_) => {
                if let Some(open) = s.alerts.last_mut().filter(|a| a.off_s.is_none()) {
                    open.off_s = Some(t_s());
                }
            }
            Record::Marker(_) => s.markers.push(t_s()),
            Record::Dropout(d) => {
                *s.dropouts.entry(d.reason.as_str()).or_default() += 1;
                s.frames_dropped += u64::from(d.frames_lost);
            }
            Record::Fault(f) => {
                *s.faults.entry(f.source.as_str()).or_default() += u64::from(f.count.max(1))
            }
            Record::LogInfo(info) => {
                // Kept as written; text output escapes it (JSON has its own escapes).
                s.firmware = Some(info.firmware.to_string());
                s.device_id = Some(info.device_id.iter().map(|b| format!("{b:02x}")).collect());
                s.run = Some(info.run);
                s.sample_rate_hz = Some(info.sample_rate_hz);
            }
            Record::Kick(k) => {
                s.kicks += 1;
                s.kick_records.push(*k);
            }
            // `wobblog events` lists the margin warning.
            Record::Channel(_) | Record::Margin(_) => {}
            Record::Config(line) => s.config.push(line.text.to_string()),
        }
        if let Some(rows) = &mut self.rows {
            let stats = &mut self.row_stats;
            rows.push(record, &mut |row: &Row| stats.take(row));
        }
    }

    /// The frame rate the log has given so far (see
    /// [`Summary::frame_rate_hz`]).
    #[must_use]
    pub fn frame_rate_hz(&self) -> f64 {
        self.summary.frame_rate_hz()
    }

    /// The config lines the log has given so far (its header's).
    #[must_use]
    pub fn config(&self) -> &[String] {
        &self.summary.config
    }

    fn period_us(&self) -> u64 {
        1_000_000 / u64::from(self.summary.sample_rate_hz.unwrap_or(100).max(1))
    }

    /// Adds the current segment's span to the duration.
    fn close_segment(&mut self) {
        if let Some((first, last)) = self.span_us.take() {
            self.closed_us += last.saturating_sub(first).saturating_add(self.period_us());
            self.summary.segments += 1;
            let frames = std::mem::take(&mut self.segment_frames);
            if self
                .summary
                .longest_segment
                .is_none_or(|(_, most)| frames > most)
            {
                let span_s = (first as f64 / 1e6, last as f64 / 1e6);
                self.summary.longest_segment = Some((span_s, frames));
            }
        }
    }

    /// The summary, given the decoder's totals.
    #[must_use]
    pub fn finish(mut self, stats: &DecodeStats) -> Summary {
        if let Some(rows) = &mut self.rows {
            let row_stats = &mut self.row_stats;
            rows.finish(&mut |row: &Row| row_stats.take(row));
        }
        self.finish_rows_taken(stats)
    }

    /// The summary, given the decoder's totals and those of the rows the
    /// caller assembled (see [`SummaryBuilder::rows_elsewhere`]).
    #[must_use]
    pub fn finish_with_rows(mut self, stats: &DecodeStats, rows: RowStats) -> Summary {
        self.rows = None;
        self.row_stats = rows;
        self.finish_rows_taken(stats)
    }

    fn finish_rows_taken(mut self, stats: &DecodeStats) -> Summary {
        self.close_segment();
        let mut s = self.summary;
        self.frame_times.fill(&mut s);
        let utc_text = |us: Option<i64>| us.and_then(iso8601_unix_us);
        s.first_utc = utc_text(self.row_stats.first_utc_us);
        s.first_utc_us = self.row_stats.first_utc_us;
        s.last_utc = utc_text(self.row_stats.last_utc_us);
        s.duration_s = self.closed_us as f64 / 1e6;
        for (name, &count) in KIND_NAMES.iter().zip(&self.kinds) {
            if count > 0 {
                let rate_hz = (s.duration_s > 0.0).then(|| count as f64 / s.duration_s);
                s.records.insert(name, RecordCount { count, rate_hz });
            }
        }
        s.gps_coverage_pct = if s.samples == 0 {
            0.0
        } else {
            100.0 * self.row_stats.with_gps as f64 / s.samples as f64
        };
        s.lost_blocks = stats.blocks_lost;
        s.frames_lost = stats.frames_lost;
        s.damaged_blocks = stats.damaged_blocks;
        s.bytes_skipped = stats.bytes_skipped;
        s.unwritten_blocks = stats.unwritten_blocks;
        s.bad_records = stats.bad_records;
        s.time_jumps = stats.time_jumps;
        s.forward_time_jumps = stats.forward_time_jumps;
        s.out_of_order_blocks = stats.out_of_order_blocks;
        s.repeated_blocks = stats.repeated_blocks;
        s.out_of_range = stats.out_of_range;
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use wobble_core::format::GpsFix;

    /// A fix counts as one with a position only with both coordinates (the
    /// card's format stores them together; a record made otherwise must
    /// not be counted as a position).
    #[test]
    fn a_fix_needs_both_coordinates_to_count_as_a_position() {
        let mut builder = SummaryBuilder::new();
        let fixes = [
            (Some(520_000_000), Some(43_000_000)),
            (Some(520_000_000), None),
            (None, Some(43_000_000)),
            (None, None),
        ];
        for (i, (lat_e7, lon_e7)) in fixes.into_iter().enumerate() {
            let fix = GpsFix {
                t_us: 1000 * i as u64,
                lat_e7,
                lon_e7,
                ..GpsFix::default()
            };
            builder.observe(&Event::Record(Record::Gps(fix)));
        }
        let summary = builder.finish(&DecodeStats::default());
        let count = |kind: &str| summary.records.get(kind).map(|c| c.count);
        assert_eq!(count("gps_fix"), Some(1));
        assert_eq!(count("gps_no_position"), Some(3));
        assert_eq!(summary.gps_fixes, 4);
    }
}
