//! Wobble episodes measured on the synthetic corpus, against its
//! ground truth (`hil-tests/fixtures/corpus/manifest.json`).
//!
//! Each fixture CSV goes through `wobblog encode` into a card log and is read
//! back like any ride, so the card's quantisation is part of the test.

mod analysis_support;

use std::path::Path;

use analysis_support::corpus_dir;
use analysis_support::limits::{
    FREQ_TOL_HZ, KICK_FREQ_TOL_HZ, KICK_SIGMA_TOL_REL, ONSET_TOL_S, SIGMA_TOL_REL, SPEED_TOL_MPS,
};

use serde_json::Value;
use wobblog::analysis::{find_episodes, wobble_speed_mps, Episode, Run, Stability};

/// Fixtures the fit is known to measure worse, with their own (sigma,
/// onset) limits, so they cannot get worse unnoticed. The limit cycle (0.9
/// deg held for 6 s at 6.6 Hz, 4.4 m/s) beats with the wheel's 3rd harmonic
/// 0.55 Hz below it (2.18 m wheel). The largest envelope is a beat's crest,
/// so the climb reaches 85 % of it 0.39 s into the plateau; a beat's trough
/// restarts the climb at 10.83 s, so the tone fitted alongside is sought
/// where the wobble already grows and is the wobble itself (6.58 Hz).
/// Measured: sigma 21 % low, onset 0.57 s early. Correcting the three costs
/// the simulated family its onset limit (host-tools/docs/analysis.md).
const KNOWN_WORSE: [(&str, f64, f64); 1] = [("wobble_limit_cycle", 0.25, 0.6)];

fn manifest() -> Value {
    let path = corpus_dir().join("manifest.json");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("{}: {e} (corpus not generated?)", path.display()));
    serde_json::from_str(&text).unwrap()
}

/// The committed fixtures' ground truth.
fn committed(manifest: &Value) -> Vec<&Value> {
    manifest["fixtures"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["committed"] == true)
        .collect()
}

/// The fixture's CSV encoded into a log and loaded.
fn load(fixture: &Value, tmp: &Path) -> Run {
    let csv = corpus_dir().join(fixture["file"].as_str().unwrap());
    let log = tmp.join(format!("{}.wbl", fixture["name"].as_str().unwrap()));
    let input = std::fs::File::open(&csv).unwrap();
    let output = std::io::BufWriter::new(std::fs::File::create(&log).unwrap());
    wobblog::cmd::encode::encode(input, &csv, output, &log, false).unwrap();
    Run::load(&log).unwrap()
}

fn f(v: &Value, key: &str) -> f64 {
    v[key].as_f64().unwrap_or_else(|| panic!("no {key} in {v}"))
}

/// The unstable episode found for a true one: the one whose span holds the
/// true peak.
fn matching<'a>(found: &'a [Episode], truth: &Value) -> Option<&'a Episode> {
    let peak_s = f(truth, "peak_s");
    found
        .iter()
        .filter(|e| e.stability == Stability::Unstable)
        .find(|e| e.onset_s - 1.0 <= peak_s && peak_s <= e.end_s + 0.5)
}

#[test]
fn corpus_episodes_meet_the_acceptance_limits() {
    let manifest = manifest();
    let tmp = tempfile::tempdir().unwrap();
    let mut failures = Vec::new();
    let mut report =
        String::from("fixture               f err Hz  sigma err %  onset err s  speed err m/s\n");
    let mut measured = 0;
    for fixture in committed(&manifest) {
        let truths = fixture["episodes"].as_array().unwrap();
        if truths.is_empty() {
            continue;
        }
        let run = load(fixture, tmp.path());
        let found = find_episodes(&run);
        let name = fixture["name"].as_str().unwrap();
        for truth in truths {
            let Some(e) = matching(&found, truth) else {
                failures.push(format!(
                    "{name}: no unstable episode at {}",
                    truth["onset_s"]
                ));
                continue;
            };
            measured += 1;
            let errs = [
                e.freq_hz - f(truth, "freq_hz"),
                (e.sigma_per_s - f(truth, "growth_per_s")) / f(truth, "growth_per_s"),
                e.onset_s - f(truth, "onset_s"),
                e.speed_at_onset_mps - f(truth, "speed_mps"),
            ];
            report.push_str(&format!(
                "{name:<20} {:>9.3} {:>12.1} {:>12.3} {:>14.3}\n",
                errs[0],
                100.0 * errs[1],
                errs[2],
                errs[3]
            ));
            let (sigma_tol, onset_tol) = KNOWN_WORSE
                .iter()
                .find(|k| k.0 == name)
                .map_or((SIGMA_TOL_REL, ONSET_TOL_S), |k| (k.1, k.2));
            let limits = [FREQ_TOL_HZ, sigma_tol, onset_tol, SPEED_TOL_MPS];
            let what = ["frequency", "sigma", "onset", "speed"];
            for ((err, limit), what) in errs.iter().zip(limits).zip(what) {
                if err.abs() > limit {
                    failures.push(format!("{name}: {what} off by {err:.3} ({e:?})"));
                }
            }
        }
    }
    println!("{report}");
    assert!(measured >= 10, "only {measured} episodes measured");
    assert!(failures.is_empty(), "{}\n{report}", failures.join("\n"));
}

/// Rides with kicks, potholes, kerbs, corners and wheel ripple hold no
/// unstable wobble: whatever rings there must be found stable, or not at all.
#[test]
fn corpus_rides_without_wobble_have_no_unstable_episode() {
    let manifest = manifest();
    let tmp = tempfile::tempdir().unwrap();
    let mut checked = 0;
    for fixture in committed(&manifest) {
        if !fixture["episodes"].as_array().unwrap().is_empty() {
            continue;
        }
        let run = load(fixture, tmp.path());
        let found = find_episodes(&run);
        let unstable: Vec<&Episode> = found
            .iter()
            .filter(|e| e.stability == Stability::Unstable)
            .collect();
        assert!(unstable.is_empty(), "{}: {unstable:#?}", fixture["name"]);
        assert_eq!(wobble_speed_mps(&found), None);
        checked += 1;
    }
    assert!(checked >= 4, "only {checked} rides without wobble");
}

/// Kicks on the handlebar ring the stable wobble mode down: the episodes
/// found at them are stable, near the ring's frequency and decay rate.
#[test]
fn corpus_kicks_are_stable_modes_with_their_decay() {
    let manifest = manifest();
    let tmp = tempfile::tempdir().unwrap();
    let fixture = committed(&manifest)
        .into_iter()
        .find(|f| f["name"] == "ride_kicks")
        .expect("ride_kicks fixture");
    let found = find_episodes(&load(fixture, tmp.path()));
    let mut report = String::new();
    let mut matched = 0;
    for kick in fixture["events"].as_array().unwrap() {
        let t = f(kick, "t_s");
        let Some(e) = found.iter().find(|e| (e.onset_s - t).abs() < 0.5) else {
            continue;
        };
        matched += 1;
        report.push_str(&format!(
            "kick at {t:6.2}: f {:.2}/{:.2} Hz, sigma {:.2}/{:.2} 1/s\n",
            e.freq_hz,
            f(kick, "freq_hz"),
            e.sigma_per_s,
            -f(kick, "decay_per_s")
        ));
        assert_eq!(e.stability, Stability::Stable, "{report}");
        assert!(
            (e.freq_hz - f(kick, "freq_hz")).abs() < KICK_FREQ_TOL_HZ,
            "{report}"
        );
        let rel = e.sigma_per_s / -f(kick, "decay_per_s") - 1.0;
        assert!(rel.abs() < KICK_SIGMA_TOL_REL, "{report}");
    }
    println!("{report}");
    assert!(matched >= 10, "only {matched} kicks found:\n{report}");
}
