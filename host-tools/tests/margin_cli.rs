//! `wobblog margin`: a hand-made campaign whose answer is written down
//! (ring-downs decaying at `sigma = 0.5 (u - 4)`, so the wobble speed is
//! 4 m/s), its JSON and table forms, the figure, refusals and errors.

mod analysis_support;

use std::path::Path;

use analysis_support::{wobblog, Extras, Ride};
use serde_json::Value;

/// The wobble speed of the hand-made campaign, m/s.
const WOBBLE_MPS: f64 = 4.0;
/// Its ring's frequency, Hz.
const FREQ_HZ: f64 = 6.5;

/// A 10 s pass at `speed` with one kick at 3 s: a 0.1 s push of 4 degrees,
/// then a ring of 1.5 degrees decaying at `0.5 (u - 4)`, plus a weave and
/// small deterministic noise.
fn pass(path: &Path, speed: f64, seed: u32) {
    analysis_support::write_log(path, &pass_ride(speed, seed), &Extras::default());
}

/// The ride of [`pass`].
fn pass_ride(speed: f64, seed: u32) -> Ride {
    analysis_support::kick_pass(speed, WOBBLE_MPS, FREQ_HZ, seed)
}

/// `speeds.len()` passes in a new directory.
fn campaign(speeds: &[f64]) -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    for (i, &u) in speeds.iter().enumerate() {
        pass(&dir.path().join(format!("RUN{i:05}.WBL")), u, i as u32);
    }
    dir
}

fn speeds(from: f64, to: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| from + (to - from) * i as f64 / (n - 1) as f64)
        .collect()
}

fn margin_json(args: &[&std::ffi::OsStr]) -> (Option<i32>, Value, String) {
    let out = wobblog()
        .arg("margin")
        .args(args)
        .arg("--json")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let v = serde_json::from_slice(&out.stdout).unwrap_or(Value::Null);
    (out.status.code(), v, stderr)
}

#[test]
fn predicts_the_written_down_wobble_speed() {
    let dir = campaign(&speeds(2.0, 3.4, 12));
    let (code, v, stderr) = margin_json(&[dir.path().as_os_str()]);
    assert_eq!(code, Some(0), "{stderr}");
    // A straight sigma: the line, bent as the prior's mean shape, crosses
    // a little late (by 2.5 % here), well inside its interval.
    let w = v["wobble_speed_mps"].as_f64().unwrap();
    assert!((w - WOBBLE_MPS).abs() < 0.15, "{v}");
    let lo = v["ci95_mps"][0].as_f64().unwrap();
    let hi = v["ci95_mps"][1].as_f64().unwrap();
    // Its width is the bend allowance's (SD 4 in the shape, judged at each
    // candidate's scale): about half the wobble speed, most of it above.
    assert!(lo < WOBBLE_MPS && WOBBLE_MPS < hi, "{v}");
    assert!(WOBBLE_MPS - lo < 0.15 * WOBBLE_MPS, "{v}");
    assert!(hi - lo < 0.6 * WOBBLE_MPS, "{v}");
    // The riding limit, 10 % below the lower bound by default, and the
    // next pass no faster than it.
    let ride = v["ride_below_mps"].as_f64().unwrap();
    assert!((ride - 0.9 * lo).abs() < 1e-9, "{v}");
    assert!(v["next_pass_max_mps"].as_f64().unwrap() <= ride, "{v}");
    assert!(v["open_because"].is_null(), "{v}");
    let (_, wider, _) = margin_json(&[
        dir.path().as_os_str(),
        std::ffi::OsStr::new("--ride-margin"),
        std::ffi::OsStr::new("20"),
    ]);
    assert!((wider["ride_below_mps"].as_f64().unwrap() - 0.8 * lo).abs() < 1e-9);
    assert_eq!(v["kicks_used"], 12);
    assert_eq!(v["kicks_rejected"], 0);
    assert!(v["method"].as_str().unwrap().contains("profile likelihood"));
    let kicks = v["kicks"].as_array().unwrap();
    assert_eq!(kicks.len(), 12);
    for k in kicks {
        let u = k["speed_mps"].as_f64().unwrap();
        let s = k["sigma_per_s"].as_f64().unwrap();
        assert!((s - 0.5 * (u - WOBBLE_MPS)).abs() < 0.05, "{k}");
        assert!(
            (k["freq_hz"].as_f64().unwrap() - FREQ_HZ).abs() < 0.05,
            "{k}"
        );
        assert_eq!(k["source"], "host");
    }
}

#[test]
fn table_says_it_in_words_and_the_figure_is_drawn() {
    let dir = campaign(&speeds(2.0, 3.4, 8));
    let png = dir.path().join("trend.png");
    let out = wobblog()
        .arg("margin")
        .arg(dir.path())
        .arg("--plot")
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("predicted wobble speed 3.9") || text.contains("predicted wobble speed 4.0"),
        "{text}"
    );
    assert!(text.contains("95 % interval"), "{text}");
    let bytes = std::fs::read(&png).unwrap();
    assert!(bytes.starts_with(b"\x89PNG"));
}

#[test]
fn refuses_to_pretend() {
    // Three kicks: too few.
    let few = campaign(&speeds(2.0, 3.0, 3));
    let (code, v, _) = margin_json(&[few.path().as_os_str()]);
    assert_eq!(code, Some(0));
    assert!(v["wobble_speed_mps"].is_null(), "{v}");
    assert!(
        v["warnings"][0].as_str().unwrap().contains("too few"),
        "{v}"
    );
    // Kicks far below it over a narrow range: a long extrapolation, open.
    let far = campaign(&speeds(1.6, 2.1, 8));
    let (code, v, _) = margin_json(&[far.path().as_os_str()]);
    assert_eq!(code, Some(0));
    assert!(v["ci95_mps"][1].is_null(), "{v}");
    let warnings = v["warnings"].to_string();
    assert!(
        warnings.contains("narrow") && warnings.contains("extrapolation"),
        "{v}"
    );
}

#[test]
fn errors_name_the_input() {
    let dir = tempfile::tempdir().unwrap();
    // An empty directory, a missing file: runtime failures naming them.
    let (code, _, stderr) = margin_json(&[dir.path().as_os_str()]);
    assert_eq!(code, Some(1));
    assert!(stderr.contains("no *.WBL logs"), "{stderr}");
    let missing = dir.path().join("RUN00001.WBL");
    let (code, _, stderr) = margin_json(&[missing.as_os_str()]);
    assert_eq!(code, Some(1));
    assert!(stderr.contains("RUN00001.WBL"), "{stderr}");
    // A figure of an unknown kind: a usage error before any work.
    let out = wobblog()
        .args(["margin", "x.wbl", "--plot", "trend.jpg"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    // `--param` needs `--model`; a missing parameter file is named.
    let out = wobblog()
        .args(["margin", "x.wbl", "--param", "steer_head.damping"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let some = campaign(&speeds(2.0, 3.4, 6));
    let params = some.path().join("nothing.toml");
    let out = wobblog()
        .arg("margin")
        .arg(some.path())
        .arg("--model")
        .arg(&params)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("nothing.toml"));
    // One unreadable log among good ones: the others still count, the
    // exit code says one failed.
    let good = campaign(&speeds(2.0, 3.4, 8));
    std::fs::write(good.path().join("RUN09999.WBL"), b"not a log").unwrap();
    let (code, v, stderr) = margin_json(&[good.path().as_os_str()]);
    assert_eq!(code, Some(1));
    assert!(stderr.contains("RUN09999.WBL"), "{stderr}");
    assert_eq!(v["kicks_used"], 8, "{v}");
}

/// `encode --detect` runs the on-board detector over a CSV as the board
/// does: the log holds its kick records (and the configuration in its
/// header), `margin` takes them and says so per kick (`card-host`: the
/// card's record, re-measured by the host), `--kicks card` uses the
/// records alone, and a log encoded without `--detect` has none.
#[test]
fn card_kick_records_are_used_and_said_per_kick() {
    let dir = tempfile::tempdir().unwrap();
    for (i, u) in speeds(2.0, 3.4, 8).into_iter().enumerate() {
        let ride = pass_ride(u, i as u32);
        let mut csv = String::from("t_s,steer_deg,speed_mps\n");
        for k in 0..ride.t_s.len() {
            csv.push_str(&format!(
                "{:.2},{:.3},{:.3}\n",
                ride.t_s[k], ride.steer_deg[k], ride.speed_mps[k]
            ));
        }
        let csv_path = dir.path().join(format!("pass{i}.csv"));
        std::fs::write(&csv_path, csv).unwrap();
        let status = wobblog()
            .arg("encode")
            .arg("--csv")
            .arg(&csv_path)
            .arg("-o")
            .arg(dir.path().join(format!("RUN{i:05}.WBL")))
            .arg("--detect")
            .output()
            .unwrap();
        assert!(status.status.success());
    }
    let first = dir.path().join("RUN00000.WBL");
    let info = analysis_support::info_json(&first);
    assert_eq!(info["kicks"], 1, "{info}");
    assert!(!info["config"].as_array().unwrap().is_empty(), "{info}");
    let (code, v, stderr) = margin_json(&[dir.path().as_os_str()]);
    assert_eq!(code, Some(0), "{stderr}");
    let kicks = v["kicks"].as_array().unwrap();
    assert_eq!(kicks.len(), 8, "{v}");
    for k in kicks {
        assert_eq!(k["source"], "card-host", "{k}");
        assert!(k["card"]["sigma_per_s"].is_number(), "{k}");
        assert_eq!(k["sigma_per_s"], k["host"]["sigma_per_s"], "{k}");
    }
    let w = v["wobble_speed_mps"].as_f64().unwrap();
    assert!((w - WOBBLE_MPS).abs() < 0.15, "{v}");
    // The card's records alone.
    let (code, v, _) = margin_json(&[
        dir.path().as_os_str(),
        std::ffi::OsStr::new("--kicks"),
        std::ffi::OsStr::new("card"),
    ]);
    assert_eq!(code, Some(0));
    for k in v["kicks"].as_array().unwrap() {
        assert_eq!(k["source"], "card", "{k}");
        assert!(k["host"].is_null(), "{k}");
    }
    // Without --detect: no records.
    let plain = dir.path().join("plain.wbl");
    let status = wobblog()
        .arg("encode")
        .arg("--csv")
        .arg(dir.path().join("pass0.csv"))
        .arg("-o")
        .arg(&plain)
        .output()
        .unwrap();
    assert!(status.status.success());
    assert_eq!(analysis_support::info_json(&plain)["kicks"], 0);
}

#[test]
fn hostile_log_names_are_escaped_in_the_table_and_exact_in_json() {
    let dir = campaign(&speeds(2.0, 3.4, 6));
    let name = "RUN\u{1b}[2J\u{202e}\n  9.99  forged.WBL";
    pass(&dir.path().join(name), 3.0, 99);
    let out = wobblog().arg("margin").arg(dir.path()).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let raw = |c: char| c.is_control() && c != '\n' || c == '\u{202e}';
    assert!(!text.chars().any(raw), "{text:?}");
    assert!(
        text.contains("RUN\\u{1b}[2J\\u{202e}\\n  9.99  forged.WBL"),
        "{text}"
    );
    assert!(
        !text.lines().any(|l| l.starts_with("  9.99")),
        "a forged line: {text}"
    );
    let (code, v, _) = margin_json(&[dir.path().as_os_str()]);
    assert_eq!(code, Some(0));
    let logs: Vec<&str> = v["kicks"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|k| k["log"].as_str())
        .collect();
    assert!(logs.iter().any(|l| l.ends_with(name)), "{logs:?}");
}

#[test]
fn a_log_named_twice_linked_or_copied_is_counted_once() {
    let dir = campaign(&speeds(2.0, 3.4, 6));
    let d = dir.path();
    let (code, once, stderr) = margin_json(&[d.as_os_str()]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(once["kicks"].as_array().unwrap().len(), 6);
    let other = tempfile::tempdir().unwrap();
    let linked = other.path().join("linked.WBL");
    let copied = other.path().join("copied.WBL");
    std::fs::hard_link(d.join("RUN00001.WBL"), &linked).unwrap();
    std::fs::copy(d.join("RUN00002.WBL"), &copied).unwrap();
    let first = d.join("RUN00000.WBL");
    let (code, v, stderr) = margin_json(&[
        d.as_os_str(),
        first.as_os_str(),
        first.as_os_str(),
        linked.as_os_str(),
        copied.as_os_str(),
    ]);
    assert_eq!(code, Some(0), "{stderr}");
    assert_eq!(v["kicks"], once["kicks"], "{stderr}");
    assert_eq!(v["wobble_speed_mps"], once["wobble_speed_mps"]);
    assert_eq!(v["ci95_mps"], once["ci95_mps"]);
    assert_eq!(stderr.matches("counted once").count(), 4, "{stderr}");
    assert!(
        stderr.contains("linked.WBL is the same file as"),
        "{stderr}"
    );
    assert!(stderr.contains("copied.WBL is a copy of"), "{stderr}");
}

#[test]
fn no_figure_when_a_log_failed() {
    let dir = campaign(&speeds(2.0, 3.4, 6));
    std::fs::write(dir.path().join("RUN00099.WBL"), b"not a log").unwrap();
    let png = dir.path().join("margin.png");
    std::fs::write(&png, b"old figure").unwrap();
    let out = wobblog()
        .arg("margin")
        .arg(dir.path())
        .arg("--plot")
        .arg(&png)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&out.stderr).contains("RUN00099.WBL"));
    assert_eq!(std::fs::read(&png).unwrap(), b"old figure");
}
