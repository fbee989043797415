//! A Bulletinboard inside the caller's own program: a robot node in Python
//! or C++ posts its sensors' events by name and reads the situation, with
//! no other process. It is [`situ_runtime::local::LocalBoard`] (what
//! `situ repl` runs on) with names resolved, payloads typed from the
//! caller's values, a clock, and every answer as data.
//!
//! **Admission** is the running stack's (language reference §10.4, §10.7):
//! an event stamped before its agent's latest accepted one is refused (out
//! of order), one stamped more than the skew bound ahead of the board's
//! clock is refused (from the future; only with [`Clock::System`]), one of
//! an agent that sleeps in the current situation is dropped (or taken:
//! [`Board::set_take_sleeping`]). NaN and the
//! infinities are accepted and match as §10.3 says. None of these is an
//! error: [`Board::post`] returns [`Posted::NotTaken`] with the reason,
//! and the board counts it. An event name, field or value that the rules
//! do not have *is* an error ([`BoardError`]): the caller's code is wrong.
//!
//! ```
//! use situ_api::{Arg, Board, Clock, Posted};
//! let checked = situ_api::check(situ_api::Input::Text {
//!     name: "door.situ",
//!     text: "states { Closed initial Open }\n\
//!            agent Door sensor { event OPENED { width: f64 } }\n\
//!            rule opened { when state == Closed and OPENED(width > 0.1) then Open }\n",
//! })?;
//! let program = situ_api::load(&situ_api::build(&checked, &Default::default())?.bytes, &situ_api::Trust::Any)?;
//! let mut board = Board::new(std::sync::Arc::new(program.content), Clock::Manual);
//! let opened = board.event("OPENED")?;
//! let payload = board.payload(opened, &[("width", Arg::F64(0.5))])?;
//! let posted = board.post(opened, Some(1_000_000), &payload)?;
//! assert!(matches!(posted, Posted::Taken { change: Some(_), .. }));
//! assert_eq!(board.state(), "Open");
//! assert_eq!(board.why().unwrap().firings[0].rule, "opened");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use situ_bundle::suggest::suggest;
use situ_bundle::{Content, FieldType, Value};
use situ_runtime::bulletinboard::SwapError;
use situ_runtime::local::{LocalBoard, NotTaken};
use situ_runtime::rete::{MatchedFact, PostError, StateChange};
use std::collections::{BTreeMap, HashMap};
use std::sync::Arc;

/// Where the board's time comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Clock {
    /// Time is what the caller stamps: an event without a stamp is posted
    /// at the board's latest time, and time moves only with stamps and
    /// [`Board::advance`]. No event is from the future. For tests, and
    /// for a node that replays a recording.
    Manual,
    /// The system's clock (UNIX time, ns), as a running stack's: an event
    /// without a stamp is stamped now, and one stamped more than the skew
    /// bound ahead of now is refused.
    System,
}

/// A value given for a field, before it is checked against the field's type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Arg<'a> {
    F64(f64),
    I64(i64),
    Bool(bool),
    /// A symbol of an enumeration, by name.
    Symbol(&'a str),
}

/// A value of a fact, in the rules' terms.
#[derive(Debug, Clone, PartialEq)]
pub enum FieldValue {
    F64(f64),
    I64(i64),
    Bool(bool),
    Symbol(String),
}

/// Why a call on the board is wrong. Nothing changed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BoardError {
    #[error("no event `{name}` in the rules{}", did_you_mean(.suggestion))]
    UnknownEvent { name: String, suggestion: Option<String> },
    #[error("`{event}` is an event of `{owner}`, not of `{agent}`")]
    NotItsAgent { event: String, owner: String, agent: String },
    #[error("`{event}` has no field `{field}`{}", did_you_mean(.suggestion))]
    UnknownField { event: String, field: String, suggestion: Option<String> },
    #[error("`{event}` needs every field: {} missing", .missing.join(", "))]
    MissingFields { event: String, missing: Vec<String> },
    #[error("`{event}.{field}` is given twice")]
    FieldTwice { event: String, field: String },
    #[error("`{event}.{field}` is {expected}, not {found}")]
    FieldType { event: String, field: String, expected: String, found: String },
    #[error("a time is a whole number of nanoseconds from 0, not {0}")]
    BadTime(String),
    #[error("the new rules cannot take over: {0}; the old rules stay")]
    Reload(String),
}

impl BoardError {
    /// A stable code for the kind of error (for bindings and their tests).
    pub fn code(&self) -> &'static str {
        match self {
            BoardError::UnknownEvent { .. } => "unknown-event",
            BoardError::NotItsAgent { .. } => "not-its-agent",
            BoardError::UnknownField { .. } => "unknown-field",
            BoardError::MissingFields { .. } => "missing-fields",
            BoardError::FieldTwice { .. } => "field-twice",
            BoardError::FieldType { .. } => "field-type",
            BoardError::BadTime(_) => "bad-time",
            BoardError::Reload(_) => "reload",
        }
    }
}

fn did_you_mean(suggestion: &Option<String>) -> String {
    suggestion.as_ref().map_or(String::new(), |s| format!("; did you mean `{s}`?"))
}

/// A change of the state at rest.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    pub from: String,
    pub to: String,
    /// The board's time (ns).
    pub time: u64,
    /// The rules that fired, in order.
    pub rules: Vec<String>,
}

/// What [`Board::post`] did with an event.
#[derive(Debug, Clone, PartialEq)]
pub enum Posted {
    /// Taken: the state changed, or not.
    Taken {
        change: Option<Change>,
        /// The rules did not come to rest (a cascade): the board is in the
        /// state where they stopped, and this says why.
        error: Option<String>,
    },
    /// Not taken; nothing changed.
    NotTaken(Refusal),
}

/// Why an event was not taken, kept as data: its text is made only when
/// asked for ([`Refusal::reason`]), so that a stream with many refusals
/// costs no formatting.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    /// The count's word: `sleeping`, `out of order`, `from the future`,
    /// `payload`.
    pub key: &'static str,
    why: NotTaken,
    /// The state when it was refused.
    state: u32,
}

impl Refusal {
    /// The reason in the rules' terms (`content`: the board's rules).
    pub fn reason(&self, content: &Content) -> String {
        let state = content.states.get(self.state as usize).map_or("?", |s| s.name.as_str());
        self.why.describe(content, state)
    }
}

/// An agent's fact, in the rules' terms.
#[derive(Debug, Clone, PartialEq)]
pub struct Fact {
    pub agent: String,
    pub event: String,
    /// Its stamp (ns).
    pub time: u64,
    pub fields: Vec<(String, FieldValue)>,
}

/// One rule that fired in the last change.
#[derive(Debug, Clone, PartialEq)]
pub struct Fired {
    pub rule: String,
    /// Where the rule is written: file, line and its first line.
    pub file: String,
    pub line: u32,
    pub text: String,
    pub from: String,
    pub to: String,
    /// The facts its patterns matched.
    pub facts: Vec<Fact>,
    /// The agents its `stale` tests found stale.
    pub stale: Vec<String>,
}

/// Why the board is in its state: the last change, rule by rule.
#[derive(Debug, Clone, PartialEq)]
pub struct Why {
    pub from: String,
    pub to: String,
    pub time: u64,
    pub firings: Vec<Fired>,
}

/// An agent now: its mode, function and links in the current situation.
#[derive(Debug, Clone, PartialEq)]
pub struct AgentNow {
    pub name: String,
    /// `running`, `waiting` or `sleeping`.
    pub mode: &'static str,
    pub function: Option<String>,
    /// Whom it reads from and sends to now (a running agent's links).
    pub from: Vec<String>,
    pub to: Vec<String>,
    /// Its FSM's state, for an agent with an FSM.
    pub fsm_state: Option<String>,
}

/// An agent's entry in the working memory.
#[derive(Debug, Clone, PartialEq)]
pub struct FactNow {
    pub agent: String,
    /// Its latest fact, unless it is stale.
    pub fact: Option<Fact>,
    pub stale: bool,
}

/// What the board did so far.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Counters {
    pub accepted: u64,
    /// Events not taken, by reason.
    pub not_taken: BTreeMap<&'static str, u64>,
    pub changes: u64,
    /// New missions started ([`Board::reset`], or after a final state).
    pub missions: u64,
}

/// What a reload kept.
#[derive(Debug, Clone, PartialEq)]
pub struct Reloaded {
    /// Agents whose facts carried over.
    pub carried: Vec<String>,
    /// Agents whose facts were dropped, and why.
    pub dropped: Vec<(String, String)>,
    /// The new rules fired at once.
    pub change: Option<Change>,
}

/// A Bulletinboard in the caller's process.
pub struct Board {
    local: LocalBoard,
    clock: Clock,
    /// `EVENT` and `AGENT.EVENT` to the event's id.
    names: Names,
    counters: Counters,
    /// A final state ends the mission: the next post starts a new one.
    missions: bool,
}

impl Board {
    pub fn new(content: Arc<Content>, clock: Clock) -> Board {
        Board {
            names: names(&content),
            local: LocalBoard::new(content),
            clock,
            counters: Counters::default(),
            missions: false,
        }
    }

    pub fn content(&self) -> &Arc<Content> {
        self.local.content()
    }

    pub fn clock(&self) -> Clock {
        self.clock
    }

    /// How far ahead of the clock an event may be stamped (ns).
    pub fn set_max_skew(&mut self, ns: u64) {
        self.local.set_max_skew(ns);
    }

    /// The state at rest.
    pub fn state(&self) -> &str {
        self.local.state_name()
    }

    /// The state at rest, as its index in the rules' states.
    pub fn state_id(&self) -> u32 {
        self.local.state()
    }

    /// Whether the state at rest is `final`.
    pub fn is_final(&self) -> bool {
        self.local.is_final()
    }

    /// The board's latest time (ns).
    pub fn now(&self) -> u64 {
        self.local.now()
    }

    pub fn counters(&self) -> &Counters {
        &self.counters
    }

    /// With `true`, a `final` state ends the mission (language reference
    /// §10.12, as `situ bench` and `--random` runs do): the next post first
    /// starts a new one ([`reset`](Self::reset)). Off by default: a final
    /// state stays, as on a robot whose run ends there.
    pub fn set_missions(&mut self, on: bool) {
        self.missions = on;
    }

    /// With `true`, events of agents that sleep in the current situation
    /// are taken, as a Bulletinboard of a distributed deployment takes
    /// them from agents that are not situ's (a sensor that reports whatever
    /// its mode); by default they are dropped and counted (`sleeping`), as
    /// in a run of situ's agents, where a sleeping agent is not stepped.
    pub fn set_take_sleeping(&mut self, take: bool) {
        self.local.set_take_sleeping(take);
    }

    /// A new mission: the initial state with no facts, every FSM in its
    /// initial state; time and each agent's latest stamp are kept.
    pub fn reset(&mut self) {
        self.local.reset();
        self.counters.missions += 1;
    }

    /// An event by name: `EVENT`, or `AGENT.EVENT` (which also checks
    /// that the agent reports it).
    pub fn event(&self, name: &str) -> Result<u32, BoardError> {
        if let Some(&id) = self.names.get(name) {
            return Ok(id);
        }
        let c = self.content();
        let (agent, event) = match name.split_once('.') {
            Some((a, e)) => (Some(a), e),
            None => (None, name),
        };
        let Some(id) = c.event_id(event) else {
            let suggestion = suggest(event, c.events.iter().map(|e| e.name.as_str())).map(str::to_string);
            return Err(BoardError::UnknownEvent { name: name.to_string(), suggestion });
        };
        let owner = c.agents[c.events[id as usize].agent as usize].name.clone();
        Err(BoardError::NotItsAgent { event: event.to_string(), owner, agent: agent.unwrap_or("").to_string() })
    }

    /// An event's payload from values given by field name: every field
    /// once, each of its type (an integer is taken for an `f64` field).
    pub fn payload(&self, event: u32, args: &[(&str, Arg)]) -> Result<Vec<Value>, BoardError> {
        let mut values = Vec::new();
        let mut fields = self.fields(event, &mut values);
        for (name, arg) in args {
            fields.set(name, *arg)?;
        }
        fields.finish()?;
        Ok(values)
    }

    /// An event's payload built field by field into `into` (cleared
    /// first, so that a caller reuses one buffer): the bindings' path,
    /// which gives each value as it reads it. [`Fields::finish`] says
    /// which fields are missing.
    pub fn fields<'a>(&'a self, event: u32, into: &'a mut Vec<Value>) -> Fields<'a> {
        let def = &self.content().events[event as usize];
        into.clear();
        into.resize(def.fields.len(), Value::Bool(false));
        Fields { def, values: into, seen: 0 }
    }

    /// An event's payload from values in field order, without names (the
    /// bindings' fast path), each typed as [`payload`](Self::payload)
    /// types it; written into `into`, which is cleared first so that a
    /// caller reuses one buffer. A value past the last field is an unknown
    /// field `#N`; an event id the rules do not have, an unknown event `#ID`.
    pub fn payload_in_order(&self, event: u32, args: &[Arg], into: &mut Vec<Value>) -> Result<(), BoardError> {
        into.clear();
        let Some(def) = self.content().events.get(event as usize) else {
            return Err(BoardError::UnknownEvent { name: format!("#{event}"), suggestion: None });
        };
        if let Some(extra) = args.len().checked_sub(def.fields.len()).filter(|&n| n > 0) {
            let field = format!("#{}", args.len() - extra);
            return Err(BoardError::UnknownField { event: def.name.clone(), field, suggestion: None });
        }
        if args.len() < def.fields.len() {
            let missing = def.fields[args.len()..].iter().map(|f| f.name.clone()).collect();
            return Err(BoardError::MissingFields { event: def.name.clone(), missing });
        }
        for (f, arg) in def.fields.iter().zip(args) {
            into.push(convert(&def.name, &f.name, &f.ty, arg)?);
        }
        Ok(())
    }

    /// Posts an event (its id from [`event`](Self::event), its payload
    /// from [`payload`](Self::payload)) stamped `at` (ns; `None`: now, by
    /// the board's [`Clock`]).
    pub fn post(&mut self, event: u32, at: Option<u64>, payload: &[Value]) -> Result<Posted, BoardError> {
        let now = self.tick_clock();
        let time = at.unwrap_or(now);
        if self.missions && self.local.is_final() {
            self.reset();
        }
        match self.local.post(event, time, payload) {
            Ok(taken) => {
                self.counters.accepted += 1;
                let change = self.local.last_change().filter(|_| taken.changed).map(|c| self.change(c));
                self.counters.changes += change.is_some() as u64;
                Ok(Posted::Taken { change, error: taken.error.map(|e| e.describe(self.content())) })
            }
            Err(why) => {
                if let NotTaken::Refused(PostError::UnknownEvent { event }) = why {
                    return Err(BoardError::UnknownEvent { name: format!("#{event}"), suggestion: None });
                }
                *self.counters.not_taken.entry(why.key()).or_default() += 1;
                Ok(Posted::NotTaken(Refusal { key: why.key(), why, state: self.local.state() }))
            }
        }
    }

    /// Lets time pass to `to` (ns; `None`: now, by the board's clock):
    /// facts age and silent agents go stale, as a running board's
    /// heartbeat does. Returns the change, if the state changed.
    pub fn advance(&mut self, to: Option<u64>) -> Option<Change> {
        let now = self.tick_clock();
        let taken = self.local.advance(to.unwrap_or(now));
        let change = self.local.last_change().filter(|_| taken.changed).map(|c| self.change(c));
        self.counters.changes += change.is_some() as u64;
        change
    }

    /// The board's clock now: the system's, or the latest time for a
    /// manual clock. The system clock is also the clock events arrive at.
    fn tick_clock(&mut self) -> u64 {
        match self.clock {
            Clock::Manual => self.local.now(),
            Clock::System => {
                let now = std::time::SystemTime::now()
                    .duration_since(std::time::UNIX_EPOCH)
                    .map_or(0, |d| d.as_nanos().min(u64::MAX as u128) as u64);
                self.local.set_clock(Some(now));
                now
            }
        }
    }

    /// Takes new rules, keeping the state and the facts that still fit
    /// (a hot swap); on failure the old rules stay.
    pub fn reload(&mut self, content: Arc<Content>) -> Result<Reloaded, BoardError> {
        let report = self.local.reload(content.clone()).map_err(|e| BoardError::Reload(swap_error(&e)))?;
        self.names = names(&content);
        let change = report.change.as_ref().filter(|c| c.changed()).map(|c| self.change(c));
        Ok(Reloaded { carried: report.carried, dropped: report.dropped, change })
    }

    /// The last change, rule by rule, with the facts each matched; `None`
    /// in the initial state before any rule fired.
    pub fn why(&self) -> Option<Why> {
        let change = self.local.last_change()?;
        let c = self.content();
        let state = |s: u32| c.states[s as usize].name.clone();
        let firings = change
            .firings
            .iter()
            .map(|f| {
                let rule = &c.rules[f.rule as usize];
                Fired {
                    rule: rule.name.clone(),
                    file: rule.source.file.clone(),
                    line: rule.source.line,
                    text: rule.source.text.lines().next().unwrap_or("").to_string(),
                    from: state(f.from),
                    to: state(f.to),
                    facts: f.matched.iter().map(|m| fact(c, m)).collect(),
                    stale: f.stale.iter().map(|&a| c.agents[a as usize].name.clone()).collect(),
                }
            })
            .collect();
        Some(Why { from: state(change.from), to: state(change.to), time: change.time, firings })
    }

    /// Every agent's mode, function and links now.
    pub fn agents(&self) -> Vec<AgentNow> {
        let c = self.content();
        let org = self.local.organisation();
        let names = |ids: &[u32]| ids.iter().map(|&i| c.agents[i as usize].name.clone()).collect::<Vec<_>>();
        (0..c.agents.len() as u32)
            .map(|a| {
                let def = &c.agents[a as usize];
                let mode = org.mode(a);
                let running = mode == situ_bundle::Mode::Running;
                let action = org.action(a).filter(|_| running);
                let fsm_state = match (&def.behaviour, org.fsm_state(a)) {
                    (situ_bundle::Behaviour::Fsm(f), Some(s)) => f.states.get(s as usize).map(|s| s.name.clone()),
                    _ => None,
                };
                AgentNow {
                    name: def.name.clone(),
                    mode: mode.adjective(),
                    function: org.function(a).filter(|_| mode != situ_bundle::Mode::Sleeping).map(str::to_string),
                    from: action.map(|x| names(&x.from)).unwrap_or_default(),
                    to: action.map(|x| names(&x.to)).unwrap_or_default(),
                    fsm_state,
                }
            })
            .collect()
    }

    /// The working memory: every agent that has a fact, or is stale.
    pub fn facts(&self) -> Vec<FactNow> {
        let c = self.content();
        let engine = self.local.bulletinboard().engine();
        (0..c.agents.len() as u32)
            .filter_map(|a| {
                let agent = c.agents[a as usize].name.clone();
                if engine.is_stale(a) {
                    return Some(FactNow { agent, fact: None, stale: true });
                }
                engine.fact(a).map(|m| FactNow { agent, fact: Some(fact(c, &m)), stale: false })
            })
            .collect()
    }

    fn change(&self, change: &StateChange) -> Change {
        let c = self.content();
        Change {
            from: c.states[change.from as usize].name.clone(),
            to: c.states[change.to as usize].name.clone(),
            time: change.time,
            rules: change.firings.iter().map(|f| c.rules[f.rule as usize].name.clone()).collect(),
        }
    }
}

/// An event's payload being built by field name ([`Board::fields`]).
pub struct Fields<'a> {
    def: &'a situ_bundle::EventDef,
    values: &'a mut Vec<Value>,
    /// Which fields are given, a bit each.
    seen: u128,
}

impl Fields<'_> {
    /// The bit of field `i` (a bundle has at most 64 fields per event:
    /// its codec refuses more).
    fn bit(i: usize) -> u128 {
        1u128.checked_shl(i as u32).unwrap_or(0)
    }

    fn given(&self, i: usize) -> bool {
        self.seen & Self::bit(i) != 0
    }

    fn mark(&mut self, i: usize) {
        self.seen |= Self::bit(i);
    }

    /// The value of the field `name`: a field the event does not have,
    /// one given twice and a value of the wrong type are errors.
    pub fn set(&mut self, name: &str, arg: Arg) -> Result<(), BoardError> {
        let def = self.def;
        let Some(i) = def.fields.iter().position(|f| f.name == name) else {
            let suggestion = suggest(name, def.fields.iter().map(|f| f.name.as_str())).map(str::to_string);
            return Err(BoardError::UnknownField { event: def.name.clone(), field: name.to_string(), suggestion });
        };
        if self.given(i) {
            return Err(BoardError::FieldTwice { event: def.name.clone(), field: name.to_string() });
        }
        self.values[i] = convert(&def.name, &def.fields[i].name, &def.fields[i].ty, &arg)?;
        self.mark(i);
        Ok(())
    }

    /// Every field was given, or the missing ones are named.
    pub fn finish(self) -> Result<(), BoardError> {
        let n = self.def.fields.len();
        let missing: Vec<String> =
            (0..n).filter(|&i| !self.given(i)).map(|i| self.def.fields[i].name.clone()).collect();
        if missing.is_empty() {
            Ok(())
        } else {
            Err(BoardError::MissingFields { event: self.def.name.clone(), missing })
        }
    }
}

/// Names to ids, hashed fast (the names are the rules', not an attacker's).
type Names = HashMap<String, u32, foldhash::fast::FixedState>;

fn names(c: &Content) -> Names {
    let mut m = Names::with_capacity_and_hasher(c.events.len() * 2, foldhash::fast::FixedState::default());
    for (i, e) in c.events.iter().enumerate() {
        m.insert(e.name.clone(), i as u32);
        m.insert(format!("{}.{}", c.agents[e.agent as usize].name, e.name), i as u32);
    }
    m
}

fn fact(c: &Content, m: &MatchedFact) -> Fact {
    let def = &c.events[m.event as usize];
    let fields = def.fields.iter().zip(&m.payload).map(|(f, v)| (f.name.clone(), field_value(&f.ty, *v))).collect();
    Fact { agent: c.agents[m.agent as usize].name.clone(), event: def.name.clone(), time: m.time, fields }
}

fn field_value(ty: &FieldType, v: Value) -> FieldValue {
    match (ty, v) {
        (FieldType::Symbols(s), Value::Symbol(i)) => FieldValue::Symbol(s.get(i as usize).cloned().unwrap_or_default()),
        (_, Value::F64(x)) => FieldValue::F64(x),
        (_, Value::I64(x)) => FieldValue::I64(x),
        (_, Value::Bool(x)) => FieldValue::Bool(x),
        (_, Value::Symbol(i)) => FieldValue::I64(i as i64),
    }
}

fn convert(event: &str, field: &str, ty: &FieldType, arg: &Arg) -> Result<Value, BoardError> {
    let wrong = |expected: &str| BoardError::FieldType {
        event: event.to_string(),
        field: field.to_string(),
        expected: expected.to_string(),
        found: describe(arg),
    };
    match (ty, arg) {
        (FieldType::F64, Arg::F64(x)) => Ok(Value::F64(*x)),
        (FieldType::F64, Arg::I64(x)) => Ok(Value::F64(*x as f64)),
        (FieldType::F64, _) => Err(wrong("a number (f64)")),
        (FieldType::I64, Arg::I64(x)) => Ok(Value::I64(*x)),
        (FieldType::I64, _) => Err(wrong("an integer (i64)")),
        (FieldType::Bool, Arg::Bool(x)) => Ok(Value::Bool(*x)),
        (FieldType::Bool, _) => Err(wrong("a boolean")),
        (FieldType::Symbols(symbols), Arg::Symbol(s)) => match symbols.iter().position(|x| x == s) {
            Some(i) => Ok(Value::Symbol(i as u32)),
            None => Err(wrong(&format!("one of {}", symbols.join(", ")))),
        },
        (FieldType::Symbols(symbols), _) => Err(wrong(&format!("one of {}", symbols.join(", ")))),
    }
}

fn describe(arg: &Arg) -> String {
    match arg {
        Arg::F64(x) => format!("the number {x}"),
        Arg::I64(x) => format!("the integer {x}"),
        Arg::Bool(x) => format!("the boolean {x}"),
        Arg::Symbol(s) => format!("the text {s:?}"),
    }
}

fn swap_error(e: &SwapError) -> String {
    match e {
        SwapError::StateMissing { state } => format!("the current state `{state}` is not in the new rules"),
        SwapError::Cascade(why) => format!("the new rules do not come to rest on the facts kept: {why}"),
    }
}
