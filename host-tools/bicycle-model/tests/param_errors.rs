//! Bad parameter files give errors naming the file and the parameter.

use std::path::Path;

use proptest::prelude::*;
use wobble_model::{Model, ParamSet, Problem};

fn benchmark_text() -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("params/benchmark.toml"))
        .expect("benchmark.toml")
}

fn load_edited(from: &str, to: &str) -> Result<Model, wobble_model::ParamError> {
    let text = benchmark_text();
    assert!(text.contains(from), "{from}");
    let set = ParamSet::from_toml(Path::new("edited.toml"), &text.replacen(from, to, 1))?;
    Model::from_set(&set)
}

#[test]
fn negative_mass_is_unphysical() {
    let err = load_edited("mass = { value = 85.0", "mass = { value = -85.0").unwrap_err();
    assert_eq!(err.param, "rear_frame.mass");
    assert!(matches!(err.problem, Problem::Unphysical(_)));
    let msg = err.to_string();
    assert!(
        msg.starts_with("edited.toml: rear_frame.mass: unphysical"),
        "{msg}"
    );
}

#[test]
fn inertia_that_is_not_positive_definite_is_unphysical() {
    // I_xx I_zz = 25.76 < I_xz^2 = 36.
    let err = load_edited("inertia_xz = { value = 2.4", "inertia_xz = { value = 6.0").unwrap_err();
    assert_eq!(err.param, "rear_frame.inertia_xx");
    assert!(err.to_string().contains("not positive definite"), "{err}");
}

#[test]
fn missing_parameter_is_named() {
    let text = benchmark_text();
    let line = text.lines().find(|l| l.starts_with("trail")).unwrap();
    let set = ParamSet::from_toml(Path::new("edited.toml"), &text.replace(line, "")).unwrap();
    let err = Model::from_set(&set).unwrap_err();
    assert_eq!(err.param, "geometry.trail");
    assert!(matches!(err.problem, Problem::Missing(_)));
}

#[test]
fn wrong_unit_is_named() {
    let err = load_edited(
        "wheelbase = { value = 1.02, unit = \"m\"",
        "wheelbase = { value = 1.02, unit = \"kg\"",
    )
    .unwrap_err();
    assert_eq!(err.param, "geometry.wheelbase");
    assert!(matches!(err.problem, Problem::Unit { .. }), "{err}");
}

#[test]
fn bad_txt_lines_name_the_line() {
    let err =
        ParamSet::from_benchmark_txt(Path::new("b.txt"), "w = 1.02\nc = oops+/-0.1\n").unwrap_err();
    assert_eq!(err.param, "line 2");
    let err = ParamSet::from_benchmark_txt(Path::new("b.txt"), "w = 1.02\nq = 3\n").unwrap_err();
    assert!(
        err.to_string().contains("not a benchmark parameter"),
        "{err}"
    );
}

#[test]
fn written_sets_read_back_equal() {
    let set = ParamSet::from_toml(Path::new("b.toml"), &benchmark_text()).unwrap();
    let again =
        ParamSet::from_toml(Path::new("b.toml"), &wobble_model::params::to_toml(&set)).unwrap();
    assert_eq!(set, again);
}

proptest! {
    /// No text makes either reader panic; what they reject is an error
    /// naming the file.
    #[test]
    fn arbitrary_text_never_panics(text in "\\PC{0,300}") {
        for r in [
            ParamSet::from_toml(Path::new("x.toml"), &text),
            ParamSet::from_benchmark_txt(Path::new("x.txt"), &text),
        ] {
            match r {
                Ok(set) => { let _ = Model::from_set(&set); }
                Err(e) => prop_assert!(e.to_string().starts_with("x.")),
            }
        }
    }
}
