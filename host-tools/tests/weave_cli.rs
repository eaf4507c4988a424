//! The weave in the commands, on a hand-made campaign whose answer is
//! written down (roll-rate ring-downs at 0.8 Hz decaying at `sigma =
//! 8 (1/u - 1/4)`, so the weave speed is 4 m/s and sigma is straight in
//! `1/u`): `margin --mode weave` (its JSON and table forms and its
//! refusals), `wobble`'s `mode`, the data set's episodes and `model
//! compare`.

mod analysis_support;

use std::f64::consts::TAU;
use std::path::Path;

use analysis_support::{wobblog, Extras, Ride};
use serde_json::Value;

/// The campaign's weave speed, m/s.
const WEAVE_MPS: f64 = 4.0;

/// sigma of the weave at `u`, 1/s.
fn sigma(u: f64) -> f64 {
    8.0 * (1.0 / u - 1.0 / WEAVE_MPS)
}

/// A 15 s pass at `speed` with a kick at 4 s: the roll rate rings at
/// 0.8 Hz from 15 deg/s, decaying at [`sigma`], plus small deterministic
/// noise.
fn pass(path: &Path, speed: f64, seed: u32) {
    let mut ride = Ride::new(15.0, speed, 0.0, 0.0, 0.0);
    let mut state = 0x9E37_79B9u32 ^ seed;
    for (t, g) in ride.t_s.iter().zip(ride.gyro_dps.iter_mut()) {
        state ^= state << 13;
        state ^= state >> 17;
        state ^= state << 5;
        let noise = 0.3 * (f64::from(state) / f64::from(u32::MAX) - 0.5);
        let tau = t - 4.0;
        let ring = if tau >= 0.0 {
            15.0 * (sigma(speed) * tau).exp() * (TAU * 0.8 * tau).sin()
        } else {
            0.0
        };
        g[0] += ring + noise;
    }
    analysis_support::write_log(path, &ride, &Extras::default());
}

/// Ten passes at 4.6-6.4 m/s in a new directory.
fn campaign() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for i in 0..10 {
        let u = 4.6 + 0.2 * f64::from(i);
        pass(&dir.path().join(format!("RUN{i:05}.WBL")), u, i as u32);
    }
    dir
}

#[test]
fn json_gives_the_weave_speed_below_the_kicks() {
    let dir = campaign();
    let v: Value = serde_json::from_str(&run_ok(
        &["margin", "--mode", "weave", "--json"],
        dir.path(),
    ))
    .unwrap();
    assert_eq!(v["mode"], "weave");
    let kicks = v["kicks"].as_array().unwrap();
    assert_eq!(kicks.len(), 10, "{v}");
    for k in kicks {
        let u = k["speed_mps"].as_f64().unwrap();
        assert!((k["freq_hz"].as_f64().unwrap() - 0.8).abs() < 0.02, "{k}");
        let error = (k["sigma_per_s"].as_f64().unwrap() - sigma(u)).abs();
        assert!(
            error < 0.1 && error < 2.0 * k["sigma_sd_per_s"].as_f64().unwrap(),
            "{k}"
        );
        // The roll angle's amplitude: 15 deg/s over 2 pi 0.8 rad/s, less
        // what the ring decayed before the fit's start.
        let roll = k["amp_deg"].as_f64().unwrap();
        assert!(roll > 1.0 && roll < 15.0 / (TAU * 0.8) * 1.05, "{k}");
        assert_eq!(k["used"], true);
    }
    let w = v["weave_speed_mps"].as_f64().unwrap();
    let lo = v["ci95_mps"][0].as_f64().unwrap();
    let hi = v["ci95_mps"][1].as_f64().unwrap();
    assert!(lo < WEAVE_MPS && WEAVE_MPS < hi && hi < 4.6, "{v}");
    assert!((w - WEAVE_MPS).abs() < 0.3, "{w}");
    assert_eq!(v["kicks_used"], 10);
}

#[test]
fn the_table_says_it_in_words() {
    let dir = campaign();
    let text = run_ok(&["margin", "--mode", "weave"], dir.path());
    assert!(
        text.starts_with("10 weave kicks in 10 logs: 10 used, 0 rejected\n"),
        "{text}"
    );
    assert!(text.contains("predicted weave speed "), "{text}");
    assert!(text.contains("(the weave is stable above it)"), "{text}");
}

#[test]
fn options_of_the_wobble_alone_are_refused() {
    let dir = campaign();
    for extra in [
        &["--plot", "x.png"][..],
        &["--model", "m.toml"],
        &["--kicks", "card"],
    ] {
        let out = wobblog()
            .args(["margin", "--mode", "weave"])
            .args(extra)
            .arg(dir.path())
            .output()
            .unwrap();
        assert_eq!(out.status.code(), Some(2), "{extra:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(&format!("--mode weave does not take {}", extra[0])),
            "{err}"
        );
    }
}

/// A wobble campaign's logs have no weave kicks: too few, no prediction.
#[test]
fn no_weave_kicks_no_prediction() {
    let dir = tempfile::tempdir().unwrap();
    for i in 0..3 {
        let ride = analysis_support::kick_pass(3.0 + f64::from(i), 6.0, 6.5, i);
        analysis_support::write_log(
            &dir.path().join(format!("RUN{i:05}.WBL")),
            &ride,
            &Extras::default(),
        );
    }
    let v: Value = serde_json::from_str(&run_ok(
        &["margin", "--mode", "weave", "--json"],
        dir.path(),
    ))
    .unwrap();
    assert_eq!(v["kicks"].as_array().unwrap().len(), 0, "{v}");
    assert_eq!(v["weave_speed_mps"], Value::Null);
    assert!(
        v["warnings"][0]
            .as_str()
            .unwrap()
            .starts_with("too few kicks"),
        "{v}"
    );
}

/// `wobble` lists each kick's weave ring-down with `mode` weave, beside the
/// ride's wobble (`mode` wobble), and the wobble speed is the wobble's.
#[test]
fn wobble_lists_the_weave_ring_downs() {
    let dir = campaign();
    let log = dir.path().join("RUN00003.WBL");
    let v: Value = serde_json::from_str(&run_ok(&["wobble", "--json"], &log)).unwrap();
    let episodes = v["episodes"].as_array().unwrap();
    let weave: Vec<&Value> = episodes.iter().filter(|e| e["mode"] == "weave").collect();
    let wobble: Vec<&Value> = episodes.iter().filter(|e| e["mode"] == "wobble").collect();
    assert_eq!(weave.len(), 1, "{v}");
    assert_eq!(wobble.len() + weave.len(), episodes.len(), "{v}");
    let e = weave[0];
    assert!((e["freq_hz"].as_f64().unwrap() - 0.8).abs() < 0.02, "{e}");
    assert_eq!(e["stability"], "stable");
    assert_eq!(e["source"], "host");
    assert!((e["onset_s"].as_f64().unwrap() - 4.0).abs() < 1.0, "{e}");
    // The ride's 7 Hz wobble (`analysis_support::wobble`) is unstable and
    // gives the wobble speed; the weave's ring-down does not count.
    assert!(
        wobble.iter().all(|w| w["freq_hz"].as_f64().unwrap() > 4.0),
        "{v}"
    );
    let speed = v["wobble_speed_mps"].as_f64().unwrap();
    assert!((speed - 5.2).abs() < 1e-9, "{v}");
    let text = run_ok(&["wobble"], &log);
    assert!(text.contains("\n  mode    onset_s"), "{text}");
    assert!(
        text.lines().any(|l| l.trim_start().starts_with("weave ")),
        "{text}"
    );
}

/// `events --episodes` lists the host's episodes, the weave's ring-down
/// among them, as `wobble` finds them; without it, the log's events alone.
#[test]
fn events_list_the_weave_ring_down_when_asked() {
    let dir = campaign();
    let log = dir.path().join("RUN00003.WBL");
    let v: Value = serde_json::from_str(&run_ok(&["wobble", "--json"], &log)).unwrap();
    let lines = run_ok(&["events", "--json", "--episodes"], &log);
    let listed: Vec<Value> = lines
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .filter(|e: &Value| e["event"] == "episode")
        .collect();
    let episodes = v["episodes"].as_array().unwrap();
    assert_eq!(listed.len(), episodes.len(), "{lines}");
    for (e, w) in listed.iter().zip(episodes) {
        assert_eq!(e["mode"], w["mode"], "{e} {w}");
        assert_eq!(e["t_s"], w["onset_s"], "{e} {w}");
        assert_eq!(e["freq_hz"], w["freq_hz"], "{e} {w}");
    }
    assert!(listed.iter().any(|e| e["mode"] == "weave"), "{lines}");
    // In time order among the log's own events.
    let times: Vec<f64> = lines
        .lines()
        .map(|l| {
            serde_json::from_str::<Value>(l).unwrap()["t_s"]
                .as_f64()
                .unwrap()
        })
        .collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
    let table = run_ok(&["events", "--episodes"], &log);
    assert!(table.contains("weave (host): 0.8"), "{table}");
    let plain = run_ok(&["events", "--json"], &log);
    assert!(!plain.contains("\"episode\""), "{plain}");
}

/// The data set's episodes table has a `mode` column with the weave's rows,
/// and its kicks table the weave's kicks, each used by the prediction.
#[test]
fn the_data_sets_episodes_hold_the_weave() {
    let dir = campaign();
    let out_dir = tempfile::tempdir().unwrap();
    let dataset = out_dir.path().join("set");
    run_ok(&["export", "-o", dataset.to_str().unwrap()], dir.path());
    let modes = texts(&dataset.join("episodes/part-0.parquet"), "mode");
    assert_eq!(
        modes.iter().filter(|m| *m == "weave").count(),
        10,
        "{modes:?}"
    );
    assert!(
        modes.iter().all(|m| m == "weave" || m == "wobble"),
        "{modes:?}"
    );
    // The kicks table: each weave kick, used by the weave's prediction.
    let table = dataset.join("kicks/part-0.parquet");
    let kicks: Vec<(String, String)> = texts(&table, "mode")
        .into_iter()
        .zip(texts(&table, "used"))
        .collect();
    let weave: Vec<&(String, String)> = kicks.iter().filter(|k| k.0 == "weave").collect();
    assert_eq!(weave.len(), 10, "{kicks:?}");
    assert!(weave.iter().all(|k| k.1 == "true"), "{kicks:?}");
}

/// `model compare` puts each weave ring-down against the model's weave
/// at its speed; the benchmark (a Whipple bicycle) has no wobble mode, so
/// the rides' wobbles are said and not compared.
#[test]
fn compare_sets_the_weave_against_the_models_weave() {
    let dir = campaign();
    let params = Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/benchmark.toml");
    let fig = tempfile::tempdir().unwrap();
    let svg = fig.path().join("fig8.svg");
    let text = run_ok(
        &[
            "model",
            "compare",
            params.to_str().unwrap(),
            "-o",
            svg.to_str().unwrap(),
        ],
        dir.path(),
    );
    let weave: Vec<Vec<&str>> = text
        .lines()
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .filter(|c| c.get(1) == Some(&"weave"))
        .collect();
    assert_eq!(weave.len(), 10, "{text}");
    for c in &weave {
        // The benchmark's weave above its weave speed: 0.5-1.1 Hz, decaying.
        let model_hz: f64 = c[5].parse().unwrap();
        let model_sigma: f64 = c[8].parse().unwrap();
        assert!(
            (0.5..1.1).contains(&model_hz) && model_sigma < 0.0,
            "{text}"
        );
    }
    assert!(
        text.contains("the model has no wobble mode: 10 episodes not compared"),
        "{text}"
    );
    let svg = std::fs::read_to_string(svg).unwrap();
    assert!(svg.contains("wobble and weave modes"), "title");
}

/// The standard output of `wobblog ARGS... PATH`, which must succeed.
fn run_ok(args: &[&str], path: &Path) -> String {
    let out = wobblog().args(args).arg(path).output().unwrap();
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Column `name` of the Parquet file at `path`, each cell as text.
fn texts(path: &Path, name: &str) -> Vec<String> {
    use parquet::file::reader::FileReader;
    let reader =
        parquet::file::reader::SerializedFileReader::new(std::fs::File::open(path).unwrap())
            .unwrap();
    reader
        .get_row_iter(None)
        .unwrap()
        .map(|r| {
            let row = r.unwrap();
            row.get_column_iter()
                .find(|(n, _)| n.as_str() == name)
                .map(|(_, f)| f.to_string().trim_matches('"').to_owned())
                .unwrap()
        })
        .collect()
}
