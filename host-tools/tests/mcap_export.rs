//! `wobblog decode --format mcap`, read back with the `mcap` crate as
//! Foxglove reads it: zstd chunks, every channel CDR with its ROS 2 message
//! definition (one CDR message per frame on `/sensors`, the GPS as
//! `foxglove_msgs/msg/LocationFix`, the events as `foxglove_msgs/msg/Log`),
//! log times in UTC nanoseconds, the metadata. The CDR is read back here by
//! a reader written from the specification (each field aligned to its size
//! after the 4-byte header); `python/tests` reads it with the Python
//! `mcap-ros2-support` decoder.

mod analysis_support;

use std::collections::BTreeMap;

use analysis_support::{
    gps_fix, wobblog, write_log, Extras, Ride, LON_DEG, START_LAT_DEG, UTC_AT_BOOT_MS,
};

/// One message as read back.
struct Message {
    log_time: u64,
    publish_time: u64,
    schema: String,
    encoding: String,
    data: Vec<u8>,
}

/// Plain little-endian CDR read field by field.
struct CdrReader<'a> {
    data: &'a [u8],
    at: usize,
}

impl CdrReader<'_> {
    fn take(&mut self, size: usize, align: usize) -> &[u8] {
        while !self.at.is_multiple_of(align) {
            self.at += 1;
        }
        let field = &self.data[self.at..self.at + size];
        self.at += size;
        field
    }
    fn u8(&mut self) -> u8 {
        self.take(1, 1)[0]
    }
    fn u32(&mut self) -> u32 {
        u32::from_le_bytes(self.take(4, 4).try_into().unwrap())
    }
    fn i32(&mut self) -> i32 {
        i32::from_le_bytes(self.take(4, 4).try_into().unwrap())
    }
    fn f64(&mut self) -> f64 {
        f64::from_le_bytes(self.take(8, 8).try_into().unwrap())
    }
    fn string(&mut self) -> String {
        let len = self.u32() as usize;
        let bytes = self.take(len, 1);
        assert_eq!(bytes[len - 1], 0, "NUL-terminated");
        String::from_utf8(bytes[..len - 1].to_vec()).unwrap()
    }
    fn time(&mut self) -> serde_json::Value {
        serde_json::json!({"sec": self.i32(), "nanosec": self.u32()})
    }
}

impl Message {
    /// A `foxglove_msgs` message decoded by its schema's fields.
    fn json(&self) -> serde_json::Value {
        assert_eq!(self.encoding, "cdr");
        assert_eq!(self.data[..4], [0, 1, 0, 0], "plain CDR, little-endian");
        let mut r = CdrReader {
            data: &self.data[4..],
            at: 0,
        };
        let v = if self.schema.contains("LocationFix") {
            serde_json::json!({
                "timestamp": r.time(),
                "frame_id": r.string(),
                "latitude": r.f64(),
                "longitude": r.f64(),
                "altitude": r.f64(),
                "position_covariance": (0..9).map(|_| r.f64()).collect::<Vec<_>>(),
                "position_covariance_type": r.u8(),
            })
        } else {
            assert!(
                self.schema.contains("foxglove_msgs/msg/Log"),
                "{}",
                self.schema
            );
            serde_json::json!({
                "timestamp": r.time(),
                "level": r.u8(),
                "message": r.string(),
                "name": r.string(),
                "file": r.string(),
                "line": r.u32(),
            })
        };
        assert_eq!(r.at, self.data.len() - 4, "every byte read");
        v
    }

    /// The float64 fields of a CDR message, after its encapsulation header.
    fn cdr_f64(&self) -> Vec<f64> {
        assert_eq!(self.encoding, "cdr");
        assert_eq!(self.data[..4], [0, 1, 0, 0], "plain CDR, little-endian");
        self.data[4..]
            .chunks(8)
            .map(|b| f64::from_le_bytes(b.try_into().unwrap()))
            .collect()
    }
}

/// Messages by topic, in file order; each topic's times must go forward.
fn read_back(bytes: &[u8]) -> BTreeMap<String, Vec<Message>> {
    let mut by_topic: BTreeMap<String, Vec<Message>> = BTreeMap::new();
    for message in mcap::MessageStream::new(bytes).unwrap() {
        let message = message.unwrap();
        let schema = message.channel.schema.as_ref().unwrap();
        let list = by_topic.entry(message.channel.topic.clone()).or_default();
        if let Some(last) = list.last() {
            assert!(
                message.log_time >= last.log_time,
                "{}",
                message.channel.topic
            );
        }
        list.push(Message {
            log_time: message.log_time,
            publish_time: message.publish_time,
            schema: format!(
                "{} {}: {}",
                schema.encoding,
                schema.name,
                String::from_utf8_lossy(&schema.data)
            ),
            encoding: message.channel.message_encoding.clone(),
            data: message.data.into_owned(),
        });
    }
    by_topic
}

fn decode(log: &std::path::Path, out: &std::path::Path, extra: &[&str]) -> Vec<u8> {
    let result = analysis_support::decode_to(log, out, extra);
    assert!(
        result.status.success(),
        "{}",
        String::from_utf8_lossy(&result.stderr)
    );
    std::fs::read(out).unwrap()
}

/// UTC of `t_s` since boot in the synthetic logs, ns since 1970.
fn utc_ns(t_s: f64) -> u64 {
    (UTC_AT_BOOT_MS as u64) * 1_000_000 + (t_s * 1e9).round() as u64
}

#[test]
fn mcap_is_compressed_in_utc_with_every_frame_fix_and_event_on_its_channel() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    let (ride, extras) = analysis_support::standard_log(&log);
    let bytes = decode(&log, &dir.path().join("run.mcap"), &[]);
    let by_topic = read_back(&bytes);

    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert!(!summary.chunk_indexes.is_empty());
    for chunk in &summary.chunk_indexes {
        assert_eq!(chunk.compression, "zstd");
        assert!(chunk.compressed_size < chunk.uncompressed_size / 2);
    }
    assert_eq!(summary.channels.len(), 3);

    let frames = ride.t_s.len();
    let sensors = &by_topic["/sensors"];
    assert_eq!(sensors.len(), frames);
    assert_eq!(
        sensors[0].schema,
        "ros2msg wobblog_msgs/msg/Sensors: float64 ax_g\nfloat64 ay_g\nfloat64 az_g\n\
         float64 gx_dps\nfloat64 gy_dps\nfloat64 gz_dps\nfloat64 steer_deg\nfloat64 speed_mps\n"
    );
    // Every frame in UTC, to the nanosecond, with its time since boot as
    // the publish time; the values are the frame's.
    for (i, message) in sensors.iter().enumerate() {
        let t = ride.t_s[i];
        assert_eq!(message.log_time, utc_ns(t), "frame {i}");
        assert_eq!(message.publish_time, (t * 1e9).round() as u64);
        let values = message.cdr_f64();
        assert_eq!(values.len(), 8);
        for axis in 0..3 {
            assert!(
                (values[axis] - ride.accel_g[i][axis]).abs() < 1e-3,
                "frame {i}"
            );
            assert!(
                (values[3 + axis] - ride.gyro_dps[i][axis]).abs() < 0.05,
                "frame {i}"
            );
        }
        assert!(
            (values[6] - ride.steer_deg[i]).abs() < 0.01,
            "frame {i}: {} against {}",
            values[6],
            ride.steer_deg[i]
        );
        assert_eq!(values[7], 5.0, "frame {i}");
    }

    let fixes: Vec<_> = (0..frames)
        .filter_map(|i| gps_fix(&ride, i, &extras))
        .filter(|f| f.lat_e7.is_some())
        .collect();
    let gps = &by_topic["/gps"];
    assert_eq!(gps.len(), fixes.len());
    assert!(gps[0]
        .schema
        .starts_with("ros2msg foxglove_msgs/msg/LocationFix"));
    for (message, fix) in gps.iter().zip(&fixes) {
        let body = message.json();
        // Latitude and longitude each their own value.
        let lat = f64::from(fix.lat_e7.unwrap()) / 1e7;
        let lon = f64::from(fix.lon_e7.unwrap()) / 1e7;
        assert!((body["latitude"].as_f64().unwrap() - lat).abs() < 1e-9);
        assert!((body["longitude"].as_f64().unwrap() - lon).abs() < 1e-9);
        let t = fix.t_us as f64 / 1e6;
        assert_eq!(message.log_time, utc_ns(t));
        let stamp = body["timestamp"]["sec"].as_u64().unwrap() * 1_000_000_000
            + body["timestamp"]["nanosec"].as_u64().unwrap();
        assert_eq!(stamp, message.log_time);
    }
    let first = gps[0].json();
    assert!((first["latitude"].as_f64().unwrap() - START_LAT_DEG).abs() < 1e-6);
    assert!((first["longitude"].as_f64().unwrap() - LON_DEG).abs() < 1e-9);

    // The events in Foxglove's Log panel: alerts warn.
    let events = &by_topic["/events"];
    assert!(events[0]
        .schema
        .starts_with("ros2msg foxglove_msgs/msg/Log"));
    let logged: Vec<(String, u64)> = events
        .iter()
        .map(|m| {
            let body = m.json();
            let stamp = body["timestamp"]["sec"].as_u64().unwrap() * 1_000_000_000
                + body["timestamp"]["nanosec"].as_u64().unwrap();
            assert_eq!(stamp, m.log_time);
            assert_eq!(body["file"], "RUN00003.WBL");
            (
                body["name"].as_str().unwrap().to_string(),
                body["level"].as_u64().unwrap(),
            )
        })
        .collect();
    let expected = [
        ("marker", 2),
        ("alert_on", 3),
        ("alert_off", 2),
        ("marker", 2),
    ];
    let expected: Vec<(String, u64)> = expected.iter().map(|(n, l)| (n.to_string(), *l)).collect();
    assert_eq!(logged, expected);
    assert_eq!(events[0].log_time, utc_ns(5.0));
    assert!(events[1].json()["message"]
        .as_str()
        .unwrap()
        .starts_with("alert_on at 16."));

    let meta = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(meta.name, "wobblog");
    assert_eq!(meta.metadata["run"], "3");
    assert_eq!(meta.metadata["first_utc"], "2020-03-18T10:00:01.000000Z");
}

#[test]
fn a_log_without_utc_keeps_the_loggers_clock() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let ride = Ride::new(5.0, 5.0, 0.0, 0.0, 0.0);
    write_log(&log, &ride, &Extras::default());
    let by_topic = read_back(&decode(&log, &dir.path().join("run.mcap"), &[]));
    for (message, t) in by_topic["/sensors"].iter().zip(&ride.t_s) {
        assert_eq!(message.log_time, (t * 1e9).round() as u64);
        assert_eq!(message.publish_time, message.log_time);
    }
}

#[test]
fn columns_choose_the_fields_and_channels_and_say_where_the_rest_go() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    let (ride, _) = analysis_support::standard_log(&log);
    let out = dir.path().join("some.mcap");
    let result = wobblog()
        .arg("decode")
        .arg(&log)
        .args([
            "--columns",
            "t_s,steer_deg,gz_dps,gx_dps,gps_lat_deg,gps_fix,utc",
            "-o",
        ])
        .arg(&out)
        .output()
        .unwrap();
    assert!(result.status.success());
    let stderr = String::from_utf8_lossy(&result.stderr);
    assert!(
        stderr.contains("--columns utc: in MCAP it is every message's log time"),
        "{stderr}"
    );
    assert!(
        stderr.contains("--columns t_s: in MCAP it is every message's publish time"),
        "{stderr}"
    );
    assert!(
        stderr.contains("warning: --columns gps_fix: MCAP has no field for it"),
        "{stderr}"
    );
    let bytes = std::fs::read(&out).unwrap();
    let by_topic = read_back(&bytes);
    let topics: Vec<&str> = by_topic.keys().map(String::as_str).collect();
    assert_eq!(topics, ["/events", "/gps", "/sensors"]);
    // Only the chosen fields, in schema and message, in the order chosen.
    let sensors = &by_topic["/sensors"];
    assert!(
        sensors[0]
            .schema
            .ends_with(": float64 steer_deg\nfloat64 gz_dps\nfloat64 gx_dps\n"),
        "{}",
        sensors[0].schema
    );
    assert_eq!(sensors.len(), ride.t_s.len());
    let values = sensors[10].cdr_f64();
    assert_eq!(values.len(), 3);
    assert!((values[0] - ride.steer_deg[10]).abs() < 0.01);
    assert!((values[1] - ride.gyro_dps[10][2]).abs() < 0.05);
    assert!((values[2] - ride.gyro_dps[10][0]).abs() < 0.05);
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(summary.channels.len(), 3);
    let meta = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(meta.metadata["unit.gz_dps"], "deg/s");
    assert!(!meta.metadata.contains_key("unit.ax_g"));

    // One field: its channel and the events, no map.
    let by_topic = read_back(&decode(
        &log,
        &dir.path().join("speed.mcap"),
        &["--columns", "speed_mps"],
    ));
    let topics: Vec<&str> = by_topic.keys().map(String::as_str).collect();
    assert_eq!(topics, ["/events", "/sensors"]);
    assert_eq!(by_topic["/sensors"][0].cdr_f64(), [5.0]);
}

#[test]
fn columns_that_no_message_carries_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    analysis_support::standard_log(&log);
    let mcap = dir.path().join("e.mcap");
    let out = wobblog()
        .arg("decode")
        .arg(&log)
        .args(["--columns", "t_s,utc", "-o"])
        .arg(&mcap)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("none is a field of an MCAP message"));
    assert!(!mcap.exists());
}

/// The derived signals, when named, are `/sensors` fields with the values
/// the CSV gives them (NaN where the CSV cell is empty).
#[test]
fn derived_columns_are_sensor_fields_when_named() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let columns = "steer_deg,roll_deg,steer_bp_deg,wobble_env_deg";
    let by_topic = read_back(&decode(
        &log,
        &dir.path().join("derived.mcap"),
        &["--columns", columns],
    ));
    let sensors = &by_topic["/sensors"];
    assert!(
        sensors[0].schema.ends_with(
            ": float64 steer_deg\nfloat64 roll_deg\nfloat64 steer_bp_deg\nfloat64 wobble_env_deg\n"
        ),
        "{}",
        sensors[0].schema
    );
    let csv = analysis_support::stdout_of(
        wobblog()
            .arg("decode")
            .arg(&log)
            .args(["--columns", columns]),
    );
    let rows: Vec<Vec<Option<f64>>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|c| c.parse().ok()).collect())
        .collect();
    assert_eq!(rows.len(), sensors.len());
    let mut compared = 0;
    for (row, message) in rows.iter().zip(sensors) {
        for (cell, value) in row.iter().zip(message.cdr_f64()) {
            match cell {
                Some(c) => {
                    assert!((c - value).abs() <= 1e-9 * c.abs().max(1.0), "{c} {value}");
                    compared += 1;
                }
                None => assert!(value.is_nan(), "{value}"),
            }
        }
    }
    assert!(compared > 3 * rows.len(), "{compared}");
}
