//! What an agent does in a system state (language reference §10.6): the rule
//! the runtime applies, and what the static checks can know of it when an
//! FSM makes it depend on the agent's history.

use super::transitions::Transitions;
use crate::model::*;
use situ_grammar::ast::Mode;
use std::borrow::Cow;

/// The table entry that applies in `state`: the first entry whose selector
/// names it, else the `_` entry; `None` when there is neither (the agent
/// then sleeps in that state).
pub fn table_entry(table: &Table, state: StateId) -> Option<&TableEntry> {
    let named = table.entries.iter().find(|e| e.states.as_ref().is_some_and(|s| s.contains(&state)));
    named.or_else(|| table.entries.iter().find(|e| e.states.is_none()))
}

/// The action of `agent` in system state `state`: its mode, function and links.
///
/// - No table and no FSM: running, no function, no links.
/// - Table: the action of [`table_entry`]; `None` when the table has no entry
///   for the state, which means *sleeping*, no function, no links.
/// - FSM: the action of the FSM state the agent is in, `fsm_state` (an index
///   into [`Fsm::states`]; the runtime tracks it, the static checks try every
///   reachable one, see [`possible_actions`]). It is ignored for tables.
///
/// ```
/// use situ_compiler::checks::behaviour::action_in;
/// use situ_grammar::ast::Mode;
///
/// let c = situ_compiler::check_source("fig5.situ", "states { RS initial RO final }
///     agent LADAR sensor { event LAOBS }
///     agent Fusion processing { function fuse  table { RO => run fuse() from LADAR } }
///     rule obstacle { when state == RS and LAOBS then RO }");
/// let fusion = &c.model.agents[1];
/// let (rs, ro) = (c.model.state_id("RS").unwrap(), c.model.state_id("RO").unwrap());
/// assert!(action_in(fusion, rs, 0).is_none(), "no entry for RS: Fusion sleeps");
/// let woken = action_in(fusion, ro, 0).unwrap();
/// assert_eq!((woken.mode, woken.from.len()), (Mode::Running, 1));
/// ```
pub fn action_in(agent: &Agent, state: StateId, fsm_state: usize) -> Option<Cow<'_, Action>> {
    match &agent.behaviour {
        Behaviour::Always => Some(Cow::Owned(Action::always(agent.origin))),
        Behaviour::Table(t) => table_entry(t, state).map(|e| Cow::Borrowed(&e.action)),
        Behaviour::Fsm(f) => f.states.get(fsm_state).map(|s| Cow::Borrowed(&s.action)),
    }
}

/// The mode of an action as [`action_in`] returns it (`None` sleeps).
pub fn mode_of(action: Option<&Action>) -> Mode {
    action.map_or(Mode::Sleeping, |a| a.mode)
}

/// Whether an FSM transition can ever fire: a state trigger that allows no
/// system state never does.
pub fn can_fire(t: &FsmTransition) -> bool {
    match &t.trigger {
        FsmTrigger::State(set) => !set.states.is_empty(),
        FsmTrigger::Event(_) => true,
    }
}

/// Which states of the FSM its transitions can lead to from the initial
/// state (indexed like [`Fsm::states`]).
pub fn reachable_fsm_states(fsm: &Fsm) -> Vec<bool> {
    reachable_fsm_states_with(fsm, can_fire)
}

/// The system states that a state change can lead into (indexed like
/// [`Model::states`]): those the rules can reach from the initial state, but
/// the initial state itself only when a rule leads back to it from a
/// reachable state (the start is not a change).
pub fn entered_states(model: &Model, tr: &Transitions) -> Vec<bool> {
    let mut entered = vec![false; model.states.len()];
    let Some(initial) = model.initial else { return entered };
    let reachable = tr.shortest_paths(model, initial);
    for e in tr.edges.iter().filter(|e| reachable[e.from.index()].is_some()) {
        entered[e.to.index()] = true;
    }
    entered
}

/// Whether an FSM transition can ever fire, given the system states a state
/// change can lead into ([`entered_states`]).
pub fn can_fire_in(t: &FsmTransition, entered: &[bool]) -> bool {
    match &t.trigger {
        FsmTrigger::State(set) => set.states.iter().any(|s| entered.get(s.index()).copied().unwrap_or(false)),
        FsmTrigger::Event(_) => true,
    }
}

/// As [`reachable_fsm_states`], with only the transitions that can fire
/// given the system states a state change can lead into.
pub fn reachable_fsm_states_in(fsm: &Fsm, entered: &[bool]) -> Vec<bool> {
    reachable_fsm_states_with(fsm, |t| can_fire_in(t, entered))
}

fn reachable_fsm_states_with(fsm: &Fsm, fires: impl Fn(&FsmTransition) -> bool) -> Vec<bool> {
    let mut seen = vec![false; fsm.states.len()];
    let mut stack = vec![fsm.initial];
    while let Some(s) = stack.pop() {
        if std::mem::replace(&mut seen[s], true) {
            continue;
        }
        stack.extend(fsm.transitions.iter().filter(|t| t.from == s && fires(t)).map(|t| t.to));
    }
    seen
}

/// Every action `agent` may have in `state`, as far as a static check can
/// tell: exactly one for an agent without an FSM (`None`: no table entry,
/// sleeping), and one per reachable FSM state for an FSM, whose state depends
/// on the agent's history.
pub fn possible_actions(agent: &Agent, state: StateId) -> Vec<Option<Cow<'_, Action>>> {
    match &agent.behaviour {
        Behaviour::Fsm(f) => reachable_fsm_states(f)
            .iter()
            .enumerate()
            .filter(|(_, &r)| r)
            .map(|(i, _)| action_in(agent, state, i))
            .collect(),
        _ => vec![action_in(agent, state, 0)],
    }
}

/// The links an action writes for its agent: `(X, agent)` for each `from X`,
/// `(agent, Y)` for each `to Y`, in that order.
pub fn links(agent: AgentId, action: &Action) -> Vec<(AgentId, AgentId)> {
    let from = action.from.iter().map(|&x| (x, agent));
    from.chain(action.to.iter().map(|&y| (agent, y))).collect()
}
