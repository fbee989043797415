//! E0305: rules that, under one fixed working memory, keep changing the
//! state in a cycle (RS -> RO -> RS ...). With the memory fixed, each state
//! of the cycle activates the next rule and no rule of higher salience, so
//! the cascade never comes to rest.
//!
//! Cycles only lie inside a strongly connected component of the state
//! graph, so the search walks each component alone. It extends a path of
//! states one rule at a time and meets the rules' conditions as it goes
//! (a path whose rules cannot hold together is dropped at once); a path
//! back to its first state is then examined for rules of higher salience.
//! Short cycles can still be exponentially many: the search counts its work
//! (rules tried, branches of the searches for a memory) and stops at
//! [`WORK`], saying so with W0321 — never a silent "no oscillation".

use super::budget;
use super::escape::{avoiding_in_state, Outcome};
use super::situation::Situation;
use super::transitions::{Edge, Transitions};
use crate::codes;
use crate::model::*;
use petgraph::algo::tarjan_scc;
use petgraph::graph::DiGraph;
use serde_json::json;
use situ_grammar::diag::Diagnostic;
use std::collections::{BTreeMap, BTreeSet, VecDeque};

/// The longest cycle looked for, in rules.
const MAX_CYCLE: usize = 6;
/// The work of the whole check: rules tried on a path plus the branches of
/// the searches for a memory that no rival activates.
pub const WORK: usize = 200_000;
/// The search budget for one cycle's memory (branches).
const BUDGET: usize = 5_000;
/// The oscillations reported at most: the search stops at the last, as at
/// the end of its work (a rule base with more is rewritten anyway, and
/// each finding costs a witness).
pub const MAX_FOUND: usize = 1_000;
/// The undecided cycles named in the note's witness at most.
const MAX_UNDECIDED_SHOWN: usize = 10;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    check_within(model, tr, WORK).0
}

/// The check with a given work budget; also returns the work done.
pub fn check_within(model: &Model, tr: &Transitions, work: usize) -> (Vec<Diagnostic>, usize) {
    let mut search = Search::new(model, tr, work);
    let component = components(model, &search.before);
    for start in model.state_ids() {
        if component[start.index()].is_none() {
            continue;
        }
        search.from(start, &component);
        if search.stopped_at.is_some() {
            break;
        }
    }
    let used = work - search.work;
    let full = search.found.len() >= MAX_FOUND;
    let mut out = search.found;
    let undecided = (&search.undecided[..], search.undecided_count);
    if let Some(note) = incomplete(model, search.stopped_at, full, undecided, work) {
        out.push(note);
    }
    (out, used)
}

/// Per state, the index of its strongly connected component when that
/// component has a cycle (more than one state: edges never loop).
fn components(model: &Model, before: &[Vec<StateId>]) -> Vec<Option<usize>> {
    let mut g = DiGraph::<(), ()>::new();
    let nodes: Vec<_> = model.state_ids().map(|_| g.add_node(())).collect();
    for (to, froms) in before.iter().enumerate() {
        for from in froms {
            g.add_edge(nodes[from.index()], nodes[to], ());
        }
    }
    let mut component = vec![None; model.states.len()];
    for (i, c) in tarjan_scc(&g).into_iter().filter(|c| c.len() > 1).enumerate() {
        for n in c {
            component[n.index()] = Some(i);
        }
    }
    component
}

struct Search<'a> {
    model: &'a Model,
    tr: &'a Transitions,
    /// Per state, the states one step on, in order, each with the rules of
    /// that step (parallel edges collapsed).
    after: Vec<Vec<(StateId, Vec<&'a Edge>)>>,
    /// Per state, the states one step before.
    before: Vec<Vec<StateId>>,
    /// Per state, the rules that can be activated in it, in order.
    allowed_in: Vec<Vec<usize>>,
    /// Work left.
    work: usize,
    /// The state whose cycles were being searched when the work ran out.
    stopped_at: Option<StateId>,
    /// The first cycles whose memory search ran out of its budget, and
    /// how many there were.
    undecided: Vec<Vec<&'a Edge>>,
    undecided_count: usize,
    found: Vec<Diagnostic>,
    reported: BTreeSet<BTreeSet<RuleId>>,
    /// Cycles of states with a finding: one per cycle of states.
    cycles_reported: BTreeSet<Vec<StateId>>,
}

impl<'a> Search<'a> {
    fn new(model: &'a Model, tr: &'a Transitions, work: usize) -> Self {
        let mut steps: BTreeMap<(StateId, StateId), Vec<&Edge>> = BTreeMap::new();
        for e in &tr.edges {
            steps.entry((e.from, e.to)).or_default().push(e);
        }
        let mut after = vec![Vec::new(); model.states.len()];
        let mut before = vec![Vec::new(); model.states.len()];
        for ((from, to), edges) in steps {
            after[from.index()].push((to, edges));
            before[to.index()].push(from);
        }
        let mut allowed_in = vec![Vec::new(); model.states.len()];
        for (i, sit) in tr.situations.iter().enumerate() {
            if let Ok(sit) = sit {
                for s in &sit.states {
                    allowed_in[s.index()].push(i);
                }
            }
        }
        Search {
            model,
            tr,
            after,
            before,
            allowed_in,
            work,
            stopped_at: None,
            undecided: Vec::new(),
            undecided_count: 0,
            found: Vec::new(),
            reported: BTreeSet::new(),
            cycles_reported: BTreeSet::new(),
        }
    }

    /// Spends `units` of work; false (and the search stops at `at`) when
    /// there are not that many left.
    fn spend(&mut self, units: usize, at: StateId) -> bool {
        if self.work < units {
            self.work = 0;
            self.stopped_at.get_or_insert(at);
            return false;
        }
        self.work -= units;
        true
    }

    /// Every cycle through `start` whose other states are greater than it
    /// and in its component (so each cycle is found once).
    fn from(&mut self, start: StateId, component: &[Option<usize>]) {
        let n = self.model.states.len();
        // Distances back to `start` through states greater than it, to prune
        // paths that cannot close within MAX_CYCLE steps.
        let mut dist = vec![usize::MAX; n];
        dist[start.index()] = 0;
        let mut queue = VecDeque::from([start]);
        while let Some(v) = queue.pop_front() {
            for &from in &self.before[v.index()] {
                if from > start
                    && component[from.index()] == component[start.index()]
                    && dist[from.index()] == usize::MAX
                {
                    dist[from.index()] = dist[v.index()] + 1;
                    queue.push_back(from);
                }
            }
        }
        // The state is the walk's business: the memory is kept in `start`
        // (one state, cheap to meet) and set to the cycle's first state to
        // examine it.
        let memory = Situation::states(BTreeSet::from([start]));
        self.walk(&dist, &mut vec![start], &mut Vec::new(), memory);
    }

    /// Extends the path by one rule in every way that keeps the rules'
    /// conditions able to hold together; examines each path that closes.
    fn walk(&mut self, dist: &[usize], path: &mut Vec<StateId>, chosen: &mut Vec<&'a Edge>, memory: Situation) {
        let start = path[0];
        let at = *path.last().expect("a path has a state");
        for k in 0..self.after[at.index()].len() {
            let to = self.after[at.index()][k].0;
            let closes = to == start;
            let extends = to > start
                && dist[to.index()] != usize::MAX
                // `path.len()` steps lead to `to` and `dist` more close the
                // cycle: at most MAX_CYCLE in all.
                && path.len() + dist[to.index()] <= MAX_CYCLE
                && !path.contains(&to);
            if !closes && !extends {
                continue;
            }
            for j in 0..self.after[at.index()][k].1.len() {
                let e: &'a Edge = self.after[at.index()][k].1[j];
                if closes && self.cycles_reported.contains(path) {
                    break;
                }
                if !self.spend(1, start) {
                    return;
                }
                let Ok(mut sit) = self.tr.situations[e.rule.index()].clone() else { continue };
                sit.states = memory.states.clone();
                let Ok(next) = memory.meet(self.model, &sit) else { continue };
                chosen.push(e);
                if closes {
                    self.close(chosen, path, next);
                } else {
                    path.push(to);
                    self.walk(dist, path, chosen, next);
                    path.pop();
                }
                chosen.pop();
                if self.stopped_at.is_some() {
                    return;
                }
            }
        }
    }

    fn close(&mut self, chosen: &[&'a Edge], path: &[StateId], memory: Situation) {
        let rules: BTreeSet<RuleId> = chosen.iter().map(|e| e.rule).collect();
        if self.reported.contains(&rules) {
            return;
        }
        let mut budget = BUDGET;
        let outcome = self.examine(chosen, memory, &mut budget);
        if !self.spend(BUDGET - budget, path[0]) {
            return;
        }
        match outcome {
            Some(Ok(d)) => {
                self.reported.insert(rules);
                self.cycles_reported.insert(path.to_vec());
                self.found.push(d);
                if self.found.len() >= MAX_FOUND {
                    self.stopped_at = Some(path[0]);
                }
            }
            Some(Err(())) => {
                self.undecided_count += 1;
                if self.undecided.len() < MAX_UNDECIDED_SHOWN {
                    self.undecided.push(chosen.to_vec());
                }
            }
            None => {}
        }
    }

    /// The finding for a cycle of rules whose conditions hold together, if
    /// a memory activates no rival in any of its states; `Err` when the
    /// search for one ran out of its budget.
    fn examine(&self, cycle: &[&Edge], mut memory: Situation, budget: &mut usize) -> Option<Result<Diagnostic, ()>> {
        let model = self.model;
        memory.states = BTreeSet::from([cycle[0].from]);
        // In each state of the cycle, no rule of higher salience may take over.
        let mut avoid: Vec<&Rule> = Vec::new();
        let mut avoided = BTreeSet::new();
        for e in cycle {
            let r = &model.rules[e.rule.index()];
            for &i in &self.allowed_in[e.from.index()] {
                let h = &model.rules[i];
                // A rule of higher salience wins; one of equal salience may win on
                // specificity or recency: both must stay inactive for the cycle.
                let rival = h.salience > r.salience
                    || (h.salience == r.salience
                        && !std::ptr::eq(h, r)
                        && h.target != r.target
                        && h.specificity() >= r.specificity());
                if rival && h.target != e.from && avoided.insert(i) {
                    avoid.push(h);
                }
            }
        }
        // Declaration order, as the rules were always tried.
        let mut order: Vec<(usize, &Rule)> = avoided.iter().copied().zip(avoid).collect();
        order.sort_by_key(|(i, _)| *i);
        let avoid: Vec<&Rule> = order.into_iter().map(|(_, r)| r).collect();
        let witness = match avoiding_in_state(model, &memory, &avoid, budget) {
            Outcome::Found(w) => w,
            Outcome::None => return None,
            Outcome::Unknown if *budget == 0 => return Some(Err(())),
            Outcome::Unknown => return None,
        };
        Some(Ok(finding(model, cycle, witness)))
    }
}

fn finding(model: &Model, cycle: &[&Edge], witness: super::situation::Witness) -> Diagnostic {
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
    d.with_help(format!(
        "with {memory_text} the state never comes to rest; make one rule's conditions exclude another's (e.g. require an event the other rules' memory cannot have)"
    ))
    .with_witness(json!({ "cycle": states, "rules": names, "memory": witness.json }))
}

/// W0321 when the search did not decide everything: it ran out of work, or
/// some cycle's memory search ran out of its budget.
fn incomplete(
    model: &Model,
    stopped_at: Option<StateId>,
    full: bool,
    (undecided, undecided_count): (&[Vec<&Edge>], usize),
    work: usize,
) -> Option<Diagnostic> {
    let cycle_text = |c: &[&Edge]| {
        let mut s: Vec<&str> = c.iter().map(|e| model.state(e.from).name.as_str()).collect();
        s.push(model.state(c[0].from).name.as_str());
        s.join(" -> ")
    };
    let undecided_json: Vec<_> = undecided
        .iter()
        .map(|c| json!({ "cycle": cycle_text(c), "rules": c.iter().map(|e| model.rules[e.rule.index()].name.as_str()).collect::<Vec<_>>() }))
        .collect();
    if let Some(at) = stopped_at {
        let st = model.state(at);
        let (why, help) = if full {
            (
                format!("after {MAX_FOUND} oscillations"),
                format!("{MAX_FOUND} oscillations are reported at most; fix these and check again"),
            )
        } else {
            (
                "at its work budget".to_string(),
                format!("the rules' state graph has too many short cycles to examine them all ({work} steps of work); split the rule base, or make rules exclusive, to shrink the cycles"),
            )
        };
        let d = budget::stopped(
            codes::OSCILLATION,
            format!("the oscillation check (E0305) stopped {why} in the cycles through `{}`", st.name),
            st.origin,
            "cycles through this state and the states after it were not all examined",
            if at.index() == 0 {
                help
            } else {
                format!("{help}; the cycles through states declared before `{}` were all examined", st.name)
            },
            json!({ "stopped_at": st.name, "work": work, "oscillations_reported": full.then_some(MAX_FOUND), "undecided": undecided_json, "undecided_count": undecided_count }),
        );
        return Some(d);
    }
    let (first, _) = undecided.split_first()?;
    let rule = &model.rules[first[0].rule.index()];
    Some(budget::stopped(
        codes::OSCILLATION,
        format!(
            "the oscillation check (E0305) could not decide {} cycle{} of rules, first {}",
            undecided_count,
            if undecided_count == 1 { "" } else { "s" },
            cycle_text(first)
        ),
        rule.origin,
        "a cycle from here was not decided",
        format!("no memory that keeps the rivals of these rules inactive was found within {BUDGET} branches, nor was one ruled out"),
        json!({ "work": work, "undecided": undecided_json, "undecided_count": undecided_count }),
    ))
}
