//! E0305: rules that, under one fixed working memory, keep changing the
//! state in a cycle (RS -> RO -> RS ...). With the memory fixed, each state
//! of the cycle activates the next rule and no rule of higher salience, so
//! the cascade never comes to rest.

use super::escape::{avoiding_in_state, Outcome};
use super::situation::Situation;
use super::transitions::{Edge, Transitions};
use crate::codes;
use crate::model::*;
use serde_json::json;
use situ_grammar::diag::Diagnostic;
use std::collections::{BTreeMap, BTreeSet, VecDeque};

/// The longest cycle looked for, in rules.
const MAX_CYCLE: usize = 6;
/// How many cycles of states are examined at most.
const MAX_CYCLES: usize = 10_000;
/// The search budget per cycle of states.
const BUDGET: usize = 5_000;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    let n = model.states.len();
    // The rules of each step `from -> to` (parallel edges collapsed).
    let mut steps: BTreeMap<(StateId, StateId), Vec<&Edge>> = BTreeMap::new();
    for e in &tr.edges {
        steps.entry((e.from, e.to)).or_default().push(e);
    }
    // The states with a step into each state, for the walks back below.
    let mut before: Vec<Vec<StateId>> = vec![Vec::new(); n];
    for &(from, to) in steps.keys() {
        before[to.index()].push(from);
    }
    let mut out = Vec::new();
    let mut reported: BTreeSet<BTreeSet<RuleId>> = BTreeSet::new();
    let mut cycles = 0;
    for start in model.state_ids() {
        // Distances back to `start` through states greater than it, to prune
        // paths that cannot close within MAX_CYCLE steps.
        let mut dist = vec![usize::MAX; n];
        dist[start.index()] = 0;
        let mut queue = VecDeque::from([start]);
        while let Some(v) = queue.pop_front() {
            for &from in &before[v.index()] {
                if from > start && dist[from.index()] == usize::MAX {
                    dist[from.index()] = dist[v.index()] + 1;
                    queue.push_back(from);
                }
            }
        }
        let mut path = vec![start];
        state_cycles(&steps, &dist, start, &mut path, &mut |states| {
            cycles += 1;
            if cycles > MAX_CYCLES {
                return;
            }
            if let Some((rules, d)) = examine_states(model, tr, &steps, states) {
                if reported.insert(rules) {
                    out.push(d);
                }
            }
        });
    }
    out
}

/// Calls `found` with every simple cycle of states through `path[0]` whose
/// other states are greater than it (so each cycle is found once).
fn state_cycles(
    steps: &BTreeMap<(StateId, StateId), Vec<&Edge>>,
    dist: &[usize],
    start: StateId,
    path: &mut Vec<StateId>,
    found: &mut dyn FnMut(&[StateId]),
) {
    let at = *path.last().expect("a path has a state");
    for &(_, to) in steps.range((at, StateId(0))..=(at, StateId(u32::MAX))).map(|(k, _)| k) {
        if to == start {
            found(path);
        } else if to > start
            && dist[to.index()] != usize::MAX
            // `path.len()` steps lead to `to` and `dist` more close the
            // cycle: at most MAX_CYCLE in all.
            && path.len() + dist[to.index()] <= MAX_CYCLE
            && !path.contains(&to)
        {
            path.push(to);
            state_cycles(steps, dist, start, path, found);
            path.pop();
        }
    }
}

/// Picks one rule per step of a cycle of states such that one memory makes
/// them all hold (depth first, meeting as it goes), then checks that no rule
/// of higher salience takes over.
fn examine_states(
    model: &Model,
    tr: &Transitions,
    steps: &BTreeMap<(StateId, StateId), Vec<&Edge>>,
    states: &[StateId],
) -> Option<(BTreeSet<RuleId>, Diagnostic)> {
    let hops: Vec<&Vec<&Edge>> =
        (0..states.len()).map(|i| &steps[&(states[i], states[(i + 1) % states.len()])]).collect();
    let mut chosen = Vec::new();
    let mut budget = BUDGET;
    let memory = Situation::states(model.state_ids().collect());
    choose(model, tr, &hops, memory, &mut chosen, &mut budget)
}

fn choose<'a>(
    model: &Model,
    tr: &Transitions,
    hops: &[&Vec<&'a Edge>],
    memory: Situation,
    chosen: &mut Vec<&'a Edge>,
    budget: &mut usize,
) -> Option<(BTreeSet<RuleId>, Diagnostic)> {
    if *budget == 0 {
        return None;
    }
    *budget -= 1;
    let Some((hop, rest)) = hops.split_first() else {
        let d = examine(model, tr, chosen, memory)?;
        return Some((chosen.iter().map(|e| e.rule).collect(), d));
    };
    for e in hop.iter() {
        let Ok(mut sit) = tr.situations[e.rule.index()].clone() else { continue };
        sit.states = memory.states.clone();
        let Ok(next) = memory.meet(model, &sit) else { continue };
        chosen.push(e);
        if let Some(found) = choose(model, tr, rest, next, chosen, budget) {
            return Some(found);
        }
        chosen.pop();
    }
    None
}

fn examine(model: &Model, tr: &Transitions, cycle: &[&Edge], mut memory: Situation) -> Option<Diagnostic> {
    memory.states = BTreeSet::from([cycle[0].from]);
    // In each state of the cycle, no rule of higher salience may take over.
    let mut avoid: Vec<&Rule> = Vec::new();
    let mut avoided = vec![false; model.rules.len()];
    for e in cycle {
        let r = &model.rules[e.rule.index()];
        for (i, (h, sit)) in model.rules.iter().zip(&tr.situations).enumerate() {
            let allowed = sit.as_ref().is_ok_and(|s| s.states.contains(&e.from));
            // A rule of higher salience wins; one of equal salience may win on
            // specificity or recency: both must stay inactive for the cycle.
            let rival = h.salience > r.salience
                || (h.salience == r.salience
                    && !std::ptr::eq(h, r)
                    && h.target != r.target
                    && h.specificity() >= r.specificity());
            if rival && allowed && h.target != e.from && !avoided[i] {
                avoided[i] = true;
                avoid.push(h);
            }
        }
    }
    let mut budget = BUDGET;
    let Outcome::Found(witness) = avoiding_in_state(model, &memory, &avoid, &mut budget) else { return None };
    let first = &model.rules[cycle[0].rule.index()];
    let mut states: Vec<&str> = cycle.iter().map(|e| model.state(e.from).name.as_str()).collect();
    states.push(model.state(cycle[0].from).name.as_str());
    let names: Vec<&str> = cycle.iter().map(|e| model.rules[e.rule.index()].name.as_str()).collect();
    let mut d = Diagnostic::error(
        codes::OSCILLATION,
        format!(
            "rules {} oscillate: {}",
            names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", "),
            states.join(" -> ")
        ),
        first.origin.file,
        first.origin.span,
        format!("{} -> {}", model.state(cycle[0].from).name, model.state(cycle[0].to).name),
    );
    for e in &cycle[1..] {
        let r = &model.rules[e.rule.index()];
        d = d.with_label(
            r.origin.file,
            r.origin.span,
            format!("{} -> {}", model.state(e.from).name, model.state(e.to).name),
        );
    }
    let memory_text = witness.describe();
    let memory_text = memory_text.split_once(" with ").map_or("no facts".to_string(), |(_, f)| f.to_string());
    Some(
        d.with_help(format!(
            "with {memory_text} the state never comes to rest; make one rule's conditions exclude another's (e.g. require an event the other rules' memory cannot have)"
        ))
        .with_witness(json!({ "cycle": states, "rules": names, "memory": witness.json })),
    )
}
