//! Errors and warnings as Python sees them: one exception class,
//! `wobblog.WobblogError`, whose message is the CLI's (file and cause), and
//! `wobblog.DamageWarning` for what a damaged log lost.

use std::ffi::CString;
use std::panic::{catch_unwind, AssertUnwindSafe};

use pyo3::exceptions::{PyException, PyUserWarning};
use pyo3::prelude::*;
use wobblog::CliError;

pyo3::create_exception!(
    wobblog,
    WobblogError,
    PyException,
    "A log, parameter file or argument that wobblog cannot use; the message names the file and the cause."
);
pyo3::create_exception!(
    wobblog,
    DamageWarning,
    PyUserWarning,
    "A log lost data (blocks, frames, bytes); what survived is still returned."
);

/// The Python exception for a library error.
pub fn to_py(e: CliError) -> PyErr {
    WobblogError::new_err(e.to_string())
}

/// Runs `work` without the GIL (other Python threads go on while a log is
/// decoded), turning a library error into `WobblogError` and a panic into
/// one too: no Rust panic reaches Python.
pub fn detached<T: Send>(
    py: Python<'_>,
    what: &str,
    work: impl FnOnce() -> Result<T, CliError> + Send,
) -> PyResult<T> {
    let outcome = py.detach(|| catch_unwind(AssertUnwindSafe(work)));
    match outcome {
        Ok(result) => result.map_err(to_py),
        Err(panic) => {
            let cause = panic
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "unknown cause".into());
            Err(WobblogError::new_err(format!(
                "{what}: internal error ({cause}); please report it with the file"
            )))
        }
    }
}

/// Issues `message` as a `DamageWarning` (or the exception a warnings
/// filter turns it into).
pub fn warn_damage(py: Python<'_>, message: &str) -> PyResult<()> {
    let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
    PyErr::warn(py, &py.get_type::<DamageWarning>(), &text, 2)
}
