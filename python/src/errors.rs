//! The library's errors as the package's exception classes. The classes are
//! Python's own (`situ/errors.py`: documented, typed, each with its `code`);
//! this module only picks the class and fills it.

use pyo3::prelude::*;
use situ_api::{BoardError, Error};

/// An exception of `situ.errors`: the class by name, the message, the code
/// and the details as JSON (the findings of a source that does not check,
/// the field of a bad payload).
pub fn raise(py: Python<'_>, class: &str, message: String, code: &str, detail: Option<String>) -> PyErr {
    let made = py
        .import("situ.errors")
        .and_then(|m| m.getattr(class))
        .and_then(|cls| cls.call1((message.clone(), code.to_string(), detail)));
    match made {
        Ok(value) => PyErr::from_value(value),
        // The package's Python half is missing: still an exception, never a crash.
        Err(e) => e,
    }
}

/// The library's error as the exception a user catches.
pub fn from_api(py: Python<'_>, e: Error) -> PyErr {
    let message = e.to_string();
    match e {
        Error::Read { .. } => raise(py, "ReadError", message, "read", None),
        Error::Root(_) => raise(py, "ReadError", message, "read", None),
        Error::Findings { checked, .. } => {
            let code = checked
                .diagnostics
                .iter()
                .find(|d| d.severity == situ_api::Severity::Error && !d.allowed)
                .or(checked.diagnostics.first())
                .map_or_else(|| "findings".to_string(), |d| d.code.to_string());
            raise(py, "FindingsError", message, &code, Some(findings_json(&checked)))
        }
        Error::Syntax(diags) => {
            let code = diags.first().map_or("E0001".to_string(), |d| d.code.to_string());
            raise(py, "SituSyntaxError", message, &code, None)
        }
        Error::UnsignedSource { .. } | Error::Trust(_) => raise(py, "TrustError", message, "trust", None),
        Error::Bundle(_) | Error::Attached(_) | Error::NoAttachedBundle => {
            raise(py, "BundleError", message, "bundle", None)
        }
        Error::Recording(_) | Error::Replay(_) => raise(py, "RecordingError", message, "recording", None),
        Error::Script(_) => raise(py, "Error", message, "script", None),
        Error::Write { .. } => raise(py, "WriteError", message, "write", None),
    }
}

/// A wrong call on a board.
pub fn from_board(py: Python<'_>, e: BoardError) -> PyErr {
    raise(py, "BoardError", e.to_string(), e.code(), None)
}

/// Every finding of a check as the JSON objects of `situ check --format json`.
pub fn findings_json(checked: &situ_api::Checked) -> String {
    serde_json::Value::from(situ_api::findings_json(checked)).to_string()
}
