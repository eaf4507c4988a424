//! Library results as Python objects through their JSON form: the package
//! returns exactly the keys and values the CLI's `--json` prints.

use pyo3::prelude::*;
use serde::Serialize;

/// `value` as the Python object `json.loads` makes of its JSON.
pub fn to_py<'py>(py: Python<'py>, value: &impl Serialize) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value).map_err(|e| {
        crate::errors::WobblogError::new_err(format!("cannot convert a result: {e}"))
    })?;
    py.import("json")?.call_method1("loads", (text,))
}
