//! Everything that happened in a log besides the samples, in time order:
//! what `wobblog events` lists, as the log is read.

use std::cmp::{Ordering, Reverse};
use std::collections::BinaryHeap;

use serde::Serialize;
use wobble_core::format::Record;
use wobble_core::format::{Event, MarginRecord, MarginState};

use crate::codes::{dropout_meaning, fault_meaning};
use crate::losses::{cause_name, LostBlocks};
use crate::time::{utc_us_after_pair, SyncPair};

/// One thing that happened, at a time since boot.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LogEvent {
    /// Seconds since boot (for damage: the last time read before it).
    pub t_s: f64,
    /// What happened.
    #[serde(flatten)]
    pub kind: EventKind,
}

/// The kinds of events, with their details. Serialised with an `event`
/// field naming the kind in lower case.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum EventKind {
    /// The on-board detector switched the alert on.
    AlertOn {
        /// Dominant frequency, Hz.
        freq_hz: f64,
        /// Steering amplitude, degrees.
        amp_deg: f64,
    },
    /// The alert switched off.
    AlertOff,
    /// A kick's ring-down as the detector measured it on board (the time
    /// is the kick's).
    Kick {
        /// Mean speed over the ring, m/s (`null`: unknown).
        speed_mps: Option<f64>,
        /// Ring frequency, Hz.
        freq_hz: f64,
        /// Growth rate, 1/s (negative: decaying).
        sigma_per_s: f64,
        /// Ring amplitude at the kick, degrees.
        amp_deg: f64,
        /// Standard error of `sigma_per_s`, 1/s.
        sigma_se_per_s: f64,
    },
    /// A kick updated the on-board estimate of the wobble speed.
    MarginEstimate(Margin),
    /// The on-board margin warning started: the speed came within
    /// `alert.margin_mps` of the estimate's lower bound.
    Approaching(Margin),
    /// The margin warning stopped: the speed stayed clear of it.
    ApproachingOff(Margin),
    /// The rider pressed the marker button.
    Marker {
        /// Marker number since boot.
        id: u16,
    },
    /// Counted faults of one source and code.
    Fault {
        /// Where (`imu`, `gps`, ...).
        source: &'static str,
        /// Code, per source.
        code: u8,
        /// Faults since the previous record of this kind.
        count: u16,
        /// What the code means.
        meaning: &'static str,
    },
    /// Frames the logger could not write.
    Dropout {
        /// How many.
        frames_lost: u32,
        /// Why (`queue_full`, ...).
        reason: &'static str,
        /// What the reason means.
        meaning: &'static str,
    },
    /// Blocks missing from the file.
    LostBlocks {
        /// First missing block number.
        first_block: u32,
        /// Last missing block number.
        last_block: u32,
        /// Frames they held.
        frames: u32,
        /// Where the data resumes, s.
        to_s: f64,
    },
    /// Bytes that were not valid blocks.
    Skipped {
        /// File offset.
        offset: u64,
        /// Length in bytes.
        len: u64,
        /// Why.
        cause: &'static str,
    },
    /// A valid block whose records could not all be read.
    BadRecord {
        /// Block number.
        block: u32,
        /// What was wrong.
        error: String,
    },
    /// A frame whose time went backwards, or forwards beyond what missing
    /// frames explain.
    TimeJump {
        /// The time it went to, s.
        to_s: f64,
    },
    /// A value the firmware cannot have written, dropped or replaced.
    OutOfRange {
        /// Block number.
        block: u32,
        /// What it was and what became of it.
        what: String,
    },
    /// A wobble episode or weave ring-down the host measured in the frames
    /// (`wobblog events --episodes`; the time is its onset), as `wobblog
    /// wobble` lists it.
    Episode {
        /// `wobble` or `weave`.
        mode: &'static str,
        /// Frequency, Hz.
        freq_hz: f64,
        /// Growth rate, 1/s (negative: decaying).
        sigma_per_s: f64,
        /// Speed at onset, m/s.
        speed_mps: f64,
        /// Where it ends, s since boot.
        end_s: f64,
    },
}

/// What a margin record says: the speed at the time and the wobble speed
/// the ride's kicks predict on board.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Margin {
    /// Wheel speed at the time, m/s (`null`: unknown).
    pub speed_mps: Option<f64>,
    /// The predicted wobble speed, m/s (`null`: only a lower bound, or no
    /// estimate).
    pub wobble_speed_mps: Option<f64>,
    /// Its 95 % interval, m/s: `[lower, upper]`, `null` where open (or no
    /// estimate).
    pub ci95_mps: [Option<f64>; 2],
    /// Kicks the estimate was made from.
    pub kicks: u8,
}

impl Margin {
    /// The fields of a margin record.
    #[must_use]
    pub fn of(m: &MarginRecord) -> Self {
        let mps = |v: Option<u16>| v.map(|v| f64::from(v) / 1000.0);
        Self {
            speed_mps: mps(m.speed_mm_s),
            wobble_speed_mps: mps(m.estimate_mm_s),
            ci95_mps: [mps(m.lower_mm_s), mps(m.upper_mm_s)],
            kicks: m.kicks,
        }
    }

    /// The event of a margin record (`None` for a state of a later minor
    /// version, which this reader cannot name).
    #[must_use]
    pub fn event(m: &MarginRecord) -> Option<EventKind> {
        let fields = Self::of(m);
        Some(match m.state {
            MarginState::Estimate => EventKind::MarginEstimate(fields),
            MarginState::Approaching => EventKind::Approaching(fields),
            MarginState::Clear => EventKind::ApproachingOff(fields),
            MarginState::Other(_) => return None,
        })
    }

    fn describe(&self) -> String {
        let v = |x: Option<f64>| x.map_or("-".to_owned(), |v| format!("{v:.2}"));
        let speed = self
            .speed_mps
            .map_or("speed unknown".to_owned(), |v| format!("at {v:.2} m/s"));
        format!(
            "wobble speed {} m/s (95 % {}-{}) from {} kicks, {speed}",
            v(self.wobble_speed_mps),
            v(self.ci95_mps[0]),
            self.ci95_mps[1].map_or("open".to_owned(), |h| format!("{h:.2}")),
            self.kicks
        )
    }
}

impl LogEvent {
    /// A wobble episode or weave ring-down the host measured.
    #[must_use]
    pub fn of_episode(e: &crate::analysis::Episode) -> Self {
        Self {
            t_s: e.onset_s,
            kind: EventKind::Episode {
                mode: e.mode.as_str(),
                freq_hz: e.freq_hz,
                sigma_per_s: e.sigma_per_s,
                speed_mps: e.speed_at_onset_mps,
                end_s: e.end_s,
            },
        }
    }
}

impl EventKind {
    /// The kind's name, as in the JSON `event` field.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::AlertOn { .. } => "alert_on",
            Self::AlertOff => "alert_off",
            Self::Kick { .. } => "kick",
            Self::MarginEstimate(_) => "margin_estimate",
            Self::Approaching(_) => "approaching",
            Self::ApproachingOff(_) => "approaching_off",
            Self::Marker { .. } => "marker",
            Self::Fault { .. } => "fault",
            Self::Dropout { .. } => "dropout",
            Self::LostBlocks { .. } => "lost_blocks",
            Self::Skipped { .. } => "skipped",
            Self::BadRecord { .. } => "bad_record",
            Self::TimeJump { .. } => "time_jump",
            Self::OutOfRange { .. } => "out_of_range",
            Self::Episode { .. } => "episode",
        }
    }

    /// The details in words, for the table.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::AlertOn { freq_hz, amp_deg } => format!("{freq_hz:.2} Hz, {amp_deg:.2} deg"),
            Self::AlertOff => String::new(),
            Self::Kick {
                speed_mps,
                freq_hz,
                sigma_per_s,
                amp_deg,
                sigma_se_per_s,
            } => format!(
                "{freq_hz:.2} Hz, sigma {sigma_per_s:.2} +- {sigma_se_per_s:.2} 1/s, {amp_deg:.2} deg, {}",
                speed_mps.map_or("speed unknown".to_owned(), |v| format!("{v:.2} m/s"))
            ),
            Self::MarginEstimate(m) | Self::Approaching(m) | Self::ApproachingOff(m) => {
                m.describe()
            }
            Self::Marker { id } => format!("marker {id}"),
            Self::Fault {
                source,
                code,
                count,
                meaning,
            } => format!("{source} {code} x{count}: {meaning}"),
            Self::Dropout {
                frames_lost,
                reason,
                meaning,
            } => format!("{frames_lost} frames ({reason}: {meaning})"),
            Self::LostBlocks {
                first_block,
                last_block,
                frames,
                to_s,
            } => format!(
                "blocks {first_block}-{last_block}: {frames} frames, resumes at {to_s:.3} s"
            ),
            Self::Skipped { offset, len, cause } => {
                format!("{len} bytes at offset {offset} ({cause})")
            }
            Self::BadRecord { block, error } => format!("block {block}: {error}"),
            Self::TimeJump { to_s } => format!("to {to_s:.6} s"),
            Self::OutOfRange { block, what } => format!("block {block}: {what}"),
            Self::Episode {
                mode,
                freq_hz,
                sigma_per_s,
                speed_mps,
                end_s,
            } => format!(
                "{mode} (host): {freq_hz:.2} Hz, sigma {sigma_per_s:.2} 1/s, {speed_mps:.2} m/s, to {end_s:.3} s"
            ),
        }
    }
}

/// Turns decoder events into [`LogEvent`]s.
#[derive(Default)]
pub struct EventConverter {
    last_t_s: f64,
}

impl EventConverter {
    /// A converter at the start of a log.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// The [`LogEvent`] of a decoder event, if it is one (not kept).
    pub fn convert(&mut self, event: &Event<'_>) -> Option<LogEvent> {
        let (t_s, kind) = match event {
            Event::Record(record) => {
                let t_s = record.t_us() as f64 / 1e6;
                self.last_t_s = t_s;
                (t_s, record_event(record)?)
            }
            Event::Gap(gap) => {
                let lost = LostBlocks::from(gap);
                (
                    lost.from_s.unwrap_or(lost.to_s),
                    EventKind::LostBlocks {
                        first_block: lost.first_block,
                        last_block: lost.last_block,
                        frames: lost.frames,
                        to_s: lost.to_s,
                    },
                )
            }
            Event::Skipped { offset, len, cause } => (
                self.last_t_s,
                EventKind::Skipped {
                    offset: *offset,
                    len: *len,
                    cause: cause_name(*cause),
                },
            ),
            Event::BadRecord { seq, error } => (
                self.last_t_s,
                EventKind::BadRecord {
                    block: *seq,
                    error: error.to_string(),
                },
            ),
            Event::OutOfRange { seq, what } => (
                self.last_t_s,
                EventKind::OutOfRange {
                    block: *seq,
                    what: crate::losses::out_of_range_text(*what),
                },
            ),
            Event::TimeJump { from_us, to_us } => (
                *from_us as f64 / 1e6,
                EventKind::TimeJump {
                    to_s: *to_us as f64 / 1e6,
                },
            ),
        };
        Some(LogEvent { t_s, kind })
    }
}

/// How far behind the latest time an event may come and still be put in
/// its place, s: a GPS fix is written up to an epoch (about a second) after
/// its time, and nothing else comes late.
pub const REORDER_S: f64 = 10.0;
/// Most events held back for reordering, whatever their times.
pub const REORDER_MAX: usize = 4096;

/// Puts events that come nearly in time order into time order (file order
/// among equal times) while holding only those of the last [`REORDER_S`]
/// (at most [`REORDER_MAX`]): a log of any length, or with its clock jumping
/// at every block, costs the same memory.
#[derive(Default)]
pub struct TimeOrder {
    held: BinaryHeap<Reverse<Held>>,
    latest_s: Option<f64>,
    taken: u64,
}

/// An event held back, with its place in the file.
struct Held {
    seq: u64,
    event: LogEvent,
}

impl Held {
    fn key(&self) -> (f64, u64) {
        (self.event.t_s, self.seq)
    }
}

impl Ord for Held {
    fn cmp(&self, other: &Self) -> Ordering {
        let ((t, n), (u, m)) = (self.key(), other.key());
        t.total_cmp(&u).then(n.cmp(&m))
    }
}

impl PartialOrd for Held {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Held {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Held {}

impl TimeOrder {
    /// Nothing held yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes the next event in file order; `out` gets every event that no
    /// later one can come before, and its first error is returned.
    ///
    /// # Errors
    /// `out` failed.
    pub fn push<E>(
        &mut self,
        event: LogEvent,
        out: &mut impl FnMut(LogEvent) -> Result<(), E>,
    ) -> Result<(), E> {
        let latest_s = self.latest_s.map_or(event.t_s, |l| l.max(event.t_s));
        self.latest_s = Some(latest_s);
        self.held.push(Reverse(Held {
            seq: self.taken,
            event,
        }));
        self.taken += 1;
        while let Some(Reverse(first)) = self.held.peek() {
            if self.held.len() <= REORDER_MAX && first.event.t_s >= latest_s - REORDER_S {
                break;
            }
            if let Some(Reverse(first)) = self.held.pop() {
                out(first.event)?;
            }
        }
        Ok(())
    }

    /// Hands over every event still held, in order.
    ///
    /// # Errors
    /// `out` failed.
    pub fn finish<E>(mut self, out: &mut impl FnMut(LogEvent) -> Result<(), E>) -> Result<(), E> {
        while let Some(Reverse(first)) = self.held.pop() {
            out(first.event)?;
        }
        Ok(())
    }
}

fn record_event(record: &Record<'_>) -> Option<EventKind> {
    Some(match record {
        Record::Alert(a) if a.on => EventKind::AlertOn {
            freq_hz: f64::from(a.freq_chz) / 100.0,
            amp_deg: f64::from(a.amp_cdeg) / 100.0,
        },
        Record::Alert(_) => EventKind::AlertOff,
        Record::Kick(k) => EventKind::Kick {
            speed_mps: k.speed_mm_s.map(|v| f64::from(v) / 1000.0),
            freq_hz: f64::from(k.freq_chz) / 100.0,
            sigma_per_s: f64::from(k.sigma_milli_per_s) / 1000.0,
            amp_deg: f64::from(k.amp_cdeg) / 100.0,
            sigma_se_per_s: f64::from(k.sigma_se_milli_per_s) / 1000.0,
        },
        Record::Margin(m) => return Margin::event(m),
        Record::Marker(m) => EventKind::Marker { id: m.id },
        Record::Fault(f) => EventKind::Fault {
            source: f.source.as_str(),
            code: f.code,
            count: f.count,
            meaning: fault_meaning(f.source, f.code),
        },
        Record::Dropout(d) => EventKind::Dropout {
            frames_lost: d.frames_lost,
            reason: d.reason.as_str(),
            meaning: dropout_meaning(d.reason),
        },
        _ => return None,
    })
}

/// A log's events as its decoder hands them over, in time order, each with
/// its UTC (µs since 1970) through the sync pairs read so far, as
/// `decode`'s `utc` column places a frame: what `wobblog events` lists,
/// run beside any other reading of the log.
#[derive(Default)]
pub struct EventWalk {
    converter: EventConverter,
    order: TimeOrder,
    /// Every pair: an event held back may come before the latest one.
    pairs: Vec<SyncPair>,
}

impl EventWalk {
    /// Takes one decoder event; hands `visit` each event now in time order,
    /// with its UTC and the pairs read so far. An error from `visit` is
    /// returned.
    ///
    /// # Errors
    /// `visit`'s.
    pub fn observe<E>(
        &mut self,
        event: &Event<'_>,
        visit: &mut impl FnMut(LogEvent, Option<i64>, &[SyncPair]) -> Result<(), E>,
    ) -> Result<(), E> {
        let Self {
            converter,
            order,
            pairs,
        } = self;
        if let Event::Record(Record::UtcSync(pair)) = event {
            if let Ok(ms) = i64::try_from(pair.unix_ms) {
                pairs.push((pair.t_us as f64 / 1e6, ms));
            }
        }
        match converter.convert(event) {
            Some(e) => order.push(e, &mut |e: LogEvent| {
                let utc = utc_us_after_pair(pairs, e.t_s);
                visit(e, utc, pairs)
            }),
            None => Ok(()),
        }
    }

    /// Hands `visit` the events still held, at the end of the log.
    ///
    /// # Errors
    /// `visit`'s.
    pub fn finish<E>(
        &mut self,
        visit: &mut impl FnMut(LogEvent, Option<i64>, &[SyncPair]) -> Result<(), E>,
    ) -> Result<(), E> {
        let pairs = &self.pairs;
        std::mem::take(&mut self.order).finish(&mut |e: LogEvent| {
            let utc = utc_us_after_pair(pairs, e.t_s);
            visit(e, utc, pairs)
        })
    }

    /// The log's sync pairs read so far.
    #[must_use]
    pub fn pairs(&self) -> &[SyncPair] {
        &self.pairs
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn event(t_s: f64, id: u16) -> LogEvent {
        LogEvent {
            t_s,
            kind: EventKind::Marker { id },
        }
    }

    fn ordered(events: &[LogEvent]) -> (Vec<LogEvent>, usize) {
        let mut order = TimeOrder::new();
        let mut out = Vec::new();
        let mut most_held = 0;
        for e in events {
            let pushed: Result<(), ()> = order.push(e.clone(), &mut |e| {
                out.push(e);
                Ok(())
            });
            pushed.unwrap();
            most_held = most_held.max(order.held.len());
        }
        let finished: Result<(), ()> = order.finish(&mut |e| {
            out.push(e);
            Ok(())
        });
        finished.unwrap();
        (out, most_held)
    }

    proptest! {
        /// Events at most `REORDER_S` behind the latest come out as a
        /// stable sort by time would put them.
        #[test]
        fn nearly_ordered_events_come_out_sorted(
            steps in prop::collection::vec((0.0..5.0f64, 0.0..REORDER_S), 0..300),
        ) {
            let mut clock = 0.0;
            let events: Vec<LogEvent> = steps
                .iter()
                .enumerate()
                .map(|(i, &(step, late))| {
                    clock += step;
                    event((clock - late).max(0.0).round(), i as u16)
                })
                .collect();
            let mut sorted = events.clone();
            sorted.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
            prop_assert_eq!(ordered(&events).0, sorted);
        }

        /// Whatever the times, every event comes out once.
        #[test]
        fn every_event_comes_out_once(times in prop::collection::vec(-1e9..1e9f64, 0..300)) {
            let events: Vec<LogEvent> =
                times.iter().enumerate().map(|(i, &t)| event(t, i as u16)).collect();
            let mut ids: Vec<u16> = ordered(&events)
                .0
                .iter()
                .map(|e| match e.kind {
                    EventKind::Marker { id } => id,
                    _ => unreachable!(),
                })
                .collect();
            ids.sort_unstable();
            prop_assert_eq!(ids, (0..events.len() as u16).collect::<Vec<_>>());
        }
    }

    #[test]
    fn what_is_held_is_bounded_by_time_and_by_count() {
        // A clock jumping forward at every event: nothing waits.
        let jumping: Vec<LogEvent> = (0..10_000).map(|i| event(f64::from(i) * 1e6, 0)).collect();
        assert_eq!(ordered(&jumping).1, 1);
        // Ten thousand events at one instant: at most the cap waits, and
        // they come out in file order.
        let still: Vec<LogEvent> = (0..10_000).map(|i| event(5.0, i)).collect();
        let (out, most_held) = ordered(&still);
        assert_eq!(most_held, REORDER_MAX);
        assert_eq!(out, still);
    }
}
