//! What a log says about itself, for the metadata of exported files.

use wobble_core::format::{Event, Record};

/// The log's identity and configuration, collected from its records.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct LogMetadata {
    /// Firmware version.
    pub firmware: Option<String>,
    /// Device id, hex.
    pub device_id: Option<String>,
    /// Run number on the card.
    pub run: Option<u32>,
    /// Nominal frame rate, Hz.
    pub sample_rate_hz: Option<u16>,
    /// The configuration in force, `key=value` lines.
    pub config: Vec<String>,
    /// The first GPS sync pair's UTC, ISO 8601.
    pub first_utc: Option<String>,
}

impl LogMetadata {
    /// Takes one decoder event.
    pub fn observe(&mut self, event: &Event<'_>) {
        match event {
            Event::Record(Record::LogInfo(info)) => {
                self.firmware = Some(info.firmware.to_string());
                self.device_id = Some(info.device_id.iter().map(|b| format!("{b:02x}")).collect());
                self.run = Some(info.run);
                self.sample_rate_hz = Some(info.sample_rate_hz);
            }
            Event::Record(Record::Config(line)) => self.config.push(line.text.to_string()),
            Event::Record(Record::UtcSync(sync)) if self.first_utc.is_none() => {
                self.first_utc = i64::try_from(sync.unix_ms)
                    .ok()
                    .and_then(|ms| crate::time::iso8601_unix_us(ms.checked_mul(1000)?));
            }
            _ => {}
        }
    }

    /// Key-value pairs: the file's own description, then the units of
    /// each column.
    #[must_use]
    pub fn pairs(&self, columns: &[super::columns::Column]) -> Vec<(String, String)> {
        let mut pairs = vec![
            (
                "wobblog.version".to_string(),
                env!("CARGO_PKG_VERSION").to_string(),
            ),
            (
                "sample_rate_hz".to_string(),
                self.sample_rate_hz.unwrap_or(100).to_string(),
            ),
        ];
        let optional = [
            ("firmware", self.firmware.clone()),
            ("device_id", self.device_id.clone()),
            ("run", self.run.map(|r| r.to_string())),
            ("first_utc", self.first_utc.clone()),
        ];
        pairs.extend(
            optional
                .into_iter()
                .filter_map(|(k, v)| v.map(|v| (k.to_string(), v))),
        );
        pairs.push(("config".to_string(), self.config.join("\n")));
        pairs.extend(units(columns));
        pairs
    }
}

/// `unit.NAME` metadata pairs, the unit each column's name ends with, for
/// every table a log or a dataset writes.
#[must_use]
pub fn units<R>(columns: &[super::columns::Column<R>]) -> Vec<(String, String)> {
    columns
        .iter()
        .map(|c| (format!("unit.{}", c.name), unit_of(c.name).to_string()))
        .collect()
}

/// The unit a column's name ends with; empty for counts, names and text.
fn unit_of(name: &str) -> &'static str {
    if name.ends_with("_per_s") {
        return "1/s";
    }
    match name.rsplit('_').next() {
        Some("s") => "s",
        Some("g") => "g",
        Some("dps") => "deg/s",
        Some("deg") => "deg",
        Some("mps") => "m/s",
        Some("hz") => "Hz",
        Some("m") => "m",
        Some("utc") => "UTC",
        _ => "",
    }
}

#[cfg(test)]
mod tests {
    use super::unit_of;

    #[test]
    fn units_come_from_the_names() {
        let cases = [
            ("t_s", "s"),
            ("sigma_per_s", "1/s"),
            ("freq_hz", "Hz"),
            ("distance_m", "m"),
            ("gps_speed_mps", "m/s"),
            ("gz_dps", "deg/s"),
            ("peak_amp_deg", "deg"),
            ("az_g", "g"),
            ("first_utc", "UTC"),
            ("utc", "UTC"),
            ("episodes", ""),
            ("gps_fix", ""),
        ];
        for (name, unit) in cases {
            assert_eq!(unit_of(name), unit, "{name}");
        }
    }
}
