//! The `wobblog` Python package's native module: card logs as Arrow
//! tables, and the analyses of the `wobblog` library crate (the CLI's own
//! functions, so the numbers are the CLI's).

#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

mod arrays;
mod campaign;
mod errors;
mod frames;
mod json;
mod log;
mod model;
mod scan;
mod stream;
mod table;
mod window;

mod source;

use pyo3::prelude::*;

/// Opens a card log, `source`: a path (`RUNnnnnn.WBL`), `"-"` for standard
/// input, or a binary stream (an object with `read`); decodes it once, for
/// its summary and its frames (kept for `frames()`), and warns
/// (`wobblog.DamageWarning`) of what it lost.
#[pyfunction]
fn open(py: Python<'_>, source: &Bound<'_, PyAny>) -> PyResult<log::Log> {
    let path = source::log_path(source)?;
    log::Log::open(py, path)
}

#[pymodule]
fn _wobblog(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(open, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::margin, m)?)?;
    m.add_function(wrap_pyfunction!(scan::scan, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::episodes, m)?)?;
    m.add_function(wrap_pyfunction!(arrays::kicks, m)?)?;
    m.add_function(wrap_pyfunction!(model::load_model, m)?)?;
    m.add_class::<model::Model>()?;
    m.add_function(wrap_pyfunction!(scan::summary, m)?)?;
    m.add_class::<scan::Scan>()?;
    m.add_class::<log::Log>()?;
    m.add_class::<stream::Table>()?;
    m.add("WobblogError", m.py().get_type::<errors::WobblogError>())?;
    m.add("DamageWarning", m.py().get_type::<errors::DamageWarning>())?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
