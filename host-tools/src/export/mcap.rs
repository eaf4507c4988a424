//! Rows, GPS fixes and events as an MCAP file for Foxglove and other
//! robotics viewers: zstd-compressed chunks; every channel a ROS 2 message
//! definition in CDR, one encoding, so a reader with a ROS 2 decoder (the
//! Python `mcap-ros2-support`, Foxglove) decodes every topic without a
//! decoder of its own: the sensors of a frame as one message on `/sensors`
//! (binary, and one message per frame rather than one per sensor group: a
//! 64 MiB log is 2.6 M messages, and the writer's cost is per message); the
//! GPS as `foxglove_msgs/msg/LocationFix` (the map panel) and the events as
//! `foxglove_msgs/msg/Log` (the Log panel); the log's metadata as an MCAP
//! metadata record.
//!
//! Message log times are UTC, nanoseconds since 1970, when the log has a
//! GPS sync pair (frames before the first pair are placed through it), so
//! Foxglove's timeline shows the ride's date and time; otherwise, and always
//! as the publish time, the logger's clock, nanoseconds since boot.

use std::collections::BTreeMap;
use std::io::Write;

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

/// The definition a ROS 2 schema that uses a time appends for it.
const TIME_DEFINITION: &str =
    "================================================================================\n\
MSG: builtin_interfaces/Time\n\
int32 sec\n\
uint32 nanosec\n";

/// Foxglove's `foxglove_msgs/msg/LocationFix`, its ROS 2 definition.
const LOCATION_FIX_SCHEMA_NAME: &str = "foxglove_msgs/msg/LocationFix";
/// See [`LOCATION_FIX_SCHEMA_NAME`].
const LOCATION_FIX_FIELDS: &str = "builtin_interfaces/Time timestamp\n\
string frame_id\n\
float64 latitude\n\
float64 longitude\n\
float64 altitude\n\
float64[9] position_covariance\n\
uint8 position_covariance_type\n";

/// Foxglove's `foxglove_msgs/msg/Log`, its ROS 2 definition (`level`: 1
/// debug, 2 info, 3 warning, 4 error, 5 fatal).
const LOG_SCHEMA_NAME: &str = "foxglove_msgs/msg/Log";
/// See [`LOG_SCHEMA_NAME`].
const LOG_FIELDS: &str = "builtin_interfaces/Time timestamp\n\
uint8 level\n\
string message\n\
string name\n\
string file\n\
uint32 line\n";

/// Every sensor field of a frame, one message per frame.
pub const SENSORS_TOPIC: &str = "/sensors";
/// GPS fixes with a position.
pub const GPS_TOPIC: &str = "/gps";
/// Alerts, markers, faults, dropouts and damage.
pub const EVENTS_TOPIC: &str = "/events";

/// The ROS 2 type of a `/sensors` message.
const SENSORS_SCHEMA_NAME: &str = "wobblog_msgs/msg/Sensors";

/// The stored columns a `/sensors` message may carry: the CSV's after `t_s`
/// and before the GPS (`ax_g` ... `speed_mps`).
const SENSOR_FIELDS: &[&str] = super::CSV_COLUMNS.split_at(9).0.split_at(1).1;

/// Whether `column` is a field of `/sensors`: a stored sensor column, or a
/// derived one (`roll_deg`, `steer_bp_deg`, `wobble_env_deg`, when named;
/// NaN where the filter has no value yet).
fn is_sensor_field(column: &str) -> bool {
    SENSOR_FIELDS.contains(&column)
        || super::columns::DERIVED_COLUMNS
            .iter()
            .any(|c| c.name == column)
}

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
        _ if is_sensor_field(column) => Some(SENSORS_TOPIC),
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

/// A CDR message body (plain CDR, little-endian) written field by
/// field: each field aligned to its size, counted from the end of the
/// encapsulation header. Written here: the ROS 2 types used are four plain
/// structs, and a serialisation crate would bring a message model of its
/// own for them.
struct Cdr<'a>(&'a mut Vec<u8>);

impl<'a> Cdr<'a> {
    /// A body in `buf` (cleared), its header written.
    fn start(buf: &'a mut Vec<u8>) -> Self {
        buf.clear();
        buf.extend_from_slice(&CDR_LE);
        Self(buf)
    }

    fn align(&mut self, size: usize) {
        while !(self.0.len() - CDR_LE.len()).is_multiple_of(size) {
            self.0.push(0);
        }
    }

    fn u8(&mut self, v: u8) {
        self.0.push(v);
    }

    fn u32(&mut self, v: u32) {
        self.align(4);
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    fn f64(&mut self, v: f64) {
        self.align(8);
        self.0.extend_from_slice(&v.to_le_bytes());
    }

    /// A string: its length with the terminating NUL, its bytes, the NUL.
    fn string(&mut self, text: &str) {
        self.u32(u32::try_from(text.len() + 1).unwrap_or(u32::MAX));
        self.0.extend_from_slice(text.as_bytes());
        self.0.push(0);
    }

    /// A `builtin_interfaces/Time` of `ns` nanoseconds since 1970 (or since
    /// boot): seconds as an `int32`, which holds them until 2038.
    fn time(&mut self, ns: u64) {
        let sec = i32::try_from(ns / 1_000_000_000).unwrap_or(i32::MAX);
        self.align(4);
        self.0.extend_from_slice(&sec.to_le_bytes());
        self.u32((ns % 1_000_000_000) as u32);
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
        let mut channel = |topic: &str, schema_name: &str, schema: &str| {
            let id = file.add_schema(schema_name, "ros2msg", schema.as_bytes())?;
            file.add_channel(id, topic, "cdr")
        };
        let chosen: Vec<Column> = columns
            .iter()
            .filter(|c| is_sensor_field(c.name))
            .copied()
            .collect();
        let sensors = if chosen.is_empty() {
            None
        } else {
            let schema = numbers_schema(&chosen);
            Some(SensorChannel {
                id: channel(SENSORS_TOPIC, SENSORS_SCHEMA_NAME, &schema)?,
                columns: chosen,
            })
        };
        let gps = if columns.iter().any(|c| c.name.starts_with("gps_")) {
            let schema = format!("{LOCATION_FIX_FIELDS}{TIME_DEFINITION}");
            Some(channel(GPS_TOPIC, LOCATION_FIX_SCHEMA_NAME, &schema)?)
        } else {
            None
        };
        let events = channel(
            EVENTS_TOPIC,
            LOG_SCHEMA_NAME,
            &format!("{LOG_FIELDS}{TIME_DEFINITION}"),
        )?;
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

    /// Writes the CDR body `fill` makes as a message of `channel_id` at
    /// `t_s` since boot.
    fn message(
        &mut self,
        channel_id: u16,
        t_s: f64,
        fill: impl FnOnce(&mut Cdr<'_>),
    ) -> std::io::Result<()> {
        let mut data = std::mem::take(&mut self.body);
        fill(&mut Cdr::start(&mut data));
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
            // Sensor fields are numbers (derived ones absent at first).
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
        let altitude_m = fix.alt_cm.map_or(0.0, |cm| f64::from(cm) / 100.0);
        self.message(gps, t_s, |m| {
            m.time(ns);
            m.string("gps");
            m.f64(pos.lat_deg);
            m.f64(pos.lon_deg);
            m.f64(altitude_m);
            // No covariance is logged: zeros, type 0 (unknown).
            for _ in 0..9 {
                m.f64(0.0);
            }
            m.u8(0);
        })
    }

    /// Writes one event.
    ///
    /// # Errors
    /// When the output fails.
    pub fn event(&mut self, event: &LogEvent, log_name: &str) -> std::io::Result<()> {
        let details = event.kind.describe();
        let name = event.kind.name();
        let message = if details.is_empty() {
            format!("{name} at {:.3} s", event.t_s)
        } else {
            format!("{name} at {:.3} s: {details}", event.t_s)
        };
        let stamp = self.log_time(boot_ns(event.t_s));
        let level = level(&event.kind);
        self.message(self.events, event.t_s, |m| {
            m.time(stamp);
            m.u8(level);
            m.string(&message);
            // The event kind (`alert_on`, `fault`, ...), to filter on.
            m.string(name);
            m.string(log_name);
            m.u32(0);
        })
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
