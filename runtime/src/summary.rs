//! The figures of a run, for a person (a table at the end of `situ run`)
//! and for tools (`metrics.json`): the states visited and for how long, the
//! rules that fired, the messages of each stream and what was dropped.

use crate::bus::BusCounters;
use crate::rete::StateChange;
use crate::runner::{AgentCounters, BoardCounters};
use serde::Serialize;
use situ_bundle::Content;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// States of a path shown whole at the end of a run (see [`Summary::path_line`]).
pub const PATH_SHOWN: usize = 40;

#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// Simulated (or wall) time covered, seconds.
    pub duration_s: f64,
    pub final_state: String,
    /// Per state, in declaration order: time spent there (s), times entered.
    pub states: Vec<StateFigures>,
    /// The sequence of states at rest.
    pub path: Vec<String>,
    pub rules_fired: BTreeMap<String, u64>,
    pub board: BoardCounters,
    pub bus: BusCounters,
    pub agents: BTreeMap<String, AgentCounters>,
    #[serde(skip)]
    names: Vec<String>,
    #[serde(skip)]
    agent_names: Vec<String>,
    #[serde(skip)]
    since: u64,
    #[serde(skip)]
    origin: u64,
    #[serde(skip)]
    current: usize,
}

#[derive(Debug, Clone, Default, Serialize)]
pub struct StateFigures {
    pub state: String,
    pub seconds: f64,
    pub entered: u64,
    /// Agent steps taken in this state (sleeping agents take none).
    pub agent_steps: u64,
}

impl Summary {
    pub fn new(c: &Content) -> Summary {
        let mut states: Vec<StateFigures> =
            c.states.iter().map(|s| StateFigures { state: s.name.clone(), ..Default::default() }).collect();
        states[c.initial as usize].entered = 1;
        Summary {
            duration_s: 0.0,
            final_state: c.states[c.initial as usize].name.clone(),
            states,
            path: vec![c.states[c.initial as usize].name.clone()],
            rules_fired: BTreeMap::new(),
            board: BoardCounters::default(),
            bus: BusCounters::default(),
            agents: BTreeMap::new(),
            names: c.states.iter().map(|s| s.name.clone()).collect(),
            agent_names: c.agents.iter().map(|a| a.name.clone()).collect(),
            since: 0,
            origin: 0,
            current: c.initial as usize,
        }
    }

    /// Times are counted from `origin` (ns), e.g. a wall clock's start.
    pub fn starting_at(mut self, origin: u64) -> Summary {
        self.origin = origin;
        self.since = origin;
        self
    }

    /// The run starts in `state` rather than the initial state (a board
    /// that resumed from its journal).
    pub fn starting_in(mut self, state: u32) -> Summary {
        let state = state as usize;
        if state != self.current && state < self.states.len() {
            self.states[self.current].entered -= 1;
            self.states[state].entered += 1;
            self.current = state;
            self.final_state = self.names[state].clone();
            self.path = vec![self.names[state].clone()];
        }
        self
    }

    /// A change of the state at rest.
    pub fn change(&mut self, c: &StateChange) {
        if !c.changed() {
            return;
        }
        let dt = c.time.saturating_sub(self.since);
        self.states[self.current].seconds += dt as f64 * 1e-9;
        self.since = c.time;
        self.current = c.to as usize;
        self.states[self.current].entered += 1;
        self.path.push(self.names[self.current].clone());
    }

    /// An agent's turn came (`stepped`: it was not sleeping).
    pub fn stepped(&mut self, _agent: u32, stepped: bool) {
        if stepped {
            self.states[self.current].agent_steps += 1;
        }
    }

    /// `n` agent steps taken since the last call, all in the current state
    /// (the real-time scheduler counts them on its workers and hands them
    /// over at each state change and at the end).
    pub fn add_steps(&mut self, n: u64) {
        self.states[self.current].agent_steps += n;
    }

    /// Closes the figures at `now`.
    pub fn finish(
        &mut self,
        now: u64,
        state: u32,
        board: &BoardCounters,
        agents: Vec<(u32, AgentCounters)>,
        bus: BusCounters,
    ) {
        let dt = now.saturating_sub(self.since);
        self.states[self.current].seconds += dt as f64 * 1e-9;
        self.since = now;
        self.duration_s = now.saturating_sub(self.origin) as f64 * 1e-9;
        self.final_state = self.names[state as usize].clone();
        self.rules_fired = board.fired.clone();
        self.board = board.clone();
        self.bus = bus;
        self.agents = agents.into_iter().map(|(a, c)| (self.agent_names[a as usize].clone(), c)).collect();
    }

    /// The path for a person: whole up to [`PATH_SHOWN`] states, else its
    /// start and its end around the count of the changes left out (the
    /// whole path is in `path`, and in metrics.json).
    pub fn path_line(&self) -> String {
        const TAIL: usize = 5;
        if self.path.len() <= PATH_SHOWN {
            return self.path.join(" → ");
        }
        let head = PATH_SHOWN - TAIL;
        let left_out = self.path.len() - PATH_SHOWN;
        format!(
            "{} → … {left_out} more … → {}",
            self.path[..head].join(" → "),
            self.path[self.path.len() - TAIL..].join(" → ")
        )
    }

    /// The table a person reads at the end of a run.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "{:.1} s, final state {}", self.duration_s, self.final_state);
        let _ = writeln!(s, "path: {}", self.path_line());
        let w = self.states.iter().map(|f| f.state.chars().count()).max().unwrap_or(0).max(6);
        let _ = writeln!(s, "\n  {:<w$} {:>9}  entered  agent steps", "state", "time (s)");
        for f in self.states.iter().filter(|f| f.entered > 0) {
            let _ = writeln!(s, "  {:<w$} {:>9.1}  {:>7}  {:>11}", f.state, f.seconds, f.entered, f.agent_steps);
        }
        if !self.rules_fired.is_empty() {
            let w = self.rules_fired.keys().map(|r| r.chars().count()).max().unwrap_or(0).max(30);
            let _ = writeln!(s, "\n  {:<w$} fired", "rule");
            for (r, n) in &self.rules_fired {
                let _ = writeln!(s, "  {r:<w$} {n:>5}");
            }
        }
        let (mut out, mut suppressed, mut undelivered, mut stale) = (0, 0, 0, 0);
        for c in self.agents.values() {
            out += c.data_out;
            suppressed += c.suppressed;
            undelivered += c.undelivered;
            stale += c.stale_inputs;
        }
        let refused: u64 = self.board.refused.values().sum();
        let _ = writeln!(s, "\n  stream   messages  dropped");
        let _ = writeln!(
            s,
            "  data     {:>8}  {} (waiting senders {suppressed}, sleeping or unlinked receivers {undelivered}, full queues {}, backlog at wake-up {stale})",
            out,
            suppressed + undelivered + self.bus.data_overflow + stale,
            self.bus.data_overflow
        );
        let _ = writeln!(
            s,
            "  events   {:>8}  {} (refused {refused}, lost to a full queue {})",
            self.board.accepted + refused + self.board.lost,
            refused + self.board.lost,
            self.board.lost
        );
        let _ = writeln!(s, "  status   {:>8}  0", self.board.status_sent);
        if !self.board.refused.is_empty() {
            let reasons: Vec<String> = self.board.refused.iter().map(|(k, v)| format!("{k}: {v}")).collect();
            let _ = writeln!(s, "  refused events by reason: {}", reasons.join(", "));
        }
        s
    }
}
