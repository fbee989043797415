//! Tests and properties in the runtime's terms (`situ test`): bundle ids,
//! bundle values and field tests, and a source place for every expectation,
//! so that the runtime's checkers (`situ_verify`) never look at the
//! model or the AST. Ids are the bundle's: the model's indices, unchanged.
//!
//! The data types are `situ_bundle::spec`'s (re-exported here), so that the
//! runtime reads scripts without the compiler; this module makes them from a
//! checked program ([`lower`], [`scripts`]). [`TestSpec`] and
//! [`PropertySpec`] stay here: they keep the block's [`model::Origin`] (a
//! file of the compiler's source map and a span) for findings about it.
//!
//! [`lower`] also computes the timing of a test's events (language reference
//! §10.9), so that the runtime posts exactly what the reference describes.

use crate::bundle;
use crate::model;
use crate::{rete, Checked};
use serde::Serialize;

pub use situ_bundle::spec::*;

/// The spacing of test events without `at` (§10.9).
pub const TEST_SPACING_NS: u64 = 10_000_000;

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
