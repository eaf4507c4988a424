//! Errors that say what is valid: an unknown `--set` key or `--param` name
//! gets the closest known one or the list, and a file that is no parameter
//! file says what was expected.

mod analysis_support;

use std::path::{Path, PathBuf};

use analysis_support::wobblog;

fn params() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/test-bicycle.toml")
}

fn golden(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../firmware/core/tests/golden")
        .join(name)
}

/// The stderr of `cmd`, which must fail with exit code `code`.
fn failure_of(cmd: &mut assert_cmd::Command, code: i32) -> String {
    let out = cmd.output().unwrap();
    assert_eq!(out.status.code(), Some(code), "{out:?}");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn an_unknown_set_key_gets_the_closest_key_or_the_list() {
    let log = golden("clean.WBL");
    let near = failure_of(
        wobblog()
            .arg("detect")
            .arg(&log)
            .args(["--set", "detector.amp_on_dg=0.6"]),
        2,
    );
    assert!(
        near.contains(
            "--set detector.amp_on_dg=0.6: unknown key; did you mean \"detector.amp_on_deg\"?"
        ),
        "{near}"
    );
    let far = failure_of(
        wobblog()
            .arg("detect")
            .arg(&log)
            .args(["--set", "colour=red"]),
        2,
    );
    assert!(
        far.contains("--set colour=red: unknown key; the keys are "),
        "{far}"
    );
    for key in ["wheel.circumference_m", "detector.amp_on_deg"] {
        assert!(far.contains(key), "{far}");
    }
}

#[test]
fn an_unknown_param_gets_the_closest_parameter_or_the_list() {
    let out = tempfile::tempdir().unwrap();
    let file = params().display().to_string();
    let fit = failure_of(
        wobblog()
            .args(["model", "fit"])
            .arg(params())
            .arg(golden("clean.WBL"))
            .args(["--param", "steer_head.stifness", "-o"])
            .arg(out.path().join("fitted.toml")),
        1,
    );
    assert!(
        fit.contains(&format!(
            "{file}: steer_head.stifness: no such parameter in the file; did you mean \"steer_head.stiffness\"?"
        )),
        "{fit}"
    );
    assert!(!out.path().join("fitted.toml").exists());

    let margin = failure_of(
        wobblog()
            .arg("margin")
            .arg(golden("clean.WBL"))
            .arg("--model")
            .arg(params())
            .args(["--param", "steer_head.dampng"]),
        1,
    );
    assert!(
        margin.contains("did you mean \"steer_head.damping\"?"),
        "{margin}"
    );

    let sweep = failure_of(
        wobblog().args(["model", "sweep"]).arg(params()).args([
            "--param",
            "mass",
            "--factors",
            "1,2",
        ]),
        1,
    );
    // Every body has a mass: each is offered.
    assert!(
        sweep.contains("mass: no such parameter in the file; did you mean one of \"fork.mass\", "),
        "{sweep}"
    );
    assert!(sweep.contains("\"torso.mass\""), "{sweep}");
    assert!(!sweep.contains("steer_head.stiffness"), "{sweep}");
    // Far from every name: the list.
    let far = failure_of(
        wobblog().args(["model", "sweep"]).arg(params()).args([
            "--param",
            "saddle_height",
            "--factors",
            "1,2",
        ]),
        1,
    );
    assert!(far.contains("the parameters of the file are "), "{far}");
    for key in ["steer_head.stiffness", "front_tyre.cornering_stiffness"] {
        assert!(far.contains(key), "{far}");
    }
}

#[test]
fn a_file_that_is_no_parameter_file_says_what_was_expected() {
    let dir = tempfile::tempdir().unwrap();
    let empty = dir.path().join("empty.toml");
    std::fs::write(&empty, "").unwrap();
    let other = dir.path().join("settings.toml");
    std::fs::write(&other, "colour = \"red\"\n").unwrap();
    let csv = dir.path().join("ride.csv");
    std::fs::write(&csv, "t_s,steer_deg\n0,1\n").unwrap();
    for file in [empty, other, csv, golden("clean.WBL")] {
        let err = failure_of(wobblog().args(["model", "eig"]).arg(&file), 1);
        let named = format!(
            "{}: not a parameter file: expected a TOML parameter file",
            file.display()
        );
        assert!(err.contains(&named), "{err}");
        assert!(
            err.contains("or a BicycleParameters `*Benchmark.txt`"),
            "{err}"
        );
        assert!(!err.contains("missing"), "{err}");
    }
}
