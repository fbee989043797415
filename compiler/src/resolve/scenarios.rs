//! Phase 4: `test` and `property` blocks.

use super::rules::{collect_binds, pattern, stale_agent};
use super::{types, Cx};
use crate::codes;
use crate::model::*;
use situ_grammar::ast;
use situ_grammar::diag::{Diagnostic, FileId};

pub(super) fn test(cx: &mut Cx, file: FileId, test: &ast::Test) {
    let origin = Cx::origin(file, test.name.span);
    if let Some(first) = cx.test_names.get(&test.name.value).copied() {
        cx.duplicate("test", &test.name.value, file, test.name.span, first);
    } else {
        cx.test_names.insert(test.name.value.clone(), origin);
    }
    let mut steps = Vec::new();
    let mut ok = true;
    // The time of the latest posted event (§10.9), for E0117.
    let mut last: Option<(u64, ast::Span)> = None;
    for clause in &test.clauses {
        let step = match clause {
            ast::TestClause::Given { items, span } => {
                let mut state = None;
                let mut facts = Vec::new();
                for item in items {
                    match item {
                        ast::GivenItem::State { state: s, .. } => match cx.state(file, s) {
                            Some(s) => state = Some(s),
                            None => ok = false,
                        },
                        ast::GivenItem::Event(e) if not_an_event(cx, file, e) => ok = false,
                        ast::GivenItem::Event(e) => match event_fact(cx, file, e) {
                            Some(f) => facts.push(f),
                            None => ok = false,
                        },
                    }
                }
                TestStep::Given { state, facts, origin: Cx::origin(file, *span) }
            }
            ast::TestClause::On { events, span } => {
                let facts: Vec<EventFact> = events.iter().filter_map(|e| event_fact(cx, file, e)).collect();
                ok &= facts.len() == events.len();
                for (fact, e) in facts.iter().zip(events) {
                    ok &= time_order(cx, file, fact, e, &mut last);
                }
                TestStep::On { events: facts, origin: Cx::origin(file, *span) }
            }
            ast::TestClause::Expect { expectations, span } => {
                let resolved: Vec<Expectation> = expectations.iter().filter_map(|e| expectation(cx, file, e)).collect();
                ok &= resolved.len() == expectations.len();
                TestStep::Expect { expectations: resolved, origin: Cx::origin(file, *span) }
            }
        };
        steps.push(step);
    }
    if ok {
        cx.model.tests.push(Test { name: test.name.value.clone(), steps, origin });
    }
}

/// E0117: an event stamped `at` a time before the previous posted event.
/// Advances `last` to the time of the fact's last copy.
fn time_order(
    cx: &mut Cx,
    file: FileId,
    fact: &EventFact,
    e: &ast::EventInstance,
    last: &mut Option<(u64, ast::Span)>,
) -> bool {
    let mut at = last.map_or(0, |(t, _)| t);
    let times = crate::spec::post_times(&mut at, fact);
    let first = times.first().copied().unwrap_or(at);
    let ok = match *last {
        Some((previous, span)) if first < previous => {
            let show = |ns: u64| format!("{}ms", ns as f64 / 1e6);
            cx.diags.push(
                Diagnostic::error(
                    codes::TEST_TIME_ORDER,
                    format!(
                        "`{}` is posted at {}, before the previous event ({})",
                        e.event.name,
                        show(first),
                        show(previous)
                    ),
                    file,
                    e.span,
                    "earlier than the previous event",
                )
                .with_label(file, span, format!("posted at {}", show(previous)))
                .with_help(format!(
                    "time only moves forward in a test: stamp it `at {}` or later, or move it before the earlier event",
                    show(previous)
                )),
            );
            false
        }
        _ => true,
    };
    *last = Some((at, e.span));
    ok
}

/// E0104 in a `given`: a name that is no event but a system state, an agent
/// or a state of an agent's FSM. Says what the name is and how `given` writes
/// what the writer meant; false (and nothing said) for any other name.
fn not_an_event(cx: &mut Cx, file: FileId, e: &ast::EventInstance) -> bool {
    let name = e.event.name.as_str();
    if cx.events.contains_key(name) {
        return false;
    }
    let bare = e.arguments.is_empty() && e.repeat.is_none() && e.at.is_none();
    let (what, help) = if cx.states.contains_key(name) {
        ("a system state".to_string(), format!("to start the test in this state, write `given state {name}`"))
    } else if let Some(&agent) = cx.agents.get(name) {
        let events: Vec<String> =
            cx.model.agent(agent).events.iter().map(|&ev| format!("`{}`", cx.model.event(ev).name)).collect();
        let reports = match events.as_slice() {
            [] => format!("`{name}` reports no event"),
            _ => format!("the events of `{name}` are {}", events.join(", ")),
        };
        (
            "an agent".to_string(),
            format!("`given` sets the system state (`given state S`) and the latest event of agents: {reports}"),
        )
    } else if let Some(owner) = fsm_owner(cx, name) {
        (
            format!("a state of the FSM of `{owner}`"),
            "`given` cannot set an FSM's state: every FSM starts in its initial state and follows the system state and its agent's events; write `given state S` for the system state that leads there".to_string(),
        )
    } else {
        return false;
    };
    let mut d = Diagnostic::error(
        codes::UNDEFINED_EVENT,
        format!("`{name}` is {what}, not an event"),
        file,
        e.event.span,
        "not an event",
    )
    .with_help(help);
    if bare && cx.states.contains_key(name) {
        let at = ast::Span::new(e.event.span.start, e.event.span.start);
        d = d.with_fix(format!("write `state {name}`"), file, at, "state ");
    }
    cx.diags.push(d);
    true
}

/// The agent whose FSM has a state of this name (as far as resolved).
fn fsm_owner(cx: &Cx, name: &str) -> Option<String> {
    cx.model.agents.iter().find_map(|a| match &a.behaviour {
        Behaviour::Fsm(fsm) if fsm.states.iter().any(|s| s.name == name) => Some(a.name.clone()),
        _ => None,
    })
}

/// A concrete event: every field given once, each of the right type.
pub(super) fn event_fact(cx: &mut Cx, file: FileId, e: &ast::EventInstance) -> Option<EventFact> {
    let event = cx.event(file, &e.event)?;
    let fields = cx.model.event(event).fields.clone();
    let mut payload: Vec<Option<Value>> = vec![None; fields.len()];
    let mut given: Vec<Option<ast::Span>> = vec![None; fields.len()];
    let mut ok = true;
    for arg in &e.arguments {
        let Some(i) = cx.field(file, event, &arg.field) else {
            ok = false;
            continue;
        };
        if let Some(first) = given[i] {
            cx.duplicate("argument", &arg.field.name, file, arg.field.span, Cx::origin(file, first));
            ok = false;
            continue;
        }
        given[i] = Some(arg.field.span);
        payload[i] = types::literal(cx, file, &arg.value, &fields[i].ty, &fields[i].name);
        ok &= payload[i].is_some();
    }
    let missing: Vec<&str> =
        fields.iter().zip(&given).filter(|(_, g)| g.is_none()).map(|(f, _)| f.name.as_str()).collect();
    if !missing.is_empty() {
        let example: Vec<String> = fields
            .iter()
            .map(|f| {
                let v = match &f.ty {
                    Type::F64 => "0.0".to_string(),
                    Type::I64 => "0".to_string(),
                    Type::Bool => "false".to_string(),
                    Type::Symbols(s) => s.first().cloned().unwrap_or_default(),
                };
                format!("{}: {v}", f.name)
            })
            .collect();
        cx.diags.push(
            Diagnostic::error(
                codes::MISSING_FIELD,
                format!(
                    "event `{}` is missing {}: {}",
                    e.event.name,
                    plural(missing.len(), "field"),
                    missing.join(", ")
                ),
                file,
                e.event.span,
                "incomplete payload",
            )
            .with_help(format!(
                "a test event gives every field: `{}({})`",
                e.event.name,
                example.join(", ")
            )),
        );
        ok = false;
    }
    let repeat = match &e.repeat {
        Some(r) => {
            ok &= cx.positive(file, r.count, r.span, "a repeat count");
            r.count
        }
        None => 1,
    };
    ok.then(|| EventFact {
        event,
        payload: payload.into_iter().map(|v| v.expect("every field is given when ok")).collect(),
        repeat,
        at: e.at.map(|d| d.nanos),
        origin: Cx::origin(file, e.span),
    })
}

fn plural(n: usize, word: &str) -> String {
    if n == 1 {
        word.to_string()
    } else {
        format!("{word}s")
    }
}

fn expectation(cx: &mut Cx, file: FileId, e: &ast::Expectation) -> Option<Expectation> {
    let origin = Cx::origin(file, e.span());
    match e {
        ast::Expectation::State { state, .. } => {
            cx.state(file, state).map(|state| Expectation::State { state, origin })
        }
        ast::Expectation::Mode { agent, mode, .. } => {
            cx.agent(file, agent).map(|agent| Expectation::Mode { agent, mode: *mode, origin })
        }
        ast::Expectation::Runs { agent, function, .. } => {
            let agent = cx.agent(file, agent)?;
            let function = cx.function(file, agent, function)?;
            Some(Expectation::Runs { agent, function, origin })
        }
        ast::Expectation::Link { from, to, present, .. } => {
            let from = cx.agent(file, from);
            let to = cx.agent(file, to);
            Some(Expectation::Link { from: from?, to: to?, present: *present, origin })
        }
    }
}

pub(super) fn property(cx: &mut Cx, file: FileId, prop: &ast::Property) {
    let origin = Cx::origin(file, prop.name.span);
    if let Some(first) = cx.property_names.get(&prop.name.value).copied() {
        cx.duplicate("property", &prop.name.value, file, prop.name.span, first);
    } else {
        cx.property_names.insert(prop.name.value.clone(), origin);
    }
    let formula = match &prop.formula {
        ast::Formula::Now(p) => pred(cx, file, p).map(Formula::Now),
        ast::Formula::Implies { premise, consequent, .. } => {
            let premise = pred(cx, file, premise);
            let consequent = match consequent {
                ast::Consequent::Now(q) => pred(cx, file, q).map(Consequent::Now),
                ast::Consequent::Next { predicate, .. } => pred(cx, file, predicate).map(Consequent::Next),
                ast::Consequent::Eventually { predicate, bound, .. } => {
                    let q = pred(cx, file, predicate);
                    let bound = match bound {
                        None => Some(None),
                        Some(ast::Bound::Events { count, span }) => {
                            cx.positive(file, *count, *span, "an event bound").then_some(Some(Bound::Events(*count)))
                        }
                        Some(ast::Bound::Time(d)) => {
                            cx.positive(file, d.nanos, d.span, "a time bound").then_some(Some(Bound::Nanos(d.nanos)))
                        }
                    };
                    match (q, bound) {
                        (Some(pred), Some(bound)) => Some(Consequent::Eventually { pred, bound }),
                        _ => None,
                    }
                }
            };
            match (premise, consequent) {
                (Some(premise), Some(consequent)) => Some(Formula::Implies { premise, consequent }),
                _ => None,
            }
        }
    };
    if let Some(formula) = formula {
        cx.model.properties.push(Property {
            name: prop.name.value.clone(),
            quantifier: prop.quantifier,
            formula,
            origin,
        });
    }
}

fn pred(cx: &mut Cx, file: FileId, p: &ast::Predicate) -> Option<Pred> {
    let all = |cx: &mut Cx, ps: &[ast::Predicate]| -> Option<Vec<Pred>> {
        let resolved: Vec<Option<Pred>> = ps.iter().map(|p| pred(cx, file, p)).collect();
        resolved.into_iter().collect()
    };
    match p {
        ast::Predicate::Or(ps, _) => all(cx, ps).map(Pred::Or),
        ast::Predicate::And(ps, _) => all(cx, ps).map(Pred::And),
        ast::Predicate::Not(q, _) => pred(cx, file, q).map(|q| Pred::Not(Box::new(q))),
        ast::Predicate::Bool(b, _) => Some(Pred::Bool(*b)),
        ast::Predicate::State(test) => {
            let before = cx.diags.len();
            let set = cx.state_set(file, test);
            (cx.diags.len() == before).then_some(Pred::State(set))
        }
        ast::Predicate::Mode { agent, mode, .. } => {
            cx.agent(file, agent).map(|agent| Pred::Mode { agent, mode: *mode })
        }
        ast::Predicate::Link { from, to, .. } => {
            let from = cx.agent(file, from);
            let to = cx.agent(file, to);
            Some(Pred::Link { from: from?, to: to? })
        }
        ast::Predicate::Stale { agent, .. } => stale_agent(cx, file, agent).map(Pred::Stale),
        ast::Predicate::Event(pat) => {
            let mut variables = Vec::new();
            collect_binds(cx, file, pat, &mut variables);
            let pattern = pattern(cx, file, pat, &mut variables, &mut Vec::new())?;
            Some(Pred::Event { pattern, variables })
        }
    }
}
