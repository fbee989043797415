//! Tests and properties in the runtime's terms (`situ test`): bundle ids,
//! bundle values and field tests, and a source place for every expectation,
//! so that the runtime's checkers (`situ_verify`) never look at the
//! model or the AST. Ids are the bundle's: the model's indices, unchanged.
//!
//! [`lower`] also computes the timing of a test's events (language reference
//! §10.9), so that the runtime posts exactly what the reference describes.

use crate::bundle::{self, Mode, Test as FieldTest, Value};
use crate::model;
use crate::{rete, Checked};
use serde::Serialize;

/// The spacing of test events without `at` (§10.9).
pub const TEST_SPACING_NS: u64 = 10_000_000;

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

/// Every test and property of a checked program.
#[derive(Debug, Clone, Serialize)]
pub struct Spec {
    pub tests: Vec<TestSpec>,
    pub properties: Vec<PropertySpec>,
}

/// A `test` block.
#[derive(Debug, Clone, Serialize)]
pub struct TestSpec {
    pub name: String,
    pub place: Place,
    /// The block's file and span (for findings about it).
    pub origin: model::Origin,
    pub steps: Vec<TestStep>,
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

/// A `property` block.
#[derive(Debug, Clone, Serialize)]
pub struct PropertySpec {
    pub name: String,
    pub place: Place,
    /// The block's file and span (for findings about it).
    pub origin: model::Origin,
    /// `never F` rather than `always F`.
    pub never: bool,
    pub premise: Option<Pred>,
    pub consequent: Consequent,
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

impl PropertySpec {
    /// The predicates of the property: the premise (if any), then the consequent's.
    pub fn preds(&self) -> impl Iterator<Item = &Pred> {
        let q = match &self.consequent {
            Consequent::Now(q) | Consequent::Next(q) | Consequent::Eventually { pred: q, .. } => q,
        };
        self.premise.iter().chain(std::iter::once(q))
    }
}

/// The tests and properties of a program without errors.
pub fn lower(checked: &Checked) -> Spec {
    let place = |o: model::Origin| {
        let file = checked.sources.get(o.file);
        let (line, column) = file.line_col(o.span.start);
        Place { file: file.name.clone(), line: line as u32, column: column as u32 }
    };
    let model = &checked.model;
    let tests = model.tests.iter().map(|t| test(t, &place)).collect();
    let properties = model.properties.iter().map(|p| property(p, &place)).collect();
    Spec { tests, properties }
}

fn test(t: &model::Test, place: &dyn Fn(model::Origin) -> Place) -> TestSpec {
    let mut last = 0u64;
    let steps = t
        .steps
        .iter()
        .map(|step| match step {
            model::TestStep::Given { state, facts, .. } => TestStep::Given {
                state: state.map(|s| s.0),
                facts: facts
                    .iter()
                    .map(|f| GivenFact {
                        event: f.event.0,
                        payload: f.payload.iter().map(|v| rete::value(*v)).collect(),
                        run: f.repeat,
                        place: place(f.origin),
                    })
                    .collect(),
            },
            model::TestStep::On { events, .. } => {
                let mut posted = Vec::new();
                for f in events {
                    for time in post_times(&mut last, f) {
                        posted.push(Posted {
                            event: f.event.0,
                            payload: f.payload.iter().map(|v| rete::value(*v)).collect(),
                            time,
                            place: place(f.origin),
                        });
                    }
                }
                TestStep::On { events: posted }
            }
            model::TestStep::Expect { expectations, .. } => {
                TestStep::Expect { expectations: expectations.iter().map(|e| expectation(e, place)).collect() }
            }
        })
        .collect();
    TestSpec { name: t.name.clone(), place: place(t.origin), origin: t.origin, steps }
}

/// The times of the copies of a test event (§10.9): the first at `at`, or
/// 10 ms after the previous posted event (`last`, 0 at the start); the
/// others 10 ms apart. Advances `last`. An `at` before `last` is reported
/// by the resolver (E0117), so here it is taken as written.
pub fn post_times(last: &mut u64, f: &model::EventFact) -> Vec<u64> {
    let mut out = Vec::new();
    let mut t = f.at.unwrap_or_else(|| last.saturating_add(TEST_SPACING_NS));
    for k in 0..f.repeat.max(1) {
        if k > 0 {
            t = t.saturating_add(TEST_SPACING_NS);
        }
        out.push(t);
        if out.len() >= 1_000_000 {
            break;
        }
    }
    *last = t;
    out
}

fn expectation(e: &model::Expectation, place: &dyn Fn(model::Origin) -> Place) -> Expect {
    let (what, origin) = match e {
        model::Expectation::State { state, origin } => (Expected::State(state.0), origin),
        model::Expectation::Mode { agent, mode, origin } => {
            (Expected::Mode { agent: agent.0, mode: bundle::build::mode(*mode) }, origin)
        }
        model::Expectation::Runs { agent, function, origin } => {
            (Expected::Runs { agent: agent.0, function: *function as u32 }, origin)
        }
        model::Expectation::Link { from, to, present, origin } => {
            (Expected::Link { from: from.0, to: to.0, present: *present }, origin)
        }
    };
    Expect { what, place: place(*origin) }
}

fn property(p: &model::Property, place: &dyn Fn(model::Origin) -> Place) -> PropertySpec {
    let (premise, consequent) = match &p.formula {
        model::Formula::Now(q) => (None, Consequent::Now(pred(q))),
        model::Formula::Implies { premise, consequent } => {
            let c = match consequent {
                model::Consequent::Now(q) => Consequent::Now(pred(q)),
                model::Consequent::Next(q) => Consequent::Next(pred(q)),
                model::Consequent::Eventually { pred: q, bound } => Consequent::Eventually {
                    pred: pred(q),
                    bound: bound.map(|b| match b {
                        model::Bound::Events(n) => Bound::Events(n),
                        model::Bound::Nanos(n) => Bound::Nanos(n),
                    }),
                },
            };
            (Some(pred(premise)), c)
        }
    };
    PropertySpec {
        name: p.name.clone(),
        place: place(p.origin),
        origin: p.origin,
        never: matches!(p.quantifier, situ_grammar::ast::Quantifier::Never),
        premise,
        consequent,
    }
}

fn pred(p: &model::Pred) -> Pred {
    match p {
        model::Pred::Or(ps) => Pred::Or(ps.iter().map(pred).collect()),
        model::Pred::And(ps) => Pred::And(ps.iter().map(pred).collect()),
        model::Pred::Not(q) => Pred::Not(Box::new(pred(q))),
        model::Pred::Bool(b) => Pred::Bool(*b),
        model::Pred::State(set) => Pred::State(set.states.iter().map(|s| s.0).collect()),
        model::Pred::Mode { agent, mode } => Pred::Mode { agent: agent.0, mode: bundle::build::mode(*mode) },
        model::Pred::Link { from, to } => Pred::Link { from: from.0, to: to.0 },
        model::Pred::Stale(a) => Pred::Stale(a.0),
        model::Pred::Event { pattern, .. } => {
            Pred::Event { event: pattern.event.0, tests: rete::pattern_alone(pattern), min_run: pattern.run_length }
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

/// The scripts of a program without errors.
pub fn scripts(checked: &Checked) -> Vec<ScriptSpec> {
    let place = |o: model::Origin| {
        let file = checked.sources.get(o.file);
        let (line, column) = file.line_col(o.span.start);
        Place { file: file.name.clone(), line: line as u32, column: column as u32 }
    };
    let event = |e: &model::ScriptEvent| ScriptEvent {
        event: e.event.0,
        payload: e.payload.iter().map(|v| rete::value(*v)).collect(),
        place: place(e.origin),
    };
    checked
        .model
        .scripts
        .iter()
        .map(|s| ScriptSpec {
            name: s.name.clone(),
            place: place(s.origin),
            end: s.end,
            steps: s
                .steps
                .iter()
                .map(|step| match step {
                    model::ScriptStep::At { time, event: e, .. } => ScriptStep::At { time: *time, event: event(e) },
                    model::ScriptStep::Every { period, from, to, event: e, .. } => {
                        ScriptStep::Every { period: *period, from: *from, to: *to, event: event(e) }
                    }
                    model::ScriptStep::Silent { agent, from, to, origin } => {
                        ScriptStep::Silent { agent: agent.0, from: *from, to: *to, place: place(*origin) }
                    }
                    model::ScriptStep::Random { from, length, seed, origin } => {
                        ScriptStep::Random { from: *from, length: *length, seed: *seed, place: place(*origin) }
                    }
                })
                .collect(),
        })
        .collect()
}
