//! The extension module `situ._situ`: the library (`situ-api`) for Python.
//! The package's Python half (`python/situ/`) gives it its public shape:
//! typed findings and reports, the exception classes, the pytest plugin.
//! Nothing here decides: every verdict, admission and check is the
//! library's.

mod board;
mod errors;
mod program;

use pyo3::prelude::*;

#[pymodule]
fn _situ(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(program::check, m)?)?;
    m.add_function(wrap_pyfunction!(program::format, m)?)?;
    m.add_function(wrap_pyfunction!(program::build, m)?)?;
    m.add_function(wrap_pyfunction!(program::load, m)?)?;
    m.add_function(wrap_pyfunction!(program::load_path, m)?)?;
    m.add_function(wrap_pyfunction!(program::load_text, m)?)?;
    m.add_function(wrap_pyfunction!(program::test, m)?)?;
    m.add_function(wrap_pyfunction!(program::blocks, m)?)?;
    m.add_class::<program::Program>()?;
    m.add_class::<program::Bundle>()?;
    m.add_class::<board::Board>()?;
    m.add_class::<board::Outcome>()?;
    m.add_class::<board::Batch>()?;
    m.add_class::<board::Change>()?;
    m.add_class::<board::Fact>()?;
    m.add_class::<board::Fired>()?;
    m.add_class::<board::Why>()?;
    m.add_class::<board::Agent>()?;
    m.add_class::<board::Counters>()?;
    m.add_class::<board::Reloaded>()?;
    Ok(())
}
