//! `wobblog decode --format mcap`, read back with the `mcap` crate: a
//! channel per sensor group with its JSON schema, the GPS as
//! `foxglove.LocationFix`, the events on their own channel, the metadata.

mod analysis_support;

use std::collections::BTreeMap;

use analysis_support::{gps_fix, wobblog, START_LAT_DEG};

fn json(data: &[u8]) -> serde_json::Value {
    serde_json::from_slice(data).unwrap()
}

#[test]
fn mcap_has_every_frame_fix_and_event_on_its_channel() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    let (ride, extras) = analysis_support::standard_log(&log);
    let out = dir.path().join("run.mcap");
    wobblog()
        .arg("decode")
        .arg(&log)
        .arg("-o")
        .arg(&out)
        .assert()
        .success();
    let bytes = std::fs::read(&out).unwrap();

    let mut by_topic: BTreeMap<String, Vec<serde_json::Value>> = BTreeMap::new();
    let mut last_ns: BTreeMap<String, u64> = BTreeMap::new();
    for message in mcap::MessageStream::new(&bytes).unwrap() {
        let message = message.unwrap();
        let topic = message.channel.topic.clone();
        let schema = message.channel.schema.as_ref().unwrap();
        assert_eq!(schema.encoding, "jsonschema");
        assert_eq!(message.channel.message_encoding, "json");
        if topic == "/gps" {
            assert_eq!(schema.name, "foxglove.LocationFix");
        }
        // Times go forward on each channel.
        let last = last_ns.entry(topic.clone()).or_insert(0);
        assert!(message.log_time >= *last, "{topic}");
        *last = message.log_time;
        by_topic.entry(topic).or_default().push(json(&message.data));
    }
    let frames = ride.t_s.len();
    assert_eq!(by_topic["/imu"].len(), frames);
    assert_eq!(by_topic["/steering"].len(), frames);
    assert_eq!(by_topic["/wheel"].len(), frames);
    assert_eq!(by_topic["/wheel"][0]["speed_mps"], 5.0);
    let fixes_with_position = (0..frames)
        .filter_map(|i| gps_fix(&ride, i, &extras))
        .filter(|f| f.lat_e7.is_some())
        .count();
    assert_eq!(by_topic["/gps"].len(), fixes_with_position);
    let first_fix = &by_topic["/gps"][0];
    assert_eq!(first_fix["latitude"], START_LAT_DEG);
    assert_eq!(first_fix["timestamp"]["sec"], 1_584_525_601u64);
    let kinds: Vec<&str> = by_topic["/events"]
        .iter()
        .map(|e| e["event"].as_str().unwrap())
        .collect();
    assert_eq!(kinds, ["marker", "alert_on", "alert_off", "marker"]);

    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(summary.channels.len(), 5);
    let index = &summary.metadata_indexes[0];
    let meta = mcap::read::metadata(&bytes, index).unwrap();
    assert_eq!(meta.name, "wobblog");
    assert_eq!(meta.metadata["run"], "3");
    assert_eq!(meta.metadata["first_utc"], "2020-03-18T10:00:01.000Z");
}

/// Messages by topic, and each topic's JSON Schema, of an MCAP file.
fn read_back(
    bytes: &[u8],
) -> (
    BTreeMap<String, Vec<serde_json::Value>>,
    BTreeMap<String, serde_json::Value>,
) {
    let mut by_topic: BTreeMap<String, Vec<serde_json::Value>> = BTreeMap::new();
    let mut schemas = BTreeMap::new();
    for message in mcap::MessageStream::new(bytes).unwrap() {
        let message = message.unwrap();
        let topic = message.channel.topic.clone();
        let schema = message.channel.schema.as_ref().unwrap();
        schemas.insert(topic.clone(), json(&schema.data));
        by_topic.entry(topic).or_default().push(json(&message.data));
    }
    (by_topic, schemas)
}

#[test]
fn columns_choose_the_fields_and_channels() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    let (ride, _) = analysis_support::standard_log(&log);
    let decode = |columns: &str, name: &str| {
        let out = dir.path().join(name);
        wobblog()
            .arg("decode")
            .arg(&log)
            .args(["--columns", columns, "-o"])
            .arg(&out)
            .assert()
            .success();
        std::fs::read(&out).unwrap()
    };
    let keys =
        |v: &serde_json::Value| -> Vec<String> { v.as_object().unwrap().keys().cloned().collect() };

    let bytes = decode("t_s,steer_deg,gz_dps,gx_dps,gps_lat_deg", "some.mcap");
    let (by_topic, schemas) = read_back(&bytes);
    let topics: Vec<&str> = by_topic.keys().map(String::as_str).collect();
    assert_eq!(topics, ["/events", "/gps", "/imu", "/steering"]);
    // Only the chosen fields, in schema and message, in the order chosen
    // (the messages are stored uncompressed).
    assert_eq!(keys(&by_topic["/imu"][0]), ["gx_dps", "gz_dps"]);
    let raw = |needle: &str| bytes.windows(needle.len()).any(|w| w == needle.as_bytes());
    assert!(raw("{\"gz_dps\":") && !raw("{\"gx_dps\":"));
    assert_eq!(
        schemas["/imu"]["properties"]
            .as_object()
            .unwrap()
            .keys()
            .collect::<Vec<_>>(),
        ["gx_dps", "gz_dps"]
    );
    assert_eq!(keys(&by_topic["/steering"][0]), ["steer_deg"]);
    assert_eq!(by_topic["/imu"].len(), ride.t_s.len());
    assert_eq!(by_topic["/gps"][0]["latitude"], START_LAT_DEG);
    let summary = mcap::Summary::read(&bytes).unwrap().unwrap();
    assert_eq!(summary.channels.len(), 4);
    let meta = mcap::read::metadata(&bytes, &summary.metadata_indexes[0]).unwrap();
    assert_eq!(meta.metadata["unit.gz_dps"], "deg/s");
    assert!(!meta.metadata.contains_key("unit.ax_g"));

    // One field: its channel and the events, no map.
    let (by_topic, _) = read_back(&decode("speed_mps", "speed.mcap"));
    let topics: Vec<&str> = by_topic.keys().map(String::as_str).collect();
    assert_eq!(topics, ["/events", "/wheel"]);
    assert_eq!(by_topic["/wheel"][0]["speed_mps"], 5.0);
}
