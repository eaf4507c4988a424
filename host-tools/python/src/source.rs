//! Where a log comes from: a path, `"-"` for standard input, or a Python
//! binary stream, which is copied as the CLI copies a pipe
//! (`wobblog::spool`): a log is read more than once (its frames, then its
//! events or episodes), and a stream only once.

use std::io::Read;
use std::path::PathBuf;
use std::sync::atomic::{AtomicU64, Ordering};

use pyo3::prelude::*;
use pyo3::types::PyBytes;

use crate::errors::WobblogError;

/// The path the log `source` is read through: a path as it is, `"-"` as
/// standard input (`/dev/stdin`, copied once), a stream (anything with
/// `read`) copied now under a name of its own, `<stream N>` (with the
/// stream's `name` where it has one).
///
/// # Errors
/// `source` is none of these, or the stream cannot be read or is no log.
pub fn log_path(source: &Bound<'_, PyAny>) -> PyResult<PathBuf> {
    if let Ok(text) = source.extract::<String>() {
        if text == "-" {
            return Ok(PathBuf::from("/dev/stdin"));
        }
    }
    if !source.hasattr("read")? {
        return source.extract::<PathBuf>();
    }
    static STREAMS: AtomicU64 = AtomicU64::new(0);
    let n = STREAMS.fetch_add(1, Ordering::Relaxed) + 1;
    let name = match source.getattr("name").and_then(|v| v.extract::<String>()) {
        Ok(name) => format!("<stream {n}: {name}>"),
        Err(_) => format!("<stream {n}>"),
    };
    let name = PathBuf::from(name);
    let mut reader = PyReader(source);
    wobblog::spool::adopt(&name, &mut reader).map_err(|e| WobblogError::new_err(e.to_string()))?;
    Ok(name)
}

/// A Python binary stream as a Rust reader: `read(n)` must return bytes
/// (an empty result is the end).
struct PyReader<'a, 'py>(&'a Bound<'py, PyAny>);

impl Read for PyReader<'_, '_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let chunk = self
            .0
            .call_method1("read", (buf.len(),))
            .map_err(|e| std::io::Error::other(e.to_string()))?;
        let bytes = chunk.cast::<PyBytes>().map_err(|_| {
            std::io::Error::other("the stream's read() gave no bytes (open it in binary mode)")
        })?;
        let bytes = bytes.as_bytes();
        let n = bytes.len().min(buf.len());
        buf[..n].copy_from_slice(&bytes[..n]);
        Ok(n)
    }
}
