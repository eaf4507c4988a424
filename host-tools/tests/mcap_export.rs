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

#[test]
fn mcap_refuses_column_selection() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    analysis_support::standard_log(&log);
    let out = wobblog()
        .arg("decode")
        .arg(&log)
        .args(["--columns", "t_s", "-o"])
        .arg(dir.path().join("a.mcap"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(!dir.path().join("a.mcap").exists());
}
