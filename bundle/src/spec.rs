//! Tests, properties and scripts in the runtime's terms: bundle ids,
//! bundle values and field tests, and a source place for every expectation
//! and event, so that the runtime and its checkers never look at a model or
//! an AST. The compiler makes them from a checked program
//! (`situ_compiler::spec`, which also holds the test and property records
//! that keep their place in the compiler's source map).

use crate::{Mode, Test as FieldTest, Value};
use serde::Serialize;

/// Where something was written: `file:line:column` (1-based, characters).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Place {
    pub file: String,
    pub line: u32,
    pub column: u32,
}

impl std::fmt::Display for Place {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

/// One clause of a test.
#[derive(Debug, Clone, Serialize)]
pub enum TestStep {
    /// Set the state and facts (stamped at 0) without firing rules or FSMs.
    Given {
        state: Option<u32>,
        facts: Vec<GivenFact>,
    },
    /// Post these events, in order, at these times.
    On {
        events: Vec<Posted>,
    },
    Expect {
        expectations: Vec<Expect>,
    },
}

/// A fact set by `given`: the event with run length `run`, at time 0.
#[derive(Debug, Clone, Serialize)]
pub struct GivenFact {
    pub event: u32,
    pub payload: Vec<Value>,
    pub run: u64,
    pub place: Place,
}

/// One posted event (a test's `E xN` is N of them).
#[derive(Debug, Clone, Serialize)]
pub struct Posted {
    pub event: u32,
    pub payload: Vec<Value>,
    /// Nanoseconds from the start of the test.
    pub time: u64,
    pub place: Place,
}

/// One expectation, with where it is written.
#[derive(Debug, Clone, Serialize)]
pub struct Expect {
    pub what: Expected,
    pub place: Place,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Expected {
    State(u32),
    Mode { agent: u32, mode: Mode },
    Runs { agent: u32, function: u32 },
    Link { from: u32, to: u32, present: bool },
}

/// What must hold at a point (of the premise, where there is one).
#[derive(Debug, Clone, Serialize)]
pub enum Consequent {
    Now(Pred),
    Next(Pred),
    Eventually { pred: Pred, bound: Option<Bound> },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Bound {
    Events(u64),
    Nanos(u64),
}

/// A predicate on the system at one point of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Pred {
    Or(Vec<Pred>),
    And(Vec<Pred>),
    Not(Box<Pred>),
    Bool(bool),
    /// The state is one of these (sorted).
    State(Vec<u32>),
    Mode {
        agent: u32,
        mode: Mode,
    },
    Link {
        from: u32,
        to: u32,
    },
    Stale(u32),
    /// The latest live fact of the event's agent is this event, passes the
    /// tests (on its own fields) and has run length `min_run` or more.
    Event {
        event: u32,
        tests: Vec<FieldTest>,
        min_run: u64,
    },
}

impl Pred {
    /// Calls `f` on this predicate and every predicate inside it.
    pub fn visit(&self, f: &mut dyn FnMut(&Pred)) {
        f(self);
        match self {
            Pred::Or(ps) | Pred::And(ps) => ps.iter().for_each(|p| p.visit(f)),
            Pred::Not(p) => p.visit(f),
            _ => {}
        }
    }
}

/// A `script` block in the runtime's terms (`situ run --script`).
#[derive(Debug, Clone, Serialize)]
pub struct ScriptSpec {
    pub name: String,
    pub place: Place,
    pub steps: Vec<ScriptStep>,
    /// When the last step ends (ns from the start of the run).
    pub end: u64,
}

/// One step of a script; times in nanoseconds from the start of the run.
#[derive(Debug, Clone, Serialize)]
pub enum ScriptStep {
    /// One event at `time`.
    At { time: u64, event: ScriptEvent },
    /// The event at `from`, `from + period`, … while before `to`.
    Every { period: u64, from: u64, to: u64, event: ScriptEvent },
    /// The agent reports nothing in `[from, to)`.
    Silent { agent: u32, from: u64, to: u64, place: Place },
    /// The guided generator drives every agent in `[from, from + length)`.
    Random { from: u64, length: u64, seed: u64, place: Place },
}

/// A concrete event of a script.
#[derive(Debug, Clone, Serialize)]
pub struct ScriptEvent {
    pub event: u32,
    pub payload: Vec<Value>,
    pub place: Place,
}
