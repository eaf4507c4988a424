//! BicycleParameters' benchmark parameter files (`*Benchmark.txt`): one
//! `name = value` or `name = value+/-uncertainty` line per parameter, in SI
//! units with the benchmark's symbols (`IBxx`, `lam`, `rR`, ...). They
//! describe the Whipple model.
//!
//! BicycleParameters also writes what the Whipple model has no place for: a
//! wheel's inertia about its vertical diameter (`IRzz`, `IFzz`, equal to
//! `IRxx`, `IFxx` for a disc) and the lateral mass-centre offsets and
//! lateral products of inertia of the frames (`yB`, `yH`, `IBxy`, `IByz`,
//! ...), zero for a bicycle symmetric about its plane. Those lines are read,
//! checked (a wheel's `zz` must equal its `xx`, an offset or product must be
//! zero) and left out, with one note naming them.

use std::path::Path;

use super::{ModelKind, ParamError, ParamSet, Problem, Quantity, Unit};

/// BicycleParameters' symbol, the set's name for it and its unit.
const SYMBOLS: [(&str, &str, Unit); 26] = [
    ("w", "geometry.wheelbase", Unit::Length),
    ("c", "geometry.trail", Unit::Length),
    ("lam", "geometry.steer_axis_tilt", Unit::Angle),
    ("g", "geometry.gravity", Unit::Acceleration),
    ("rR", "rear_wheel.radius", Unit::Length),
    ("mR", "rear_wheel.mass", Unit::Mass),
    ("IRxx", "rear_wheel.inertia_xx", Unit::Inertia),
    ("IRyy", "rear_wheel.inertia_yy", Unit::Inertia),
    ("xB", "rear_frame.x", Unit::Length),
    ("zB", "rear_frame.z", Unit::Length),
    ("mB", "rear_frame.mass", Unit::Mass),
    ("IBxx", "rear_frame.inertia_xx", Unit::Inertia),
    ("IBxz", "rear_frame.inertia_xz", Unit::Inertia),
    ("IByy", "rear_frame.inertia_yy", Unit::Inertia),
    ("IBzz", "rear_frame.inertia_zz", Unit::Inertia),
    ("xH", "front_frame.x", Unit::Length),
    ("zH", "front_frame.z", Unit::Length),
    ("mH", "front_frame.mass", Unit::Mass),
    ("IHxx", "front_frame.inertia_xx", Unit::Inertia),
    ("IHxz", "front_frame.inertia_xz", Unit::Inertia),
    ("IHyy", "front_frame.inertia_yy", Unit::Inertia),
    ("IHzz", "front_frame.inertia_zz", Unit::Inertia),
    ("rF", "front_wheel.radius", Unit::Length),
    ("mF", "front_wheel.mass", Unit::Mass),
    ("IFxx", "front_wheel.inertia_xx", Unit::Inertia),
    ("IFyy", "front_wheel.inertia_yy", Unit::Inertia),
];

/// Lines the model checks but does not use: symbol, and for a wheel the
/// symbol it must equal (else the symbol must be zero).
const CHECKED: [(&str, Option<&str>); 10] = [
    ("IRzz", Some("IRxx")),
    ("IFzz", Some("IFxx")),
    ("yB", None),
    ("yH", None),
    ("IBxy", None),
    ("IByz", None),
    ("IHxy", None),
    ("IHyz", None),
    ("yR", None),
    ("yF", None),
];

pub(super) fn parse(path: &Path, text: &str) -> Result<ParamSet, ParamError> {
    let name = path
        .file_stem()
        .map_or_else(|| "bicycle".into(), |s| s.to_string_lossy().into_owned());
    let mut set = ParamSet::new(
        path,
        &name,
        ModelKind::Whipple,
        "BicycleParameters benchmark file",
    );
    let mut checked: Vec<(usize, String, f64, Option<&str>)> = Vec::new();
    for (n, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let at = |problem| ParamError {
            path: path.to_path_buf(),
            param: format!("line {}", n + 1),
            problem,
        };
        let (symbol, value) = line.split_once('=').ok_or_else(|| {
            at(Problem::Syntax(format!(
                "expected `name = value[+/-uncertainty]`, found {line:?}"
            )))
        })?;
        let symbol = symbol.trim();
        let (nominal, uncertainty) = value
            .split_once("+/-")
            .map_or((value, None), |(v, u)| (v, Some(u.trim())));
        let value: f64 = nominal
            .trim()
            .parse()
            .ok()
            .filter(|v: &f64| v.is_finite())
            .ok_or_else(|| {
                at(Problem::Syntax(format!(
                    "{symbol}: {nominal:?} is not a number"
                )))
            })?;
        if let Some((_, equal_to)) = CHECKED.iter().find(|(s, _)| *s == symbol) {
            checked.push((n + 1, symbol.to_owned(), value, *equal_to));
            continue;
        }
        let (_, key, unit) = SYMBOLS
            .iter()
            .find(|(s, _, _)| *s == symbol)
            .ok_or_else(|| {
                at(Problem::Syntax(format!(
                    "{symbol:?} is not a benchmark parameter"
                )))
            })?;
        let source = match uncertainty {
            Some(u) => format!("{} ({symbol} = {} +/- {u})", set.source, nominal.trim()),
            None => format!("{} ({symbol})", set.source),
        };
        set.insert(
            key,
            Quantity {
                value,
                unit: unit.canonical().to_owned(),
                source,
            },
        );
    }
    check_ignored(&mut set, &checked)?;
    Ok(set)
}

/// Checks the lines the model leaves out and notes them.
fn check_ignored(
    set: &mut ParamSet,
    checked: &[(usize, String, f64, Option<&str>)],
) -> Result<(), ParamError> {
    for (line, symbol, value, equal_to) in checked {
        let (want, what) = match equal_to {
            Some(other) => {
                let key = SYMBOLS
                    .iter()
                    .find(|(s, _, _)| s == other)
                    .map_or("", |(_, k, _)| *k);
                let want = set.quantity(key).map_or(*value, |q| q.value);
                (want, format!("{other} (a wheel is a disc)"))
            }
            None => (0.0, "0 (the model is symmetric about its plane)".to_owned()),
        };
        if (value - want).abs() > 1e-9 * want.abs().max(1e-3) {
            return Err(ParamError {
                path: set.path.clone(),
                param: format!("line {line}"),
                problem: Problem::Unphysical(format!(
                    "{symbol} = {value}: the model needs it to equal {what}"
                )),
            });
        }
    }
    if !checked.is_empty() {
        let names: Vec<&str> = checked.iter().map(|c| c.1.as_str()).collect();
        set.notes.push(format!(
            "left out (checked: a wheel's zz equals its xx, lateral offsets and products are 0): {}",
            names.join(", ")
        ));
    }
    Ok(())
}
