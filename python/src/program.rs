//! From rules to a program, for Python: check, format, build, load, test.
//! Findings and test reports cross as the library's JSON records
//! (`situ_api::findings_json`, `situ_api::test_records`), which the
//! package's Python half turns into typed objects.

use crate::errors::{findings_json, from_api, raise};
use pyo3::prelude::*;
use pyo3::types::PyBytes;
use situ_api::{BuildOptions, Content, Encoding, Input, Trust};
use situ_bundle::key;
use std::path::PathBuf;
use std::sync::Arc;

/// Loaded rules, ready for a board.
#[pyclass(module = "situ", frozen)]
pub struct Program {
    pub content: Arc<Content>,
    /// The key that signed the bundle, when a trust policy checked it.
    #[pyo3(get)]
    pub signed_by: Option<String>,
}

#[pymethods]
impl Program {
    /// The states, in the order they are declared.
    #[getter]
    fn states(&self) -> Vec<String> {
        self.content.states.iter().map(|s| s.name.clone()).collect()
    }
    /// The `final` states: a mission ends there.
    #[getter]
    fn final_states(&self) -> Vec<String> {
        self.content.states.iter().filter(|s| s.is_final).map(|s| s.name.clone()).collect()
    }
    #[getter]
    fn initial(&self) -> String {
        self.content.states[self.content.initial as usize].name.clone()
    }
    #[getter]
    fn agents(&self) -> Vec<String> {
        self.content.agents.iter().map(|a| a.name.clone()).collect()
    }
    /// Every event as `Agent.EVENT`.
    #[getter]
    fn events(&self) -> Vec<String> {
        let c = &self.content;
        c.events.iter().map(|e| format!("{}.{}", c.agents[e.agent as usize].name, e.name)).collect()
    }
    #[getter]
    fn rules(&self) -> Vec<String> {
        self.content.rules.iter().map(|r| r.name.clone()).collect()
    }
    /// An event's fields and their types (`f64`, `i64`, `bool`, or the
    /// enumeration's symbols as `{a, b}`).
    fn fields(&self, py: Python<'_>, event: &str) -> PyResult<Vec<(String, String)>> {
        let name = event.rsplit('.').next().unwrap_or(event);
        let Some(id) = self.content.event_id(name) else {
            return Err(raise(py, "BoardError", format!("no event `{event}` in the rules"), "unknown-event", None));
        };
        Ok(self.content.events[id as usize].fields.iter().map(|f| (f.name.clone(), type_name(&f.ty))).collect())
    }
    fn __repr__(&self) -> String {
        let c = &self.content;
        format!("Program({} states, {} agents, {} rules)", c.states.len(), c.agents.len(), c.rules.len())
    }
}

/// A built bundle: its bytes, their SHA-256 and the key that signed it.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Bundle {
    pub data: Py<PyBytes>,
    pub sha256: String,
    pub signed_by: Option<String>,
}

#[pymethods]
impl Bundle {
    /// Writes the bundle to `path` atomically (beside it, then renamed).
    fn save(&self, py: Python<'_>, path: PathBuf) -> PyResult<()> {
        let bytes = self.data.as_bytes(py);
        situ_bundle::file::write_atomically(&path, bytes, false)
            .map_err(|e| raise(py, "WriteError", format!("cannot write `{}`: {e}", path.display()), "write", None))
    }
    fn __len__(&self, py: Python<'_>) -> usize {
        self.data.as_bytes(py).len()
    }
}

fn trust_of(py: Python<'_>, keys: Option<Vec<PathBuf>>) -> PyResult<Trust> {
    let Some(keys) = keys else { return Ok(Trust::Any) };
    if keys.is_empty() {
        let msg = "a trust policy with no key trusts nothing: give public key files, or no trust for any bundle";
        return Err(raise(py, "TrustError", msg.to_string(), "trust", None));
    }
    let mut public = Vec::new();
    for k in keys {
        public.push(key::read_public(&k).map_err(|e| raise(py, "TrustError", e.to_string(), "trust", None))?);
    }
    Ok(Trust::from_keys(public))
}

fn checked_of(py: Python<'_>, path: Option<PathBuf>, text: Option<&str>, name: &str) -> PyResult<situ_api::Checked> {
    let input = match (&path, text) {
        (Some(p), _) => Input::Path(p),
        (None, Some(text)) => Input::Text { name, text },
        (None, None) => return Err(raise(py, "Error", "give a path or a source".into(), "usage", None)),
    };
    py.detach(|| situ_api::check(input)).map_err(|e| from_api(py, e))
}

/// The findings of a check, as JSON (a list of objects).
#[pyfunction]
#[pyo3(signature = (path = None, text = None, name = "<source>"))]
pub fn check(py: Python<'_>, path: Option<PathBuf>, text: Option<&str>, name: &str) -> PyResult<String> {
    Ok(findings_json(&checked_of(py, path, text, name)?))
}

/// A source in the canonical layout.
#[pyfunction]
pub fn format(py: Python<'_>, text: &str) -> PyResult<String> {
    match situ_api::format(text) {
        Ok(s) => Ok(s),
        Err(e) => {
            // The syntax errors with their places: the check's findings.
            let checked = situ_api::check(Input::Text { name: "<source>", text }).map_err(|e| from_api(py, e))?;
            let code = checked.diagnostics.first().map_or("E0001".to_string(), |d| d.code.to_string());
            Err(raise(py, "SituSyntaxError", e.to_string(), &code, Some(findings_json(&checked))))
        }
    }
}

/// Builds rules (a path or a source) to a bundle.
#[pyfunction]
#[pyo3(signature = (path = None, text = None, name = "<source>", key = None, binary = false, deny_warnings = false))]
pub fn build(
    py: Python<'_>,
    path: Option<PathBuf>,
    text: Option<&str>,
    name: &str,
    key: Option<PathBuf>,
    binary: bool,
    deny_warnings: bool,
) -> PyResult<Bundle> {
    let checked = checked_of(py, path, text, name)?;
    let key = match key {
        Some(k) => Some(key::read_secret(&k).map_err(|e| raise(py, "TrustError", e.to_string(), "key", None))?),
        None => None,
    };
    let options = BuildOptions { encoding: if binary { Encoding::Binary } else { Encoding::Json }, key, deny_warnings };
    let built = situ_api::build(&checked, &options).map_err(|e| from_api(py, e))?;
    Ok(Bundle {
        data: PyBytes::new(py, &built.bytes).unbind(),
        sha256: built.sha256,
        signed_by: built.signed_by.map(|k| k.to_string()),
    })
}

/// A bundle's bytes, decoded and verified under a trust policy.
#[pyfunction]
#[pyo3(signature = (data, trust = None))]
pub fn load(py: Python<'_>, data: &[u8], trust: Option<Vec<PathBuf>>) -> PyResult<Program> {
    let trust = trust_of(py, trust)?;
    let loaded = situ_api::load(data, &trust).map_err(|e| from_api(py, e))?;
    Ok(Program { content: Arc::new(loaded.content), signed_by: loaded.signer.map(|k| k.to_string()) })
}

/// A `.situ` file (checked and compiled) or a bundle file.
#[pyfunction]
#[pyo3(signature = (path, trust = None, deny_warnings = false))]
pub fn load_path(py: Python<'_>, path: PathBuf, trust: Option<Vec<PathBuf>>, deny_warnings: bool) -> PyResult<Program> {
    let trust = trust_of(py, trust)?;
    let program = py.detach(|| situ_api::load_path(&path, &trust, deny_warnings)).map_err(|e| from_api(py, e))?;
    Ok(Program { content: program.content, signed_by: program.signed_by.map(|k| k.to_string()) })
}

/// A source text, checked and compiled.
#[pyfunction]
#[pyo3(signature = (text, name = "<source>", deny_warnings = false))]
pub fn load_text(py: Python<'_>, text: &str, name: &str, deny_warnings: bool) -> PyResult<Program> {
    let checked = checked_of(py, None, Some(text), name)?;
    let options = BuildOptions { deny_warnings, ..BuildOptions::default() };
    let built = situ_api::build(&checked, &options).map_err(|e| from_api(py, e))?;
    Ok(Program { content: Arc::new(built.content), signed_by: None })
}

/// Runs the tests and properties of files: the suite's JSON records and
/// its verdict (`pass`, `fail`).
#[pyfunction]
#[pyo3(signature = (paths, filter = None, allow_undecided = false, effort = None, max_states = None, depth = None, cases = None, length = None, seed = None))]
#[allow(clippy::too_many_arguments)]
pub fn test(
    py: Python<'_>,
    paths: Vec<PathBuf>,
    filter: Option<String>,
    allow_undecided: bool,
    effort: Option<u64>,
    max_states: Option<usize>,
    depth: Option<usize>,
    cases: Option<u32>,
    length: Option<usize>,
    seed: Option<u64>,
) -> PyResult<(String, String)> {
    let mut options = situ_api::TestOptions { filter, allow_undecided, ..Default::default() };
    let p = &mut options.properties;
    p.effort = effort.unwrap_or(p.effort);
    p.limits.max_states = max_states.unwrap_or(p.limits.max_states);
    p.limits.depth = depth.unwrap_or(p.limits.depth);
    p.search.cases = cases.unwrap_or(p.search.cases);
    p.search.length = length.unwrap_or(p.search.length);
    p.search.seed = seed.unwrap_or(p.search.seed);
    let (records, verdict, unreadable) = py.detach(|| {
        let report = situ_api::test(&paths, &options);
        let unreadable: Vec<String> = report
            .files
            .iter()
            .filter_map(|f| match &f.outcome {
                situ_api::FileOutcome::Unreadable(e) => Some(e.to_string()),
                _ => None,
            })
            .collect();
        (serde_json::Value::from(situ_api::test_records(&report)).to_string(), report.verdict(), unreadable)
    });
    if let Some(e) = unreadable.first() {
        return Err(raise(py, "ReadError", e.clone(), "read", None));
    }
    let verdict = match verdict {
        situ_api::Verdict::Pass => "pass",
        situ_api::Verdict::Fail | situ_api::Verdict::Unreadable => "fail",
    };
    Ok((records, verdict.to_string()))
}

fn type_name(ty: &situ_bundle::FieldType) -> String {
    match ty {
        situ_bundle::FieldType::F64 => "f64".into(),
        situ_bundle::FieldType::I64 => "i64".into(),
        situ_bundle::FieldType::Bool => "bool".into(),
        situ_bundle::FieldType::Symbols(s) => format!("{{{}}}", s.join(", ")),
    }
}

/// The `test` and `property` blocks of a file: `(kind, name, file, line)`.
/// Rules with errors raise [`FindingsError`].
#[pyfunction]
pub fn blocks(py: Python<'_>, path: PathBuf) -> PyResult<Vec<(String, String, String, u32)>> {
    let checked = checked_of(py, Some(path), None, "")?;
    if checked.errors() > 0 {
        let name = checked.sources.iter().next().map(|(_, f)| f.name.clone()).unwrap_or_default();
        let e = situ_api::Error::Findings {
            name,
            errors: checked.errors(),
            warnings: checked.warnings(),
            checked: Box::new(checked),
        };
        return Err(from_api(py, e));
    }
    Ok(situ_api::blocks(&checked).into_iter().map(|b| (b.kind.to_string(), b.name, b.file, b.line)).collect())
}
