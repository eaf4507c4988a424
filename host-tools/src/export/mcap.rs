//! Rows, GPS fixes and events as an MCAP file for Foxglove and other
//! robotics viewers: zstd-compressed chunks; one channel per sensor group in
//! ROS 2 message definitions and CDR (binary: a 64 MiB log encodes in a
//! fraction of the JSON time); the GPS as `foxglove.LocationFix` (the map
//! panel) and the events as `foxglove.Log` (the Log panel), both JSON; the
//! log's metadata as an MCAP metadata record.
//!
//! Message log times are UTC, nanoseconds since 1970, when the log has a
//! GPS sync pair (frames before the first pair are placed through it), so
//! Foxglove's timeline shows the ride's date and time; otherwise, and always
//! as the publish time, the logger's clock, nanoseconds since boot.

use std::collections::BTreeMap;
use std::io::Write;

use mcap::records::{MessageHeader, Metadata};
use mcap::write::{NoSeek, WriteOptions, Writer};
use mcap::{Compression, McapError};
use serde::Serialize;
use wobble_core::format::GpsFix;

use super::columns::{Column, Value};
use super::LogMetadata;
use crate::events::{EventKind, LogEvent};
use crate::rows::{GpsColumns, Row};

/// The ROS 2 message definition of a message of plain numbers with units
/// in their names.
fn numbers_schema(fields: &[Column]) -> String {
    fields
        .iter()
        .map(|f| format!("float64 {}\n", f.name))
        .collect()
}

/// The CDR encapsulation header: plain CDR, little-endian.
const CDR_LE: [u8; 4] = [0, 1, 0, 0];

/// Foxglove's `foxglove.LocationFix`, as its JSON Schema.
const LOCATION_FIX_SCHEMA: &str = r#"{"title":"foxglove.LocationFix","type":"object","properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"frame_id":{"type":"string"},"latitude":{"type":"number"},"longitude":{"type":"number"},"altitude":{"type":"number"},"position_covariance":{"type":"array","items":{"type":"number"},"minItems":9,"maxItems":9},"position_covariance_type":{"type":"integer"}}}"#;

/// Foxglove's `foxglove.Log`, as its JSON Schema.
const LOG_SCHEMA: &str = r#"{"title":"foxglove.Log","type":"object","properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"level":{"type":"integer","description":"1 debug, 2 info, 3 warning, 4 error, 5 fatal"},"message":{"type":"string"},"name":{"type":"string"},"file":{"type":"string"},"line":{"type":"integer"}}}"#;

/// Topics, one per sensor group.
pub const IMU_TOPIC: &str = "/imu";
/// Steering angle.
pub const STEERING_TOPIC: &str = "/steering";
/// Wheel speed.
pub const WHEEL_TOPIC: &str = "/wheel";
/// GPS fixes with a position.
pub const GPS_TOPIC: &str = "/gps";
/// Alerts, markers, faults, dropouts and damage.
pub const EVENTS_TOPIC: &str = "/events";

/// The sensor groups of a row: topic, schema name and the columns a
/// message may carry.
const SENSOR_GROUPS: [(&str, &str, &[&str]); 3] = [
    (
        IMU_TOPIC,
        "wobblog_msgs/msg/Imu",
        &["ax_g", "ay_g", "az_g", "gx_dps", "gy_dps", "gz_dps"],
    ),
    (STEERING_TOPIC, "wobblog_msgs/msg/Steering", &["steer_deg"]),
    (WHEEL_TOPIC, "wobblog_msgs/msg/Wheel", &["speed_mps"]),
];

/// Where a chosen column goes in MCAP (`"its sensor channel"` for a sensor
/// field), or `None` when it has no home there.
#[must_use]
pub fn home_of(column: &str) -> Option<&'static str> {
    match column {
        "t_s" => Some("every message's publish time (ns since boot)"),
        "utc" => Some("every message's log time (ns since 1970, UTC)"),
        "gps_lat_deg" | "gps_lon_deg" => Some("/gps (foxglove.LocationFix)"),
        _ if SENSOR_GROUPS.iter().any(|g| g.2.contains(&column)) => Some("its sensor channel"),
        _ => None,
    }
}

/// A channel of row messages: its id and the chosen columns it carries.
struct RowChannel {
    id: u16,
    columns: Vec<Column>,
}

/// Writes an MCAP file front to back on any writer.
pub struct McapWriter<W: Write> {
    writer: Writer<NoSeek<W>>,
    rows: Vec<RowChannel>,
    /// Absent when no GPS column is chosen.
    gps: Option<u16>,
    events: u16,
    sequence: u32,
    /// The chosen columns, for the metadata's units.
    columns: Vec<Column>,
    /// A message being built, kept to reuse its allocation.
    body: Vec<u8>,
    /// UTC minus time since boot, ns, from the latest sync pair (the first
    /// one before it comes); `None` in a log without UTC.
    utc_offset_ns: Option<i64>,
}

#[derive(Serialize)]
struct Time {
    sec: u64,
    nsec: u32,
}

/// Foxglove's `foxglove.Log`.
#[derive(Serialize)]
struct Log<'a> {
    timestamp: Time,
    /// 2 info, 3 warning, 4 error.
    level: u8,
    message: String,
    /// The event kind (`alert_on`, `fault`, ...), to filter on.
    name: &'static str,
    file: &'a str,
    line: u32,
}

impl Time {
    fn of_ns(ns: u64) -> Self {
        Self {
            sec: ns / 1_000_000_000,
            nsec: (ns % 1_000_000_000) as u32,
        }
    }
}

/// The Log panel's level of an event: alerts and losses are warnings,
/// faults errors, the rest information.
fn level(kind: &EventKind) -> u8 {
    match kind {
        EventKind::AlertOff | EventKind::Marker { .. } => 2,
        EventKind::Fault { .. } => 4,
        _ => 3,
    }
}

#[derive(Serialize)]
struct LocationFix {
    timestamp: Time,
    frame_id: &'static str,
    latitude: f64,
    longitude: f64,
    altitude: f64,
    position_covariance: [f64; 9],
    /// 0: unknown (no covariance is logged).
    position_covariance_type: u8,
}

impl<W: Write> McapWriter<W> {
    /// A writer of `columns` on `out`; the header and channel definitions
    /// go out at once. Each sensor group's channel carries the chosen
    /// columns of its group, in the order chosen, and is left out when none
    /// is chosen; `/gps` is there when a GPS column is; `/events` always.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn new(out: W, columns: &[Column]) -> Result<Self, McapError> {
        let mut writer = WriteOptions::new()
            .disable_seeking(true)
            .compression(Some(Compression::Zstd))
            // One thread: the CPU a decode costs is the CPU it uses.
            .compression_threads(0)
            .library(concat!("wobblog ", env!("CARGO_PKG_VERSION")))
            .create(NoSeek::new(out))?;
        let no_meta = BTreeMap::new();
        let mut channel = |topic: &str, schema_name: &str, schema: &str, json: bool| {
            let (schema_encoding, message_encoding) = if json {
                ("jsonschema", "json")
            } else {
                ("ros2msg", "cdr")
            };
            let id = writer.add_schema(schema_name, schema_encoding, schema.as_bytes())?;
            writer.add_channel(id, topic, message_encoding, &no_meta)
        };
        let mut rows = Vec::new();
        for (topic, schema_name, names) in SENSOR_GROUPS {
            let chosen: Vec<Column> = columns
                .iter()
                .filter(|c| names.contains(&c.name))
                .copied()
                .collect();
            if !chosen.is_empty() {
                let schema = numbers_schema(&chosen);
                let id = channel(topic, schema_name, &schema, false)?;
                rows.push(RowChannel {
                    id,
                    columns: chosen,
                });
            }
        }
        let gps = if columns.iter().any(|c| c.name.starts_with("gps_")) {
            Some(channel(
                GPS_TOPIC,
                "foxglove.LocationFix",
                LOCATION_FIX_SCHEMA,
                true,
            )?)
        } else {
            None
        };
        let events = channel(EVENTS_TOPIC, "foxglove.Log", LOG_SCHEMA, true)?;
        Ok(Self {
            writer,
            rows,
            gps,
            events,
            sequence: 0,
            columns: columns.to_vec(),
            body: Vec::new(),
            utc_offset_ns: None,
        })
    }

    /// Takes a GPS sync pair (`t_us` since boot is `unix_ms` UTC): log
    /// times from here on follow it.
    pub fn sync(&mut self, t_us: u64, unix_ms: u64) {
        let (Ok(t), Ok(ms)) = (i64::try_from(t_us), i64::try_from(unix_ms)) else {
            return;
        };
        self.utc_offset_ns = ms
            .checked_mul(1_000_000)
            .and_then(|ns| ns.checked_sub(t.checked_mul(1000)?));
    }

    /// The log time of `boot_ns` since boot: UTC when known.
    fn log_time(&self, boot_ns: u64) -> u64 {
        self.utc_offset_ns
            .and_then(|off| i64::try_from(boot_ns).ok()?.checked_add(off))
            .and_then(|ns| u64::try_from(ns).ok())
            .unwrap_or(boot_ns)
    }

    fn message(
        &mut self,
        channel_id: u16,
        t_s: f64,
        body: &impl Serialize,
    ) -> Result<(), McapError> {
        let data = serde_json::to_vec(body).map_err(std::io::Error::other)?;
        self.message_data(channel_id, t_s, &data)
    }

    fn message_data(&mut self, channel_id: u16, t_s: f64, data: &[u8]) -> Result<(), McapError> {
        let boot_ns = boot_ns(t_s);
        self.sequence = self.sequence.wrapping_add(1);
        self.writer.write_to_known_channel(
            &MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: self.log_time(boot_ns),
                publish_time: boot_ns,
            },
            data,
        )
    }

    /// Writes one row as one message per sensor group.
    ///
    /// # Errors
    /// When the output fails.
    pub fn row(&mut self, row: &Row) -> Result<(), McapError> {
        let mut body = std::mem::take(&mut self.body);
        for k in 0..self.rows.len() {
            body.clear();
            body.extend_from_slice(&CDR_LE);
            for column in &self.rows[k].columns {
                // Sensor fields are numbers in every row.
                let Value::Number(v) = (column.value)(row) else {
                    continue;
                };
                body.extend_from_slice(&v.unwrap_or(f64::NAN).to_le_bytes());
            }
            self.message_data(self.rows[k].id, row.t_s, &body)?;
        }
        self.body = body;
        Ok(())
    }

    /// Writes a GPS fix with a position (others have nothing for a map).
    ///
    /// # Errors
    /// When the output fails.
    pub fn gps(&mut self, fix: &GpsFix) -> Result<(), McapError> {
        let (Some(gps), Some(pos)) = (self.gps, GpsColumns::from_fix(fix)) else {
            return Ok(());
        };
        // The fix's own UTC, else the log's clock.
        let t_s = fix.t_us as f64 / 1e6;
        let ns = fix
            .utc
            .map_or_else(|| self.log_time(boot_ns(t_s)), |u| u.unix_ms() * 1_000_000);
        let location = LocationFix {
            timestamp: Time::of_ns(ns),
            frame_id: "gps",
            latitude: pos.lat_deg,
            longitude: pos.lon_deg,
            altitude: fix.alt_cm.map_or(0.0, |cm| f64::from(cm) / 100.0),
            position_covariance: [0.0; 9],
            position_covariance_type: 0,
        };
        self.message(gps, t_s, &location)
    }

    /// Writes one event.
    ///
    /// # Errors
    /// When the output fails.
    pub fn event(&mut self, event: &LogEvent, log_name: &str) -> Result<(), McapError> {
        let details = event.kind.describe();
        let name = event.kind.name();
        let log = Log {
            timestamp: Time::of_ns(self.log_time(boot_ns(event.t_s))),
            level: level(&event.kind),
            message: if details.is_empty() {
                format!("{name} at {:.3} s", event.t_s)
            } else {
                format!("{name} at {:.3} s: {details}", event.t_s)
            },
            name,
            file: log_name,
            line: 0,
        };
        self.message(self.events, event.t_s, &log)
    }

    /// Writes the log's metadata and the summary; the file is complete
    /// after this.
    ///
    /// # Errors
    /// When the output fails.
    pub fn finish(&mut self, meta: &LogMetadata) -> Result<(), McapError> {
        let metadata = Metadata {
            name: "wobblog".into(),
            metadata: meta.pairs(&self.columns).into_iter().collect(),
        };
        self.writer.write_metadata(&metadata)?;
        // The output flushes itself when committed.
        self.writer.finish().map(drop)
    }
}

/// Nanoseconds since boot of `t_s` seconds since boot (never negative).
fn boot_ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}
