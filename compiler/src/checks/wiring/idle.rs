//! W0315: a running agent's link names an agent that takes no part in the
//! data flow in that state: data into the void. `to Y` when Y sleeps (a
//! sleeping agent drops its data; a waiting one receives it, §10.6), and
//! `from X` when X sleeps or waits (neither sends data).

use super::{state_list, StateWiring};
use crate::checks::behaviour::links;
use crate::codes;
use crate::model::{Action, AgentId, Model, Origin, StateId};
use serde_json::{json, Map, Value};
use situ_grammar::ast::Mode;
use situ_grammar::diag::Diagnostic;
use std::collections::BTreeMap;

type Link = (AgentId, AgentId);

/// One link of one action into the void, in the states where it is.
struct Finding {
    agent: AgentId,
    other: AgentId,
    states: Vec<StateId>,
    modes: Map<String, Value>,
    /// Where the other agent's mode in those states comes from.
    why: BTreeMap<Origin, (String, Vec<StateId>)>,
}

pub fn check(model: &Model, wirings: &[StateWiring]) -> Vec<Diagnostic> {
    let mut found: BTreeMap<(Origin, Link), Finding> = BTreeMap::new();
    for w in wirings {
        for agent in (0..model.agents.len() as u32).map(AgentId) {
            for (origin, link) in void_links(w, agent) {
                let other = if link.0 == agent { link.1 } else { link.0 };
                let f = found.entry((origin, link)).or_insert_with(|| Finding {
                    agent,
                    other,
                    states: Vec::new(),
                    modes: Map::new(),
                    why: BTreeMap::new(),
                });
                f.states.push(w.state);
                f.modes.insert(model.state(w.state).name.clone(), json!(w.mode_text(other)));
                for (at, text) in why_idle(model, w, other) {
                    f.why.entry(at).or_insert((text, Vec::new())).1.push(w.state);
                }
            }
        }
    }
    found.into_iter().map(|((origin, link), f)| diagnostic(model, origin, link, f)).collect()
}

/// The links of the agent's action that go into the void in this state,
/// with the action that writes them; only when every action the agent may
/// have here is running and writes the link.
fn void_links(w: &StateWiring, agent: AgentId) -> Vec<(Origin, Link)> {
    if !w.surely(agent, |m| m == Mode::Running) {
        return Vec::new();
    }
    let actions: Vec<&Action> = w.actions[agent.index()].iter().flatten().map(|a| a.as_ref()).collect();
    let mut out = Vec::new();
    for action in &actions {
        for link in links(agent, action) {
            let always = actions.iter().all(|b| links(agent, b).contains(&link));
            let void = if link.0 == agent {
                w.surely(link.1, |m| m == Mode::Sleeping)
            } else {
                w.surely(link.0, |m| m != Mode::Running)
            };
            if always && void {
                out.push((action.origin, link));
            }
        }
    }
    out
}

/// Where the other agent's mode in this state is written, and what it is.
fn why_idle(model: &Model, w: &StateWiring, other: AgentId) -> Vec<(Origin, String)> {
    let name = &model.agent(other).name;
    w.actions[other.index()]
        .iter()
        .map(|a| match a {
            Some(a) => (a.origin, format!("`{name}` {}s here", a.mode.verb())),
            None => (model.agent(other).origin, format!("`{name}` has no table entry, so it sleeps")),
        })
        .collect()
}

fn diagnostic(model: &Model, origin: Origin, link: Link, f: Finding) -> Diagnostic {
    let (agent, other) = (&model.agent(f.agent).name, &model.agent(f.other).name);
    let states = state_list(model, &f.states);
    let sends = link.0 == f.agent;
    let (message, label, help) = if sends {
        (
            format!("`{agent}` sends data to `{other}`, which sleeps in {states}"),
            format!("sends to `{other}`"),
            format!(
                "wake `{other}` in {states} (`run`, or `wait`: a waiting agent receives data), or do not send to it there"
            ),
        )
    } else {
        (
            format!("`{agent}` reads from `{other}`, which does not run in {states}"),
            format!("reads from `{other}`"),
            format!(
                "make `{other}` run in {states}, or do not read from it there: a sleeping agent sends nothing and a waiting agent's data outputs are dropped"
            ),
        )
    };
    let mut d = Diagnostic::warning(codes::LINK_TO_IDLE, message, origin.file, origin.span, label);
    for (at, (text, states)) in &f.why {
        d = d.with_label(at.file, at.span, format!("{text} (in {})", state_list(model, states)));
    }
    let names = |s: &[StateId]| s.iter().map(|&x| model.state(x).name.clone()).collect::<Vec<_>>();
    d.with_help(help).with_witness(json!({
        "agent": agent,
        "link": format!("{} -> {}", model.agent(link.0).name, model.agent(link.1).name),
        "states": names(&f.states),
        "mode_of_other": f.modes,
    }))
}
