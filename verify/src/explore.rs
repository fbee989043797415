//! Exhaustive exploration: the abstract state graph of a program, breadth
//! first from the initial system, then each property checked on it.
//!
//! 1. **The graph.** From the initial system (a node), every letter of the
//!    [`Alphabet`] after every gap is posted to a copy of the node's system
//!    (the real engine and organisation); the successor's abstract state
//!    ([`Alphabet::key`]) is a node, new or already seen. Gaps that age
//!    every fact alike are posted once. Nodes are expanded level by level
//!    up to `depth` events, and no more than `max_states` nodes are made.
//!    At each node the premise and consequent of every property are
//!    evaluated once.
//! 2. **The properties.** A property's monitor ([`Monitor`]) runs on the
//!    graph: breadth first over (node, monitor state) pairs, so the first
//!    violation found is on a shortest run. Unbounded `eventually` is
//!    decided on infinite runs: a reachable cycle of pairs along which the
//!    obligation stays pending is a counterexample (a lasso).
//!
//! The answer is **proved** when every node was expanded (the space is
//! closed) and the abstraction is exact; **exhausted** when closed but the
//! abstraction samples something (time gaps, linked values: it says which);
//! otherwise **bounded**: no counterexample among the runs that stay within
//! the nodes expanded (every run of up to `depth` events, at least).
//!
//! A bounded answer short of the depth asked for is made deeper by the
//! caller on the circuit ([`bmc::deepen`](super::bmc::deepen)).

use super::abstraction::Alphabet;
use super::monitor::{Monitor, MonitorState};
use super::{Counterexample, RunStep, System, Verdict};
use situ_compiler::bundle::Content;
use situ_compiler::spec::PropertySpec;
use situ_runtime::rete::PostError;
use std::collections::{HashMap, VecDeque};
use std::sync::Arc;

/// How far to explore.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// The most events from the start.
    pub depth: usize,
    /// The most abstract states.
    pub max_states: usize,
}

#[derive(Debug, Clone)]
pub(super) struct Node {
    pub(super) depth: u32,
    pub(super) expanded: bool,
    /// The rules did not come to rest here (a cascade): every run that
    /// reaches it fails.
    pub(super) error: Option<String>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Edge {
    pub(super) to: u32,
    pub(super) gap: u8,
    pub(super) letter: u32,
}

/// The explored abstract state graph.
pub struct Graph {
    content: Arc<Content>,
    pub alphabet: Alphabet,
    properties: usize,
    pub(super) nodes: Vec<Node>,
    /// Per node, its premise and consequent values, two bits per property.
    bits: Vec<bool>,
    pub(super) succ: Vec<(u32, u32)>,
    pub(super) edges: Vec<Edge>,
    /// Every node was expanded.
    pub closed: bool,
    /// Every run of up to this many events is in the graph.
    pub complete_depth: usize,
}

impl Graph {
    /// Explores the program for these properties.
    pub fn build(content: &Arc<Content>, properties: &[&PropertySpec], limits: Limits) -> Graph {
        let alphabet = Alphabet::new(content, properties);
        let mut g = Graph {
            content: content.clone(),
            alphabet,
            properties: properties.len(),
            nodes: Vec::new(),
            bits: Vec::new(),
            succ: Vec::new(),
            edges: Vec::new(),
            closed: false,
            complete_depth: 0,
        };
        let root = System::new(content.clone());
        let mut index: HashMap<Vec<u64>, u32> = HashMap::new();
        let mut key = Vec::new();
        g.alphabet.key(&root, &mut key);
        index.insert(key.clone(), 0);
        g.add_node(&root, properties, 0, None);
        let error_key = vec![u64::MAX - 2];
        let mut frontier = vec![(0u32, root)];
        let mut tmp = System::new(content.clone());
        let mut sig = Vec::new();
        let mut depth = 0usize;
        let mut truncated = false;
        'levels: while !frontier.is_empty() && depth < limits.depth {
            let mut next = Vec::new();
            for (id, sys) in &frontier {
                let start = g.edges.len();
                // Gaps grouped by how they age the facts.
                let mut classes: Vec<(Vec<u64>, Vec<u8>)> = Vec::new();
                for (k, &gap) in g.alphabet.gaps.iter().enumerate() {
                    g.alphabet.gap_signature(sys, gap, &mut sig);
                    match classes.iter_mut().find(|(s, _)| *s == sig) {
                        Some((_, ks)) => ks.push(k as u8),
                        None => classes.push((sig.clone(), vec![k as u8])),
                    }
                }
                for (_, ks) in &classes {
                    let gap = g.alphabet.gaps[ks[0] as usize];
                    for l in 0..g.alphabet.letters.len() {
                        let letter = &g.alphabet.letters[l];
                        tmp.copy_from(sys);
                        let time = sys.engine.now().saturating_add(gap);
                        let error = match tmp.post(letter.event, time, &letter.payload) {
                            Ok(_) => None,
                            Err(e @ PostError::Cascade { .. }) => Some(e.describe(content)),
                            Err(_) => continue,
                        };
                        if error.is_some() {
                            key.clone_from(&error_key);
                        } else {
                            g.alphabet.key(&tmp, &mut key);
                        }
                        let to = match index.get(&key) {
                            Some(&to) => to,
                            None => {
                                if g.nodes.len() >= limits.max_states {
                                    g.edges.truncate(start);
                                    truncated = true;
                                    break 'levels;
                                }
                                let to = g.nodes.len() as u32;
                                index.insert(key.clone(), to);
                                let is_error = error.is_some();
                                g.add_node(&tmp, properties, depth as u32 + 1, error);
                                if !is_error && depth + 1 < limits.depth {
                                    next.push((to, tmp.clone()));
                                }
                                to
                            }
                        };
                        for &k in ks {
                            g.edges.push(Edge { to, gap: k, letter: l as u32 });
                        }
                    }
                }
                // One edge per (successor, gap): the first letter that leads there.
                let mine = &mut g.edges[start..];
                mine.sort_by_key(|e| (e.to, e.gap, e.letter));
                let mut kept = start;
                for i in start..g.edges.len() {
                    let e = g.edges[i];
                    if kept == start || (g.edges[kept - 1].to, g.edges[kept - 1].gap) != (e.to, e.gap) {
                        g.edges[kept] = e;
                        kept += 1;
                    }
                }
                g.edges.truncate(kept);
                g.succ[*id as usize] = (start as u32, kept as u32);
                g.nodes[*id as usize].expanded = true;
            }
            frontier = next;
            depth += 1;
        }
        g.complete_depth = if truncated { depth } else { depth.min(limits.depth) };
        g.closed = !truncated && g.nodes.iter().all(|n| n.expanded || n.error.is_some());
        g
    }

    fn add_node(&mut self, sys: &System, properties: &[&PropertySpec], depth: u32, error: Option<String>) {
        for p in properties {
            let (a, b) = sys.point(p);
            self.bits.push(a);
            self.bits.push(b);
        }
        self.nodes.push(Node { depth, expanded: false, error });
        self.succ.push((0, 0));
    }

    /// The number of abstract states made.
    pub fn states(&self) -> usize {
        self.nodes.len()
    }

    /// The number of edges kept.
    pub fn edges(&self) -> usize {
        self.edges.len()
    }

    /// The deepest node.
    pub fn max_depth(&self) -> usize {
        self.nodes.iter().map(|n| n.depth as usize).max().unwrap_or(0)
    }

    pub(super) fn point(&self, node: u32, property: usize) -> (bool, bool) {
        let at = (node as usize * self.properties + property) * 2;
        (self.bits[at], self.bits[at + 1])
    }

    /// Checks property number `index` (in the list given to [`build`](Self::build)).
    pub fn check(&self, index: usize, property: &PropertySpec) -> Verdict {
        let monitor = Monitor::new(property);
        let mut st0 = MonitorState::default();
        let (p, q) = self.point(0, index);
        if let Some(reason) = monitor.step(&mut st0, p, q, 0) {
            return Verdict::Failed(Counterexample::replay(&self.content, &[], 0, reason));
        }
        // Breadth first over (node, monitor state).
        let mut seen: HashMap<(u32, MonitorState), u32> = HashMap::new();
        let mut pairs: Vec<(u32, MonitorState, u32, Option<Edge>)> = vec![(0, st0, u32::MAX, None)];
        seen.insert((0, st0), 0);
        let mut queue = VecDeque::from([0u32]);
        while let Some(i) = queue.pop_front() {
            let (n, st, _, _) = pairs[i as usize];
            let node = &self.nodes[n as usize];
            if !node.expanded {
                continue;
            }
            let (s, e) = self.succ[n as usize];
            for edge in &self.edges[s as usize..e as usize] {
                let mut st2 = st;
                let violation = match &self.nodes[edge.to as usize].error {
                    Some(why) => Some(why.clone()),
                    None => {
                        let (p, q) = self.point(edge.to, index);
                        monitor.step(&mut st2, p, q, self.alphabet.gaps[edge.gap as usize])
                    }
                };
                if let Some(reason) = violation {
                    let mut run = self.path(&pairs, i);
                    run.push(self.step_of(edge));
                    let point = run.len();
                    return Verdict::Failed(Counterexample::replay(&self.content, &run, point, reason));
                }
                if let std::collections::hash_map::Entry::Vacant(v) = seen.entry((edge.to, st2)) {
                    v.insert(pairs.len() as u32);
                    queue.push_back(pairs.len() as u32);
                    pairs.push((edge.to, st2, i, Some(*edge)));
                }
            }
        }
        if monitor.is_liveness() && !monitor.never {
            if let Some(v) = self.lasso(index, &monitor, &pairs, &seen) {
                return v;
            }
        }
        let mut note = self.alphabet.samples.join("; ");
        if self.closed {
            if self.alphabet.exact() {
                return Verdict::Proved { states: self.states() };
            }
            return Verdict::Exhausted { states: self.states(), note };
        }
        if note.is_empty() {
            note = "exact abstraction".into();
        }
        Verdict::Bounded { depth: self.complete_depth, states: self.states(), note }
    }

    /// A cycle of pairs along which the obligation stays pending, reached
    /// from the start: an infinite run on which the consequent never comes.
    fn lasso(
        &self,
        index: usize,
        monitor: &Monitor,
        pairs: &[(u32, MonitorState, u32, Option<Edge>)],
        seen: &HashMap<(u32, MonitorState), u32>,
    ) -> Option<Verdict> {
        // Pending pairs at expanded nodes, with their pending successors.
        let mut alive: HashMap<u32, Vec<(u32, Edge)>> = HashMap::new();
        for (i, &(n, st, _, _)) in pairs.iter().enumerate() {
            if st.pending && self.nodes[n as usize].expanded {
                alive.insert(i as u32, Vec::new());
            }
        }
        let keys: Vec<u32> = alive.keys().copied().collect();
        for i in keys {
            let (n, st, _, _) = pairs[i as usize];
            let (s, e) = self.succ[n as usize];
            let mut next = Vec::new();
            for edge in &self.edges[s as usize..e as usize] {
                let mut st2 = st;
                let (p, q) = self.point(edge.to, index);
                let _ = monitor.step(&mut st2, p, q, self.alphabet.gaps[edge.gap as usize]);
                if st2.pending && self.nodes[edge.to as usize].error.is_none() {
                    if let Some(&j) = seen.get(&(edge.to, st2)) {
                        next.push((j, *edge));
                    }
                }
            }
            alive.insert(i, next);
        }
        // Remove pairs without a pending successor left, until none is removed.
        loop {
            let dead: Vec<u32> = alive.iter().filter(|(_, v)| v.is_empty()).map(|(&i, _)| i).collect();
            if dead.is_empty() {
                break;
            }
            for d in &dead {
                alive.remove(d);
            }
            for v in alive.values_mut() {
                v.retain(|(j, _)| !dead.contains(j));
            }
        }
        let start = *alive.keys().min()?;
        // Walk until a pair repeats: the cycle.
        let mut walk = vec![start];
        let mut edges = Vec::new();
        loop {
            let at = *walk.last()?;
            let (j, edge) = *alive.get(&at)?.first()?;
            edges.push(edge);
            if let Some(k) = walk.iter().position(|&w| w == j) {
                let mut run = self.path(pairs, walk[k]);
                let prefix = run.len();
                run.extend(edges[k..].iter().map(|e| self.step_of(e)));
                let reason = format!(
                    "the premise held and the consequent never comes: events {} to {} repeat forever",
                    prefix + 1,
                    run.len()
                );
                let point = run.len();
                return Some(Verdict::Failed(Counterexample::replay(&self.content, &run, point, reason)));
            }
            walk.push(j);
        }
    }

    fn step_of(&self, e: &Edge) -> RunStep {
        let l = &self.alphabet.letters[e.letter as usize];
        RunStep { event: l.event, payload: l.payload.clone(), gap: self.alphabet.gaps[e.gap as usize] }
    }

    /// The run that leads to pair `i`.
    fn path(&self, pairs: &[(u32, MonitorState, u32, Option<Edge>)], mut i: u32) -> Vec<RunStep> {
        let mut out = Vec::new();
        while let Some(e) = pairs[i as usize].3 {
            out.push(self.step_of(&e));
            i = pairs[i as usize].2;
        }
        out.reverse();
        out
    }
}
