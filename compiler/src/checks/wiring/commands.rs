//! W0320: an actuator commanded by several agents at once. An agent says
//! what it sends as commands with `commands X` (its links to X carry
//! commands; its other links, and every other agent's, carry data). In the
//! wiring graph of some state, two or more agents that declare `commands X`
//! are linked to the actuator X: it gets two commands and nothing says how
//! they combine — the last to arrive wins, and which one that is depends on
//! the agents' rates and the bus.
//!
//! Combining is said with an agent of its own: the commanders command a
//! `processing` agent (`commands Merger`), which reads them and commands the
//! actuator (Dafflon et al.'s merge: `run blend() from Reacher, Avoider to
//! Vehicle`). Only actuators are checked: a merger is commanded by several
//! agents on purpose. Only links present whatever the FSMs' history count,
//! so a finding holds in every run through the state.

use super::{state_list, StateWiring};
use crate::codes;
use crate::model::{AgentId, AgentKind, Model, Origin, StateId};
use serde_json::{json, Map, Value};
use situ_grammar::diag::Diagnostic;
use std::collections::BTreeMap;

pub fn check(model: &Model, wirings: &[StateWiring]) -> Vec<Diagnostic> {
    let actuators = (0..model.agents.len() as u32).map(AgentId).filter(|&a| model.agent(a).kind == AgentKind::Actuator);
    actuators.filter_map(|a| actuator(model, wirings, a)).collect()
}

/// Whether `from` declares that what it sends to `to` are commands.
fn commands(model: &Model, from: AgentId, to: AgentId) -> bool {
    model.agent(from).commands.iter().any(|(t, _)| *t == to)
}

/// A commander and the table entries that write its link.
type Commander<'w> = (AgentId, &'w [Origin]);

/// The commanders of `actuator` in one state; `None` unless there are two
/// or more.
fn commanders<'w>(model: &Model, w: &'w StateWiring, actuator: AgentId) -> Option<Vec<Commander<'w>>> {
    let found: Vec<Commander<'w>> = w
        .must
        .iter()
        .filter(|(&(from, to), _)| to == actuator && from != actuator && commands(model, from, to))
        .map(|(&(from, _), origins)| (from, origins.as_slice()))
        .collect();
    (found.len() >= 2).then_some(found)
}

fn actuator(model: &Model, wirings: &[StateWiring], actuator: AgentId) -> Option<Diagnostic> {
    // Each distinct set of commanders once, with the states it commands in
    // (and, per state, each commander's table entries).
    type PerState<'w> = Vec<(StateId, Vec<&'w [Origin]>)>;
    let mut sets: BTreeMap<Vec<AgentId>, PerState> = BTreeMap::new();
    for w in wirings {
        if let Some(found) = commanders(model, w, actuator) {
            let (agents, origins): (Vec<AgentId>, Vec<&[Origin]>) = found.into_iter().unzip();
            sets.entry(agents).or_default().push((w.state, origins));
        }
    }
    if sets.is_empty() {
        return None;
    }
    let a = model.agent(actuator);
    let name = |x: &AgentId| model.agent(*x).name.clone();
    let all_states: Vec<StateId> = sets.values().flatten().map(|(s, _)| *s).collect();
    let list = state_list(model, &all_states);
    let (first_set, _) = sets.iter().next().expect("at least one set");
    let senders = first_set.iter().map(|x| format!("`{}`", name(x))).collect::<Vec<_>>().join(" and ");
    let message = format!("actuator `{}` is commanded by {senders} at once in {list}", a.name);
    let mut d = Diagnostic::warning(
        codes::CONCURRENT_COMMANDS,
        message,
        a.origin.file,
        a.origin.span,
        format!("gets several commands in {list}"),
    );
    // A label at each action that writes one of the links, with its states.
    let mut labels: BTreeMap<Origin, (AgentId, Vec<StateId>)> = BTreeMap::new();
    for (agents, states) in &sets {
        for (state, origins) in states {
            for (x, at) in agents.iter().zip(origins) {
                for o in at.iter() {
                    let entry = labels.entry(*o).or_insert((*x, Vec::new()));
                    if !entry.1.contains(state) {
                        entry.1.push(*state);
                    }
                }
            }
        }
    }
    for (at, (x, states)) in labels {
        d = d.with_label(at.file, at.span, format!("links `{}` to it in {}", name(&x), state_list(model, &states)));
    }
    let per_state: Map<String, Value> = sets
        .iter()
        .flat_map(|(agents, states)| {
            let names: Vec<String> = agents.iter().map(name).collect();
            states.iter().map(move |(s, _)| (model.state(*s).name.clone(), json!(names)))
        })
        .collect();
    let first: Vec<String> = first_set.iter().map(name).collect();
    Some(
        d.with_help(format!(
            "combine the commands in an agent of its own: a `processing` agent that {} command \
             (`commands Merger`) and that alone commands `{}` (`run blend() from {} to {}`) in {list}; \
             or link one commander there",
            first.join(" and "),
            a.name,
            first.join(", "),
            a.name,
        ))
        .with_witness(json!({ "actuator": a.name, "commanders": per_state })),
    )
}
