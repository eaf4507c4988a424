//! What cuts a stretch of a run: the ends of the data, blocks lost from the
//! file, frames the logger dropped, or a jump of its clock. An analysis
//! whose window reaches one of these only saw part of what happened.

use serde::Serialize;

use super::run::Run;

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
        }
    }
}

/// Frame times match a reported time when this close, s (times are whole
/// microseconds on both sides).
const SAME_TIME_S: f64 = 1e-6;

/// What lies between frames `i` and `i + 1` of `run`, which are not one
/// frame period apart.
#[must_use]
pub fn cut_after(run: &Run, i: usize) -> Cut {
    let (before, after) = (run.t_s[i], run.t_s[i + 1]);
    let losses = &run.summary.losses;
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

/// What cuts the stretch `span` of `run` at its start and at its end.
#[must_use]
pub fn span_cuts(run: &Run, span: &std::ops::Range<usize>) -> (Cut, Cut) {
    let start = if span.start == 0 {
        Cut::DataStart
    } else {
        cut_after(run, span.start - 1)
    };
    let end = if span.end >= run.len() {
        Cut::DataEnd
    } else {
        cut_after(run, span.end - 1)
    };
    (start, end)
}
