//! What cuts a stretch of a run: the ends of the data, blocks lost from the
//! file, frames the logger dropped, or a jump of its clock. An analysis
//! whose window reaches one of these only saw part of what happened.

use serde::Serialize;

use crate::losses::Losses;

/// Why the data stop (or start) at a point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Cut {
    /// The first frame of the log.
    DataStart,
    /// The last frame of the log (a run cut short, or a power cut).
    DataEnd,
    /// Blocks missing from the file (damaged or lost).
    LostBlocks,
    /// Frames missing that no lost block accounts for: dropped by the
    /// logger (its dropout records say why).
    Dropout,
    /// The frame times jump (backwards, or forwards beyond missing frames).
    TimeJump,
    /// The steering stays above the quiet level for longer than the
    /// analysis holds at once ([`super::search::MAX_WINDOW_FRAMES`] frames):
    /// the stretch is measured in pieces, each cut here.
    Overlong,
}

impl Cut {
    /// The name used in tables, JSON and CSV.
    #[must_use]
    pub const fn as_str(self) -> &'static str {
        match self {
            Self::DataStart => "data_start",
            Self::DataEnd => "data_end",
            Self::LostBlocks => "lost_blocks",
            Self::Dropout => "dropout",
            Self::TimeJump => "time_jump",
            Self::Overlong => "overlong",
        }
    }
}

/// Frame times match a reported time when this close, s (times are whole
/// microseconds on both sides).
const SAME_TIME_S: f64 = 1e-6;

/// Where a stretch of frames starts or stops, as seen while the frames
/// stream by; which [`Cut`] it is follows from the losses of the whole log.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Edge {
    /// The first frame of the log.
    DataStart,
    /// The last frame of the log.
    DataEnd,
    /// Between frames at these two times, s, which are not one frame period
    /// apart.
    Between(f64, f64),
    /// Where the analysis window was full (see [`Cut::Overlong`]).
    Overlong,
}

impl Edge {
    /// What the edge is, given the log's `losses`.
    #[must_use]
    pub fn cut(self, losses: &Losses) -> Cut {
        match self {
            Self::DataStart => Cut::DataStart,
            Self::DataEnd => Cut::DataEnd,
            Self::Overlong => Cut::Overlong,
            Self::Between(before, after) => cut_between(losses, before, after),
        }
    }
}

/// What lies between frames at `before` and `after`, s, which are not one
/// frame period apart.
#[must_use]
pub fn cut_between(losses: &Losses, before: f64, after: f64) -> Cut {
    let same = |a: f64, b: f64| (a - b).abs() <= SAME_TIME_S;
    if losses
        .time_jumps
        .iter()
        .any(|&(from, to)| same(from, before) && same(to, after))
    {
        Cut::TimeJump
    } else if losses
        .lost_blocks
        .iter()
        .any(|g| g.from_s.is_some_and(|from| same(from, before)))
    {
        Cut::LostBlocks
    } else {
        Cut::Dropout
    }
}
