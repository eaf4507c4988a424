//! One kick, one sigma: a stable episode that is a kick reports the
//! kick's values as `wobblog margin` measures them, in `wobble`, the data
//! set's episodes, `model compare` and `model fit`; an episode that is no
//! kick keeps its own fit.

mod analysis_support;

use std::f64::consts::TAU;
use std::fs::File;
use std::path::Path;

use analysis_support::{kick_record, stdout_of, wobblog, Extras, Ride};
use parquet::file::reader::{FileReader, SerializedFileReader};
use parquet::record::Field;
use serde_json::Value;
use wobble_model::fit::{fit, Observation, Weights};
use wobblog::analysis::campaign_kicks::{campaign_kicks, load_campaign_kicks, Prefer, Source};
use wobblog::analysis::{find_episodes, Episode, Run, Stability};
use wobblog::cmd::detect::wheel_circumference_m;

/// The kick: struck at this time, s since boot...
const KICK_S: f64 = 20.0;
/// ... ringing at this frequency, Hz...
const KICK_FREQ_HZ: f64 = 6.5;
/// ... and decaying at this rate, 1/s.
const KICK_SIGMA_PER_S: f64 = -0.22;

/// A 35 s ride at 3 m/s: a kick at [`KICK_S`] (a 0.1 s push of 4 degrees,
/// then a ring of 1.5 degrees), and the growing wobble of
/// [`analysis_support::wobble`] at 14 s, over small deterministic noise.
fn ride() -> Ride {
    let mut ride = Ride::new(35.0, 3.0, 0.0, 0.5, 0.0);
    let mut state = 0x9E37_79B9u32;
    for (t, s) in ride.t_s.iter().zip(ride.steer_deg.iter_mut()) {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let noise = 0.02 * (f64::from(state) / f64::from(u32::MAX) - 0.5);
        let tau = t - KICK_S;
        let push = if (0.0..0.1).contains(&tau) {
            4.0 * (TAU / 0.2 * tau).sin()
        } else {
            0.0
        };
        let ring = if tau >= 0.1 {
            1.5 * (KICK_SIGMA_PER_S * (tau - 0.1)).exp() * (TAU * KICK_FREQ_HZ * (tau - 0.1)).sin()
        } else {
            0.0
        };
        *s += push + ring + noise;
    }
    ride
}

fn json_of(cmd: &mut assert_cmd::Command) -> Value {
    serde_json::from_str(&stdout_of(cmd)).unwrap()
}

fn params() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/test-bicycle.toml")
}

/// The kick as `wobblog margin --json` gives it: frequency, sigma, its SD
/// and where they come from.
struct MarginKick {
    freq_hz: f64,
    sigma_per_s: f64,
    sigma_sd_per_s: f64,
    source: String,
}

fn margin_kick(log: &Path) -> MarginKick {
    let report = json_of(wobblog().args(["margin", "--json"]).arg(log));
    let kicks: Vec<&Value> = report["kicks"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|k| (k["t_s"].as_f64().unwrap() - KICK_S).abs() < 0.5)
        .collect();
    assert_eq!(kicks.len(), 1, "{report:#}");
    let f = |key: &str| kicks[0][key].as_f64().unwrap();
    MarginKick {
        freq_hz: f("freq_hz"),
        sigma_per_s: f("sigma_per_s"),
        sigma_sd_per_s: f("sigma_sd_per_s"),
        source: kicks[0]["source"].as_str().unwrap().to_owned(),
    }
}

/// The episodes' own fits (the episode finder alone): what every command
/// reported before one kick had one sigma.
fn own_fits(log: &Path) -> (Episode, Episode) {
    let found = find_episodes(&Run::load(log).unwrap());
    assert_eq!(found.len(), 2, "{found:#?}");
    let kick = found
        .iter()
        .find(|e| e.stability == Stability::Stable && (e.onset_s - KICK_S).abs() < 0.5)
        .expect("the kick's episode");
    let wobble = found
        .iter()
        .find(|e| e.stability == Stability::Unstable)
        .expect("the wobble");
    (kick.clone(), wobble.clone())
}

#[test]
fn a_kick_has_margins_sigma_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let card = dir.path().join("card");
    std::fs::create_dir(&card).unwrap();
    let log = card.join("RUN00001.WBL");
    analysis_support::write_log(&log, &ride(), &Extras::default());

    let margin = margin_kick(&log);
    assert_eq!(margin.source, "host");
    let (own_kick, own_wobble) = own_fits(&log);
    // The two estimates of the kick differ (the episode's own fit starts
    // within the push and stops early); margin's is the nearer the truth.
    assert!(
        (own_kick.sigma_per_s - margin.sigma_per_s).abs() > 0.03,
        "own {} margin {}",
        own_kick.sigma_per_s,
        margin.sigma_per_s
    );
    assert!(
        (margin.sigma_per_s - KICK_SIGMA_PER_S).abs()
            < (own_kick.sigma_per_s - KICK_SIGMA_PER_S).abs()
    );

    // `wobble --json`: the kick with margin's values, the wobble its own.
    let report = json_of(wobblog().args(["wobble", "--json"]).arg(&log));
    let episodes = report["episodes"].as_array().unwrap();
    assert_eq!(episodes.len(), 2, "{report:#}");
    let kick = episodes
        .iter()
        .find(|e| e["stability"] == "stable")
        .unwrap();
    assert_eq!(kick["sigma_per_s"].as_f64(), Some(margin.sigma_per_s));
    assert_eq!(kick["sigma_sd_per_s"].as_f64(), Some(margin.sigma_sd_per_s));
    assert_eq!(kick["freq_hz"].as_f64(), Some(margin.freq_hz));
    assert_eq!(kick["source"], "host");
    assert_eq!(kick["onset_s"].as_f64(), Some(own_kick.onset_s));
    let wobble = episodes
        .iter()
        .find(|e| e["stability"] == "unstable")
        .unwrap();
    assert_eq!(wobble["sigma_per_s"].as_f64(), Some(own_wobble.sigma_per_s));
    assert_eq!(wobble["freq_hz"].as_f64(), Some(own_wobble.freq_hz));
    assert_eq!(wobble["sigma_sd_per_s"], Value::Null);
    assert_eq!(wobble["source"], "episode");

    // `export`'s episodes table: the same.
    let dataset = dir.path().join("season");
    stdout_of(wobblog().arg("export").arg(&card).arg("-o").arg(&dataset));
    let table = dataset.join("episodes/part-0.parquet");
    let reader = SerializedFileReader::new(File::open(&table).unwrap()).unwrap();
    let rows: Vec<parquet::record::Row> = reader
        .get_row_iter(None)
        .unwrap()
        .map(Result::unwrap)
        .collect();
    assert_eq!(rows.len(), 2);
    let cell = |row: &parquet::record::Row, name: &str| {
        row.get_column_iter()
            .find(|(n, _)| n.as_str() == name)
            .map(|(_, f)| f.clone())
            .unwrap()
    };
    for row in &rows {
        let expected = if cell(row, "stability") == Field::Str("stable".into()) {
            [
                Field::Double(margin.freq_hz),
                Field::Double(margin.sigma_per_s),
                Field::Double(margin.sigma_sd_per_s),
                Field::Str("host".into()),
            ]
        } else {
            [
                Field::Double(own_wobble.freq_hz),
                Field::Double(own_wobble.sigma_per_s),
                Field::Null,
                Field::Str("episode".into()),
            ]
        };
        let got = ["freq_hz", "sigma_per_s", "sigma_sd_per_s", "source"].map(|c| cell(row, c));
        assert_eq!(got, expected);
    }

    // `model compare`: the measured columns are margin's for the kick.
    let text = stdout_of(wobblog().args(["model", "compare"]).arg(params()).arg(&log));
    let rows: Vec<Vec<&str>> = text
        .lines()
        .filter(|l| l.starts_with("RUN00001.WBL"))
        .map(|l| l.split_whitespace().collect())
        .collect();
    assert_eq!(rows.len(), 2, "{text}");
    let kick_row = rows
        .iter()
        .find(|r| r[2] == format!("{:.2}", own_kick.onset_s))
        .expect(&text);
    assert_eq!(kick_row[1], "wobble", "{text}");
    assert_eq!(kick_row[4], format!("{:.2}", margin.freq_hz), "{text}");
    assert_eq!(kick_row[7], format!("{:.2}", margin.sigma_per_s), "{text}");
    assert_ne!(kick_row[7], format!("{:.2}", own_kick.sigma_per_s));
    assert_eq!(kick_row[10], "host", "{text}");
    let wobble_row = rows.iter().find(|r| r[10] == "episode").expect(&text);
    assert_eq!(
        wobble_row[7],
        format!("{:.2}", own_wobble.sigma_per_s),
        "{text}"
    );

    // `model fit`: fitted to margin's values for the kick (the fit of the
    // observations built here from margin's report and the wobble's own).
    let fitted = dir.path().join("fitted.toml");
    let out = stdout_of(
        wobblog()
            .args(["model", "fit"])
            .arg(params())
            .arg(&log)
            .args(["--param", "steer_head.stiffness", "-o"])
            .arg(&fitted),
    );
    let obs = [
        Observation {
            speed_mps: own_kick.speed_at_onset_mps,
            freq_hz: margin.freq_hz,
            sigma_per_s: margin.sigma_per_s,
        },
        Observation {
            speed_mps: own_wobble.speed_at_onset_mps,
            freq_hz: own_wobble.freq_hz,
            sigma_per_s: own_wobble.sigma_per_s,
        },
    ];
    // The order of the episodes in time: the wobble (14 s) first.
    let obs = [obs[1], obs[0]];
    let set = wobble_model::ParamSet::load(&params()).unwrap();
    let weights = Weights {
        freq_sd_hz: 0.1,
        sigma_sd_per_s: 0.5,
    };
    let keys = ["steer_head.stiffness".to_owned()];
    let expected = fit(&set, &keys, &obs, weights).unwrap();
    let value = expected.estimates[0].value;
    assert!(
        out.contains(&format!("steer_head.stiffness = {value:.6}")),
        "{out}\nexpected {value:.6}"
    );
    // ... which is not the fit to the kick's own estimate.
    let mut own = obs;
    own[1].freq_hz = own_kick.freq_hz;
    own[1].sigma_per_s = own_kick.sigma_per_s;
    let own_value = fit(&set, &keys, &own, weights).unwrap().estimates[0].value;
    assert_ne!(format!("{value:.6}"), format!("{own_value:.6}"));
}

/// `margin` reads a log's kicks as it streams by (in bounded memory): the
/// same kicks as the run loaded whole gives, a card record without a speed
/// taking the mean wheel speed over the 2 s after it.
#[test]
fn streamed_kicks_are_the_whole_runs() {
    let dir = tempfile::tempdir().unwrap();
    let log = dir.path().join("RUN00001.WBL");
    let mut ride = ride();
    // Speeding up from 2 m/s at 0.1 m/s per second.
    for (t, v) in ride.t_s.iter().zip(&mut ride.speed_mps) {
        *v = 2.0 + 0.1 * t;
    }
    let extras = Extras {
        // One record beside the host's kick, two alone (one without a
        // speed).
        records: vec![
            kick_record(KICK_S, Some(4000)),
            kick_record(8.0, None),
            kick_record(30.0, Some(5000)),
        ],
        ..Extras::default()
    };
    analysis_support::write_log(&log, &ride, &extras);
    for prefer in [Prefer::Best, Prefer::Card, Prefer::Host] {
        let (summary, streamed) = load_campaign_kicks(&log, prefer).unwrap();
        let run = Run::load(&log).unwrap();
        assert_eq!(summary.kick_records, run.summary.kick_records);
        let wheel_m = wheel_circumference_m(&run.summary.config).unwrap();
        let whole = campaign_kicks(&run, wheel_m, prefer);
        assert_eq!(streamed, whole, "{prefer:?}");
    }
    let (_, kicks) = load_campaign_kicks(&log, Prefer::Best).unwrap();
    let sources: Vec<Source> = kicks.iter().map(|k| k.source).collect();
    // The growing wobble at 14 s is no kick.
    assert_eq!(sources, [Source::Card, Source::CardHost, Source::Card]);
    // 2 + 0.1 t over 8-10 s, frames 10 ms apart, speeds in mm/s.
    let frames: Vec<f64> = (800..=1000)
        .map(|i| 2.0 + 0.1 * f64::from(i) / 100.0)
        .collect();
    let mean = frames.iter().sum::<f64>() / frames.len() as f64;
    assert!((kicks[0].speed_mps - mean).abs() < 1e-3, "{:?}", kicks[0]);
    assert!((mean - 2.9).abs() < 1e-9);
}
