//! UTC formatting.

use wobble_core::format::UtcTime;

/// `2020-03-18T13:28:20.600Z`.
#[must_use]
pub fn iso8601(utc: UtcTime) -> String {
    let (year, month, day) = utc.date();
    let ms = utc.ms_of_day;
    let (h, m, s, milli) = if ms >= 86_400_000 {
        // A leap second: 23:59:60, not the next day's midnight.
        (23, 59, 60, ms % 1000)
    } else {
        (ms / 3_600_000, ms / 60_000 % 60, ms / 1000 % 60, ms % 1000)
    };
    format!("{year:04}-{month:02}-{day:02}T{h:02}:{m:02}:{s:02}.{milli:03}Z")
}
