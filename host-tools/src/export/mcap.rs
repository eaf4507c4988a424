//! Rows, GPS fixes and events as an MCAP file for Foxglove and other
//! robotics viewers: one JSON channel per sensor group, the GPS as
//! `foxglove.LocationFix` (so the map panel shows the track), the events on
//! their own channel, and the log's metadata as an MCAP metadata record.
//!
//! Message times are the logger's clock (nanoseconds since boot), the one
//! time every sample has; the UTC of each fix is in its `timestamp`.

use std::collections::BTreeMap;
use std::io::Write;

use mcap::records::{MessageHeader, Metadata};
use mcap::write::{NoSeek, WriteOptions, Writer};
use mcap::McapError;
use serde::Serialize;
use wobble_core::format::GpsFix;

use super::columns::Column;
use super::{json_object, LogMetadata};
use crate::events::LogEvent;
use crate::rows::{GpsColumns, Row};

/// The JSON Schema of a message of plain numbers with units in their names.
fn numbers_schema(title: &str, fields: &[Column]) -> String {
    let properties: Vec<String> = fields
        .iter()
        .map(|f| format!("\"{}\":{{\"type\":\"number\"}}", f.name))
        .collect();
    format!(
        "{{\"title\":\"{title}\",\"type\":\"object\",\"properties\":{{{}}}}}",
        properties.join(",")
    )
}

/// Foxglove's `foxglove.LocationFix`, as its JSON Schema.
const LOCATION_FIX_SCHEMA: &str = r#"{"title":"foxglove.LocationFix","type":"object","properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer"}}},"frame_id":{"type":"string"},"latitude":{"type":"number"},"longitude":{"type":"number"},"altitude":{"type":"number"},"position_covariance":{"type":"array","items":{"type":"number"},"minItems":9,"maxItems":9},"position_covariance_type":{"type":"integer"}}}"#;

/// The events' JSON Schema: a time, a kind, and the kind's fields.
const EVENT_SCHEMA: &str = r#"{"title":"wobblog.Event","type":"object","properties":{"t_s":{"type":"number"},"event":{"type":"string"}},"required":["t_s","event"]}"#;

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
        "wobblog.Imu",
        &["ax_g", "ay_g", "az_g", "gx_dps", "gy_dps", "gz_dps"],
    ),
    (STEERING_TOPIC, "wobblog.Steering", &["steer_deg"]),
    (WHEEL_TOPIC, "wobblog.Wheel", &["speed_mps"]),
];

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
    body: String,
}

#[derive(Serialize)]
struct Time {
    sec: u64,
    nsec: u32,
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
            .compression(None)
            .library(concat!("wobblog ", env!("CARGO_PKG_VERSION")))
            .create(NoSeek::new(out))?;
        let no_meta = BTreeMap::new();
        let mut channel = |topic: &str, schema_name: &str, schema: &str| {
            let id = writer.add_schema(schema_name, "jsonschema", schema.as_bytes())?;
            writer.add_channel(id, topic, "json", &no_meta)
        };
        let mut rows = Vec::new();
        for (topic, schema_name, names) in SENSOR_GROUPS {
            let chosen: Vec<Column> = columns
                .iter()
                .filter(|c| names.contains(&c.name))
                .copied()
                .collect();
            if !chosen.is_empty() {
                let schema = numbers_schema(schema_name, &chosen);
                let id = channel(topic, schema_name, &schema)?;
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
            )?)
        } else {
            None
        };
        let events = channel(EVENTS_TOPIC, "wobblog.Event", EVENT_SCHEMA)?;
        Ok(Self {
            writer,
            rows,
            gps,
            events,
            sequence: 0,
            columns: columns.to_vec(),
            body: String::new(),
        })
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
        let ns = (t_s.max(0.0) * 1e9).round() as u64;
        self.sequence = self.sequence.wrapping_add(1);
        self.writer.write_to_known_channel(
            &MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: ns,
                publish_time: ns,
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
            json_object(&mut body, &self.rows[k].columns, row);
            self.message_data(self.rows[k].id, row.t_s, body.as_bytes())?;
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
        let unix_ms = fix.utc.map_or(0, |u| u.unix_ms());
        let location = LocationFix {
            timestamp: Time {
                sec: unix_ms / 1000,
                nsec: (unix_ms % 1000) as u32 * 1_000_000,
            },
            frame_id: "gps",
            latitude: pos.lat_deg,
            longitude: pos.lon_deg,
            altitude: fix.alt_cm.map_or(0.0, |cm| f64::from(cm) / 100.0),
            position_covariance: [0.0; 9],
            position_covariance_type: 0,
        };
        self.message(gps, fix.t_us as f64 / 1e6, &location)
    }

    /// Writes one event.
    ///
    /// # Errors
    /// When the output fails.
    pub fn event(&mut self, event: &LogEvent) -> Result<(), McapError> {
        self.message(self.events, event.t_s, event)
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
