//! The exceptions of `anim`: the crates' errors carry their own messages; bad arguments found at
//! the boundary are `ValueError` / `TypeError`, missing files `FileNotFoundError` (an `OSError`).

use pyo3::exceptions::{PyException, PyFileNotFoundError, PyOSError, PyValueError};
use pyo3::prelude::*;

pyo3::create_exception!(anim, AnimError, PyException, "The base of every error a crate of anim reports.");
pyo3::create_exception!(
    anim,
    BuildError,
    AnimError,
    "A model, mesh or scene the crate refused (the message names the element or field)."
);
pyo3::create_exception!(
    anim,
    SimulationError,
    AnimError,
    "A step that failed (non-finite state, solver failure); the simulation is left as before the step."
);
pyo3::create_exception!(
    anim,
    CheckpointError,
    AnimError,
    "A checkpoint that could not be read, written or restored."
);

/// A build error with the crate's message.
pub fn build(e: impl std::fmt::Display) -> PyErr {
    BuildError::new_err(e.to_string())
}

/// A failed step with the crate's message.
pub fn step(e: impl std::fmt::Display) -> PyErr {
    SimulationError::new_err(e.to_string())
}

/// A checkpoint error with the crate's message.
pub fn checkpoint(e: impl std::fmt::Display) -> PyErr {
    CheckpointError::new_err(e.to_string())
}

/// An argument the crate refused (wrong length, out of range, non-finite).
pub fn value(e: impl std::fmt::Display) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A file that could not be read: `FileNotFoundError` when it does not exist, `OSError` for any
/// other I/O failure, `None` when the error is not about reading the file.
pub fn file(path: &std::path::Path, source: &std::io::Error) -> PyErr {
    let message = format!("{}: {source}", path.display());
    if source.kind() == std::io::ErrorKind::NotFound {
        PyFileNotFoundError::new_err(message)
    } else {
        PyOSError::new_err(message)
    }
}

/// Registers the exceptions on the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("AnimError", py.get_type::<AnimError>())?;
    m.add("BuildError", py.get_type::<BuildError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("CheckpointError", py.get_type::<CheckpointError>())?;
    Ok(())
}
