//! Python values (dicts, lists, numbers, strings) as JSON values, for the crates' serde
//! parameter types: the crates read them with their own names and checks.

use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// `obj` through Python's `json.dumps`; an error names the argument.
pub fn of(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<serde_json::Value> {
    let text: String = obj
        .py()
        .import("json")?
        .call_method1("dumps", (obj,))
        .map_err(|e| PyValueError::new_err(format!("{name}: not JSON-like ({e})")))?
        .extract()?;
    serde_json::from_str(&text).map_err(|e| PyValueError::new_err(format!("{name}: {e}")))
}
