//! Progress of a trace as the Python side shows it: `blutrace._progress.reporter` makes a
//! tqdm bar, a stderr line or a wrapper of the caller's function from the `progress`
//! argument; the waiting thread updates it every tick.

use pyo3::prelude::*;

/// The reporter for `progress` (None: no report) over `total` photons.
pub fn reporter(
    py: Python<'_>,
    progress: Option<&Bound<'_, PyAny>>,
    total: u64,
) -> PyResult<Option<Py<PyAny>>> {
    let Some(progress) = progress else {
        return Ok(None);
    };
    let made = py
        .import("blutrace._progress")?
        .call_method1("reporter", (progress, total))?;
    Ok((!made.is_none()).then(|| made.unbind()))
}

/// Tell the reporter `done` photons are traced.
pub fn update(py: Python<'_>, reporter: &Option<Py<PyAny>>, done: u64) -> PyResult<()> {
    if let Some(r) = reporter {
        r.call_method1(py, "update", (done,))?;
    }
    Ok(())
}

/// The last report (`done` photons) and the end of the reporter's display.
pub fn close(py: Python<'_>, reporter: &Option<Py<PyAny>>, done: u64) -> PyResult<()> {
    if let Some(r) = reporter {
        r.call_method1(py, "close", (done,))?;
    }
    Ok(())
}

/// An event of a search (one iteration or design): its line of text and its record.
pub fn event(
    py: Python<'_>,
    reporter: &Option<Py<PyAny>>,
    line: &str,
    record: &serde_json::Value,
) -> PyResult<()> {
    if let Some(r) = reporter {
        r.call_method1(py, "event", (line, crate::convert::json_to_py(py, record)?))?;
    }
    Ok(())
}
