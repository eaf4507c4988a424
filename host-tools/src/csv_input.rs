//! Checks on CSV input shared by `encode` and `detect`: every value is a
//! finite number the log can store, and the time column advances at the
//! log's sample rate. Errors name the file, the line and the column.

use std::io::{self, Read};
use std::path::Path;

use crate::CliError;

/// Where a value sits in the CSV, for messages.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Cell<'a> {
    /// Line in the file, from 1 (the header is line 1).
    pub line: u64,
    /// Column, from 1.
    pub column: usize,
    /// The column's name in the header.
    pub name: &'a str,
}

impl Cell<'_> {
    /// An error about this cell of `path`.
    pub fn error(&self, path: &Path, what: impl std::fmt::Display) -> CliError {
        CliError::file(
            path,
            format!(
                "line {}, column {}: `{}` {what}",
                self.line, self.column, self.name
            ),
        )
    }
}

/// The value of `text` if it is a finite number within `range` (both ends
/// included), else what is wrong with it. NaN and infinities are never
/// accepted: a log stores neither, and clamping them would invent data.
pub fn number_in(text: &str, range: (f64, f64), unit: &str) -> Result<f64, String> {
    let v: f64 = text
        .parse()
        .map_err(|_| format!("is not a number: {}", echo(text)))?;
    if !v.is_finite() {
        return Err(format!(
            "is {}: only finite numbers can be stored",
            cut(text)
        ));
    }
    let (lo, hi) = range;
    if !(lo..=hi).contains(&v) {
        return Err(format!(
            "is {v}, outside what the log stores ({lo} to {hi}{unit})"
        ));
    }
    Ok(v)
}

/// Characters of a cell shown in a message; a longer cell is cut.
const ECHO_CHARS: usize = 40;

/// `text` quoted for a message, cut after [`ECHO_CHARS`] characters (with
/// its length), its control characters escaped.
#[must_use]
pub fn echo(text: &str) -> String {
    match text.char_indices().nth(ECHO_CHARS) {
        None => format!("{text:?}"),
        Some((end, _)) => format!("{:?}... ({} bytes)", &text[..end], text.len()),
    }
}

/// Longest CSV line read, bytes: a line of samples is a few hundred; a
/// longer one is not a CSV of samples and is refused before it fills memory.
pub const LINE_MAX: usize = 1 << 20;

/// A reader that fails once a line grows past [`LINE_MAX`] bytes.
pub struct LineCap<R> {
    inner: R,
    /// Bytes since the last newline.
    run: usize,
    /// Newlines so far.
    lines: u64,
}

impl<R: Read> LineCap<R> {
    /// Caps the lines of `inner`.
    pub fn new(inner: R) -> Self {
        Self {
            inner,
            run: 0,
            lines: 0,
        }
    }
}

impl<R: Read> Read for LineCap<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        let n = self.inner.read(buf)?;
        let got = &buf[..n];
        let (first, last) = (
            got.iter().position(|&b| b == b'\n'),
            got.iter().rposition(|&b| b == b'\n'),
        );
        let longest = match (first, last) {
            (Some(f), Some(l)) => {
                let before = self.run + f;
                self.lines += got.iter().filter(|&&b| b == b'\n').count() as u64;
                self.run = n - l - 1;
                before
            }
            _ => {
                self.run += n;
                self.run
            }
        };
        if longest.max(self.run) > LINE_MAX {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "line {} is longer than {LINE_MAX} bytes: not a CSV of samples",
                    self.lines + 1
                ),
            ));
        }
        Ok(n)
    }
}

/// `text` as it is, cut like [`echo`] (for text that parsed as a number).
fn cut(text: &str) -> String {
    match text.char_indices().nth(ECHO_CHARS) {
        None => crate::text::escape_controls(text).into_owned(),
        Some((end, _)) => format!("{}... ({} bytes)", &text[..end], text.len()),
    }
}

/// What one time step of the CSV was.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step {
    /// The first row.
    First,
    /// About one frame period after the previous row.
    Regular,
    /// A gap (frames missing) of this many seconds.
    Gap(f64),
}

/// Steps shorter than this share of the frame period mean a faster rate.
const MIN_STEP: f64 = 0.75;
/// Steps longer than this share of the frame period are gaps.
const MAX_STEP: f64 = 1.5;
/// This many gaps in a row, each of about the same length, are a slower
/// rate, not missing frames: a log's gaps are separated by frames.
const SLOW_RATE_RUN: u32 = 3;
/// Regular steps averaged to check the rate: one second at 100 Hz.
const RATE_WINDOW: u32 = 100;
/// Largest deviation of the average step from the frame period: 5 %
/// (a rate of 95-105 Hz for 100 Hz; jitter of a few ms averages out).
const RATE_TOLERANCE: f64 = 0.05;

/// Follows the time column of a CSV that claims the log's sample rate.
#[derive(Debug)]
pub struct TimeSteps {
    /// The rate the steps must show; `None` takes any steps that advance.
    rate_hz: Option<f64>,
    last: Option<(f64, u64)>,
    /// Consecutive gaps so far and the first one's length.
    gap_run: (u32, f64),
    /// Regular steps since the rate was last checked, and the time and
    /// line they started from.
    regular: (u32, f64, u64),
}

impl TimeSteps {
    /// A checker for a log sampled at `rate_hz`.
    #[must_use]
    pub fn new(rate_hz: f64) -> Self {
        Self {
            rate_hz: Some(rate_hz),
            last: None,
            gap_run: (0, 0.0),
            regular: (0, 0.0, 0),
        }
    }

    /// A checker that only asks the time to advance (a CSV to be
    /// resampled).
    #[must_use]
    pub fn any_rate() -> Self {
        Self {
            rate_hz: None,
            ..Self::new(1.0)
        }
    }

    /// Takes the time of the row on `line`; an error says why the time
    /// cannot be a frame of the log: it does not advance, or the steps say
    /// the CSV was sampled at another rate.
    pub fn step(&mut self, t_s: f64, line: u64) -> Result<Step, String> {
        let Some((prev, prev_line)) = self.last.replace((t_s, line)) else {
            return Ok(Step::First);
        };
        let dt = t_s - prev;
        if dt <= 0.0 {
            self.last = Some((prev, prev_line));
            let how = if dt == 0.0 {
                "repeats"
            } else {
                "goes backwards"
            };
            return Err(format!(
                "{t_s} does not come after {prev} (line {prev_line}): time {how}"
            ));
        }
        let Some(rate_hz) = self.rate_hz else {
            return Ok(Step::Regular);
        };
        let period = 1.0 / rate_hz;
        let rate = |dt: f64| format!("{:.0} Hz", 1.0 / dt);
        if dt < MIN_STEP * period {
            return Err(format!(
                "steps by {dt} s, about {}, but a log is sampled at {rate_hz} Hz \
                 (`encode --resample` resamples it)",
                rate(dt),
            ));
        }
        if dt <= MAX_STEP * period {
            self.gap_run = (0, 0.0);
            return self.regular_step(t_s, prev, prev_line, line, rate_hz);
        }
        self.regular = (0, 0.0, 0);
        let (run, first) = self.gap_run;
        self.gap_run = if run > 0 && (dt - first).abs() < 0.25 * first {
            (run + 1, first)
        } else {
            (1, dt)
        };
        if self.gap_run.0 >= SLOW_RATE_RUN {
            return Err(format!(
                "steps by {dt} s {SLOW_RATE_RUN} times in a row, about {}, but a log \
                 is sampled at {rate_hz} Hz (`encode --resample` resamples it)",
                rate(dt),
            ));
        }
        Ok(Step::Gap(dt))
    }
}

impl TimeSteps {
    /// Counts a regular step; every [`RATE_WINDOW`] of them in a row, their
    /// average must be the frame period: steps each within the tolerated
    /// jitter can still add up to another rate (133 Hz passes 0.75 period
    /// steps one by one).
    fn regular_step(
        &mut self,
        t_s: f64,
        prev: f64,
        prev_line: u64,
        line: u64,
        rate_hz: f64,
    ) -> Result<Step, String> {
        let (n, from, from_line) = self.regular;
        let (n, from, from_line) = if n == 0 {
            (1, prev, prev_line)
        } else {
            (n + 1, from, from_line)
        };
        self.regular = (n, from, from_line);
        if n < RATE_WINDOW {
            return Ok(Step::Regular);
        }
        self.regular = (0, 0.0, 0);
        let mean = (t_s - from) / f64::from(n);
        let period = 1.0 / rate_hz;
        if (mean - period).abs() > RATE_TOLERANCE * period {
            return Err(format!(
                "steps by {mean:.6} s on average from line {from_line} to line {line}, about \
                 {:.0} Hz, but a log is sampled at {rate_hz} Hz (`encode --resample` resamples it)",
                1.0 / mean
            ));
        }
        Ok(Step::Regular)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_rate_each_step_of_which_passes_is_refused_by_its_average() {
        for hz in [67.0, 80.0, 90.0, 110.0, 133.0] {
            let times: Vec<f64> = (0..300).map(|i| f64::from(i) / hz).collect();
            let (i, e) = steps(&times).unwrap_err();
            assert_eq!(i, 100, "{hz} Hz");
            assert!(
                e.contains(&format!("{hz:.0} Hz")) && e.contains("line 2"),
                "{e}"
            );
        }
        for hz in [96.0, 100.0, 104.0] {
            let times: Vec<f64> = (0..300).map(|i| f64::from(i) / hz).collect();
            assert!(steps(&times).is_ok(), "{hz} Hz");
        }
    }

    #[test]
    fn a_long_line_is_refused_and_a_long_cell_is_cut_in_messages() {
        let mut text = b"t_s,steer_deg\n0,1\n".to_vec();
        text.extend(std::iter::repeat_n(b'7', LINE_MAX + 10));
        let mut read = Vec::new();
        let e = LineCap::new(&text[..]).read_to_end(&mut read).unwrap_err();
        assert!(e.to_string().contains("line 3 is longer than"), "{e}");
        let mut ok = Vec::new();
        LineCap::new(&text[..LINE_MAX])
            .read_to_end(&mut ok)
            .unwrap();
        let long = "x".repeat(10_000);
        let e = number_in(&long, (0.0, 1.0), "").unwrap_err();
        assert!(e.len() < 100 && e.contains("10000 bytes"), "{e}");
    }

    fn steps(times: &[f64]) -> Result<Vec<Step>, (usize, String)> {
        let mut t = TimeSteps::new(100.0);
        times
            .iter()
            .enumerate()
            .map(|(i, &s)| t.step(s, i as u64 + 2).map_err(|e| (i, e)))
            .collect()
    }

    #[test]
    fn a_gap_between_frames_is_a_gap_but_a_slower_rate_is_an_error() {
        let s = steps(&[0.0, 0.01, 0.02, 0.5, 0.51, 0.52]).unwrap();
        assert_eq!(s[3], Step::Gap(0.48));
        assert_eq!(s[4], Step::Regular);
        let (i, e) = steps(&[0.0, 0.02, 0.04, 0.06, 0.08]).unwrap_err();
        assert_eq!(i, 3);
        assert!(e.contains("50 Hz") && e.contains("100 Hz"), "{e}");
    }

    #[test]
    fn faster_rates_and_time_not_advancing_are_errors() {
        let (i, e) = steps(&[0.0, 0.005]).unwrap_err();
        assert_eq!(i, 1);
        assert!(e.contains("200 Hz"), "{e}");
        let (_, e) = steps(&[0.0, 0.01, 0.005]).unwrap_err();
        assert!(e.contains("goes backwards") && e.contains("line 3"), "{e}");
        let (_, e) = steps(&[0.0, 0.01, 0.01]).unwrap_err();
        assert!(e.contains("repeats"), "{e}");
    }

    #[test]
    fn non_finite_and_unstorable_values_are_refused() {
        let r = (-327.68, 327.67);
        assert_eq!(number_in("1.5", r, " deg"), Ok(1.5));
        for bad in ["NaN", "inf", "-inf", "1e9", "abc", ""] {
            assert!(number_in(bad, r, " deg").is_err(), "{bad}");
        }
        assert!(number_in("327.68", r, " deg")
            .unwrap_err()
            .contains("outside"));
    }

    proptest! {
        /// 100 Hz with jitter and occasional dropouts always passes.
        #[test]
        fn jittered_100_hz_with_dropouts_passes(
            jitter in proptest::collection::vec(-0.002..0.002f64, 10..300),
            gaps in proptest::collection::vec((0usize..60).prop_map(|g| g * 5), 0..5),
        ) {
            let mut t = 0.0;
            let mut times = Vec::new();
            for (i, j) in jitter.iter().enumerate() {
                t += 0.01 + j + if gaps.contains(&i) { 0.1 } else { 0.0 };
                times.push(t);
            }
            prop_assert!(steps(&times).is_ok());
        }
    }
}
