//! W0315–W0318, W0320: the wiring graph of every system state (§10.6). The graph
//! of a state is the union of the links of the agents running in it: for a
//! running agent A, `from X` gives `X -> A` and `to Y` gives `A -> Y`. What
//! an agent does in a state is [`behaviour::action_in`].
//!
//! An FSM agent's action depends on its history, so the checks treat it as
//! possibly in any reachable FSM state: it is the *subject* of a finding only
//! when the finding holds in every one of them, its links *may* be present
//! when some of them writes them (so no link is reported missing falsely),
//! and *must* be present only when all of them write them (so no cycle is
//! reported falsely).
//!
//! [`behaviour::action_in`]: super::behaviour::action_in

mod commands;
mod cycles;
mod ends;
mod idle;

use super::behaviour::{links, mode_of, possible_actions};
use super::transitions::Transitions;
use crate::model::{Action, AgentId, Behaviour, Model, Origin, StateId};
use situ_grammar::ast::Mode;
use situ_grammar::diag::Diagnostic;
use std::borrow::Cow;
use std::collections::BTreeMap;

pub use super::behaviour::action_in;

pub fn check(model: &Model, _tr: &Transitions) -> Vec<Diagnostic> {
    let wirings: Vec<StateWiring> = model.state_ids().map(|s| StateWiring::build(model, s)).collect();
    let mut out = idle::check(model, &wirings);
    out.extend(ends::check(model, &wirings));
    out.extend(cycles::check(model, &wirings));
    out.extend(commands::check(model, &wirings));
    out
}

/// Links with the actions that write them.
pub type LinkMap = BTreeMap<(AgentId, AgentId), Vec<Origin>>;

/// What the static checks know of one system state.
pub struct StateWiring<'m> {
    pub state: StateId,
    /// Per agent (by index): every action it may have here (`None`: no
    /// table entry, sleeping).
    pub actions: Vec<Vec<Option<Cow<'m, Action>>>>,
    /// Links that some possible action of a running agent writes.
    pub may: LinkMap,
    /// Links present whatever the FSMs' history.
    pub must: LinkMap,
    /// Per agent: whether it has a table without an entry for this state.
    no_entry: Vec<bool>,
}

impl<'m> StateWiring<'m> {
    pub fn build(model: &'m Model, state: StateId) -> Self {
        let actions: Vec<_> = model.agents.iter().map(|a| possible_actions(a, state)).collect();
        let no_entry = model
            .agents
            .iter()
            .zip(&actions)
            .map(|(a, acts)| matches!(a.behaviour, Behaviour::Table(_)) && acts.iter().all(Option::is_none))
            .collect();
        let mut w = StateWiring { state, actions, may: LinkMap::new(), must: LinkMap::new(), no_entry };
        for i in 0..model.agents.len() {
            w.add_links(AgentId(i as u32));
        }
        w
    }

    fn add_links(&mut self, agent: AgentId) {
        let running: Vec<&Action> = self.actions[agent.index()]
            .iter()
            .flatten()
            .map(|a| a.as_ref())
            .filter(|a| a.mode == Mode::Running)
            .collect();
        let all_run = running.len() == self.actions[agent.index()].len();
        for action in &running {
            for link in links(agent, action) {
                let in_all = all_run && running.iter().all(|b| links(agent, b).contains(&link));
                self.may.entry(link).or_default().push(action.origin);
                if in_all {
                    self.must.entry(link).or_default().push(action.origin);
                }
            }
        }
    }

    /// Whether every action the agent may have here has a mode that passes `pred`.
    pub fn surely(&self, agent: AgentId, pred: impl Fn(Mode) -> bool) -> bool {
        self.actions[agent.index()].iter().all(|a| pred(mode_of(a.as_deref())))
    }

    /// The functions the agent surely runs here, one per possible action, or
    /// `None` if it may not be running or may run no function (an agent
    /// without a table).
    pub fn running_functions(&self, agent: AgentId) -> Option<Vec<usize>> {
        let acts = &self.actions[agent.index()];
        acts.iter().map(|a| a.as_ref().filter(|a| a.mode == Mode::Running).and_then(|a| a.function)).collect()
    }

    /// How its mode here is described: `sleeping`, `waiting`, `sleeping
    /// (no table entry)`, or several modes joined by ` or `.
    pub fn mode_text(&self, agent: AgentId) -> String {
        if self.no_entry[agent.index()] {
            return "sleeping (no table entry)".into();
        }
        let mut modes: Vec<&str> =
            self.actions[agent.index()].iter().map(|a| mode_of(a.as_deref()).adjective()).collect();
        modes.sort_unstable();
        modes.dedup();
        modes.join(" or ")
    }

    /// Whether some link of the may-graph ends at the agent.
    pub fn has_input(&self, agent: AgentId) -> bool {
        self.may.keys().any(|&(_, to)| to == agent)
    }

    /// Whether some link of the may-graph starts at the agent.
    pub fn has_output(&self, agent: AgentId) -> bool {
        self.may.keys().any(|&(from, _)| from == agent)
    }
}

/// State names joined by `, `.
pub fn state_list(model: &Model, states: &[StateId]) -> String {
    states.iter().map(|&s| model.state(s).name.as_str()).collect::<Vec<_>>().join(", ")
}
