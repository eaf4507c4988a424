//! The parameters each model reads, so that a misspelt key (an optional one
//! above all, which would otherwise fall back to its default in silence) is
//! an error naming the file and the key.

use super::ModelKind;

const GEOMETRY: &[&str] = &["wheelbase", "trail", "steer_axis_tilt", "gravity"];
const WHEEL: &[&str] = &["radius", "mass", "inertia_xx", "inertia_yy"];
const BODY: &[&str] = &[
    "x",
    "z",
    "mass",
    "inertia_xx",
    "inertia_xz",
    "inertia_yy",
    "inertia_zz",
];
const SPRING: &[&str] = &["z", "stiffness", "damping"];
const HEAD: &[&str] = &["z", "stiffness", "damping", "axis_angle"];
const STEER: &[&str] = &["damping"];
const TYRE: &[&str] = &[
    "cornering_stiffness",
    "camber_stiffness",
    "aligning_coefficient",
    "twisting_coefficient",
    "overturning_coefficient",
    "relaxation_length",
    "camber_relaxation_length",
];

/// The sections of `model` with the keys each takes.
#[must_use]
pub fn sections(model: ModelKind) -> Vec<(&'static str, &'static [&'static str])> {
    let mut s = vec![
        ("geometry", GEOMETRY),
        ("rear_wheel", WHEEL),
        ("front_wheel", WHEEL),
        ("rear_frame", BODY),
        ("front_frame", BODY),
    ];
    if model == ModelKind::Wobble {
        s.extend([
            ("torso", BODY),
            ("rider_legs", BODY),
            ("seated_legs", BODY),
            ("fork", BODY),
            ("hip", SPRING),
            ("steer_head", HEAD),
            ("steer", STEER),
            ("front_tyre", TYRE),
            ("rear_tyre", TYRE),
        ]);
    }
    s
}

/// Why `section.key` is not a parameter of `model`, if it is not.
#[must_use]
pub fn unknown(model: ModelKind, section: &str, key: &str) -> Option<String> {
    let all = sections(model);
    match all.iter().find(|(s, _)| *s == section) {
        Some((_, keys)) if keys.contains(&key) => None,
        Some((_, keys)) => Some(format!(
            "not a parameter of the {} model ([{section}] takes {})",
            model.name(),
            keys.join(", ")
        )),
        None => Some(format!(
            "[{section}] is not a section of the {} model (sections: {})",
            model.name(),
            all.iter().map(|(s, _)| *s).collect::<Vec<_>>().join(", ")
        )),
    }
}
