//! The explorer that drives `situ run FILE --random SEED`: the guided
//! generator of [`crate::stream`] steered, in closed loop, by the state the
//! running stack is really in, towards the states it has visited least.
//!
//! - **Episodes.** A final state ends an episode; the run then goes on with
//!   a new one from the initial state ([`crate::sched::SimRuntime::restart`])
//!   until its end, so that a file whose missions end fast (an abort in the
//!   first second) is still explored. The report counts the episodes.
//! - **The map.** From the compiled bundle: the rules that can fire in each
//!   state (their `state` guard; a rule without one, in every state), their
//!   targets, and so the static graph of the states, where a final state
//!   leads to the initial one (the next episode). The states it reaches
//!   from the initial one are the *reachable* states the report counts
//!   (an over-approximation: a rule's events may never all hold).
//! - **The goal.** In each state the explorer picks a rule that can fire
//!   there, weighting each by its target's distance in the graph to the
//!   nearest least-visited state (each step away a quarter as likely; a
//!   state not yet visited is least visited), and keeps it until the state
//!   changes or [`GOAL_NS`] passes (longer when the rule waits for an agent
//!   to go stale). Half the events are the goal's: one of its patterns,
//!   with a payload that passes the pattern's tests; repeated, they build
//!   its runs (`x3`) and conjunctions.
//! - **The background.** The other half come from the agents in proportion
//!   to their rates, as in `situ bench`'s stream, so that the agents stay
//!   fresh; a draw that a rule leading away from the least-visited states
//!   (or the goal's wait for a stale agent) would take is drawn again, up
//!   to [`REDRAWS`] times, else that slot has no event.
//!
//! Nothing reads a clock: one file and seed give the same run.

use super::timeline::{Due, MAX_RANDOM_EVENTS};
use crate::rete::passes;
use crate::stream::Generator;
use rand::RngExt;
use serde::Serialize;
use situ_bundle::{AlphaNode, BetaKind, Content, Value};
use std::collections::VecDeque;
use std::sync::Arc;

/// How long a goal is kept when the state does not change (ns).
pub const GOAL_NS: u64 = 2_000_000_000;

/// The share of events that serve the goal.
const GOAL_SHARE: f64 = 0.5;

/// Background draws before a slot is left empty.
const REDRAWS: usize = 4;

/// What the rules say of the states, for steering.
#[derive(Debug, Clone)]
pub struct Map {
    /// Per state, the rules that can fire in it (their target elsewhere).
    pub from: Vec<Vec<u32>>,
    /// Per state, the states its rules lead to; a final state's: the initial one.
    pub edges: Vec<Vec<u32>>,
    /// Per rule, the agents it needs stale.
    pub stale: Vec<Vec<u32>>,
    /// The states the graph reaches from the initial one.
    pub reachable: Vec<bool>,
}

impl Map {
    pub fn new(content: &Content) -> Map {
        let n = content.states.len();
        let net = &content.network;
        let mut from = vec![Vec::new(); n];
        let mut stale = vec![Vec::new(); content.rules.len()];
        for t in &net.terminals {
            let mut guard: Option<&[u32]> = None;
            let mut at = Some(t.beta);
            while let Some(b) = at {
                let node = &net.beta[b as usize];
                match &net.alpha[node.alpha as usize] {
                    AlphaNode::State { states } => guard = Some(states),
                    AlphaNode::Stale { agent } if node.kind == BetaKind::Join => stale[t.rule as usize].push(*agent),
                    _ => {}
                }
                at = node.parent;
            }
            let target = content.rules[t.rule as usize].target;
            let states: Vec<u32> = guard.map_or_else(|| (0..n as u32).collect(), <[u32]>::to_vec);
            for s in states {
                if s != target && !content.states[s as usize].is_final {
                    from[s as usize].push(t.rule);
                }
            }
        }
        let edges: Vec<Vec<u32>> = (0..n)
            .map(|s| {
                if content.states[s].is_final {
                    return vec![content.initial];
                }
                let mut e: Vec<u32> = from[s].iter().map(|&r| content.rules[r as usize].target).collect();
                e.sort_unstable();
                e.dedup();
                e
            })
            .collect();
        let mut reachable = vec![false; n];
        reachable[content.initial as usize] = true;
        let mut queue = VecDeque::from([content.initial]);
        while let Some(s) = queue.pop_front() {
            for &t in &edges[s as usize] {
                if !reachable[t as usize] {
                    reachable[t as usize] = true;
                    queue.push_back(t);
                }
            }
        }
        Map { from, edges, stale, reachable }
    }

    /// Per state, the rules' steps to the nearest of `targets` (`u32::MAX`: none).
    pub fn distances(&self, targets: &[bool]) -> Vec<u32> {
        let n = self.edges.len();
        let mut into = vec![Vec::new(); n];
        for (s, e) in self.edges.iter().enumerate() {
            for &t in e {
                into[t as usize].push(s as u32);
            }
        }
        let mut d = vec![u32::MAX; n];
        let mut queue = VecDeque::new();
        for s in 0..n {
            if targets[s] {
                d[s] = 0;
                queue.push_back(s as u32);
            }
        }
        while let Some(s) = queue.pop_front() {
            for &p in &into[s as usize] {
                if d[p as usize] == u32::MAX {
                    d[p as usize] = d[s as usize] + 1;
                    queue.push_back(p);
                }
            }
        }
        d
    }
}

/// How much of the rules a run explored.
#[derive(Debug, Clone, Default, PartialEq, Eq, Serialize)]
pub struct Coverage {
    /// Episodes begun (a final state ends one; the next starts at once).
    pub episodes: u64,
    /// The reachable states visited at rest, in the order of the rules' `states`.
    pub visited: Vec<String>,
    /// The states of the rules' graph reachable from the initial one.
    pub reachable: Vec<String>,
}

impl Coverage {
    /// `episodes: E, states visited: V of R reachable (P %)`.
    pub fn line(&self) -> String {
        let (v, r) = (self.visited.len(), self.reachable.len());
        let pct = if r > 0 { v as f64 / r as f64 * 100.0 } else { 100.0 };
        format!("episodes: {}, states visited: {v} of {r} reachable ({pct:.0} %)", self.episodes)
    }
}

struct Goal {
    rule: u32,
    until: u64,
}

/// The closed-loop generator of a `--random` run.
pub struct Explorer {
    content: Arc<Content>,
    generator: Generator,
    map: Map,
    visits: Vec<u64>,
    /// Per state, the steps to the nearest least-visited reachable state.
    distance: Vec<u32>,
    state: u32,
    goal: Option<Goal>,
    episodes: u64,
    now: u64,
    end: u64,
    slots: u64,
}

impl Explorer {
    /// An explorer of the rules from time 0 to `end` (ns), with this seed.
    pub fn new(content: Arc<Content>, seed: u64, end: u64) -> Explorer {
        let map = Map::new(&content);
        let n = content.states.len();
        let mut x = Explorer {
            generator: Generator::new(content.clone(), seed),
            state: content.initial,
            content,
            map,
            visits: vec![0; n],
            distance: vec![0; n],
            goal: None,
            episodes: 1,
            now: 0,
            end,
            slots: 0,
        };
        x.visit(x.state);
        x
    }

    /// The state at rest became `state`.
    pub fn visit(&mut self, state: u32) {
        self.state = state;
        self.goal = None;
        self.visits[state as usize] += 1;
        let least = (0..self.visits.len()).filter(|&s| self.map.reachable[s]).map(|s| self.visits[s]).min();
        let targets: Vec<bool> =
            (0..self.visits.len()).map(|s| self.map.reachable[s] && Some(self.visits[s]) == least).collect();
        self.distance = self.map.distances(&targets);
    }

    /// A final state ended the episode; the next one began in `state` (the initial one).
    pub fn new_episode(&mut self, state: u32) {
        self.episodes += 1;
        self.visit(state);
    }

    pub fn coverage(&self) -> Coverage {
        let names = |keep: &dyn Fn(usize) -> bool| -> Vec<String> {
            (0..self.visits.len()).filter(|&s| keep(s)).map(|s| self.content.states[s].name.clone()).collect()
        };
        Coverage {
            episodes: self.episodes,
            visited: names(&|s| self.map.reachable[s] && self.visits[s] > 0),
            reachable: names(&|s| self.map.reachable[s]),
        }
    }

    /// How strongly a move to `target` is wanted.
    fn weight(&self, target: u32) -> f64 {
        0.25f64.powi(self.distance[target as usize].min(30) as i32)
    }

    fn pick_goal(&mut self) {
        let rules = &self.map.from[self.state as usize];
        let total: f64 = rules.iter().map(|&r| self.weight(self.content.rules[r as usize].target)).sum();
        if rules.is_empty() || total <= 0.0 {
            self.goal = None;
            return;
        }
        let mut pick = self.generator.rng().random::<f64>() * total;
        let mut rule = rules[rules.len() - 1];
        for &r in rules {
            pick -= self.weight(self.content.rules[r as usize].target);
            if pick < 0.0 {
                rule = r;
                break;
            }
        }
        let wait = self.map.stale[rule as usize]
            .iter()
            .filter_map(|&a| self.content.agents[a as usize].stale_after_ns)
            .max()
            .map_or(0, |s| s.saturating_add(GOAL_NS / 4));
        self.goal = Some(Goal { rule, until: self.now.saturating_add(GOAL_NS.max(wait)) });
    }

    /// Whether a background event would serve a rule that leads away from
    /// the least-visited states, or break the goal's wait for a stale agent.
    fn unwanted(&self, event: u32, payload: &[Value]) -> bool {
        let agent = self.content.events[event as usize].agent;
        if let Some(g) = &self.goal {
            if self.map.stale[g.rule as usize].contains(&agent) {
                return true;
            }
        }
        let here = self.distance[self.state as usize];
        self.map.from[self.state as usize].iter().any(|&r| {
            let target = self.content.rules[r as usize].target;
            self.distance[target as usize] > here
                && self.generator.patterns()[r as usize].iter().any(|&a| {
                    match &self.content.network.alpha[a as usize] {
                        AlphaNode::Event { event: e, tests, .. } => {
                            *e == event && tests.iter().all(|t| passes(t, payload))
                        }
                        _ => false,
                    }
                })
        })
    }

    /// The event of one slot, if it has one.
    fn pick(&mut self, total: f64) -> Option<(u32, Vec<Value>)> {
        if self.goal.as_ref().is_none_or(|g| self.now >= g.until) {
            self.pick_goal();
        }
        let mut payload = Vec::new();
        if let Some(rule) = self.goal.as_ref().map(|g| g.rule as usize) {
            let n = self.generator.patterns()[rule].len();
            if n > 0 && self.generator.rng().random_bool(GOAL_SHARE) {
                let k = self.generator.rng().random_range(0..n);
                let alpha = self.generator.patterns()[rule][k] as usize;
                return self.generator.payload_for(alpha, &mut payload).map(|e| (e, payload));
            }
        }
        for _ in 0..REDRAWS {
            payload.clear();
            let event = self.generator.random_event(total, &mut payload);
            if !self.unwanted(event, &payload) {
                return Some((event, payload));
            }
        }
        None
    }
}

impl Explorer {
    /// The next event, before the run's end (`None`: the run has no more).
    pub fn next_due(&mut self) -> Option<Due> {
        let total = self.generator.total_rate()?;
        while self.slots < MAX_RANDOM_EVENTS {
            self.slots += 1;
            self.now = self.now.saturating_add(self.generator.gap());
            if self.now >= self.end {
                return None;
            }
            if let Some((event, payload)) = self.pick(total) {
                let agent = self.content.events[event as usize].agent;
                return Some(Due { time: self.now, agent, event, payload, step: usize::MAX });
            }
        }
        None
    }
}
