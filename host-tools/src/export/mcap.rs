//! Rows, GPS fixes and events as an MCAP file for Foxglove and other
//! robotics viewers: zstd-compressed chunks; the sensors of a frame as one
//! message on `/sensors`, a ROS 2 message definition in CDR (binary, and one
//! message per frame rather than one per sensor group: a 64 MiB log is 2.6 M
//! messages, and the writer's cost is per message); the GPS as
//! `foxglove.LocationFix` (the map panel) and the events as `foxglove.Log`
//! (the Log panel), both JSON; the log's metadata as an MCAP metadata record.
//!
//! Message log times are UTC, nanoseconds since 1970, when the log has a
//! GPS sync pair (frames before the first pair are placed through it), so
//! Foxglove's timeline shows the ride's date and time; otherwise, and always
//! as the publish time, the logger's clock, nanoseconds since boot.

use std::collections::BTreeMap;
use std::io::Write;

use serde::Serialize;
use wobble_core::format::GpsFix;

use super::columns::{Column, Value};
use super::mcap_file::McapFile;
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

/// Every sensor field of a frame, one message per frame.
pub const SENSORS_TOPIC: &str = "/sensors";
/// GPS fixes with a position.
pub const GPS_TOPIC: &str = "/gps";
/// Alerts, markers, faults, dropouts and damage.
pub const EVENTS_TOPIC: &str = "/events";

/// The ROS 2 type of a `/sensors` message.
const SENSORS_SCHEMA_NAME: &str = "wobblog_msgs/msg/Sensors";

/// The columns a `/sensors` message may carry: the CSV's after `t_s` and
/// before the GPS (`ax_g` ... `speed_mps`).
const SENSOR_FIELDS: &[&str] = super::CSV_COLUMNS.split_at(9).0.split_at(1).1;

/// Where the GPS columns go in MCAP ([`home_of`]).
pub const GPS_HOME: &str = "/gps (foxglove.LocationFix)";

/// Where a chosen column goes in MCAP (`"/sensors"` for a sensor field), or
/// `None` when it has no home there.
#[must_use]
pub fn home_of(column: &str) -> Option<&'static str> {
    match column {
        "t_s" => Some("every message's publish time (ns since boot)"),
        "utc" => Some("every message's log time (ns since 1970, UTC)"),
        "gps_lat_deg" | "gps_lon_deg" => Some(GPS_HOME),
        _ if SENSOR_FIELDS.contains(&column) => Some(SENSORS_TOPIC),
        _ => None,
    }
}

/// The `/sensors` channel: its id and the chosen columns it carries.
struct SensorChannel {
    id: u16,
    columns: Vec<Column>,
}

/// Writes an MCAP file front to back on any writer.
pub struct McapWriter<W: Write> {
    file: McapFile<W>,
    /// Absent when no sensor column is chosen.
    sensors: Option<SensorChannel>,
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
    /// go out at once. `/sensors` carries the chosen sensor columns, in the
    /// order chosen, and is left out when none is chosen; `/gps` is there
    /// when a GPS column is; `/events` always.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn new(out: W, columns: &[Column]) -> std::io::Result<Self> {
        let mut file = McapFile::new(out, concat!("wobblog ", env!("CARGO_PKG_VERSION")))?;
        let mut channel = |topic: &str, schema_name: &str, schema: &str, json: bool| {
            let (schema_encoding, message_encoding) = if json {
                ("jsonschema", "json")
            } else {
                ("ros2msg", "cdr")
            };
            let id = file.add_schema(schema_name, schema_encoding, schema.as_bytes())?;
            file.add_channel(id, topic, message_encoding)
        };
        let chosen: Vec<Column> = columns
            .iter()
            .filter(|c| SENSOR_FIELDS.contains(&c.name))
            .copied()
            .collect();
        let sensors = if chosen.is_empty() {
            None
        } else {
            let schema = numbers_schema(&chosen);
            Some(SensorChannel {
                id: channel(SENSORS_TOPIC, SENSORS_SCHEMA_NAME, &schema, false)?,
                columns: chosen,
            })
        };
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
            file,
            sensors,
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

    fn message(&mut self, channel_id: u16, t_s: f64, body: &impl Serialize) -> std::io::Result<()> {
        let mut data = std::mem::take(&mut self.body);
        data.clear();
        serde_json::to_writer(&mut data, body).map_err(std::io::Error::other)?;
        let written = self.message_data(channel_id, t_s, &data);
        self.body = data;
        written
    }

    fn message_data(&mut self, channel_id: u16, t_s: f64, data: &[u8]) -> std::io::Result<()> {
        let boot_ns = boot_ns(t_s);
        self.sequence = self.sequence.wrapping_add(1);
        let times = (self.log_time(boot_ns), boot_ns);
        self.file.message(channel_id, self.sequence, times, data)
    }

    /// Writes one row as one `/sensors` message.
    ///
    /// # Errors
    /// When the output fails.
    pub fn row(&mut self, row: &Row) -> std::io::Result<()> {
        let Some(sensors) = &self.sensors else {
            return Ok(());
        };
        let id = sensors.id;
        let mut body = std::mem::take(&mut self.body);
        body.clear();
        body.extend_from_slice(&CDR_LE);
        for column in &sensors.columns {
            // Sensor fields are numbers in every row.
            if let Value::Number(v) = (column.value)(row) {
                body.extend_from_slice(&v.unwrap_or(f64::NAN).to_le_bytes());
            }
        }
        let written = self.message_data(id, row.t_s, &body);
        self.body = body;
        written
    }

    /// Writes a GPS fix with a position (others have nothing for a map).
    ///
    /// # Errors
    /// When the output fails.
    pub fn gps(&mut self, fix: &GpsFix) -> std::io::Result<()> {
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
    pub fn event(&mut self, event: &LogEvent, log_name: &str) -> std::io::Result<()> {
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
    pub fn finish(mut self, meta: &LogMetadata) -> std::io::Result<()> {
        let pairs: BTreeMap<String, String> = meta.pairs(&self.columns).into_iter().collect();
        self.file.metadata("wobblog", &pairs)?;
        // The output flushes itself when committed.
        self.file.finish().map(drop)
    }
}

/// Nanoseconds since boot of `t_s` seconds since boot (never negative).
fn boot_ns(t_s: f64) -> u64 {
    (t_s.max(0.0) * 1e9).round() as u64
}
