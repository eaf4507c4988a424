//! A card folder (a directory of `RUNnnnnn.WBL` logs) where a command takes
//! logs: `wobble`, `model compare` and `model fit` read every log in it as
//! if each were named; `plot` and `events`, which take one log, refuse it
//! naming the folder and listing its logs; `summary` given a log points to
//! `info`.

mod analysis_support;

use std::path::{Path, PathBuf};

use analysis_support::{stdout_of, wobblog, Extras, Ride};

/// A card folder with two logs (a ride with a wobble, a calm one) and a
/// file that is no log; returns the folder and the logs in name order.
fn card() -> (tempfile::TempDir, Vec<PathBuf>) {
    let dir = tempfile::tempdir().unwrap();
    let first = dir.path().join("RUN00001.WBL");
    analysis_support::standard_log(&first);
    let second = dir.path().join("RUN00002.WBL");
    let mut calm = Ride::new(20.0, 3.0, 0.0, 0.0, 0.0);
    calm.steer_deg.fill(0.0);
    analysis_support::write_log(&second, &calm, &Extras::default());
    std::fs::write(dir.path().join("notes.txt"), b"not a log").unwrap();
    (dir, vec![first, second])
}

fn params() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("bicycle-model/params/test-bicycle.toml")
}

/// The stderr of `cmd`, which must fail with exit code 1.
fn failure_of(cmd: &mut assert_cmd::Command) -> String {
    let out = cmd.output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    assert!(out.stdout.is_empty(), "{out:?}");
    String::from_utf8(out.stderr).unwrap()
}

#[test]
fn wobble_of_a_folder_is_wobble_of_its_logs() {
    let (dir, logs) = card();
    let of_folder = stdout_of(wobblog().arg("wobble").arg(dir.path()).arg("--json"));
    let of_logs = stdout_of(wobblog().arg("wobble").args(&logs).arg("--json"));
    assert_eq!(of_folder, of_logs);
    assert_eq!(of_folder.lines().count(), 2, "{of_folder}");
    assert!(of_folder.contains("\"episodes\":[{"), "{of_folder}");
}

#[test]
fn model_compare_and_fit_of_a_folder_are_those_of_its_logs() {
    let (dir, logs) = card();
    let compare = |inputs: &[&Path]| {
        stdout_of(
            wobblog()
                .args(["model", "compare"])
                .arg(params())
                .args(inputs),
        )
    };
    let of_folder = compare(&[dir.path()]);
    let named: Vec<&Path> = logs.iter().map(PathBuf::as_path).collect();
    assert_eq!(of_folder, compare(&named));
    assert!(of_folder.contains("RUN00001.WBL"), "{of_folder}");

    let out = tempfile::tempdir().unwrap();
    let fit = |inputs: &[&Path], name: &str| {
        let fitted = out.path().join(name);
        let text = stdout_of(
            wobblog()
                .args(["model", "fit"])
                .arg(params())
                .args(inputs)
                .args(["--param", "steer_head.damping", "-o"])
                .arg(&fitted),
        );
        (text, std::fs::read_to_string(fitted).unwrap())
    };
    let (text, file) = fit(&[dir.path()], "folder.toml");
    assert_eq!((text.clone(), file), fit(&named, "logs.toml"));
    assert!(text.contains("steer_head.damping = "), "{text}");
}

#[test]
fn a_folder_with_no_log_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let err = failure_of(wobblog().arg("wobble").arg(dir.path()));
    assert!(err.contains("no *.WBL logs in this directory"), "{err}");
    assert!(err.contains(&dir.path().display().to_string()), "{err}");
}

#[test]
fn plot_and_events_of_a_folder_list_its_logs() {
    let (dir, _) = card();
    let figure = dir.path().join("figure.png");
    let folder = dir.path().display().to_string();
    for (command, mut cmd) in [
        ("plot", {
            let mut c = wobblog();
            c.arg("plot").arg(dir.path()).arg("-o").arg(&figure);
            c
        }),
        ("events", {
            let mut c = wobblog();
            c.arg("events").arg(dir.path());
            c
        }),
    ] {
        let err = failure_of(&mut cmd);
        assert!(err.contains(&folder), "{err}");
        assert!(
            err.contains(&format!("`wobblog {command}` takes one log")),
            "{err}"
        );
        assert!(
            err.contains("its logs: RUN00001.WBL, RUN00002.WBL)"),
            "{err}"
        );
        assert!(!err.contains("Is a directory"), "{err}");
    }
    assert!(!figure.exists());
}

#[test]
fn decode_gpx_and_config_of_a_folder_list_its_logs() {
    let (dir, _) = card();
    for command in ["decode", "gpx", "config"] {
        let err = failure_of(wobblog().arg(command).arg(dir.path()));
        assert!(err.contains(&dir.path().display().to_string()), "{err}");
        assert!(
            err.contains(&format!(
                "`wobblog {command}` takes one log (its logs: RUN00001.WBL, RUN00002.WBL)"
            )),
            "{err}"
        );
    }
}

#[test]
fn summary_of_a_log_points_to_info() {
    let (_dir, logs) = card();
    let err = failure_of(wobblog().arg("summary").arg(&logs[0]));
    assert!(err.contains("RUN00001.WBL"), "{err}");
    assert!(err.contains("takes a card folder"), "{err}");
    assert!(err.contains("`wobblog info`"), "{err}");
}
