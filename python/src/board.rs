//! `situ.Board`: `situ_api::Board` for Python. Times are seconds (float or
//! int) on the board's clock; answers are frozen classes; callbacks given
//! to `on_change` are called after each post or advance that changed the
//! state, in order, and an exception in one propagates out of that call
//! (the event stays taken).

use crate::errors::{from_board, raise};
use crate::program::Program;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString, PyTuple};
use situ_api::{Arg, BoardError, Clock, FieldValue, Posted};
use std::collections::BTreeMap;

const NS: f64 = 1e9;

fn seconds(ns: u64) -> f64 {
    ns as f64 / NS
}

/// A change of the state at rest.
#[pyclass(module = "situ", frozen, get_all)]
#[derive(Clone)]
pub struct Change {
    /// The state before.
    pub previous: String,
    /// The state after.
    pub state: String,
    /// The board's time, in seconds.
    pub time: f64,
    /// The rules that fired, in order.
    pub rules: Vec<String>,
}

#[pymethods]
impl Change {
    fn __repr__(&self) -> String {
        format!("Change({} -> {} at {}s by {})", self.previous, self.state, self.time, self.rules.join(", "))
    }
}

fn change(c: situ_api::Change) -> Change {
    Change { previous: c.from, state: c.to, time: seconds(c.time), rules: c.rules }
}

/// What a post did with its event.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Outcome {
    /// The board took the event (whether or not the state changed).
    pub accepted: bool,
    /// Why it was not taken: `sleeping`, `out of order`, `from the future`.
    pub key: Option<String>,
    pub reason: Option<String>,
    /// The change it made, if the state changed.
    pub change: Option<Change>,
    /// The rules did not come to rest (a cascade): why.
    pub error: Option<String>,
}

#[pymethods]
impl Outcome {
    fn __repr__(&self) -> String {
        match (&self.reason, &self.change) {
            (Some(r), _) => format!("Outcome(not taken: {r})"),
            (None, Some(c)) => format!("Outcome(taken, {} -> {})", c.previous, c.state),
            (None, None) => "Outcome(taken, no change)".to_string(),
        }
    }
    fn __bool__(&self) -> bool {
        self.accepted
    }
}

/// What a batch did.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Batch {
    pub accepted: u64,
    /// Events not taken, by reason.
    pub not_taken: BTreeMap<String, u64>,
    /// The changes, in order, each with the index of its event in the batch.
    pub changes: Vec<(usize, Change)>,
}

/// An agent's fact (or its staleness).
#[pyclass(module = "situ", frozen, get_all)]
pub struct Fact {
    pub agent: String,
    /// The event, unless the agent is stale.
    pub event: Option<String>,
    /// Its stamp in seconds, unless stale.
    pub time: Option<f64>,
    pub fields: BTreeMap<String, Py<PyAny>>,
    pub stale: bool,
}

#[pymethods]
impl Fact {
    fn __repr__(&self) -> String {
        match &self.event {
            Some(e) => format!("Fact({}: {e} at {}s)", self.agent, self.time.unwrap_or(0.0)),
            None => format!("Fact({}: stale)", self.agent),
        }
    }
}

/// A rule that fired in the last change.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Fired {
    pub rule: String,
    pub file: String,
    pub line: u32,
    /// The rule's first line.
    pub text: String,
    pub previous: String,
    pub state: String,
    /// The facts its patterns matched.
    pub facts: Vec<Py<Fact>>,
    /// The agents its `stale` tests found stale.
    pub stale: Vec<String>,
}

/// Why the board is in its state.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Why {
    pub previous: String,
    pub state: String,
    pub time: f64,
    pub firings: Vec<Py<Fired>>,
}

/// An agent now.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Agent {
    pub name: String,
    /// `running`, `waiting` or `sleeping`.
    pub mode: String,
    pub function: Option<String>,
    pub reads_from: Vec<String>,
    pub sends_to: Vec<String>,
    pub fsm_state: Option<String>,
}

#[pymethods]
impl Agent {
    fn __repr__(&self) -> String {
        format!(
            "Agent({} {}{})",
            self.name,
            self.mode,
            self.function.as_ref().map_or(String::new(), |f| format!(" {f}()"))
        )
    }
}

/// What the board did so far.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Counters {
    pub accepted: u64,
    pub not_taken: BTreeMap<String, u64>,
    pub changes: u64,
    pub missions: u64,
}

/// What a reload kept.
#[pyclass(module = "situ", frozen, get_all)]
pub struct Reloaded {
    pub carried: Vec<String>,
    pub dropped: Vec<(String, String)>,
    pub change: Option<Change>,
}

/// A Bulletinboard inside this process.
#[pyclass(module = "situ")]
pub struct Board {
    inner: situ_api::Board,
    callbacks: Vec<Py<PyAny>>,
    /// The payload being built, reused from post to post.
    buf: Vec<situ_bundle::Value>,
}

/// A field's value as given, borrowed from the Python object.
fn arg_of<'a>(event: &str, field: &str, v: &'a Bound<'_, PyAny>) -> Result<Arg<'a>, BoardError> {
    let wrong = |found: String| BoardError::FieldType {
        event: event.to_string(),
        field: field.to_string(),
        expected: "a number, a boolean or a symbol's name".to_string(),
        found,
    };
    if let Ok(f) = v.cast::<PyFloat>() {
        return Ok(Arg::F64(f.value()));
    }
    if v.is_instance_of::<PyBool>() {
        return Ok(Arg::Bool(v.is_truthy().unwrap_or(false)));
    }
    if v.is_instance_of::<PyInt>() {
        return v.extract::<i64>().map(Arg::I64).map_err(|_| wrong("an integer out of the i64 range".into()));
    }
    if let Ok(s) = v.cast::<PyString>() {
        return s.to_str().map(Arg::Symbol).map_err(|_| wrong("a text that is not UTF-8".into()));
    }
    let ty = v.get_type().name().map(|n| n.to_string()).unwrap_or_else(|_| "?".into());
    Err(wrong(format!("a value of type {ty}")))
}

/// A time in seconds as nanoseconds: finite, not negative.
fn nanos(at: Option<&Bound<'_, PyAny>>) -> Result<Option<u64>, BoardError> {
    let Some(at) = at.filter(|a| !a.is_none()) else { return Ok(None) };
    let bad = |what: String| BoardError::BadTime(what);
    // A float first: the common case, and a failed integer extraction
    // would cost an exception.
    let seconds = if let Ok(f) = at.cast::<PyFloat>() {
        f.value()
    } else if at.is_instance_of::<PyBool>() {
        return Err(bad("a boolean".into()));
    } else if at.is_instance_of::<PyInt>() {
        let i: i64 = at.extract().map_err(|_| bad("an integer out of range".into()))?;
        return u64::try_from(i).ok().and_then(|s| s.checked_mul(1_000_000_000)).map(Some).ok_or(bad(format!("{i} s")));
    } else {
        return Err(bad("a value that is not a number".into()));
    };
    let ns = (seconds * NS).round();
    if !(ns.is_finite() && ns >= 0.0 && ns < u64::MAX as f64) {
        return Err(bad(format!("{seconds} s")));
    }
    Ok(Some(ns as u64))
}

fn field_value(py: Python<'_>, v: &FieldValue) -> PyResult<Py<PyAny>> {
    Ok(match v {
        FieldValue::F64(x) => x.into_pyobject(py)?.into_any().unbind(),
        FieldValue::I64(x) => x.into_pyobject(py)?.into_any().unbind(),
        FieldValue::Bool(x) => PyBool::new(py, *x).to_owned().into_any().unbind(),
        FieldValue::Symbol(s) => s.into_pyobject(py)?.into_any().unbind(),
    })
}

fn fact(py: Python<'_>, f: &situ_api::Fact) -> PyResult<Fact> {
    let mut fields = BTreeMap::new();
    for (name, v) in &f.fields {
        fields.insert(name.clone(), field_value(py, v)?);
    }
    Ok(Fact { agent: f.agent.clone(), event: Some(f.event.clone()), time: Some(seconds(f.time)), fields, stale: false })
}

impl Board {
    /// One event, by name, with its fields from a dict: what the library
    /// did with it, or why the call is wrong.
    fn post_raw(
        &mut self,
        py: Python<'_>,
        event: &str,
        at: Option<&Bound<'_, PyAny>>,
        payload: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Posted> {
        let id = self.inner.event(event).map_err(|e| from_board(py, e))?;
        let name = &self.inner.content().events[id as usize].name;
        let mut fields = self.inner.fields(id, &mut self.buf);
        if let Some(d) = payload {
            for (k, v) in d.iter() {
                let Ok(k) = k.cast::<PyString>().map_err(|_| ()).and_then(|k| k.to_str().map_err(|_| ())) else {
                    let msg = format!("`{name}`: a field's name is a text");
                    return Err(raise(py, "BoardError", msg, "unknown-field", None));
                };
                let arg = arg_of(name, k, &v).map_err(|e| from_board(py, e))?;
                fields.set(k, arg).map_err(|e| from_board(py, e))?;
            }
        }
        fields.finish().map_err(|e| from_board(py, e))?;
        let at = nanos(at).map_err(|e| from_board(py, e))?;
        self.inner.post(id, at, &self.buf).map_err(|e| from_board(py, e))
    }

    /// One event by id (`Board.event_id`) with its values in field order
    /// (a tuple): the batch's fast path, no name looked up.
    fn post_values(
        &mut self,
        py: Python<'_>,
        id: u32,
        at: Option<&Bound<'_, PyAny>>,
        values: &Bound<'_, PyTuple>,
    ) -> PyResult<Posted> {
        let content = self.inner.content().clone();
        let Some(def) = content.events.get(id as usize) else {
            let e = BoardError::UnknownEvent { name: format!("#{id}"), suggestion: None };
            return Err(from_board(py, e));
        };
        let items: Vec<Bound<'_, PyAny>> = values.iter().collect();
        let mut args = Vec::with_capacity(items.len());
        for (i, v) in items.iter().enumerate() {
            let field = def.fields.get(i).map_or("?", |f| f.name.as_str());
            args.push(arg_of(&def.name, field, v).map_err(|e| from_board(py, e))?);
        }
        self.inner.payload_in_order(id, &args, &mut self.buf).map_err(|e| from_board(py, e))?;
        let at = nanos(at).map_err(|e| from_board(py, e))?;
        self.inner.post(id, at, &self.buf).map_err(|e| from_board(py, e))
    }
}

fn outcome(posted: Posted, content: &situ_api::Content) -> Outcome {
    match posted {
        Posted::Taken { change: c, error } => {
            Outcome { accepted: true, key: None, reason: None, change: c.map(change), error }
        }
        Posted::NotTaken(r) => Outcome {
            accepted: false,
            key: Some(r.key.to_string()),
            reason: Some(r.reason(content)),
            change: None,
            error: None,
        },
    }
}

/// Calls the board's callbacks with a change, the board not borrowed (a
/// callback may read the board, or post to it).
fn notify(slf: &Bound<'_, Board>, c: &Change) -> PyResult<()> {
    let py = slf.py();
    let callbacks: Vec<Py<PyAny>> = slf.borrow().callbacks.iter().map(|cb| cb.clone_ref(py)).collect();
    for cb in callbacks {
        cb.call1(py, (c.clone(),))?;
    }
    Ok(())
}

#[pymethods]
impl Board {
    /// A board on rules: a `Program` (`situ.load`, `situ.load_path`), a
    /// `Bundle` or its bytes (verified under `trust`), a path to a source or
    /// a bundle, or a source text; with a manual clock (`"manual"`: time is
    /// what the caller stamps) or the system's (`"system"`: UNIX time;
    /// events from the future are refused).
    #[new]
    #[pyo3(signature = (rules, clock = "manual", max_skew = None, missions = false, trust = None, sleeping = "drop"))]
    fn new(
        py: Python<'_>,
        rules: &Bound<'_, PyAny>,
        clock: &str,
        max_skew: Option<&Bound<'_, PyAny>>,
        missions: bool,
        trust: Option<&Bound<'_, PyAny>>,
        sleeping: &str,
    ) -> PyResult<Board> {
        let take_sleeping = match sleeping {
            "drop" => false,
            "take" => true,
            other => {
                let msg = format!("a sleeping agent's events are \"drop\" or \"take\", not {other:?}");
                return Err(raise(py, "Error", msg, "sleeping", None));
            }
        };
        let clock = match clock {
            "manual" => Clock::Manual,
            "system" => Clock::System,
            other => {
                return Err(raise(
                    py,
                    "Error",
                    format!("a clock is \"manual\" or \"system\", not {other:?}"),
                    "clock",
                    None,
                ))
            }
        };
        let program: Bound<'_, Program> = match rules.cast::<Program>() {
            Ok(p) => p.clone(),
            // Anything else is loaded as `situ.load`/`load_path`/`load_text` would.
            Err(_) => py.import("situ")?.getattr("_program_of")?.call1((rules, trust))?.cast_into::<Program>()?,
        };
        let program = program.get();
        let mut inner = situ_api::Board::new(program.content.clone(), clock);
        inner.set_missions(missions);
        inner.set_take_sleeping(take_sleeping);
        if let Some(ns) = nanos(max_skew).map_err(|e| from_board(py, e))? {
            inner.set_max_skew(ns);
        }
        Ok(Board { inner, callbacks: Vec::new(), buf: Vec::new() })
    }

    /// Posts an event (`"EVENT"` or `"Agent.EVENT"`) stamped `at` seconds
    /// (`None`: now on the board's clock), its fields by name.
    #[pyo3(signature = (agent_event, at = None, payload = None, **fields))]
    fn post(
        slf: &Bound<'_, Self>,
        agent_event: &str,
        at: Option<&Bound<'_, PyAny>>,
        payload: Option<&Bound<'_, PyDict>>,
        fields: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Outcome> {
        let merged;
        let given = match (payload, fields) {
            (Some(p), Some(f)) => {
                merged = p.copy()?;
                merged.update(f.as_mapping())?;
                Some(&merged)
            }
            (Some(p), None) => Some(p),
            (None, f) => f,
        };
        let out = {
            let mut b = slf.borrow_mut();
            let posted = b.post_raw(slf.py(), agent_event, at, given)?;
            outcome(posted, b.inner.content())
        };
        if let Some(c) = &out.change {
            notify(slf, c)?;
        }
        Ok(out)
    }

    /// Posts a batch of `(agent_event, at, payload)` in order; stops at the
    /// first wrong event (an error) with the ones before it taken.
    fn post_many(slf: &Bound<'_, Self>, events: &Bound<'_, PyAny>) -> PyResult<Batch> {
        let py = slf.py();
        let mut batch = Batch { accepted: 0, not_taken: BTreeMap::new(), changes: Vec::new() };
        // The board is borrowed for each event only: the iterable and the
        // callbacks may read it.
        for (index, item) in events.try_iter()?.enumerate() {
            let item = item?;
            let (event, at, payload): (Bound<'_, PyAny>, Bound<'_, PyAny>, Bound<'_, PyAny>) = item.extract()?;
            let posted = if event.is_instance_of::<PyInt>() {
                // The fast path: an id and the values in field order.
                let id: u32 = event.extract()?;
                let empty = PyTuple::empty(py);
                let values = if payload.is_none() { &empty } else { payload.cast::<PyTuple>()? };
                slf.borrow_mut().post_values(py, id, Some(&at), values)?
            } else {
                let name = event.cast::<PyString>()?;
                let payload = if payload.is_none() { None } else { Some(payload.cast::<PyDict>()?) };
                slf.borrow_mut().post_raw(py, name.to_str()?, Some(&at), payload)?
            };
            match posted {
                Posted::NotTaken(r) => *batch.not_taken.entry(r.key.to_string()).or_default() += 1,
                Posted::Taken { change: c, .. } => {
                    batch.accepted += 1;
                    if let Some(c) = c {
                        let c = change(c);
                        notify(slf, &c)?;
                        batch.changes.push((index, c));
                    }
                }
            }
        }
        Ok(batch)
    }

    /// `post_many` of `(event id, at, (values in field order))`: no name
    /// is looked up (ids from `event_id`). `post_many` takes these too.
    fn post_many_ids(slf: &Bound<'_, Self>, events: &Bound<'_, PyAny>) -> PyResult<Batch> {
        Self::post_many(slf, events)
    }

    /// The id of an event (`"EVENT"` or `"Agent.EVENT"`), for `post_many`'s
    /// fast path: `(id, at, (values in field order))`.
    fn event_id(&self, py: Python<'_>, agent_event: &str) -> PyResult<u32> {
        self.inner.event(agent_event).map_err(|e| from_board(py, e))
    }

    /// Lets time pass to `to` seconds (`None`: now on the board's clock):
    /// facts age and silent agents go stale. The change, if any.
    #[pyo3(signature = (to = None))]
    fn advance(slf: &Bound<'_, Self>, to: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Change>> {
        let to = nanos(to).map_err(|e| from_board(slf.py(), e))?;
        let c = slf.borrow_mut().inner.advance(to).map(change);
        if let Some(c) = &c {
            notify(slf, c)?;
        }
        Ok(c)
    }

    /// The state at rest.
    #[getter]
    fn state(&self) -> String {
        self.inner.state().to_string()
    }

    /// The board's latest time, in seconds.
    #[getter]
    fn now(&self) -> f64 {
        seconds(self.inner.now())
    }

    /// The last change, rule by rule (`None` before any rule fired).
    fn why(&self, py: Python<'_>) -> PyResult<Option<Why>> {
        let Some(w) = self.inner.why() else { return Ok(None) };
        let mut firings = Vec::new();
        for f in &w.firings {
            let facts = f.facts.iter().map(|x| Py::new(py, fact(py, x)?)).collect::<PyResult<Vec<_>>>()?;
            let fired = Fired {
                rule: f.rule.clone(),
                file: f.file.clone(),
                line: f.line,
                text: f.text.clone(),
                previous: f.from.clone(),
                state: f.to.clone(),
                facts,
                stale: f.stale.clone(),
            };
            firings.push(Py::new(py, fired)?);
        }
        Ok(Some(Why { previous: w.from, state: w.to, time: seconds(w.time), firings }))
    }

    /// Every agent's mode, function and links now.
    fn agents(&self) -> Vec<Agent> {
        self.inner
            .agents()
            .into_iter()
            .map(|a| Agent {
                name: a.name,
                mode: a.mode.to_string(),
                function: a.function,
                reads_from: a.from,
                sends_to: a.to,
                fsm_state: a.fsm_state,
            })
            .collect()
    }

    /// The working memory: each agent's latest fact, or its staleness.
    fn facts(&self, py: Python<'_>) -> PyResult<Vec<Fact>> {
        self.inner
            .facts()
            .iter()
            .map(|f| match &f.fact {
                Some(x) => fact(py, x),
                None => {
                    Ok(Fact { agent: f.agent.clone(), event: None, time: None, fields: BTreeMap::new(), stale: true })
                }
            })
            .collect()
    }

    /// What the board did so far.
    fn counters(&self) -> Counters {
        let c = self.inner.counters();
        Counters {
            accepted: c.accepted,
            not_taken: c.not_taken.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            changes: c.changes,
            missions: c.missions,
        }
    }

    /// A new mission: the initial state with no facts; time is kept.
    fn reset(&mut self) {
        self.inner.reset();
    }

    /// Calls `callback(change)` after every change of the state.
    fn on_change(&mut self, callback: Py<PyAny>) {
        self.callbacks.push(callback);
    }

    /// New rules, keeping the state and the facts that still fit.
    fn reload(slf: &Bound<'_, Self>, program: &Program) -> PyResult<Reloaded> {
        let r = slf.borrow_mut().inner.reload(program.content.clone()).map_err(|e| from_board(slf.py(), e))?;
        let c = r.change.map(change);
        if let Some(c) = &c {
            notify(slf, c)?;
        }
        Ok(Reloaded { carried: r.carried, dropped: r.dropped, change: c })
    }

    fn __repr__(&self) -> String {
        format!("Board(state={}, now={}s)", self.inner.state(), seconds(self.inner.now()))
    }
}
