//! W0316 and W0317: the two ends of the data flow, left unconnected. A
//! running actuator with no link in (W0316) and a running sensor with no
//! link out (W0317), per state. Only agents that run a function count: an
//! agent without a table runs none, so it neither needs nor makes data.
//!
//! An actuator may well run with no input: braking to standstill, or a
//! warning light the state alone drives. So W0316 holds only where the
//! actuator runs a function that receives input in another state (it reads
//! data, and here gets none). A sensor that should only report events has
//! its own way to say so, `wait`, so W0317 holds wherever a running sensor's
//! data goes nowhere.

use super::{state_list, StateWiring};
use crate::codes;
use crate::model::{AgentId, AgentKind, Model, Origin, StateId};
use serde_json::{json, Map, Value};
use situ_grammar::ast::Mode;
use situ_grammar::diag::Diagnostic;
use std::collections::BTreeMap;

pub fn check(model: &Model, wirings: &[StateWiring]) -> Vec<Diagnostic> {
    let ids = (0..model.agents.len() as u32).map(AgentId);
    ids.filter_map(|a| match model.agent(a).kind {
        AgentKind::Actuator => actuator(model, wirings, a),
        AgentKind::Sensor => sensor(model, wirings, a),
        _ => None,
    })
    .collect()
}

/// States where the agent surely runs functions (one per possible action)
/// and `linked` does not hold.
fn unlinked<'w, 'm>(
    wirings: &'w [StateWiring<'m>],
    agent: AgentId,
    linked: impl Fn(&StateWiring) -> bool,
) -> Vec<(&'w StateWiring<'m>, Vec<usize>)> {
    let bare = wirings.iter().filter(|w| !linked(w));
    bare.filter_map(|w| w.running_functions(agent).map(|f| (w, f))).collect()
}

fn actuator(model: &Model, wirings: &[StateWiring], agent: AgentId) -> Option<Diagnostic> {
    let fed = fed_functions(wirings, agent);
    let bare: Vec<_> = unlinked(wirings, agent, |w| w.has_input(agent))
        .into_iter()
        .filter(|(_, functions)| functions.iter().all(|f| fed.contains_key(f)))
        .collect();
    let d = report(model, agent, &bare, codes::ACTUATOR_WITHOUT_INPUT, "with no input")?;
    let a = model.agent(agent);
    let fed: Vec<(&str, Vec<StateId>)> = fed
        .into_iter()
        .filter(|(f, _)| bare.iter().any(|(_, fs)| fs.contains(f)))
        .map(|(f, states)| (a.functions[f].name.as_str(), states))
        .collect();
    let got: Vec<String> = fed.iter().map(|(f, s)| format!("`{f}` gets input in {}", state_list(model, s))).collect();
    let with_input: Map<String, Value> =
        fed.iter().map(|(f, s)| (f.to_string(), json!(state_names(model, s)))).collect();
    let states: Vec<StateId> = bare.iter().map(|(w, _)| w.state).collect();
    Some(
        d.with_help(format!(
            "link an input to `{}` in {} (`from AGENT` here, or `to {}` on a running sender), or run a function that needs none there; {}",
            a.name,
            state_list(model, &states),
            a.name,
            got.join("; ")
        ))
        .with_witness(json!({
            "agent": a.name,
            "states": state_names(model, &states),
            "runs": runs(model, agent, &bare),
            "with_input": with_input,
        })),
    )
}

/// For each function the agent may run in a state where it has input, those states.
fn fed_functions(wirings: &[StateWiring], agent: AgentId) -> BTreeMap<usize, Vec<StateId>> {
    let mut fed: BTreeMap<usize, Vec<StateId>> = BTreeMap::new();
    for w in wirings.iter().filter(|w| w.has_input(agent)) {
        let running = w.actions[agent.index()].iter().flatten().filter(|a| a.mode == Mode::Running);
        for f in running.filter_map(|a| a.function) {
            let states = fed.entry(f).or_default();
            if !states.contains(&w.state) {
                states.push(w.state);
            }
        }
    }
    fed
}

fn sensor(model: &Model, wirings: &[StateWiring], agent: AgentId) -> Option<Diagnostic> {
    let bare = unlinked(wirings, agent, |w| w.has_output(agent));
    let d = report(model, agent, &bare, codes::SENSOR_WITHOUT_OUTPUT, "with its data going nowhere")?;
    let name = &model.agent(agent).name;
    let states: Vec<StateId> = bare.iter().map(|(w, _)| w.state).collect();
    Some(
        d.with_help(format!(
            "link a reader in {} (`to AGENT` here, or `from {name}` on a running reader), or make `{name}` `wait` there: a waiting sensor still reports its events",
            state_list(model, &states)
        ))
        .with_witness(json!({
            "agent": name,
            "states": state_names(model, &states),
            "runs": runs(model, agent, &bare),
        })),
    )
}

/// The diagnostic at the agent's name, with a label at every action involved.
fn report(
    model: &Model,
    agent: AgentId,
    bare: &[(&StateWiring, Vec<usize>)],
    code: &'static str,
    what: &str,
) -> Option<Diagnostic> {
    if bare.is_empty() {
        return None;
    }
    let a = model.agent(agent);
    let states: Vec<StateId> = bare.iter().map(|(w, _)| w.state).collect();
    let list = state_list(model, &states);
    let message = format!("{} `{}` runs {what} in {list}", a.kind.keyword(), a.name);
    let mut d = Diagnostic::warning(code, message, a.origin.file, a.origin.span, format!("runs {what} in {list}"));
    let mut actions: BTreeMap<Origin, (usize, Vec<StateId>)> = BTreeMap::new();
    for (w, functions) in bare {
        for (act, &f) in w.actions[agent.index()].iter().flatten().zip(functions) {
            actions.entry(act.origin).or_insert((f, Vec::new())).1.push(w.state);
        }
    }
    for (at, (f, states)) in actions {
        let label = format!("runs `{}` here, in {}", a.functions[f].name, state_list(model, &states));
        d = d.with_label(at.file, at.span, label);
    }
    Some(d)
}

/// Per state, the functions the agent may run there.
fn runs(model: &Model, agent: AgentId, bare: &[(&StateWiring, Vec<usize>)]) -> Map<String, Value> {
    let a = model.agent(agent);
    let name = |f: &usize| a.functions[*f].name.clone();
    bare.iter()
        .map(|(w, fs)| (model.state(w.state).name.clone(), json!(fs.iter().map(name).collect::<Vec<_>>())))
        .collect()
}

fn state_names(model: &Model, states: &[StateId]) -> Vec<String> {
    states.iter().map(|&s| model.state(s).name.clone()).collect()
}
