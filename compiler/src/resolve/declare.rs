//! Phase 1: every declared name gets its id; duplicates, the initial state,
//! and the settings of agents are checked.

use super::{items, types, Cx};
use crate::codes;
use crate::model::*;
use situ_grammar::ast::{self, Span};
use situ_grammar::diag::{Diagnostic, FileId};

pub(super) fn declare(cx: &mut Cx, files: &[(FileId, ast::File)], root: FileId) {
    let mut first_block: Option<Origin> = None;
    let mut initial: Option<Origin> = None;
    for (file, item) in items(files) {
        match item {
            ast::Item::States(block) => {
                first_block.get_or_insert(Cx::origin(file, Span::new(block.span.start, block.span.start + 6)));
                for decl in &block.states {
                    state(cx, file, decl, &mut initial);
                }
            }
            ast::Item::Agent(agent) => declare_agent(cx, file, agent),
            _ => {}
        }
    }
    if initial.is_none() {
        let (file, span, message) = match first_block {
            Some(o) => (o.file, o.span, "no state is declared `initial`"),
            None => (root, Span::new(0, 0), "no states are declared"),
        };
        cx.diags.push(
            Diagnostic::error(codes::INITIAL_STATE, message, file, span, "one state must be `initial`")
                .with_help("mark the state the stack starts in: `states { IT initial ... }`"),
        );
    }
}

fn state(cx: &mut Cx, file: FileId, decl: &ast::StateDecl, initial: &mut Option<Origin>) {
    let origin = Cx::origin(file, decl.name.span);
    if let Some(&id) = cx.states.get(&decl.name.name) {
        let first = cx.model.state(id).origin;
        cx.duplicate("state", &decl.name.name, file, decl.name.span, first);
        return;
    }
    let id = StateId(cx.model.states.len() as u32);
    if let Some(flag) = decl.initial {
        match initial {
            Some(first) => cx.diags.push(
                Diagnostic::error(
                    codes::INITIAL_STATE,
                    format!("a second initial state `{}`", decl.name.name),
                    file,
                    flag,
                    "second `initial`",
                )
                .with_label(first.file, first.span, "the initial state")
                .with_help("exactly one state is initial: the state the stack starts in"),
            ),
            None => {
                *initial = Some(origin);
                cx.model.initial = Some(id);
            }
        }
    }
    cx.states.insert(decl.name.name.clone(), id);
    cx.model.states.push(State {
        name: decl.name.name.clone(),
        is_final: decl.is_final.is_some(),
        description: decl.description.as_ref().map(|d| d.value.clone()),
        origin,
    });
}

fn declare_agent(cx: &mut Cx, file: FileId, agent: &ast::Agent) {
    if let Some(&id) = cx.agents.get(&agent.name.name) {
        let first = cx.model.agent(id).origin;
        cx.duplicate("agent", &agent.name.name, file, agent.name.span, first);
        return;
    }
    let id = AgentId(cx.model.agents.len() as u32);
    cx.agents.insert(agent.name.name.clone(), id);
    let origin = Cx::origin(file, agent.name.span);
    cx.model.agents.push(Agent {
        name: agent.name.name.clone(),
        kind: agent.kind,
        description: agent.description.as_ref().map(|d| d.value.clone()),
        stale_after: None,
        rate_hz: None,
        commands: Vec::new(),
        events: Vec::new(),
        functions: Vec::new(),
        behaviour: Behaviour::Always,
        origin,
    });
    let mut stale_seen: Option<Span> = None;
    let mut rate_seen: Option<Span> = None;
    for member in &agent.members {
        match member {
            ast::AgentMember::Stale(s) => {
                if once(cx, file, &mut stale_seen, s.span, "stale after")
                    && cx.positive(file, s.after.nanos, s.after.span, "a stale time")
                {
                    cx.model.agents[id.index()].stale_after = Some(s.after.nanos);
                }
            }
            ast::AgentMember::Rate(r) => {
                if once(cx, file, &mut rate_seen, r.span, "rate") {
                    if crate::bundle::rate_in_range(r.hertz) {
                        cx.model.agents[id.index()].rate_hz = Some(r.hertz);
                    } else if r.hertz > 0.0 {
                        rate_out_of_range(cx, file, &agent.name.name, r);
                    } else {
                        cx.positive(file, 0, r.span, "a rate");
                    }
                }
            }
            ast::AgentMember::Event(e) => event(cx, file, id, e),
            ast::AgentMember::Function(f) => function(cx, file, id, f),
            // Names other agents: resolved with the behaviour, once every agent is declared.
            ast::AgentMember::Commands(_) | ast::AgentMember::Table(_) | ast::AgentMember::Fsm(_) => {}
        }
    }
}

/// A positive rate outside [`crate::bundle::MIN_RATE_HZ`]..=[`crate::bundle::MAX_RATE_HZ`].
fn rate_out_of_range(cx: &mut Cx, file: FileId, agent: &str, r: &ast::RateDecl) {
    use crate::bundle::{MAX_RATE_HZ, MIN_RATE_HZ};
    let (label, help) = if r.hertz > MAX_RATE_HZ {
        (
            format!("above {MAX_RATE_HZ}Hz"),
            format!(
                "step the agent at most every millisecond (`rate {MAX_RATE_HZ}Hz`); a faster source should batch its readings"
            ),
        )
    } else {
        (
            format!("below {MIN_RATE_HZ}Hz"),
            "leave `rate` out: an agent without one is stepped when data or a new status arrives".to_string(),
        )
    };
    cx.diags.push(
        Diagnostic::error(
            codes::RATE_OUT_OF_RANGE,
            format!("the rate of agent `{agent}` is out of range ({MIN_RATE_HZ}Hz to {MAX_RATE_HZ}Hz)"),
            file,
            r.span,
            label,
        )
        .with_help(help),
    );
}

/// Records a member that may appear once; reports the second.
fn once(cx: &mut Cx, file: FileId, seen: &mut Option<Span>, span: Span, what: &str) -> bool {
    if let Some(first) = *seen {
        cx.diags.push(
            Diagnostic::error(codes::CONFLICTING_MEMBERS, format!("`{what}` is given twice"), file, span, "second one")
                .with_label(file, first, "first one")
                .with_help("keep one of them"),
        );
        return false;
    }
    *seen = Some(span);
    true
}

fn event(cx: &mut Cx, file: FileId, agent: AgentId, decl: &ast::EventDecl) {
    if let Some(&id) = cx.events.get(&decl.name.name) {
        let first = cx.model.event(id);
        let (owner, first_origin) = (cx.model.agent(first.agent).name.clone(), first.origin);
        cx.duplicate("event", &decl.name.name, file, decl.name.span, first_origin);
        if let Some(d) = cx.diags.last_mut() {
            d.help = Some(format!(
                "event names are global: `{}` is already reported by `{owner}`; give this one another name",
                decl.name.name
            ));
        }
        return;
    }
    let mut fields: Vec<Field> = Vec::new();
    for f in &decl.fields {
        if let Some(first) = fields.iter().find(|x| x.name == f.name.name) {
            let first = first.origin;
            cx.duplicate("field", &f.name.name, file, f.name.span, first);
            continue;
        }
        let ty = types::field_type(cx, file, &f.ty);
        fields.push(Field { name: f.name.name.clone(), ty, origin: Cx::origin(file, f.name.span) });
    }
    let id = EventId(cx.model.events.len() as u32);
    cx.events.insert(decl.name.name.clone(), id);
    cx.model.events.push(Event {
        name: decl.name.name.clone(),
        agent,
        fields,
        description: decl.description.as_ref().map(|d| d.value.clone()),
        origin: Cx::origin(file, decl.name.span),
    });
    cx.model.agents[agent.index()].events.push(id);
}

fn function(cx: &mut Cx, file: FileId, agent: AgentId, decl: &ast::FunctionDecl) {
    let functions = &cx.model.agents[agent.index()].functions;
    if let Some(first) = functions.iter().find(|f| f.name == decl.name.name) {
        let first = first.origin;
        cx.duplicate("function", &decl.name.name, file, decl.name.span, first);
        return;
    }
    cx.model.agents[agent.index()].functions.push(Function {
        name: decl.name.name.clone(),
        description: decl.description.as_ref().map(|d| d.value.clone()),
        origin: Cx::origin(file, decl.name.span),
    });
}
