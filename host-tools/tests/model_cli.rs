//! `wobblog model`: the eigenvalue CSV interface, critical speeds kept out
//! of it, and errors naming the file and the parameter.

use assert_cmd::Command;
use std::path::{Path, PathBuf};

fn wobblog() -> Command {
    Command::cargo_bin("wobblog").unwrap()
}

fn params(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("bicycle-model/params")
        .join(name)
}

#[test]
fn eig_csv_has_one_row_per_eigenvalue_and_critical_speeds_on_stderr() {
    let out = wobblog()
        .args(["model", "eig"])
        .arg(params("benchmark.toml"))
        .args(["--speeds", "0:10:0.5", "--format", "csv"])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("speed_mps,mode,re_per_s,im_rad_per_s"));
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    assert_eq!(rows.len(), 21 * 4, "4 eigenvalues at each of 21 speeds");
    assert!(rows.iter().all(|r| r.len() == 4));
    let at5: Vec<&Vec<&str>> = rows.iter().filter(|r| r[0] == "5").collect();
    let weave: Vec<f64> = at5
        .iter()
        .filter(|r| r[1] == "weave")
        .map(|r| r[3].parse().unwrap())
        .collect();
    assert_eq!(weave.len(), 2, "both members of the weave pair");
    assert!(
        (weave[0] + 4.46486771378823).abs() < 1e-10 && (weave[1] - 4.46486771378823).abs() < 1e-10
    );
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(stderr.contains("weave speed 4.292382536 m/s"), "{stderr}");
    assert!(stderr.contains("capsize speed 6.024262015 m/s"), "{stderr}");
}

#[test]
fn eig_writes_its_output_file_whole() {
    let dir = tempfile::tempdir().unwrap();
    let target = dir.path().join("eig.jsonl");
    wobblog()
        .args(["model", "eig"])
        .arg(params("benchmark.toml"))
        .args(["--speeds", "4:7:0.25", "--format", "jsonl", "-o"])
        .arg(&target)
        .assert()
        .success();
    let text = std::fs::read_to_string(&target).unwrap();
    let last: serde_json::Value = serde_json::from_str(text.lines().last().unwrap()).unwrap();
    assert_eq!(last["mode"], "capsize");
    assert!((last["critical_speed_mps"].as_f64().unwrap() - 6.024262015).abs() < 1e-9);
    assert_eq!(
        std::fs::read_dir(dir.path()).unwrap().count(),
        1,
        "no temporary file left"
    );
}

#[test]
fn unphysical_parameters_exit_1_naming_file_and_parameter() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.toml");
    let text = std::fs::read_to_string(params("benchmark.toml")).unwrap();
    std::fs::write(
        &bad,
        text.replacen(
            "value = 3.0, unit = \"kg\"",
            "value = -3.0, unit = \"kg\"",
            1,
        ),
    )
    .unwrap();
    let out = wobblog().args(["model", "eig"]).arg(&bad).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8(out.stderr).unwrap();
    assert!(
        stderr.contains("bad.toml: front_wheel.mass: unphysical"),
        "{stderr}"
    );
}

#[test]
fn usage_errors_exit_2() {
    let out = wobblog()
        .args(["model", "eig"])
        .arg(params("benchmark.toml"))
        .args(["--speeds", "5:1:0.1"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
}
