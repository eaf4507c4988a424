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
fn inertia_that_is_not_positive_semi_definite_is_unphysical() {
    // I_xx I_zz = 25.76 < I_xz^2 = 36.
    let err = load_edited("inertia_xz = { value = 2.4", "inertia_xz = { value = 6.0").unwrap_err();
    assert_eq!(err.param, "rear_frame.inertia_xx");
    assert!(
        err.to_string().contains("not positive semi-definite"),
        "{err}"
    );
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

#[test]
fn misspelt_keys_are_errors_naming_the_key() {
    // An optional key misspelt would otherwise default in silence.
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("params/test-bicycle.toml"),
    )
    .unwrap();
    let edited = text.replacen(
        "[front_tyre]",
        "[front_tyre]\ncamber_relaxaton_length = { value = 0.1, unit = \"m\", source = \"x\" }",
        1,
    );
    let err = ParamSet::from_toml(Path::new("t.toml"), &edited).unwrap_err();
    assert_eq!(err.param, "front_tyre.camber_relaxaton_length");
    assert!(
        err.to_string().contains("camber_relaxation_length"),
        "lists the keys: {err}"
    );
    let edited = text.replacen("[hip]", "[hips]", 1);
    let err = ParamSet::from_toml(Path::new("t.toml"), &edited).unwrap_err();
    assert!(err.to_string().contains("not a section"), "{err}");
    // A wobble key in a Whipple file is not silently ignored either.
    let err = ParamSet::from_toml(
        Path::new("b.toml"),
        &benchmark_text().replacen(
            "[geometry]",
            "[steer]\ndamping = { value = 1, unit = \"N m s/rad\", source = \"x\" }\n\n[geometry]",
            1,
        ),
    )
    .unwrap_err();
    assert_eq!(err.param, "steer.damping");
}

#[test]
fn a_defaulted_camber_relaxation_length_is_said() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("params/test-bicycle.toml");
    let shipped = std::fs::read_to_string(&path).unwrap();
    // The shipped file states both lengths: no note.
    assert!(ParamSet::from_toml(&path, &shipped)
        .unwrap()
        .notes
        .is_empty());
    let text: String = shipped
        .lines()
        .filter(|l| !l.starts_with("camber_relaxation_length"))
        .map(|l| format!("{l}\n"))
        .collect();
    let set = ParamSet::from_toml(&path, &text).unwrap();
    assert_eq!(set.notes.len(), 2, "{:?}", set.notes);
    assert!(set.notes[0].contains("front_tyre.camber_relaxation_length not given"));
    let given = text.replacen(
        "[front_tyre]",
        "[front_tyre]\ncamber_relaxation_length = { value = 0.1, unit = \"m\", source = \"x\" }",
        1,
    );
    let set = ParamSet::from_toml(&path, &given).unwrap();
    assert_eq!(set.notes.len(), 1);
    assert!(set.notes[0].starts_with("rear_tyre"));
    assert!(ParamSet::from_toml(&path, &benchmark_text())
        .unwrap()
        .notes
        .is_empty());
}

#[test]
fn bicycleparameters_lines_are_checked_and_noted() {
    // Silver as BicycleParameters ships it: IRzz, IFzz, yB, yH.
    let silver = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/bicycleparameters/SilverBenchmark.txt");
    let set = ParamSet::load(&silver).unwrap();
    assert_eq!(set.notes.len(), 1, "{:?}", set.notes);
    for s in ["IRzz", "IFzz", "yB", "yH"] {
        assert!(set.notes[0].contains(s), "{}", set.notes[0]);
    }
    Model::from_set(&set).unwrap();
    let text = std::fs::read_to_string(&silver).unwrap();
    for (from, to, line) in [
        ("yB = 0.0+/-0.0", "yB = 0.02+/-0.0", "line 11"),
        ("IFzz = 0.081", "IFzz = 0.09", "line 30"),
    ] {
        assert!(text.contains(from));
        let err = ParamSet::from_benchmark_txt(&silver, &text.replace(from, to)).unwrap_err();
        assert_eq!(err.param, line, "{err}");
        assert!(matches!(err.problem, Problem::Unphysical(_)), "{err}");
    }
}

#[test]
fn a_slender_rod_is_a_body() {
    // A rod along z: no inertia about its own axis (positive semi-definite).
    let text = benchmark_text();
    let front = text.split("[front_frame]").nth(1).unwrap();
    let zz = front.lines().find(|l| l.starts_with("inertia_zz")).unwrap();
    let xz = front.lines().find(|l| l.starts_with("inertia_xz")).unwrap();
    let rod = text
        .replacen(
            zz,
            "inertia_zz = { value = 0.0, unit = \"kg m^2\", source = \"rod\" }",
            1,
        )
        .replacen(
            xz,
            "inertia_xz = { value = 0.0, unit = \"kg m^2\", source = \"rod\" }",
            1,
        );
    let set = ParamSet::from_toml(Path::new("rod.toml"), &rod).unwrap();
    let model = Model::from_set(&set).unwrap();
    assert!(wobble_model::eig::eigenvalues(&model.state_matrix(5.0))
        .unwrap()
        .iter()
        .all(|v| v.re.is_finite()));
}
