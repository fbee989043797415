//! W0308, W0309, W0310: declarations that do nothing. An event that no rule
//! and no FSM reads, an agent that runs in no state, a function that no
//! table entry or FSM state runs or waits. Tests and properties check the
//! stack; they are not part of it, so they do not count as uses.

use super::behaviour::{reachable_fsm_states, table_entry};
use super::transitions::Transitions;
use crate::codes;
use crate::model::{Agent, Behaviour, FsmTrigger, Model};
use serde_json::{json, Map, Value};
use situ_grammar::ast::{Mode, Span};
use situ_grammar::diag::Diagnostic;

pub fn check(model: &Model, _tr: &Transitions) -> Vec<Diagnostic> {
    let mut out = unused_events(model);
    out.extend(model.agents.iter().filter_map(|a| never_running(model, a)));
    out.extend(model.agents.iter().flat_map(unused_functions));
    out
}

fn unused_events(model: &Model) -> Vec<Diagnostic> {
    let mut read = vec![false; model.events.len()];
    for p in model.rules.iter().flat_map(|r| r.patterns.iter().chain(&r.negations)) {
        read[p.event.index()] = true;
    }
    for a in &model.agents {
        if let Behaviour::Fsm(f) = &a.behaviour {
            for t in &f.transitions {
                if let FsmTrigger::Event(e) = t.trigger {
                    read[e.index()] = true;
                }
            }
        }
    }
    let unread = model.events.iter().zip(read).filter(|(_, read)| !read);
    unread
        .map(|(e, _)| {
            let agent = &model.agent(e.agent).name;
            Diagnostic::warning(
                codes::UNUSED_EVENT,
                format!("event `{}` of `{agent}` is read by no rule and no FSM", e.name),
                e.origin.file,
                e.origin.span,
                "never read",
            )
            .with_help(format!(
                "read it in a rule (`when {0} then …`) or an FSM transition of `{agent}` (`A -> B on {0}`), or remove it; tests and properties do not count",
                e.name
            ))
            .with_witness(json!({ "event": e.name, "agent": agent }))
        })
        .collect()
}

/// W0309, with the modes the agent has (per system state, or per reachable FSM state).
fn never_running(model: &Model, agent: &Agent) -> Option<Diagnostic> {
    let (modes, keyword, place): (Map<String, Value>, &str, _) = match &agent.behaviour {
        Behaviour::Always => return None,
        Behaviour::Table(t) => {
            let mode = |s| table_entry(t, s).map_or(Mode::Sleeping, |e| e.action.mode);
            let modes = model.state_ids().map(|s| (model.state(s).name.clone(), json!(mode(s).adjective())));
            (modes.collect(), "table", t.origin)
        }
        Behaviour::Fsm(f) => {
            let reachable = reachable_fsm_states(f);
            let states = f.states.iter().zip(reachable).filter(|(_, r)| *r);
            (states.map(|(s, _)| (s.name.clone(), json!(s.action.mode.adjective()))).collect(), "fsm", f.origin)
        }
    };
    if modes.values().any(|m| m == Mode::Running.adjective()) {
        return None;
    }
    let what = if keyword == "table" { "state" } else { "reachable FSM state" };
    Some(
        Diagnostic::warning(
            codes::NEVER_RUNNING,
            format!("agent `{}` never runs", agent.name),
            agent.origin.file,
            agent.origin.span,
            format!("running in no {what}"),
        )
        .with_label(place.file, Span::new(place.span.start, place.span.start + keyword.len()), format!("sleeps or waits in every {what}"))
        .with_help(format!(
            "give `{}` a `run` action where it should work (waiting, it is stepped but its data is dropped), or remove it",
            agent.name
        ))
        .with_witness(json!({ "agent": agent.name, "by": keyword, "modes": modes })),
    )
}

fn unused_functions(agent: &Agent) -> Vec<Diagnostic> {
    let mut used = vec![false; agent.functions.len()];
    let actions: Vec<_> = match &agent.behaviour {
        Behaviour::Always => Vec::new(),
        Behaviour::Table(t) => t.entries.iter().map(|e| &e.action).collect(),
        Behaviour::Fsm(f) => f.states.iter().map(|s| &s.action).collect(),
    };
    for f in actions.iter().filter_map(|a| a.function) {
        used[f] = true;
    }
    let unused = agent.functions.iter().zip(used).filter(|(_, used)| !used);
    unused
        .map(|(f, _)| {
            Diagnostic::warning(
                codes::UNUSED_FUNCTION,
                format!("function `{}` of `{}` is never run", f.name, agent.name),
                f.origin.file,
                f.origin.span,
                "no table entry or FSM state runs or waits it",
            )
            .with_help(format!("run it where it is meant to work (`STATE => run {}()`), or remove it", f.name))
            .with_witness(json!({ "agent": agent.name, "function": f.name }))
        })
        .collect()
}
