//! Self-organisation (language reference §10.6): what every agent does in
//! the current system state — its mode, its function and its links — from
//! its table, or from its FSM, which also follows the agent's own events.
//! The wiring graph of the moment is the union of the links of the agents
//! running now.
//!
//! An [`Organisation`] is driven by two inputs, in the order the runtime
//! sees them: [`on_event`](Organisation::on_event) when an agent reports an
//! event (before the Bulletinboard's rest for it), and
//! [`on_state`](Organisation::on_state) when the state at rest changes.

use situ_bundle::{Action, Behaviour, Content, Mode, Trigger};
use std::sync::Arc;

/// The action of an agent without a table or FSM: running, no function, no links.
static ALWAYS: Action = Action { mode: Mode::Running, function: None, from: Vec::new(), to: Vec::new() };

#[derive(Debug, Clone)]
pub struct Organisation {
    content: Arc<Content>,
    state: u32,
    /// Per agent, its FSM's current state (0 for agents without an FSM).
    fsm: Vec<u32>,
    /// Safe mode: the Bulletinboard is gone; every agent that would run
    /// waits (reports events, sends no data).
    safe: bool,
}

/// An FSM that moved: the agent, and its FSM states before and after.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct FsmMove {
    pub agent: u32,
    pub from: u32,
    pub to: u32,
}

impl Organisation {
    /// Every agent in the bundle's initial state, FSMs in their initial states.
    pub fn new(content: Arc<Content>) -> Organisation {
        let fsm = content
            .agents
            .iter()
            .map(|a| match &a.behaviour {
                Behaviour::Fsm(f) => f.initial,
                _ => 0,
            })
            .collect();
        Organisation { state: content.initial, content, fsm, safe: false }
    }

    pub fn content(&self) -> &Arc<Content> {
        &self.content
    }

    /// Back to the initial state, FSMs too (a new mission).
    pub fn reset(&mut self) {
        *self = Organisation::new(self.content.clone());
    }

    /// The system state the organisation is in.
    pub fn state(&self) -> u32 {
        self.state
    }

    /// Sets the state without stepping any FSM (tests' `given`, a hot swap).
    pub fn set_state(&mut self, state: u32) {
        self.state = state;
    }

    /// The state at rest became `state`: each FSM takes the first of its
    /// transitions (in source order) from its current state whose state
    /// trigger admits the new state. Nothing happens when the state is the
    /// same (a state that merely continues does not trigger).
    pub fn on_state(&mut self, state: u32) -> Vec<FsmMove> {
        if state == self.state {
            return Vec::new();
        }
        self.state = state;
        self.step_fsms(|t| matches!(t, Trigger::States(s) if s.contains(&state)), None)
    }

    /// `agent` reported `event`: its FSM takes the first transition from
    /// its current state triggered by that event.
    pub fn on_event(&mut self, agent: u32, event: u32) -> Option<FsmMove> {
        self.step_fsms(|t| matches!(t, Trigger::Event(e) if *e == event), Some(agent)).pop()
    }

    fn step_fsms(&mut self, fires: impl Fn(&Trigger) -> bool, only: Option<u32>) -> Vec<FsmMove> {
        let mut moves = Vec::new();
        let agents = &self.content.agents;
        // One agent's event looks at that agent's FSM only (every event
        // of a running stack passes here).
        let range = match only {
            Some(o) => (o as usize).min(agents.len())..(o as usize + 1).min(agents.len()),
            None => 0..agents.len(),
        };
        for i in range {
            let Behaviour::Fsm(f) = &agents[i].behaviour else { continue };
            let at = self.fsm[i];
            if let Some(t) = f.transitions.iter().find(|t| t.from == at && fires(&t.trigger)) {
                self.fsm[i] = t.to;
                moves.push(FsmMove { agent: i as u32, from: at, to: t.to });
            }
        }
        moves
    }

    /// The agent's action now; `None` when its table has no entry for the
    /// state (it sleeps).
    pub fn action(&self, agent: u32) -> Option<&Action> {
        match &self.content.agents.get(agent as usize)?.behaviour {
            Behaviour::Always => Some(&ALWAYS),
            Behaviour::Table { actions } => actions.get(self.state as usize)?.as_ref(),
            Behaviour::Fsm(f) => f.states.get(self.fsm[agent as usize] as usize).map(|s| &s.action),
        }
    }

    pub fn mode(&self, agent: u32) -> Mode {
        match self.action(agent).map_or(Mode::Sleeping, |a| a.mode) {
            Mode::Running if self.safe => Mode::Waiting,
            m => m,
        }
    }

    /// Enters or leaves safe mode: while the Bulletinboard is silent, no
    /// agent runs (they wait: they still report events, their data outputs
    /// are dropped, and actuators see [`Organisation::safe`] and stop).
    pub fn set_safe(&mut self, safe: bool) {
        self.safe = safe;
    }

    pub fn safe(&self) -> bool {
        self.safe
    }

    /// The name of the function the agent runs (or waits with) now.
    pub fn function(&self, agent: u32) -> Option<&str> {
        let f = self.action(agent)?.function?;
        self.content.agents[agent as usize].functions.get(f as usize).map(|f| f.name.as_str())
    }

    /// The current FSM state of an FSM agent.
    pub fn fsm_state(&self, agent: u32) -> Option<u32> {
        match &self.content.agents.get(agent as usize)?.behaviour {
            Behaviour::Fsm(_) => Some(self.fsm[agent as usize]),
            _ => None,
        }
    }

    /// Forces an FSM agent into one of its FSM states (a carried-over
    /// runtime, a test).
    pub fn set_fsm_state(&mut self, agent: u32, fsm_state: u32) {
        if let Some(Behaviour::Fsm(f)) = self.content.agents.get(agent as usize).map(|a| &a.behaviour) {
            if (fsm_state as usize) < f.states.len() {
                self.fsm[agent as usize] = fsm_state;
            }
        }
    }

    /// The wiring graph now: the links of the running agents, sorted, once each.
    pub fn links(&self) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        for agent in 0..self.content.agents.len() as u32 {
            if let Some(a) = self.action(agent).filter(|_| self.mode(agent) == Mode::Running) {
                out.extend(a.from.iter().map(|&x| (x, agent)));
                out.extend(a.to.iter().map(|&y| (agent, y)));
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    pub fn has_link(&self, from: u32, to: u32) -> bool {
        let written = |agent: u32, other: u32, outgoing: bool| {
            self.action(agent).filter(|_| self.mode(agent) == Mode::Running).is_some_and(|a| {
                if outgoing {
                    a.to.contains(&other)
                } else {
                    a.from.contains(&other)
                }
            })
        };
        written(from, to, true) || written(to, from, false)
    }
}
