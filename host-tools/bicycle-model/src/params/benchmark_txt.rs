//! BicycleParameters' benchmark parameter files (`*Benchmark.txt`): one
//! `name = value` or `name = value+/-uncertainty` line per parameter, in SI
//! units with the benchmark's symbols (`IBxx`, `lam`, `rR`, ...). They
//! describe the Whipple model.

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
        let (_, key, unit) = SYMBOLS
            .iter()
            .find(|(s, _, _)| *s == symbol)
            .ok_or_else(|| {
                at(Problem::Syntax(format!(
                    "{symbol:?} is not a benchmark parameter"
                )))
            })?;
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
    Ok(set)
}
