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

use super::LogMetadata;
use crate::events::LogEvent;
use crate::rows::{GpsColumns, Row};

/// The JSON Schema of a message of plain numbers with units in their names.
fn numbers_schema(title: &str, fields: &[&str]) -> String {
    let properties: Vec<String> = fields
        .iter()
        .map(|f| format!("\"{f}\":{{\"type\":\"number\"}}"))
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

/// Writes an MCAP file front to back on any writer.
pub struct McapWriter<W: Write> {
    writer: Writer<NoSeek<W>>,
    imu: u16,
    steering: u16,
    wheel: u16,
    gps: u16,
    events: u16,
    sequence: u32,
}

#[derive(Serialize)]
struct Imu {
    ax_g: f64,
    ay_g: f64,
    az_g: f64,
    gx_dps: f64,
    gy_dps: f64,
    gz_dps: f64,
}

#[derive(Serialize)]
struct Steering {
    steer_deg: f64,
}

#[derive(Serialize)]
struct Wheel {
    speed_mps: f64,
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
    /// A writer on `out`; the header and channel definitions go out at once.
    ///
    /// # Errors
    /// When `out` fails.
    pub fn new(out: W) -> Result<Self, McapError> {
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
        let imu = channel(
            IMU_TOPIC,
            "wobblog.Imu",
            &numbers_schema(
                "wobblog.Imu",
                &["ax_g", "ay_g", "az_g", "gx_dps", "gy_dps", "gz_dps"],
            ),
        )?;
        let steering = channel(
            STEERING_TOPIC,
            "wobblog.Steering",
            &numbers_schema("wobblog.Steering", &["steer_deg"]),
        )?;
        let wheel = channel(
            WHEEL_TOPIC,
            "wobblog.Wheel",
            &numbers_schema("wobblog.Wheel", &["speed_mps"]),
        )?;
        let gps = channel(GPS_TOPIC, "foxglove.LocationFix", LOCATION_FIX_SCHEMA)?;
        let events = channel(EVENTS_TOPIC, "wobblog.Event", EVENT_SCHEMA)?;
        Ok(Self {
            writer,
            imu,
            steering,
            wheel,
            gps,
            events,
            sequence: 0,
        })
    }

    fn message(
        &mut self,
        channel_id: u16,
        t_s: f64,
        body: &impl Serialize,
    ) -> Result<(), McapError> {
        let data = serde_json::to_vec(body).map_err(std::io::Error::other)?;
        let ns = (t_s.max(0.0) * 1e9).round() as u64;
        self.sequence = self.sequence.wrapping_add(1);
        self.writer.write_to_known_channel(
            &MessageHeader {
                channel_id,
                sequence: self.sequence,
                log_time: ns,
                publish_time: ns,
            },
            &data,
        )
    }

    /// Writes one row as one message per sensor group.
    ///
    /// # Errors
    /// When the output fails.
    pub fn row(&mut self, row: &Row) -> Result<(), McapError> {
        let [ax_g, ay_g, az_g] = row.accel_g;
        let [gx_dps, gy_dps, gz_dps] = row.gyro_dps;
        let imu = Imu {
            ax_g,
            ay_g,
            az_g,
            gx_dps,
            gy_dps,
            gz_dps,
        };
        self.message(self.imu, row.t_s, &imu)?;
        self.message(
            self.steering,
            row.t_s,
            &Steering {
                steer_deg: row.steer_deg,
            },
        )?;
        self.message(
            self.wheel,
            row.t_s,
            &Wheel {
                speed_mps: row.speed_mps,
            },
        )
    }

    /// Writes a GPS fix with a position (others have nothing for a map).
    ///
    /// # Errors
    /// When the output fails.
    pub fn gps(&mut self, fix: &GpsFix) -> Result<(), McapError> {
        let Some(pos) = GpsColumns::from_fix(fix) else {
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
        self.message(self.gps, fix.t_us as f64 / 1e6, &location)
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
            metadata: meta.pairs(&super::columns::COLUMNS).into_iter().collect(),
        };
        self.writer.write_metadata(&metadata)?;
        // The output flushes itself when committed.
        self.writer.finish().map(drop)
    }
}
