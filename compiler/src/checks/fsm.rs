//! W0313 and W0314: FSM states that no history of the agent reaches, and
//! transitions from one FSM state that compete for the same input (the
//! first in source order fires, so the other never does on that input).

use super::behaviour::{can_fire, can_fire_in, entered_states, reachable_fsm_states_in};
use super::transitions::Transitions;
use crate::codes;
use crate::model::{Agent, Behaviour, Fsm, FsmTransition, FsmTrigger, Model};
use serde_json::{json, Value};
use situ_grammar::diag::Diagnostic;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    // A state trigger fires on a change into one of its states: only the
    // states the rules can lead into count.
    let entered = entered_states(model, tr);
    for agent in &model.agents {
        if let Behaviour::Fsm(fsm) = &agent.behaviour {
            out.extend(unreachable(model, agent, fsm, &entered));
            out.extend((0..fsm.transitions.len()).filter_map(|k| competing(model, agent, fsm, k)));
        }
    }
    out
}

/// `A -> B on EVENT`, `A -> B on state in {X, Y}`.
fn describe(model: &Model, fsm: &Fsm, t: &FsmTransition) -> String {
    let trigger = match &t.trigger {
        FsmTrigger::Event(e) => model.event(*e).name.clone(),
        FsmTrigger::State(set) => {
            let names: Vec<&str> = set.states.iter().map(|&s| model.state(s).name.as_str()).collect();
            format!("state in {{{}}}", names.join(", "))
        }
    };
    format!("{} -> {} on {trigger}", fsm.states[t.from].name, fsm.states[t.to].name)
}

/// W0313.
fn unreachable(model: &Model, agent: &Agent, fsm: &Fsm, entered: &[bool]) -> Vec<Diagnostic> {
    let reachable = reachable_fsm_states_in(fsm, entered);
    let names = |keep: bool| -> Vec<&str> {
        fsm.states.iter().zip(&reachable).filter(|(_, &r)| r == keep).map(|(s, _)| s.name.as_str()).collect()
    };
    let initial = &fsm.states[fsm.initial].name;
    let mut out = Vec::new();
    for (i, state) in fsm.states.iter().enumerate().filter(|(i, _)| !reachable[*i]) {
        let mut d = Diagnostic::warning(
            codes::UNREACHABLE_FSM_STATE,
            format!("FSM state `{}` of `{}` is unreachable from `{initial}`", state.name, agent.name),
            state.origin.file,
            state.origin.span,
            "never entered",
        );
        let mut why = Vec::new();
        for t in fsm.transitions.iter().filter(|t| t.to == i && t.from != i) {
            let reason = match &t.trigger {
                FsmTrigger::State(_) if !can_fire(t) => "it never fires: its state test allows no state".to_string(),
                FsmTrigger::State(set) if !can_fire_in(t, entered) => {
                    let names: Vec<&str> = set.states.iter().map(|&s| model.state(s).name.as_str()).collect();
                    let back =
                        if model.initial.is_some_and(|i| set.states.contains(&i)) { " after the start" } else { "" };
                    format!(
                        "it never fires: no rule leads the system into {}{back}",
                        names.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(" or ")
                    )
                }
                _ => format!("it starts in `{}`, itself unreachable", fsm.states[t.from].name),
            };
            d = d.with_label(t.origin.file, t.origin.span, format!("leads here, but {reason}"));
            why.push(json!({ "transition": describe(model, fsm, t), "why": reason }));
        }
        let help = if why.is_empty() {
            format!(
                "add a transition to `{}` from a reachable state (`{initial} -> {} on …`), or remove it",
                state.name, state.name
            )
        } else {
            format!(
                "make one of these transitions able to fire from a reachable state ({}), or remove `{}`",
                names(true).join(", "),
                state.name
            )
        };
        out.push(d.with_help(help).with_witness(json!({
            "agent": agent.name,
            "state": state.name,
            "initial": initial,
            "reachable": names(true),
            "transitions": why,
        })));
    }
    out
}

/// W0314: transition `k` against the earlier transitions from the same FSM
/// state that fire on one of its inputs.
fn competing(model: &Model, agent: &Agent, fsm: &Fsm, k: usize) -> Option<Diagnostic> {
    let t = &fsm.transitions[k];
    let earlier: Vec<(&FsmTransition, (Value, String))> = fsm.transitions[..k]
        .iter()
        .filter(|u| u.from == t.from)
        .filter_map(|u| common_input(model, u, t).map(|input| (u, input)))
        .collect();
    let ((_, (_, first_input)), _) = earlier.split_first()?;
    let from = &fsm.states[t.from].name;
    let mut d = Diagnostic::warning(
        codes::NONDETERMINISTIC_FSM,
        format!("two transitions from `{from}` of `{}` fire on {first_input}", agent.name),
        t.origin.file,
        t.origin.span,
        format!("never fires on {first_input}"),
    );
    let mut witness = Vec::new();
    for (u, (input, text)) in &earlier {
        d = d.with_label(u.origin.file, u.origin.span, format!("fires first on {text}"));
        witness.push(json!({ "transition": describe(model, fsm, u), "input": input }));
    }
    Some(
        d.with_help(format!(
            "the first transition in source order fires; make the triggers of transitions from `{from}` exclusive, or remove one"
        ))
        .with_witness(json!({
            "agent": agent.name,
            "from": from,
            "transition": describe(model, fsm, t),
            "earlier": witness,
        })),
    )
}

/// The inputs on which both transitions fire, as data and as words.
fn common_input(model: &Model, a: &FsmTransition, b: &FsmTransition) -> Option<(Value, String)> {
    match (&a.trigger, &b.trigger) {
        (FsmTrigger::Event(x), FsmTrigger::Event(y)) if x == y => {
            let name = &model.event(*x).name;
            Some((json!({ "event": name }), format!("event `{name}`")))
        }
        (FsmTrigger::State(x), FsmTrigger::State(y)) => {
            let common: Vec<&str> = x.states.intersection(&y.states).map(|&s| model.state(s).name.as_str()).collect();
            let text = format!("a change to state {}", common.join(" or "));
            (!common.is_empty()).then(|| (json!({ "states": common }), text))
        }
        _ => None,
    }
}
