//! W0318: agents that feed each other data in a cycle, in the wiring graph
//! of some state: a strongly connected component of more than one agent.
//! Only links present whatever the FSMs' history count.

use super::{state_list, StateWiring};
use crate::codes;
use crate::model::{AgentId, Model, Origin, StateId};
use petgraph::algo::tarjan_scc;
use petgraph::graph::DiGraph;
use serde_json::json;
use situ_grammar::diag::Diagnostic;
use std::collections::{BTreeMap, VecDeque};

pub fn check(model: &Model, wirings: &[StateWiring]) -> Vec<Diagnostic> {
    // Each distinct set of agents once, with the states where it cycles.
    let mut found: BTreeMap<Vec<AgentId>, (Vec<StateId>, &StateWiring)> = BTreeMap::new();
    for w in wirings {
        for agents in components(model, w) {
            found.entry(agents).or_insert((Vec::new(), w)).0.push(w.state);
        }
    }
    found.into_iter().map(|(agents, (states, w))| diagnostic(model, &agents, &states, w)).collect()
}

/// The components of more than one agent, each sorted.
fn components(model: &Model, w: &StateWiring) -> Vec<Vec<AgentId>> {
    let mut g = DiGraph::<AgentId, ()>::new();
    let nodes: Vec<_> = (0..model.agents.len() as u32).map(|i| g.add_node(AgentId(i))).collect();
    for &(a, b) in w.must.keys() {
        g.add_edge(nodes[a.index()], nodes[b.index()], ());
    }
    let sccs = tarjan_scc(&g).into_iter().filter(|c| c.len() > 1);
    sccs.map(|c| {
        let mut agents: Vec<AgentId> = c.iter().map(|&n| g[n]).collect();
        agents.sort();
        agents
    })
    .collect()
}

/// A closed walk through every agent of the component, from the first:
/// `A -> B -> C -> A`.
fn walk(w: &StateWiring, agents: &[AgentId]) -> Vec<AgentId> {
    let mut path = vec![agents[0]];
    for &next in agents[1..].iter().chain(&agents[..1]) {
        if next != agents[0] && path.contains(&next) {
            continue;
        }
        let from = *path.last().expect("the walk starts with an agent");
        path.extend(shortest(w, agents, from, next).into_iter().skip(1));
    }
    path
}

/// A shortest path inside the component, both ends included (`from` and
/// `to` may be the same agent: then a shortest cycle through it).
fn shortest(w: &StateWiring, agents: &[AgentId], from: AgentId, to: AgentId) -> Vec<AgentId> {
    let mut pred: BTreeMap<AgentId, AgentId> = BTreeMap::new();
    let mut queue = VecDeque::from([from]);
    while let Some(a) = queue.pop_front() {
        for &(_, b) in w.must.keys().filter(|(x, y)| *x == a && agents.contains(y)) {
            if b == to {
                let mut path = vec![to, a];
                while let Some(&p) = pred.get(&path[path.len() - 1]) {
                    path.push(p);
                }
                path.reverse();
                return path;
            }
            if b != from && !pred.contains_key(&b) {
                pred.insert(b, a);
                queue.push_back(b);
            }
        }
    }
    vec![from, to] // not reached: the component is strongly connected
}

fn diagnostic(model: &Model, agents: &[AgentId], states: &[StateId], w: &StateWiring) -> Diagnostic {
    let path = walk(w, agents);
    let name = |a: AgentId| model.agent(a).name.clone();
    let cycle = path.iter().map(|&a| name(a)).collect::<Vec<_>>().join(" -> ");
    // Each action that writes a link of the walk, with the links it writes.
    let mut writers: Vec<(Origin, Vec<String>)> = Vec::new();
    for pair in path.windows(2) {
        let origin = w.must[&(pair[0], pair[1])][0];
        let link = format!("`{} -> {}`", name(pair[0]), name(pair[1]));
        match writers.iter_mut().find(|(o, _)| *o == origin) {
            Some((_, links)) if !links.contains(&link) => links.push(link),
            Some(_) => {}
            None => writers.push((origin, vec![link])),
        }
    }
    let list = state_list(model, states);
    let (first, rest) = writers.split_first().expect("a cycle has a link");
    let mut d = Diagnostic::warning(
        codes::DATA_CYCLE,
        format!("data cycle `{cycle}` in {list}"),
        first.0.file,
        first.0.span,
        format!("writes {}", first.1.join(", ")),
    );
    for (origin, links) in rest {
        d = d.with_label(origin.file, origin.span, format!("writes {}", links.join(", ")));
    }
    let (a, b) = (path[0], path[1]);
    let writer = if w.actions[a.index()].iter().flatten().any(|x| x.origin == first.0) { a } else { b };
    d.with_help(format!(
        "data should flow from sensors to actuators: drop one of these links in {list}; if the feedback is meant, put `#[allow(W0318)]` on `{}`",
        name(writer)
    ))
    .with_witness(json!({
        "agents": agents.iter().map(|&a| name(a)).collect::<Vec<_>>(),
        "cycle": cycle,
        "states": states.iter().map(|&s| model.state(s).name.clone()).collect::<Vec<_>>(),
    }))
}
