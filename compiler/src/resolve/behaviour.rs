//! Phase 2: what every agent does per system state, from its table or FSM.

use super::Cx;
use crate::codes;
use crate::model::*;
use situ_grammar::ast::{self, Span};
use situ_grammar::diag::{Diagnostic, FileId};

pub(super) fn agent(cx: &mut Cx, file: FileId, agent: &ast::Agent) {
    let Some(&id) = cx.agents.get(&agent.name.name) else { return };
    if cx.model.agent(id).origin != Cx::origin(file, agent.name.span) {
        return; // a duplicate agent, already reported
    }
    for member in &agent.members {
        if let ast::AgentMember::Commands(c) = member {
            for t in &c.targets {
                if let Some(target) = cx.agent(file, t) {
                    let origin = Cx::origin(file, t.span);
                    cx.model.agents[id.index()].commands.push((target, origin));
                }
            }
        }
    }
    let mut first: Option<(Span, &str)> = None;
    for member in &agent.members {
        let (span, what) = match member {
            ast::AgentMember::Table(t) => (t.span, "table"),
            ast::AgentMember::Fsm(f) => (f.span, "fsm"),
            _ => continue,
        };
        if let Some((first_span, first_what)) = first {
            cx.diags.push(
                Diagnostic::error(
                    codes::CONFLICTING_MEMBERS,
                    format!("agent `{}` has a second {what}", agent.name.name),
                    file,
                    Span::new(span.start, span.start + what.len()),
                    format!("a second {what}"),
                )
                .with_label(
                    file,
                    Span::new(first_span.start, first_span.start + first_what.len()),
                    format!("the {first_what}"),
                )
                .with_help("an agent's behaviour is one table or one fsm; merge them"),
            );
            continue;
        }
        first = Some((span, what));
        let behaviour = match member {
            ast::AgentMember::Table(t) => table(cx, file, id, t).map(Behaviour::Table),
            ast::AgentMember::Fsm(f) => fsm(cx, file, id, f).map(Behaviour::Fsm),
            _ => None,
        };
        if let Some(b) = behaviour {
            cx.model.agents[id.index()].behaviour = b;
        }
    }
}

fn table(cx: &mut Cx, file: FileId, agent: AgentId, table: &ast::Table) -> Option<Table> {
    let mut entries = Vec::new();
    let mut ok = true;
    for entry in &table.entries {
        let states = match &entry.selector {
            ast::Selector::Wildcard(_) => None,
            ast::Selector::States(names) => {
                let ids: Vec<StateId> = names.iter().filter_map(|n| cx.state(file, n)).collect();
                ok &= ids.len() == names.len();
                Some(ids)
            }
        };
        match action(cx, file, agent, &entry.action) {
            Some(action) => entries.push(TableEntry { states, action, origin: Cx::origin(file, entry.span) }),
            None => ok = false,
        }
    }
    ok.then(|| Table { entries, origin: Cx::origin(file, table.span) })
}

fn action(cx: &mut Cx, file: FileId, agent: AgentId, action: &ast::Action) -> Option<Action> {
    let mut ok = true;
    let function = match &action.function {
        Some(f) => {
            let found = cx.function(file, agent, f);
            ok &= found.is_some();
            found
        }
        None => None,
    };
    let mut links = |names: &[ast::Ident]| -> Vec<AgentId> {
        let mut ids = Vec::new();
        for n in names {
            match cx.agent(file, n) {
                Some(a) if a == agent => {
                    cx.diags.push(
                        Diagnostic::error(
                            codes::SELF_LINK,
                            format!("agent `{}` links to itself", n.name),
                            file,
                            n.span,
                            "this is the agent itself",
                        )
                        .with_help("links connect an agent to others; data it keeps for itself needs no link"),
                    );
                    ok = false;
                }
                Some(a) => ids.push(a),
                None => ok = false,
            }
        }
        ids
    };
    let from = links(&action.from);
    let to = links(&action.to);
    ok.then(|| Action { mode: action.mode, function, from, to, origin: Cx::origin(file, action.span) })
}

fn fsm(cx: &mut Cx, file: FileId, agent: AgentId, fsm: &ast::Fsm) -> Option<Fsm> {
    let mut ok = true;
    let mut states: Vec<FsmState> = Vec::new();
    let mut initial: Option<(usize, Span)> = None;
    for line in &fsm.lines {
        let ast::FsmLine::State(s) = line else { continue };
        if let Some(first) = states.iter().find(|x| x.name == s.name.name) {
            let first = first.origin;
            cx.duplicate("FSM state", &s.name.name, file, s.name.span, first);
            ok = false;
            continue;
        }
        if let Some(flag) = s.initial {
            if let Some((_, first)) = initial {
                cx.diags.push(
                    Diagnostic::error(codes::FSM_INITIAL, "a second initial FSM state", file, flag, "second `initial`")
                        .with_label(file, first, "the initial FSM state")
                        .with_help("an FSM starts in exactly one state"),
                );
                ok = false;
            } else {
                initial = Some((states.len(), flag));
            }
        }
        // A state whose action does not resolve still exists, so that the
        // transitions that name it are not reported as well.
        let origin = Cx::origin(file, s.name.span);
        let action = action(cx, file, agent, &s.action).unwrap_or_else(|| {
            ok = false;
            Action::always(origin)
        });
        states.push(FsmState { name: s.name.name.clone(), action, origin });
    }
    if initial.is_none() && ok {
        cx.diags.push(
            Diagnostic::error(
                codes::FSM_INITIAL,
                "this FSM has no initial state",
                file,
                Span::new(fsm.span.start, fsm.span.start + 3),
                "no `initial` state",
            )
            .with_help("mark the state the agent starts in: `Idle initial => sleep`"),
        );
        ok = false;
    }
    let mut transitions = Vec::new();
    for line in &fsm.lines {
        let ast::FsmLine::Transition(t) = line else { continue };
        let from = fsm_state(cx, file, &states, &t.from);
        let to = fsm_state(cx, file, &states, &t.to);
        let trigger = trigger(cx, file, agent, &t.trigger);
        match (from, to, trigger) {
            (Some(from), Some(to), Some(trigger)) => {
                transitions.push(FsmTransition { from, to, trigger, origin: Cx::origin(file, t.span) })
            }
            _ => ok = false,
        }
    }
    let initial = initial.map(|(i, _)| i)?;
    ok.then(|| Fsm { states, initial, transitions, origin: Cx::origin(file, fsm.span) })
}

fn fsm_state(cx: &mut Cx, file: FileId, states: &[FsmState], name: &ast::Ident) -> Option<usize> {
    let found = states.iter().position(|s| s.name == name.name);
    if found.is_none() {
        let names: Vec<&str> = states.iter().map(|s| s.name.as_str()).collect();
        cx.diags.push(
            Diagnostic::error(
                codes::UNDEFINED_FSM_STATE,
                format!("undefined FSM state `{}`", name.name),
                file,
                name.span,
                "not a state of this FSM",
            )
            .with_help(if names.is_empty() {
                "declare it in the FSM: `NAME => run f()`".to_string()
            } else {
                format!("the states of this FSM are: {}", names.join(", "))
            }),
        );
    }
    found
}

fn trigger(cx: &mut Cx, file: FileId, agent: AgentId, trigger: &ast::Trigger) -> Option<FsmTrigger> {
    match trigger {
        ast::Trigger::State(test) => {
            let before = cx.diags.len();
            let set = cx.state_set(file, test);
            (cx.diags.len() == before).then_some(FsmTrigger::State(set))
        }
        ast::Trigger::Event(name) => {
            if let Some(&event) = cx.events.get(&name.name) {
                let owner = cx.model.event(event).agent;
                if owner == agent {
                    return Some(FsmTrigger::Event(event));
                }
                let owner = cx.model.agent(owner).name.clone();
                cx.diags.push(
                    Diagnostic::error(
                        codes::FOREIGN_TRIGGER,
                        format!("event `{}` is reported by `{owner}`, not by this agent", name.name),
                        file,
                        name.span,
                        format!("an event of `{owner}`"),
                    )
                    .with_help("an FSM reacts to system states and to its own events; let a rule turn this event into a state and write `on state == STATE`"),
                );
                return None;
            }
            let found = cx.event(file, name);
            if found.is_none() && cx.states.contains_key(&name.name) {
                if let Some(d) = cx.diags.last_mut() {
                    d.help = Some(format!("to react to the system state write `on state == {}`", name.name));
                }
            }
            None
        }
    }
}
