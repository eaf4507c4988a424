//! `wobblog events` and `wobblog config` on logs with every kind of event.

mod analysis_support;

use analysis_support::{stdout_of, wobblog, write_log, Extras, Ride};
use wobble_core::config::Config;
use wobble_core::format::{Dropout, DropoutReason, Fault, FaultSource, Record};

/// A 10 s ride with an alert, markers, a GPS fault, a card fault, a
/// dropout and the default configuration in its header.
fn eventful_log(path: &std::path::Path) {
    let ride = Ride::new(10.0, 5.0, 0.0, 0.0, 0.0);
    let mut config = String::new();
    Config::default().write_lines(&mut config).unwrap();
    let extras = Extras {
        alerts_s: vec![(3.0, 4.5)],
        markers_s: vec![2.0],
        records: vec![
            Record::Fault(Fault {
                t_us: 5_000_000,
                source: FaultSource::Gps,
                code: 1,
                count: 3,
            }),
            Record::Fault(Fault {
                t_us: 6_000_000,
                source: FaultSource::Card,
                code: 9,
                count: 1,
            }),
            Record::Dropout(Dropout {
                t_us: 7_000_000,
                frames_lost: 12,
                reason: DropoutReason::QueueFull,
            }),
        ],
        config: config.lines().map(String::from).collect(),
        ..Extras::default()
    };
    write_log(path, &ride, &extras);
}

fn json_events(log: &std::path::Path) -> Vec<serde_json::Value> {
    let out = stdout_of(wobblog().arg("events").arg(log).arg("--json"));
    out.lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect()
}

#[test]
fn events_are_listed_in_time_order_with_meanings() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    eventful_log(&log);
    let events = json_events(&log);
    let kinds: Vec<&str> = events
        .iter()
        .map(|e| e["event"].as_str().unwrap())
        .collect();
    assert_eq!(
        kinds,
        [
            "marker",
            "alert_on",
            "alert_off",
            "fault",
            "fault",
            "dropout"
        ]
    );
    let times: Vec<f64> = events.iter().map(|e| e["t_s"].as_f64().unwrap()).collect();
    assert_eq!(times, [2.0, 3.0, 4.5, 5.0, 6.0, 7.0]);
    assert_eq!(events[1]["freq_hz"], 7.0);
    assert_eq!(events[1]["amp_deg"], 0.8);
    assert_eq!(events[3]["source"], "gps");
    assert_eq!(events[3]["code"], 1);
    assert_eq!(events[3]["count"], 3);
    assert_eq!(events[3]["meaning"], "NMEA checksum mismatch");
    assert!(events[4]["meaning"]
        .as_str()
        .unwrap()
        .starts_with("unknown"));
    assert_eq!(events[5]["frames_lost"], 12);
    assert_eq!(events[5]["reason"], "queue_full");

    let table = stdout_of(wobblog().arg("events").arg(&log));
    let lines: Vec<&str> = table.lines().collect();
    assert_eq!(lines.len(), 1 + 6 + 1, "{table}");
    assert!(
        lines[4].contains("gps 1 x3: NMEA checksum mismatch"),
        "{table}"
    );
    assert_eq!(lines[7], "6 events");
}

#[test]
fn damage_is_an_event_at_its_place() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    eventful_log(&log);
    let mut bytes = std::fs::read(&log).unwrap();
    // A block in the middle of the ride, after the marker.
    let block = bytes.len() / 512 / 2;
    bytes[block * 512 + 100] ^= 0x40;
    std::fs::write(&log, &bytes).unwrap();
    let events = json_events(&log);
    let skipped = events.iter().position(|e| e["event"] == "skipped").unwrap();
    let lost = events
        .iter()
        .position(|e| e["event"] == "lost_blocks")
        .unwrap();
    assert_eq!(events[lost]["first_block"], block as u64);
    assert_eq!(events[skipped]["cause"], "damaged block");
    let t = |i: usize| events[i]["t_s"].as_f64().unwrap();
    assert!(events
        .windows(2)
        .all(|w| w[0]["t_s"].as_f64() <= w[1]["t_s"].as_f64()));
    let to_s = events[lost]["to_s"].as_f64().unwrap();
    assert!(t(lost) < to_s && to_s - t(lost) < 1.0, "{:?}", events[lost]);
    assert!(t(lost) > 2.0 && t(lost) < 9.0);
}

#[test]
fn config_prints_a_config_txt_that_parses_back_to_the_same_configuration() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    eventful_log(&log);
    let text = stdout_of(wobblog().arg("config").arg(&log));
    assert!(text.starts_with("# CONFIG.TXT in force for RUN00003.WBL (run 3, firmware test)\n"));
    let loaded = Config::parse(text.as_bytes());
    assert!(loaded.faults.is_empty(), "{:?}", loaded.faults);
    assert_eq!(loaded.config, Config::default());
    assert_eq!(text.lines().count(), 1 + wobble_core::config::KEY_COUNT);
}

#[test]
fn config_of_a_log_without_one_is_an_error_naming_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    write_log(
        &log,
        &Ride::new(2.0, 5.0, 0.0, 0.0, 0.0),
        &Extras::default(),
    );
    let out = wobblog().arg("config").arg(&log).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("RUN00001.WBL") && err.contains("no configuration"),
        "{err}"
    );
}

#[test]
fn info_puts_losses_under_their_own_heading() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00003.WBL");
    eventful_log(&log);
    let clean = stdout_of(wobblog().arg("info").arg(&log));
    assert!(!clean.contains("losses:"), "{clean}");
    let mut bytes = std::fs::read(&log).unwrap();
    bytes[5 * 512 + 100] ^= 0x40;
    std::fs::write(&log, &bytes).unwrap();
    let text = stdout_of(wobblog().arg("info").arg(&log));
    let heading = text.find("\nlosses:\n").expect("a losses heading");
    let after = &text[heading..];
    assert!(after.contains("  blocks 5-5 lost"), "{text}");
    assert!(
        text[..heading].lines().all(|l| !l.contains("lost:")),
        "{text}"
    );
}

#[test]
fn completions_and_man_page_come_from_the_command_definitions() {
    for shell in ["bash", "zsh", "fish"] {
        let script = stdout_of(wobblog().args(["completions", shell]));
        for sub in ["decode", "events", "config", "wobble"] {
            assert!(script.contains(sub), "{shell} script lacks {sub}");
        }
    }
    let man = stdout_of(wobblog().arg("man"));
    assert!(
        man.starts_with(".ie") || man.contains(".TH wobblog"),
        "{}",
        &man[..200]
    );
    assert!(man.contains(".TH wobblog-events"));
    assert!(man.contains("\\-\\-json") || man.contains("json"));
    let out = wobblog().args(["completions", "tcsh"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
}
