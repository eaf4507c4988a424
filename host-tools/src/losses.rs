//! What a decode could not recover, collected for reports.

use serde::Serialize;
use wobble_core::format::{Event, Gap, OutOfRange, SkipCause};

/// Entries kept per list; beyond that only the totals in `DecodeStats` grow.
const MAX_ENTRIES: usize = 1000;

/// A stretch of the file that was not a valid block.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Skipped {
    /// File offset of the first byte.
    pub offset: u64,
    /// Length in bytes.
    pub len: u64,
    /// Why (`damaged`, `garbage`, `truncated_tail`, ...).
    pub cause: &'static str,
}

/// A stretch of missing blocks between two valid ones.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct LostBlocks {
    /// First missing block number.
    pub first_block: u32,
    /// Last missing block number.
    pub last_block: u32,
    /// Frames those blocks held.
    pub frames: u32,
    /// Time of the last frame before the gap, s (absent at the start of a file).
    pub from_s: Option<f64>,
    /// Time base of the block after the gap, s.
    pub to_s: f64,
}

impl From<&Gap> for LostBlocks {
    fn from(g: &Gap) -> Self {
        Self {
            first_block: g.first_seq,
            last_block: g.first_seq + g.blocks.saturating_sub(1),
            frames: g.frames,
            from_s: g.from_us.map(|t| t as f64 / 1e6),
            to_s: g.to_us as f64 / 1e6,
        }
    }
}

/// The damage a decode found, in file order.
#[derive(Clone, Debug, Default, Serialize)]
pub struct Losses {
    /// Missing blocks, with the frames and time they held.
    pub lost_blocks: Vec<LostBlocks>,
    /// Bytes that were not valid blocks, adjacent stretches merged.
    pub skipped: Vec<Skipped>,
    /// Valid blocks whose records could not all be read: (block, error).
    pub bad_records: Vec<(u32, String)>,
    /// Frames whose time jumped, backwards or forwards beyond what missing
    /// frames explain: (from s, to s). Each starts a new segment.
    pub time_jumps: Vec<(f64, f64)>,
    /// Values the firmware cannot have written, dropped or replaced:
    /// (block, what).
    pub out_of_range: Vec<(u32, String)>,
}

impl Losses {
    /// Notes an event if it is a loss.
    pub fn observe(&mut self, event: &Event<'_>) {
        match event {
            Event::Gap(g) => push_capped(&mut self.lost_blocks, LostBlocks::from(g)),
            Event::Skipped { offset, len, cause } => {
                let cause = cause_name(*cause);
                match self.skipped.last_mut() {
                    Some(last) if last.offset + last.len == *offset && last.cause == cause => {
                        last.len += len
                    }
                    _ => push_capped(
                        &mut self.skipped,
                        Skipped {
                            offset: *offset,
                            len: *len,
                            cause,
                        },
                    ),
                }
            }
            Event::BadRecord { seq, error } => {
                push_capped(&mut self.bad_records, (*seq, error.to_string()))
            }
            Event::TimeJump { from_us, to_us } => {
                push_capped(
                    &mut self.time_jumps,
                    (*from_us as f64 / 1e6, *to_us as f64 / 1e6),
                );
            }
            Event::OutOfRange { seq, what } => {
                push_capped(&mut self.out_of_range, (*seq, out_of_range_text(*what)))
            }
            Event::Record(_) => {}
        }
    }

    /// One human-readable line per loss.
    #[must_use]
    pub fn describe(&self) -> Vec<String> {
        let mut lines = Vec::new();
        for g in &self.lost_blocks {
            let from = g
                .from_s
                .map_or("the start".to_string(), |t| format!("{t:.3} s"));
            lines.push(format!(
                "blocks {}-{} lost: {} frames between {from} and {:.3} s",
                g.first_block, g.last_block, g.frames, g.to_s
            ));
        }
        for s in &self.skipped {
            lines.push(format!(
                "{} bytes skipped at offset {} ({})",
                s.len, s.offset, s.cause
            ));
        }
        for (seq, error) in &self.bad_records {
            lines.push(format!(
                "block {seq}: {error}; rest of the block unreadable"
            ));
        }
        for (from, to) in &self.time_jumps {
            let way = if to < from { "back" } else { "forward" };
            lines.push(format!(
                "time jumps {way} from {from:.6} s to {to:.6} s; a new segment starts"
            ));
        }
        for (seq, what) in &self.out_of_range {
            lines.push(format!("block {seq}: {what}"));
        }
        lines
    }
}

fn push_capped<T>(list: &mut Vec<T>, item: T) {
    if list.len() < MAX_ENTRIES {
        list.push(item);
    }
}

/// The words for why bytes were skipped.
pub fn cause_name(cause: SkipCause) -> &'static str {
    match cause {
        SkipCause::Damaged => "damaged block",
        SkipCause::UnsupportedVersion(_) => "unsupported format version",
        SkipCause::BadHeader => "bad block header",
        SkipCause::Garbage => "garbage",
        SkipCause::TruncatedTail => "truncated tail",
        SkipCause::Repeated => "copies of blocks decoded once",
    }
}

/// What an out-of-range value was and what became of it, in words.
#[must_use]
pub fn out_of_range_text(what: OutOfRange) -> String {
    match what {
        OutOfRange::SampleRate(hz) => format!(
            "sample rate {hz} Hz is not one the logger runs at; {} Hz used",
            wobble_core::format::limits::DEFAULT_SAMPLE_RATE_HZ
        ),
        OutOfRange::GpsFields(n) => format!("{n} GPS values out of range dropped"),
        OutOfRange::UtcSync => "UTC sync outside 2000-2099 dropped".into(),
        OutOfRange::FrameSpacing {
            stated_hz,
            spacing_us,
        } => format!(
            "the header states {stated_hz} Hz but frames come every {spacing_us} us \
             (about {:.0} Hz): rates, distances and frequencies taken from the header are off",
            1e6 / f64::from(spacing_us.max(1))
        ),
    }
}
