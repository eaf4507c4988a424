//! UTC formatting and parsing, and the time windows of `--from/--to`.
//!
//! Written here rather than with a date crate: the log's times are one fixed
//! ISO 8601 form in UTC, and the calendar arithmetic is the firmware core's
//! own ([`UtcTime`]), so both sides agree on every date.

use wobble_core::format::UtcTime;

/// Milliseconds from 1970-01-01 to 2000-01-01, the card's date epoch.
const UNIX_MS_AT_2000: i64 = 10_957 * 86_400_000;
const MS_PER_DAY: i64 = 86_400_000;

/// `2020-03-18T13:28:20.600Z`: a GPS fix's own time, to the millisecond
/// it has.
#[must_use]
pub fn iso8601(utc: UtcTime) -> String {
    iso8601_frac(utc, 0, 3)
}

/// `utc` plus `extra_us` (under a millisecond) with `digits` (3 or 6)
/// decimals of the second; a leap second stays 23:59:60.
fn iso8601_frac(utc: UtcTime, extra_us: u32, digits: usize) -> String {
    let (year, month, day) = utc.date();
    let ms = utc.ms_of_day;
    let (h, m, s, milli) = if ms >= 86_400_000 {
        // A leap second: 23:59:60, not the next day's midnight.
        (23, 59, 60, ms % 1000)
    } else {
        (ms / 3_600_000, ms / 60_000 % 60, ms / 1000 % 60, ms % 1000)
    };
    let date = format!("{year:04}-{month:02}-{day:02}T{h:02}:{m:02}:{s:02}");
    if digits == 6 {
        format!("{date}.{milli:03}{extra_us:03}Z")
    } else {
        format!("{date}.{milli:03}Z")
    }
}

/// The time `unix_ms` (milliseconds since 1970) as [`iso8601`] writes it;
/// `None` outside the card's dates (2000 to 2179).
#[must_use]
pub fn iso8601_unix_ms(unix_ms: i64) -> Option<String> {
    Some(iso8601(utc_time(unix_ms)?))
}

/// The time `unix_us` (microseconds since 1970) to the microsecond,
/// `2020-03-18T13:28:20.600250Z`: every UTC the log's clock places (the
/// `utc` column of every export, `info`, `events`, `wobble`, `summary`);
/// `None` outside the card's dates.
#[must_use]
pub fn iso8601_unix_us(unix_us: i64) -> Option<String> {
    let utc = utc_time(unix_us.div_euclid(1000))?;
    // A remainder of 0 to 999 µs.
    Some(iso8601_frac(utc, unix_us.rem_euclid(1000) as u32, 6))
}

/// The card's calendar form of `unix_ms`.
fn utc_time(unix_ms: i64) -> Option<UtcTime> {
    let since_2000 = unix_ms.checked_sub(UNIX_MS_AT_2000)?;
    let days = u16::try_from(since_2000.div_euclid(MS_PER_DAY)).ok()?;
    let ms_of_day = u32::try_from(since_2000.rem_euclid(MS_PER_DAY)).ok()?;
    Some(UtcTime {
        days_since_2000: days,
        ms_of_day,
    })
}

/// Parses `YYYY-MM-DDTHH:MM:SS[.fff][Z]` as [`parse_iso8601_us`] does;
/// milliseconds since 1970 (a finer fraction rounded down).
#[must_use]
pub fn parse_iso8601(text: &str) -> Option<i64> {
    parse_iso8601_us(text).map(|us| us.div_euclid(1000))
}

/// Parses `YYYY-MM-DDTHH:MM:SS[.ffffff][Z]` (a space for the `T` also
/// works; up to six decimals count, further ones are cut) as UTC;
/// microseconds since 1970.
#[must_use]
pub fn parse_iso8601_us(text: &str) -> Option<i64> {
    let text = text.strip_suffix('Z').unwrap_or(text);
    let (date, time) = text.split_once(['T', ' '])?;
    let mut d = date.splitn(3, '-').map(str::parse::<u32>);
    let (year, month, day) = (d.next()?.ok()?, d.next()?.ok()?, d.next()?.ok()?);
    let (hms, frac) = time.split_once('.').unwrap_or((time, ""));
    let mut t = hms.splitn(3, ':').map(str::parse::<u32>);
    let (h, m, s) = (t.next()?.ok()?, t.next()?.ok()?, t.next()?.ok()?);
    if h > 23 || m > 59 || s > 60 || !frac.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let frac_us = format!("{frac:0<6}")[..6].parse::<u32>().ok()?;
    let milli = frac_us / 1000;
    let days = UtcTime::days_from_date(i32::try_from(year).ok()?, month, day)?;
    // A leap second only where one can be: 23:59:60 at the end of a month
    // that can end with one (June or December, say), not on any day.
    let ms_of_day = ((h * 60 + m) * 60 + s) * 1000 + milli;
    let leap_ok = h == 23
        && m == 59
        && UtcTime {
            days_since_2000: days,
            ms_of_day,
        }
        .is_valid();
    if s == 60 && !leap_ok {
        return None;
    }
    let unix_ms = UNIX_MS_AT_2000
        + i64::from(days) * MS_PER_DAY
        + i64::from(((h * 60 + m) * 60 + s) * 1000 + milli);
    Some(unix_ms * 1000 + i64::from(frac_us % 1000))
}

/// One end of a time window: seconds since boot, or an absolute UTC time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum TimeBound {
    /// Seconds since the logger booted.
    Boot(f64),
    /// Milliseconds since 1970, UTC.
    Utc(i64),
}

impl std::str::FromStr for TimeBound {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        if let Ok(s) = text.parse::<f64>() {
            return if s.is_finite() {
                Ok(Self::Boot(s))
            } else {
                Err(format!("{text:?} is not a time"))
            };
        }
        parse_iso8601(text).map(Self::Utc).ok_or_else(|| {
            format!(
                "{text:?} is neither seconds since boot nor a UTC time like 2020-03-18T13:28:20.6Z"
            )
        })
    }
}

impl std::fmt::Display for TimeBound {
    /// As `--from/--to` take it: seconds since boot, or ISO 8601 UTC.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Self::Boot(s) => write!(f, "{s}"),
            Self::Utc(ms) => match iso8601_unix_ms(ms) {
                Some(text) => f.write_str(&text),
                None => write!(f, "{ms} ms since 1970"),
            },
        }
    }
}

/// A local time / UTC pair of the log: seconds since boot, ms since 1970.
pub type SyncPair = (f64, i64);

impl TimeBound {
    /// The bound in seconds since boot, through the log's sync pairs (the
    /// latest pair at or before the time, else the first); `None` for a
    /// UTC bound in a log without pairs.
    #[must_use]
    pub fn boot_s(self, pairs: &[SyncPair]) -> Option<f64> {
        match self {
            Self::Boot(s) => Some(s),
            Self::Utc(ms) => {
                let at = pairs.partition_point(|p| p.1 <= ms).saturating_sub(1);
                let (t_s, pair_ms) = *pairs.get(at)?;
                Some(t_s + (ms - pair_ms) as f64 / 1e3)
            }
        }
    }
}

/// UTC at `t_s` since boot through the latest pair at or before it (else
/// the first), ms since 1970; `None` without pairs.
#[must_use]
pub fn utc_ms_at(pairs: &[SyncPair], t_s: f64) -> Option<i64> {
    let at = pairs.partition_point(|p| p.0 <= t_s).saturating_sub(1);
    let (pair_s, pair_ms) = *pairs.get(at)?;
    Some(pair_ms + ((t_s - pair_s) * 1e3).round() as i64)
}

/// [`utc_ms_at`] in µs since 1970, rounded to the microsecond (the
/// precision of the log's clock).
#[must_use]
pub fn utc_us_at(pairs: &[SyncPair], t_s: f64) -> Option<i64> {
    let at = pairs.partition_point(|p| p.0 <= t_s).saturating_sub(1);
    let (pair_s, pair_ms) = *pairs.get(at)?;
    Some(pair_ms * 1000 + ((t_s - pair_s) * 1e6).round() as i64)
}

/// Why a UTC bound cannot be placed in a log.
const NO_UTC_FOR_WINDOW: &str =
    "the log has no UTC time (no GPS sync pair), so a UTC --from/--to cannot be placed";

/// UTC at `t_s` since boot as ISO 8601, through the latest pair at or
/// before it: what `decode`'s `utc` column gives a frame there (none before
/// the first pair).
#[must_use]
pub fn utc_text_at(pairs: &[SyncPair], t_s: f64) -> Option<String> {
    utc_us_after_pair(pairs, t_s).and_then(iso8601_unix_us)
}

/// UTC at `t_s` since boot, µs since 1970, through the latest pair at or
/// before it (none before the first pair), as [`utc_text_at`] gives it.
#[must_use]
pub fn utc_us_after_pair(pairs: &[SyncPair], t_s: f64) -> Option<i64> {
    let earlier = pairs.partition_point(|p| p.0 <= t_s);
    utc_us_at(&pairs[..earlier], t_s)
}

/// The `--from/--to` of a command.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TimeWindow {
    /// Start (inclusive), if any.
    pub from: Option<TimeBound>,
    /// End (inclusive), if any.
    pub to: Option<TimeBound>,
}

impl TimeWindow {
    /// Whether the window is the whole log.
    #[must_use]
    pub fn is_all(&self) -> bool {
        self.from.is_none() && self.to.is_none()
    }

    /// Whether a sample at `t_s` since boot, with UTC `utc_ms` if known,
    /// is inside. A UTC bound excludes samples without UTC.
    #[must_use]
    pub fn contains(&self, t_s: f64, utc_ms: Option<i64>) -> bool {
        let from_ok = |b: TimeBound| match b {
            TimeBound::Boot(s) => t_s >= s,
            TimeBound::Utc(ms) => utc_ms.is_some_and(|u| u >= ms),
        };
        let to_ok = |b: TimeBound| match b {
            TimeBound::Boot(s) => t_s <= s,
            TimeBound::Utc(ms) => utc_ms.is_some_and(|u| u <= ms),
        };
        self.from.is_none_or(from_ok) && self.to.is_none_or(to_ok)
    }

    /// The window as the command line gave it: `--from 10 --to 12`.
    #[must_use]
    pub fn describe(&self) -> String {
        let parts: Vec<String> = [("--from", self.from), ("--to", self.to)]
            .into_iter()
            .filter_map(|(flag, b)| b.map(|b| format!("{flag} {b}")))
            .collect();
        parts.join(" ")
    }

    /// Whether a UTC time bounds the window.
    #[must_use]
    pub fn has_utc_bound(&self) -> bool {
        matches!(self.from, Some(TimeBound::Utc(_))) || matches!(self.to, Some(TimeBound::Utc(_)))
    }

    /// Refuses, before any reading, a window whose bounds of one kind (both
    /// seconds since boot, or both UTC) end before they start.
    ///
    /// # Errors
    /// A usage error naming the window.
    pub fn check_order(&self, log: &std::path::Path) -> Result<(), crate::CliError> {
        let reversed = match (self.from, self.to) {
            (Some(TimeBound::Boot(a)), Some(TimeBound::Boot(b))) => a > b,
            (Some(TimeBound::Utc(a)), Some(TimeBound::Utc(b))) => a > b,
            _ => false,
        };
        if reversed {
            return Err(crate::CliError::Usage(format!(
                "{}: the window {} ends before it starts, so it selects nothing",
                crate::text::shown(log),
                self.describe()
            )));
        }
        Ok(())
    }

    /// The error for a window that selected nothing of `log`: the one rule
    /// of every command, so no empty output ever passes for a result.
    /// `what` names what was selected ("frames", "GPS fixes"); `span_s` is
    /// the time the log's `what` cover, s since boot; `has_utc` whether the
    /// log has UTC at all.
    #[must_use]
    pub fn selects_nothing(
        &self,
        log: &std::path::Path,
        what: &str,
        span_s: Option<(f64, f64)>,
        has_utc: bool,
    ) -> crate::CliError {
        if self.has_utc_bound() && !has_utc {
            return crate::CliError::file(
                log,
                format!("{NO_UTC_FOR_WINDOW} (window {})", self.describe()),
            );
        }
        let span = span_s.map_or_else(
            || format!("the log has no {what}"),
            |(a, b)| format!("the log's {what} span {a:.3} to {b:.3} s since boot"),
        );
        crate::CliError::file(
            log,
            format!("the window {} selects no {what}; {span}", self.describe()),
        )
    }

    /// The window in seconds since boot, through the sync pairs of `log`.
    ///
    /// # Errors
    /// A UTC bound in a log without UTC (a failure about `log`), or a
    /// window that ends before it starts (a usage error).
    pub fn boot_s(
        &self,
        pairs: &[SyncPair],
        log: &std::path::Path,
    ) -> Result<(Option<f64>, Option<f64>), crate::CliError> {
        let convert = |b: Option<TimeBound>| {
            b.map(|b| {
                b.boot_s(pairs).ok_or_else(|| {
                    crate::CliError::file(
                        log,
                        format!("{NO_UTC_FOR_WINDOW} (window {})", self.describe()),
                    )
                })
            })
            .transpose()
        };
        let (from, to) = (convert(self.from)?, convert(self.to)?);
        if let (Some(a), Some(b)) = (from, to) {
            if a >= b {
                return Err(crate::CliError::Usage(format!(
                    "{}: the window {} ends before it starts ({a:.3} to {b:.3} s since boot), so it selects nothing",
                    crate::text::shown(log),
                    self.describe()
                )));
            }
        }
        Ok((from, to))
    }
}

/// The clap arguments `--from` and `--to`, shared by every command with a
/// time window.
#[derive(Clone, Copy, Debug, Default, clap::Args)]
pub struct WindowArgs {
    /// Start of the time window: seconds since boot, or a UTC time
    /// (`2020-03-18T13:28:20.6Z`). Default: the first frame.
    #[arg(long, value_name = "TIME")]
    pub from: Option<TimeBound>,
    /// End of the time window, as --from. Default: the last frame.
    #[arg(long, value_name = "TIME")]
    pub to: Option<TimeBound>,
}

impl WindowArgs {
    /// The window.
    #[must_use]
    pub fn window(&self) -> TimeWindow {
        TimeWindow {
            from: self.from,
            to: self.to,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn published_instants() {
        // 2020-03-18T13:28:20.600Z is 1584538100600 ms since 1970.
        assert_eq!(
            parse_iso8601("2020-03-18T13:28:20.600Z"),
            Some(1_584_538_100_600)
        );
        assert_eq!(
            parse_iso8601("2020-03-18 13:28:20.6"),
            Some(1_584_538_100_600)
        );
        assert_eq!(parse_iso8601("2000-01-01T00:00:00Z"), Some(946_684_800_000));
        assert_eq!(parse_iso8601("2020-13-18T13:28:20Z"), None);
        assert_eq!(parse_iso8601("2020-03-18T25:28:20Z"), None);
        assert_eq!(parse_iso8601("2026-02-30T10:00:00Z"), None);
        assert_eq!(parse_iso8601("2026-02-14T23:59:60Z"), None);
        assert_eq!(parse_iso8601("2016-12-31T12:00:60Z"), None);
        assert_eq!(
            parse_iso8601("2016-12-31T23:59:60Z"),
            Some(1_483_228_800_000),
            "the instant 2017 began, in Unix time"
        );
        assert_eq!(parse_iso8601("yesterday"), None);
        assert_eq!("12.5".parse::<TimeBound>(), Ok(TimeBound::Boot(12.5)));
        assert!("inf".parse::<TimeBound>().is_err());
    }

    #[test]
    fn utc_bounds_go_through_the_latest_pair() {
        let pairs = [(10.0, 1_000_000), (20.0, 1_010_050)];
        assert_eq!(TimeBound::Utc(1_000_500).boot_s(&pairs), Some(10.5));
        assert_eq!(TimeBound::Utc(1_010_150).boot_s(&pairs), Some(20.1));
        assert_eq!(TimeBound::Utc(999_000).boot_s(&pairs), Some(9.0));
        assert_eq!(TimeBound::Utc(999_000).boot_s(&[]), None);
        assert_eq!(utc_ms_at(&pairs, 10.5), Some(1_000_500));
        assert_eq!(utc_ms_at(&pairs, 20.1), Some(1_010_150));
        assert_eq!(utc_ms_at(&pairs, 9.0), Some(999_000));
        assert_eq!(utc_ms_at(&[], 9.0), None);
        let w = TimeWindow {
            from: Some(TimeBound::Boot(5.0)),
            to: Some(TimeBound::Utc(1_000_500)),
        };
        let log = std::path::Path::new("x.wbl");
        assert_eq!(w.boot_s(&pairs, log).unwrap(), (Some(5.0), Some(10.5)));
        assert_eq!(w.boot_s(&[], log).unwrap_err().exit_code(), 1);
        let backwards = TimeWindow {
            from: Some(TimeBound::Boot(11.0)),
            ..w
        };
        assert_eq!(backwards.boot_s(&pairs, log).unwrap_err().exit_code(), 2);
        assert!(w.contains(5.0, Some(0)) && w.contains(10.0, Some(1_000_500)));
        assert!(!w.contains(4.99, Some(0)) && !w.contains(6.0, None));
        assert!(!w.contains(10.0, Some(1_000_501)));
    }

    #[test]
    fn microseconds_print_and_parse() {
        // 2020-03-18T13:28:20.600Z is 1584538100600 ms since 1970.
        let us = 1_584_538_100_600_250;
        assert_eq!(
            iso8601_unix_us(us).as_deref(),
            Some("2020-03-18T13:28:20.600250Z")
        );
        assert_eq!(parse_iso8601_us("2020-03-18T13:28:20.600250Z"), Some(us));
        assert_eq!(parse_iso8601_us("2020-03-18T13:28:20.6002509Z"), Some(us));
        assert_eq!(
            parse_iso8601("2020-03-18T13:28:20.600999Z"),
            Some(us / 1000)
        );
        assert_eq!(
            iso8601_unix_us(946_684_800_000_000).as_deref(),
            Some("2000-01-01T00:00:00.000000Z")
        );
        assert_eq!(iso8601_unix_us(946_684_799_999_999), None);
        // Times since boot round to the nearest microsecond.
        assert_eq!(utc_us_at(&[(1.0, 1000)], 1.000_000_6), Some(1_000_001));
        assert_eq!(utc_us_at(&[(1.0, 1000)], 1.000_000_4), Some(1_000_000));
    }

    proptest! {
        /// Formatting and parsing are inverse over the card's dates.
        #[test]
        fn iso_round_trip(ms in 946_684_800_000i64..6_000_000_000_000) {
            let text = iso8601_unix_ms(ms).unwrap();
            prop_assert_eq!(parse_iso8601(&text), Some(ms));
        }

        /// The same to the microsecond.
        #[test]
        fn iso_us_round_trip(us in 946_684_800_000_000i64..6_000_000_000_000_000) {
            let text = iso8601_unix_us(us).unwrap();
            prop_assert_eq!(parse_iso8601_us(&text), Some(us));
        }
    }
}
