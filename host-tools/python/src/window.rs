//! `start`/`end` arguments: seconds since boot (a number) or a UTC time (a
//! timezone-aware `datetime`), as the CLI's `--from`/`--to`.

use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use wobblog::time::{TimeBound, TimeWindow};

/// One end of a window from Python.
fn bound(value: Option<&Bound<'_, PyAny>>, what: &str) -> PyResult<Option<TimeBound>> {
    let Some(value) = value.filter(|v| !v.is_none()) else {
        return Ok(None);
    };
    let datetime = value.py().import("datetime")?.getattr("datetime")?;
    if value.is_instance(&datetime)? {
        if value.getattr("tzinfo")?.is_none() {
            return Err(PyTypeError::new_err(format!(
                "{what}: a datetime without a timezone is ambiguous; give one in UTC, \
                 e.g. datetime(2020, 3, 18, 13, 28, tzinfo=timezone.utc)"
            )));
        }
        let seconds: f64 = value.call_method0("timestamp")?.extract()?;
        // TimeBound::Utc is in ms, as the CLI's ISO 8601 bounds.
        return Ok(Some(TimeBound::Utc((seconds * 1e3).round() as i64)));
    }
    let seconds: f64 = value.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "{what}: seconds since boot (a number) or a UTC datetime, not {}",
            value.get_type()
        ))
    })?;
    if !seconds.is_finite() {
        return Err(PyTypeError::new_err(format!(
            "{what}: {seconds} is not a time"
        )));
    }
    Ok(Some(TimeBound::Boot(seconds)))
}

/// The window `start`..`end` (both inclusive, either open).
pub fn window(
    start: Option<&Bound<'_, PyAny>>,
    end: Option<&Bound<'_, PyAny>>,
) -> PyResult<TimeWindow> {
    Ok(TimeWindow {
        from: bound(start, "start")?,
        to: bound(end, "end")?,
    })
}
