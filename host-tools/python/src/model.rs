//! `wobblog.model`: the linear bicycle models of a parameter file, as
//! `wobblog model eig` evaluates them.

use std::path::PathBuf;

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString};
use wobble_model::ParamSet;
use wobblog::cmd::model::eig::{critical_json, visit_rows, Failure, Row};
use wobblog::cmd::model::{param_error, survey, Speeds, Variant};
use wobblog::export::columns::{Column, Kind, Value};

use crate::errors::{detached, WobblogError};
use crate::stream::Table;
use crate::table::TableBuilder;

/// The speeds `wobblog model eig` sweeps by default, m/s.
const DEFAULT_SPEEDS: &str = "0:10:0.1";

/// The eigenvalue table's columns: those of `wobblog model eig --format csv`.
const EIG_COLUMNS: [Column<Row>; 4] = [
    Column {
        name: "speed_mps",
        kind: Kind::Number,
        value: |r| Value::Number(Some(r.speed_mps)),
    },
    Column {
        name: "mode",
        kind: Kind::Label,
        value: |r| Value::Label(Some(r.mode)),
    },
    Column {
        name: "re_per_s",
        kind: Kind::Number,
        value: |r| Value::Number(Some(r.re_per_s)),
    },
    Column {
        name: "im_rad_per_s",
        kind: Kind::Number,
        value: |r| Value::Number(Some(r.im_rad_per_s)),
    },
];

/// A bicycle model: a parameter file's values and the model built of them.
#[pyclass(module = "wobblog.model", name = "Model", frozen)]
pub struct Model {
    path: PathBuf,
    set: ParamSet,
    variant: Variant,
    model: wobble_model::Model,
}

/// The model variant of a name.
fn variant_of(name: &str) -> PyResult<Variant> {
    match name {
        "own" => Ok(Variant::Own),
        "whipple" => Ok(Variant::Whipple),
        "no-slip" => Ok(Variant::NoSlip),
        _ => Err(WobblogError::new_err(format!(
            "variant={name:?}: one of own, whipple, no-slip"
        ))),
    }
}

fn variant_name(variant: Variant) -> &'static str {
    match variant {
        Variant::Own => "own",
        Variant::Whipple => "whipple",
        Variant::NoSlip => "no-slip",
    }
}

/// Builds the `variant` of `set`'s model.
fn build(set: &ParamSet, variant: Variant) -> Result<wobble_model::Model, wobblog::CliError> {
    match variant {
        Variant::Own => wobble_model::Model::from_set(set),
        Variant::Whipple => wobble_model::Model::whipple_of(set),
        Variant::NoSlip => wobble_model::Model::no_slip_of(set),
    }
    .map_err(|e| param_error(&e))
}

/// Reads a parameter file (TOML, or a BicycleParameters `*Benchmark.txt`)
/// and builds its model: `variant` `own` (the file's), `whipple` (its
/// Whipple limit) or `no-slip` (no lateral slip, torso and twist free).
#[pyfunction]
#[pyo3(signature = (path, variant = "own"))]
pub fn load_model(py: Python<'_>, path: PathBuf, variant: &str) -> PyResult<Model> {
    let variant = variant_of(variant)?;
    let (set, model) = detached(py, &path.display().to_string(), || {
        wobblog::cmd::model::load_as(&path, variant)
    })?;
    Ok(Model {
        path,
        set,
        variant,
        model,
    })
}

/// Speeds from a `"FROM:TO:STEP"` range (m/s, as `--speeds`) or a sequence.
fn speeds_of(speeds: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    if speeds.is_instance_of::<PyString>() {
        let text: String = speeds.extract()?;
        return text
            .parse::<Speeds>()
            .map(|s| s.0)
            .map_err(|e| WobblogError::new_err(format!("speeds: {e}")));
    }
    let speeds: Vec<f64> = speeds.extract().map_err(|_| {
        PyTypeError::new_err("speeds: \"FROM:TO:STEP\" (m/s) or a sequence of speeds in m/s")
    })?;
    if let Some(bad) = speeds.iter().find(|u| !u.is_finite() || **u < 0.0) {
        return Err(WobblogError::new_err(format!(
            "speeds: {bad} is not a speed (m/s, 0 or more)"
        )));
    }
    Ok(speeds)
}

impl Model {
    fn shown(&self) -> String {
        self.path.display().to_string()
    }
}

#[pymethods]
impl Model {
    /// The parameter file.
    #[getter]
    fn path(&self) -> PathBuf {
        self.path.clone()
    }

    /// `own`, `whipple` or `no-slip`.
    #[getter]
    fn variant(&self) -> &'static str {
        variant_name(self.variant)
    }

    /// Every parameter's value in its file's unit (see `units`).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (key, q) in self.set.iter() {
            dict.set_item(key, q.value)?;
        }
        Ok(dict)
    }

    /// Every parameter's unit as the file writes it (`m`, `kg m^2`, `deg`).
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let dict = PyDict::new(py);
        for (key, q) in self.set.iter() {
            dict.set_item(key, &q.unit)?;
        }
        Ok(dict)
    }

    /// A copy with the parameters in `values` (key: value in the file's
    /// unit) changed: one model per point of a parameter sweep.
    fn with_params(&self, py: Python<'_>, values: &Bound<'_, PyDict>) -> PyResult<Self> {
        let mut set = self.set.clone();
        for (key, value) in values.iter() {
            let key: String = key.extract()?;
            let value: f64 = value.extract()?;
            set.set_value(&key, value, "with_params")
                .map_err(|e| crate::errors::to_py(param_error(&e)))?;
        }
        let variant = self.variant;
        let model = detached(py, &self.shown(), || build(&set, variant))?;
        Ok(Self {
            path: self.path.clone(),
            set,
            variant,
            model,
        })
    }

    /// The names of the state vector's entries, in order.
    #[getter]
    fn state_names(&self) -> Vec<&'static str> {
        self.model.state_names()
    }

    /// The state matrix A at `speed_mps` (x' = A x), a NumPy array.
    fn state_matrix<'py>(&self, py: Python<'py>, speed_mps: f64) -> PyResult<Bound<'py, PyAny>> {
        if !speed_mps.is_finite() {
            return Err(WobblogError::new_err(format!(
                "speed_mps={speed_mps}: not a speed"
            )));
        }
        let a = self.model.state_matrix(speed_mps);
        let rows: Vec<Vec<f64>> = (0..a.nrows())
            .map(|i| a.row(i).iter().copied().collect())
            .collect();
        py.import("numpy")?.getattr("array")?.call1((rows,))
    }

    /// The eigenvalues at `speeds` (`"FROM:TO:STEP"` in m/s, or a sequence),
    /// each named by mode, as `wobblog model eig --format csv`: a table of
    /// `speed_mps`, `mode`, `re_per_s` (1/s) and `im_rad_per_s` (rad/s).
    #[pyo3(signature = (speeds = None))]
    fn eig(&self, py: Python<'_>, speeds: Option<Bound<'_, PyAny>>) -> PyResult<Table> {
        let speeds = match speeds {
            Some(s) => speeds_of(&s)?,
            None => speeds_of(PyString::new(py, DEFAULT_SPEEDS).as_any())?,
        };
        detached(py, &self.shown(), || {
            let survey = survey(&self.model, &speeds, &self.path)?;
            let mut table = TableBuilder::new(&EIG_COLUMNS);
            let visited = visit_rows(&self.model, &survey, &speeds, |row| table.push(row));
            match visited {
                Ok(()) => {}
                Err(Failure::Visit(e)) => return Err(wobblog::CliError::file(&self.path, e)),
                Err(Failure::Sweep(e)) => return Err(wobblog::CliError::file(&self.path, e)),
            }
            let (schema, batches) = table
                .finish()
                .map_err(|e| wobblog::CliError::file(&self.path, e))?;
            Ok(Table::new(schema, batches))
        })
    }

    /// The critical speeds over `speeds` (default 0 to 10 m/s by 0.1), as
    /// the lines `wobblog model eig --format jsonl` ends with:
    /// `critical_speed_mps`, `mode`, `unstable_above`, `kind`, `im_rad_per_s`.
    #[pyo3(signature = (speeds = None))]
    fn critical_speeds<'py>(
        &self,
        py: Python<'py>,
        speeds: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let speeds = match speeds {
            Some(s) => speeds_of(&s)?,
            None => speeds_of(PyString::new(py, DEFAULT_SPEEDS).as_any())?,
        };
        let lines = detached(py, &self.shown(), || {
            let survey = survey(&self.model, &speeds, &self.path)?;
            Ok(survey
                .critical
                .iter()
                .map(critical_json)
                .collect::<Vec<_>>())
        })?;
        crate::json::to_py(py, &lines)
    }

    fn __repr__(&self) -> String {
        format!(
            "wobblog.model.Model({:?}, variant={:?})",
            self.shown(),
            self.variant()
        )
    }
}
