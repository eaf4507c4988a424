//! Parameter sets: data with units and a source note per value, read from
//! TOML files or from BicycleParameters `*Benchmark.txt` files.
//!
//! A set is a flat map from a dotted name (`front_tyre.cornering_stiffness`)
//! to a [`Quantity`]. Models take what they need through [`ParamSet::get`],
//! which checks the unit and converts to SI; sweeps and fits change values
//! through [`ParamSet::set_si`] and can write the set back as TOML.

mod benchmark_txt;
pub mod keys;
mod measured;
mod toml_file;

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

pub use measured::{measured_bicycle_file, MEASURED_BICYCLES};
pub use toml_file::to_toml;

/// One value as written in a parameter file.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantity {
    /// The number, in `unit`.
    pub value: f64,
    /// The unit as written (`m`, `kg m^2`, `deg`, ...).
    pub unit: String,
    /// Where the value comes from.
    pub source: String,
}

/// Which model a parameter set describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ModelKind {
    /// The Whipple bicycle with the benchmark's parameters (4 states).
    Whipple,
    /// The extended wobble model: tyres, steering-head twist, rider torso.
    Wobble,
}

impl ModelKind {
    /// The name used in parameter files.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Whipple => "whipple",
            Self::Wobble => "wobble",
        }
    }
}

/// A parameter set.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamSet {
    /// The file it was read from (named in every error).
    pub path: PathBuf,
    /// A human name for the bicycle.
    pub name: String,
    /// The model these parameters are for.
    pub model: ModelKind,
    /// Where the set as a whole comes from.
    pub source: String,
    /// What the reader wants the user to know: lines ignored, defaults taken.
    pub notes: Vec<String>,
    values: BTreeMap<String, Quantity>,
}

/// Physical quantities a parameter can have, each with the unit spellings
/// accepted for it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Unit {
    /// m (or mm).
    Length,
    /// kg.
    Mass,
    /// kg m^2, about the body's mass centre in the benchmark frame.
    Inertia,
    /// rad or deg.
    Angle,
    /// m/s^2.
    Acceleration,
    /// N m/rad.
    TorsionalStiffness,
    /// N m s/rad.
    TorsionalDamping,
    /// 1/rad: a tyre coefficient per unit wheel load (N/N/rad).
    PerRadian,
    /// m: a tyre moment coefficient per unit wheel load (N m/N/rad).
    MetrePerRadian,
}

impl Unit {
    /// The unit as written when a value is created.
    #[must_use]
    pub fn canonical(self) -> &'static str {
        match self {
            Self::Length => "m",
            Self::Mass => "kg",
            Self::Inertia => "kg m^2",
            Self::Angle => "rad",
            Self::Acceleration => "m/s^2",
            Self::TorsionalStiffness => "N m/rad",
            Self::TorsionalDamping => "N m s/rad",
            Self::PerRadian => "1/rad",
            Self::MetrePerRadian => "m/rad",
        }
    }

    /// The factor from `unit` to SI, if `unit` is a spelling of this quantity.
    #[must_use]
    pub fn factor(self, unit: &str) -> Option<f64> {
        match (self, unit.trim()) {
            (Self::Length, "mm") => Some(1e-3),
            (Self::Angle, "deg") => Some(std::f64::consts::PI / 180.0),
            (_, u) if u == self.canonical() => Some(1.0),
            _ => None,
        }
    }
}

/// What is wrong with a parameter file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Problem {
    /// The file could not be read.
    #[error("cannot read the file: {0}")]
    Unreadable(String),
    /// The file is not in the expected format.
    #[error("{0}")]
    Syntax(String),
    /// A parameter the model needs is not in the file.
    #[error("missing (the {0} model needs it)")]
    Missing(&'static str),
    /// The unit is not one this parameter can have.
    #[error("unit {found:?} is not a unit of this parameter (expected {expected:?})")]
    Unit {
        /// The unit written.
        found: String,
        /// The unit expected.
        expected: &'static str,
    },
    /// The value is impossible for a physical bicycle.
    #[error("unphysical: {0}")]
    Unphysical(String),
    /// A name given on the command line is not in the set.
    #[error("no such parameter in the file")]
    Unknown,
    /// A fit found no answer.
    #[error("not fitted: {0}")]
    NotFitted(String),
}

/// A problem with one parameter (or the whole file) of a parameter file.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub struct ParamError {
    /// The file.
    pub path: PathBuf,
    /// The parameter concerned (empty for the file as a whole).
    pub param: String,
    /// What is wrong.
    pub problem: Problem,
}

impl fmt::Display for ParamError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.param.is_empty() {
            write!(f, "{}: {}", self.path.display(), self.problem)
        } else {
            write!(
                f,
                "{}: {}: {}",
                self.path.display(),
                self.param,
                self.problem
            )
        }
    }
}

impl ParamSet {
    /// An empty set for `model`.
    #[must_use]
    pub fn new(path: &Path, name: &str, model: ModelKind, source: &str) -> Self {
        Self {
            path: path.to_path_buf(),
            name: name.to_owned(),
            model,
            source: source.to_owned(),
            notes: Vec::new(),
            values: BTreeMap::new(),
        }
    }

    /// Reads a parameter file: BicycleParameters' `*.txt` benchmark format
    /// by its extension, TOML otherwise.
    pub fn load(path: &Path) -> Result<Self, ParamError> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            let problem = if e.kind() == std::io::ErrorKind::InvalidData {
                // Not text at all: a log or an image given by mistake.
                Problem::Syntax(format!("not a parameter file: {}", toml_file::EXPECTED))
            } else {
                Problem::Unreadable(e.to_string())
            };
            ParamError::file(path, problem)
        })?;
        let is_txt = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("txt"));
        if is_txt {
            benchmark_txt::parse(path, &text)
        } else {
            toml_file::parse(path, &text)
        }
    }

    /// Parses TOML text as if read from `path`.
    pub fn from_toml(path: &Path, text: &str) -> Result<Self, ParamError> {
        toml_file::parse(path, text)
    }

    /// Parses BicycleParameters benchmark text as if read from `path`.
    pub fn from_benchmark_txt(path: &Path, text: &str) -> Result<Self, ParamError> {
        benchmark_txt::parse(path, text)
    }

    /// The value of `key` in SI units, checked against `unit`.
    pub fn get(&self, key: &str, unit: Unit) -> Result<f64, ParamError> {
        let q = self
            .values
            .get(key)
            .ok_or_else(|| self.error(key, Problem::Missing(self.model.name())))?;
        let factor = unit.factor(&q.unit).ok_or_else(|| {
            self.error(
                key,
                Problem::Unit {
                    found: q.unit.clone(),
                    expected: unit.canonical(),
                },
            )
        })?;
        Ok(q.value * factor)
    }

    /// The value of `key` in SI units, or `default` if the file has none.
    pub fn get_or(&self, key: &str, unit: Unit, default: f64) -> Result<f64, ParamError> {
        if self.values.contains_key(key) {
            self.get(key, unit)
        } else {
            Ok(default)
        }
    }

    /// The quantity as written.
    #[must_use]
    pub fn quantity(&self, key: &str) -> Option<&Quantity> {
        self.values.get(key)
    }

    /// Every (name, quantity), in name order.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &Quantity)> {
        self.values.iter().map(|(k, v)| (k.as_str(), v))
    }

    /// Adds or replaces a value.
    pub fn insert(&mut self, key: &str, quantity: Quantity) {
        self.values.insert(key.to_owned(), quantity);
    }

    /// Removes every parameter of `section`, returning how many there were.
    pub fn remove_section(&mut self, section: &str) -> usize {
        let prefix = format!("{section}.");
        let before = self.values.len();
        self.values.retain(|k, _| !k.starts_with(&prefix));
        before - self.values.len()
    }

    /// The value of an existing parameter as a plain number in its file
    /// unit, or [`Problem::Unknown`].
    pub fn value(&self, key: &str) -> Result<f64, ParamError> {
        self.values
            .get(key)
            .map(|q| q.value)
            .ok_or_else(|| self.error(key, Problem::Unknown))
    }

    /// Sets an existing parameter to `value` in its file unit, with a new
    /// source note.
    pub fn set_value(&mut self, key: &str, value: f64, source: &str) -> Result<(), ParamError> {
        let err = self.error(key, Problem::Unknown);
        let q = self.values.get_mut(key).ok_or(err)?;
        q.value = value;
        source.clone_into(&mut q.source);
        Ok(())
    }

    /// An error about `key` of this file.
    #[must_use]
    pub fn error(&self, key: &str, problem: Problem) -> ParamError {
        ParamError {
            path: self.path.clone(),
            param: key.to_owned(),
            problem,
        }
    }
}

impl ParamError {
    /// An error about the file as a whole.
    #[must_use]
    pub fn file(path: &Path, problem: Problem) -> Self {
        Self {
            path: path.to_path_buf(),
            param: String::new(),
            problem,
        }
    }
}
