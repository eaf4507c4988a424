//! Everything that happened in a log besides the samples, in time order:
//! what `wobblog events` lists.

use serde::Serialize;
use wobble_core::format::Event;
use wobble_core::format::Record;

use crate::codes::{dropout_meaning, fault_meaning};
use crate::losses::{cause_name, LostBlocks};

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
}

impl EventKind {
    /// The kind's name, as in the JSON `event` field.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            Self::AlertOn { .. } => "alert_on",
            Self::AlertOff => "alert_off",
            Self::Marker { .. } => "marker",
            Self::Fault { .. } => "fault",
            Self::Dropout { .. } => "dropout",
            Self::LostBlocks { .. } => "lost_blocks",
            Self::Skipped { .. } => "skipped",
            Self::BadRecord { .. } => "bad_record",
            Self::TimeJump { .. } => "time_jump",
            Self::OutOfRange { .. } => "out_of_range",
        }
    }

    /// The details in words, for the table.
    #[must_use]
    pub fn describe(&self) -> String {
        match self {
            Self::AlertOn { freq_hz, amp_deg } => format!("{freq_hz:.2} Hz, {amp_deg:.2} deg"),
            Self::AlertOff => String::new(),
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
        }
    }
}

/// Turns decoder events into [`LogEvent`]s, and collects them.
#[derive(Default)]
pub struct EventCollector {
    events: Vec<LogEvent>,
    last_t_s: f64,
}

impl EventCollector {
    /// An empty collector.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes one decoder event and keeps it if it is a [`LogEvent`].
    pub fn observe(&mut self, event: &Event<'_>) {
        if let Some(e) = self.convert(event) {
            self.events.push(e);
        }
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

    /// The events in time order (file order among equal times).
    #[must_use]
    pub fn finish(mut self) -> Vec<LogEvent> {
        self.events.sort_by(|a, b| a.t_s.total_cmp(&b.t_s));
        self.events
    }
}

fn record_event(record: &Record<'_>) -> Option<EventKind> {
    Some(match record {
        Record::Alert(a) if a.on => EventKind::AlertOn {
            freq_hz: f64::from(a.freq_chz) / 100.0,
            amp_deg: f64::from(a.amp_cdeg) / 100.0,
        },
        Record::Alert(_) => EventKind::AlertOff,
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
