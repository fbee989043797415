//! The static check of a map against the rules: one function per check,
//! each returning all its findings; [`check_map`] runs them all.

use crate::check_names;
use crate::map::{self, EventEntry, Map};
use crate::msgs::{Registry, TypeError};
use crate::types::{type_of, Ty};
use situ_compiler::codes;
use situ_compiler::model::{Event, Model, Type};
use situ_compiler::suggest::suggest;
use situ_grammar::diag::{Diagnostic, FileId};
use std::collections::BTreeMap;

/// One check: every finding of one kind, the message types read from the registry.
pub type Check = fn(&Model, &Map, &Registry, FileId) -> Vec<Diagnostic>;

/// Every finding of the map `text` (file `file`) against the rules'
/// `model` and the message definitions `msgs`, sorted by place. A map that
/// does not parse is one finding.
pub fn check_map(model: &Model, text: &str, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    match map::parse(text, file) {
        Ok(map) => check_parsed(model, &map, msgs, file),
        Err(d) => vec![*d],
    }
}

/// [`check_map`] on a map already parsed (from `file`).
pub fn check_parsed(model: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    let checks: [Check; 20] = [
        unknown_types,
        unknown_names,
        foreign_events,
        extra_payload,
        missing_payload,
        syntax,
        field_paths,
        type_mismatches,
        when_not_bool,
        unmapped_events,
        two_nodes,
        topic_types,
        bad_nodes,
        check_names::bad_topics,
        check_names::shared_nodes,
        check_names::duplicates,
        check_names::own_topics,
        check_names::bridge_diagnostics,
        crate::expr_check::zero_divisions,
        crate::expr_check::non_integer_indexes,
    ];
    let mut out: Vec<Diagnostic> = checks.iter().flat_map(|c| c(model, map, msgs, file)).collect();
    out.sort_by_key(|d| (d.primary.span.start, d.code));
    out
}

fn agent(model: &Model, name: &str) -> Option<usize> {
    model.agents.iter().position(|a| a.name == name)
}

fn event<'m>(model: &'m Model, name: &str) -> Option<&'m Event> {
    model.events.iter().find(|e| e.name == name)
}

fn did_you_mean<'a>(name: &str, candidates: impl Iterator<Item = &'a str>) -> Option<String> {
    suggest(name, candidates).map(|s| format!("did you mean `{s}`?"))
}

/// E0402: a `type` that no place of the search path defines; E0422: a
/// `type` whose definition, or the definition of a type it uses, does not
/// parse or names a type that cannot be found.
pub fn unknown_types(_: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        let Err(why) = msgs.resolve(&e.ty.value) else { continue };
        let unknown = |help: String| {
            Diagnostic::error(
                codes::ROS2_UNKNOWN_TYPE,
                format!("unknown message type `{}`", e.ty.value),
                file,
                e.ty.span,
                "not a known message type",
            )
            .with_help(help)
        };
        out.push(match why {
            TypeError::Malformed => unknown("write the type as `package/msg/Name` or `package/Name`".into()),
            TypeError::UnknownPackage { package } => unknown(format!(
                "no package `{package}` in: {}; give its folder with `--msg-path DIR` or `msg_path = [\"DIR\"]`",
                msgs.search_path().describe()
            )),
            TypeError::UnknownType { package, known } => {
                let short = e.ty.value.rsplit('/').next().unwrap_or("");
                let listed = format!("`{package}` has: {}", known.join(", "));
                unknown(match suggest(short, known.iter().map(String::as_str)) {
                    Some(s) => format!("did you mean `{package}/msg/{s}`? {listed}"),
                    None => listed,
                })
            }
            TypeError::Broken(err) => Diagnostic::error(
                codes::ROS2_BAD_DEFINITION,
                format!("the definition of `{}` does not load", e.ty.value),
                file,
                e.ty.span,
                "its definition does not load",
            )
            .with_help(format!("{err}: fix the definition, or put a good one first on the search path")),
        });
    }
    out
}

/// E0405: an agent or an event the rules do not declare (events and nodes).
pub fn unknown_names(model: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let agents = || model.agents.iter().map(|a| a.name.as_str());
    let mut unknown_agent = |s: &map::Str| {
        if agent(model, &s.value).is_none() {
            let mut d = Diagnostic::error(
                codes::ROS2_UNKNOWN_NAME,
                format!("the rules have no agent `{}`", s.value),
                file,
                s.span,
                "unknown agent",
            );
            if let Some(h) = did_you_mean(&s.value, agents()) {
                d = d.with_help(h);
            }
            out.push(d);
        }
    };
    for e in &map.events {
        unknown_agent(&e.agent);
    }
    for n in &map.nodes {
        unknown_agent(&n.agent);
    }
    let named = map.events.iter().map(|e| &e.event).chain(map.nodes.iter().filter_map(|n| n.failed.as_ref()));
    for e in named {
        if event(model, &e.value).is_none() {
            let mut d = Diagnostic::error(
                codes::ROS2_UNKNOWN_NAME,
                format!("the rules have no event `{}`", e.value),
                file,
                e.span,
                "unknown event",
            );
            if let Some(h) = did_you_mean(&e.value, model.events.iter().map(|e| e.name.as_str())) {
                d = d.with_help(h);
            }
            out.push(d);
        }
    }
    out
}

/// E0406: an entry whose agent is not the one that reports its event.
pub fn foreign_events(model: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        let (Some(a), Some(ev)) = (agent(model, &e.agent.value), event(model, &e.event.value)) else { continue };
        if ev.agent.index() != a {
            let owner = &model.agents[ev.agent.index()].name;
            out.push(
                Diagnostic::error(
                    codes::ROS2_FOREIGN_EVENT,
                    format!("`{}` is reported by `{owner}`, not by `{}`", e.event.value, e.agent.value),
                    file,
                    e.agent.span,
                    format!("`{}` does not report `{}`", e.agent.value, e.event.value),
                )
                .with_label(ev.origin.file, ev.origin.span, format!("`{}` is declared by `{owner}`", ev.name))
                .with_help(format!("write `agent = \"{owner}\"`, or map an event of `{}`", e.agent.value)),
            );
        }
    }
    out
}

/// E0407: a payload field the event does not have.
pub fn extra_payload(model: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        let Some(ev) = event(model, &e.event.value) else { continue };
        for (key, _) in &e.payload {
            if ev.fields.iter().any(|f| f.name == key.value) {
                continue;
            }
            let help = if ev.fields.is_empty() {
                format!("`{}` has no payload: remove `[event.payload]`", ev.name)
            } else {
                did_you_mean(&key.value, ev.fields.iter().map(|f| f.name.as_str())).unwrap_or_else(|| {
                    let names: Vec<&str> = ev.fields.iter().map(|f| f.name.as_str()).collect();
                    format!("`{}` has: {}", ev.name, names.join(", "))
                })
            };
            out.push(
                Diagnostic::error(
                    codes::ROS2_EXTRA_PAYLOAD,
                    format!("`{}` has no payload field `{}`", ev.name, key.value),
                    file,
                    key.span,
                    "not a field of the event",
                )
                .with_help(help),
            );
        }
    }
    out
}

/// E0408: a payload field of the event that the entry does not fill.
pub fn missing_payload(model: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        let Some(ev) = event(model, &e.event.value) else { continue };
        for f in &ev.fields {
            if e.payload.iter().any(|(k, _)| k.value == f.name) {
                continue;
            }
            out.push(
                Diagnostic::error(
                    codes::ROS2_MISSING_PAYLOAD,
                    format!("the map does not fill `{}` of `{}`", f.name, ev.name),
                    file,
                    e.event.span,
                    format!("`{}` missing", f.name),
                )
                .with_label(f.origin.file, f.origin.span, "declared here")
                .with_help(format!("add `{} = \"…\"` under `[event.payload]`", f.name)),
            );
        }
    }
    out
}

/// The expressions of an entry whose type is known: `when` first, then the
/// payload values with their keys.
/// An expression of an entry: its payload key (none for `when`) and its text.
type Keyed<'a> = (Option<&'a map::Str>, &'a map::Str);

fn expressions<'e>(e: &'e EventEntry, msgs: &Registry) -> Option<(&'static str, Vec<Keyed<'e>>)> {
    let msg = msgs.lookup(&e.ty.value)?;
    let when = e.when.iter().map(|w| (None, w));
    Some((msg, when.chain(e.payload.iter().map(|(k, v)| (Some(k), v))).collect()))
}

/// E0404: an expression that does not parse.
pub fn syntax(_: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        // The syntax does not depend on the type: check even unknown ones.
        let msg = msgs.lookup(&e.ty.value).unwrap_or("std_msgs/msg/Empty");
        for text in e.when.iter().chain(e.payload.iter().map(|(_, v)| v)) {
            out.extend(type_of(text, msg, msgs, file).syntax);
        }
    }
    out
}

/// E0403: a field path that is not in the message.
pub fn field_paths(_: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for (msg, exprs) in map.events.iter().filter_map(|e| expressions(e, msgs)) {
        for (_, text) in exprs {
            out.extend(type_of(text, msg, msgs, file).paths);
        }
    }
    out
}

/// Whether a value of type `ty` fits a payload field of type `field`.
fn fits(ty: &Ty, field: &Type, literal: Option<&str>) -> bool {
    match (field, ty) {
        (Type::F64, t) => t.is_numeric(),
        (Type::I64, t) => *t == Ty::Int,
        (Type::Bool, t) => *t == Ty::Bool,
        (Type::Symbols(symbols), Ty::Str) => literal.is_none_or(|s| symbols.iter().any(|x| x == s)),
        (Type::Symbols(_), _) => false,
    }
}

/// E0409: an operator on the wrong types, or a payload value whose type is
/// not the event field's.
pub fn type_mismatches(model: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        let Some((msg, exprs)) = expressions(e, msgs) else { continue };
        let ev = event(model, &e.event.value);
        for (key, text) in exprs {
            let typed = type_of(text, msg, msgs, file);
            out.extend(typed.mismatches);
            let (Some(ty), Some(key), Some(ev)) = (typed.ty, key, ev) else { continue };
            let Some(field) = ev.fields.iter().find(|f| f.name == key.value) else { continue };
            let literal = match &typed.expr {
                Some(crate::expr::Expr::Str(s, _)) => Some(s.as_str()),
                _ => None,
            };
            if fits(&ty, &field.ty, literal) {
                continue;
            }
            let help = match (&field.ty, literal) {
                (Type::Symbols(s), Some(_)) => format!("one of: {}", s.join(", ")),
                (Type::I64, _) if ty == Ty::Float => {
                    format!("`{}` is i64: declare it f64, or read an integer field", field.name)
                }
                _ => format!("give `{}` {}", field.name, field.ty.describe()),
            };
            out.push(
                Diagnostic::error(
                    codes::ROS2_TYPE_MISMATCH,
                    format!(
                        "`{}` of `{}` is {}, but the map gives it {}",
                        field.name,
                        ev.name,
                        field.ty.describe(),
                        match literal {
                            Some(s) => format!("`{s}`"),
                            None => ty.describe(),
                        }
                    ),
                    file,
                    text.span,
                    ty.describe(),
                )
                .with_label(field.origin.file, field.origin.span, "declared here")
                .with_help(help),
            );
        }
    }
    out
}

/// E0410: a `when` whose value is not a condition.
pub fn when_not_bool(_: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        let (Some(msg), Some(when)) = (msgs.lookup(&e.ty.value), &e.when) else { continue };
        match type_of(when, msg, msgs, file).ty {
            Some(Ty::Bool) | None => {}
            Some(ty) => out.push(
                Diagnostic::error(
                    codes::ROS2_WHEN_NOT_BOOL,
                    format!("`when` must be a condition, but it is {}", ty.describe()),
                    file,
                    when.span,
                    ty.describe(),
                )
                .with_help("compare it: e.g. `min(ranges) < 0.5`, `data == true`"),
            ),
        }
    }
    out
}

/// W0411: an event of an agent that the map does map, which no entry produces.
pub fn unmapped_events(model: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut first: BTreeMap<usize, &EventEntry> = BTreeMap::new();
    for e in &map.events {
        if let Some(a) = agent(model, &e.agent.value) {
            first.entry(a).or_insert(e);
        }
    }
    let mut out = Vec::new();
    for (a, entry) in first {
        let agent = &model.agents[a];
        for id in &agent.events {
            let ev = &model.events[id.index()];
            let failure = map.nodes.iter().any(|n| n.failed.as_ref().is_some_and(|f| f.value == ev.name));
            if failure || map.events.iter().any(|e| e.event.value == ev.name) {
                continue;
            }
            out.push(
                Diagnostic::warning(
                    codes::ROS2_UNMAPPED_EVENT,
                    format!("`{}` reports `{}`, but no map entry produces it", agent.name, ev.name),
                    file,
                    entry.agent.span,
                    format!("`{}` is mapped here without `{}`", agent.name, ev.name),
                )
                .with_label(ev.origin.file, ev.origin.span, "declared here")
                .with_help(format!("add an `[[event]]` for `{}`: the rules wait for it in vain", ev.name)),
            );
        }
    }
    out
}

/// E0412: one agent played by two lifecycle nodes.
pub fn two_nodes(_: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for (i, n) in map.nodes.iter().enumerate() {
        // An entry that repeats another exactly is W0417.
        let other = |m: &&map::NodeEntry| m.agent.value == n.agent.value && !check_names::same_node(m, n);
        if let Some(first) = map.nodes[..i].iter().find(other) {
            out.push(
                Diagnostic::error(
                    codes::ROS2_TWO_NODES,
                    if first.node.value == n.node.value {
                        format!("`{}` has two `[[node]]` for `{}` that differ", n.agent.value, n.node.value)
                    } else {
                        format!("`{}` is played by `{}` and by `{}`", n.agent.value, first.node.value, n.node.value)
                    },
                    file,
                    n.agent.span,
                    "second node for this agent",
                )
                .with_label(file, first.agent.span, "first node")
                .with_help("an agent is one lifecycle node: remove one `[[node]]`"),
            );
        }
    }
    out
}

/// E0413: one topic read as two message types. Entries whose type is
/// unknown are left to E0402/E0422.
pub fn topic_types(_: &Model, map: &Map, msgs: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let full = |e: &EventEntry| crate::msgs::full_name(&e.ty.value).unwrap_or_else(|| e.ty.value.clone());
    let known: Vec<&EventEntry> = map.events.iter().filter(|e| msgs.lookup(&e.ty.value).is_some()).collect();
    for (i, e) in known.iter().enumerate() {
        let earlier = known[..i].iter().find(|m| m.topic.value == e.topic.value && full(m) != full(e));
        if let Some(first) = earlier {
            out.push(
                Diagnostic::error(
                    codes::ROS2_TOPIC_TYPES,
                    format!("`{}` is read as `{}` and as `{}`", e.topic.value, full(first), full(e)),
                    file,
                    e.ty.span,
                    "second type for this topic",
                )
                .with_label(file, first.ty.span, "first type")
                .with_help("a topic carries one message type: fix the type or the topic"),
            );
        }
    }
    out
}

/// Whether `name` is a fully qualified ROS 2 node name: `/` then tokens
/// of letters, digits and `_` (not starting with a digit), separated by `/`.
pub fn is_node_name(name: &str) -> bool {
    let Some(rest) = name.strip_prefix('/') else { return false };
    !rest.is_empty()
        && rest.len() <= 255
        && rest.split('/').all(|t| {
            !t.is_empty()
                && !t.starts_with(|c: char| c.is_ascii_digit())
                && !t.contains("__")
                && t.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        })
}

/// E0414: a `[[node]]` the bridge could not drive: a name that is not a
/// ROS 2 node name, a failure event that is another agent's or carries a
/// payload, a timeout that is not a duration.
pub fn bad_nodes(model: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    let bad = |s: &map::Str, message: String, label: &str, help: &str| {
        Diagnostic::error(codes::ROS2_BAD_NODE, message, file, s.span, label).with_help(help)
    };
    for n in &map.nodes {
        if !is_node_name(&n.node.value) {
            out.push(bad(
                &n.node,
                format!("`{}` is not a fully qualified ROS 2 node name", n.node.value),
                "not a node name",
                "write `/name` or `/namespace/name`: letters, digits and `_`, not starting with a digit",
            ));
        }
        if let (Some(f), Some(ev)) = (&n.failed, n.failed.as_ref().and_then(|f| event(model, &f.value))) {
            let owner = &model.agents[ev.agent.index()].name;
            if owner != &n.agent.value && agent(model, &n.agent.value).is_some() {
                out.push(
                    bad(
                        f,
                        format!("`{}` is reported by `{owner}`, not by `{}`", f.value, n.agent.value),
                        "another agent's event",
                        "the failure of a node is an event of the agent it plays",
                    )
                    .with_label(ev.origin.file, ev.origin.span, format!("declared by `{owner}`")),
                );
            } else if !ev.fields.is_empty() {
                out.push(
                    bad(
                        f,
                        format!("`{}` has a payload; the bridge posts a node's failure with none", f.value),
                        "an event with a payload",
                        "declare an event without fields for the failure, e.g. `event PLANNER_FAILED`",
                    )
                    .with_label(ev.origin.file, ev.origin.span, "declared here"),
                );
            }
        }
        if let (Some(t), Err(reason)) = (&n.timeout, n.timeout()) {
            let help = match reason.meant() {
                Some(meant) => format!("write `timeout = \"{meant}\"`: a number and its unit with no space"),
                None => "write a number and a unit with no space, as the rules do: `timeout = \"500ms\"`, \
                         `\"1.5s\"` (units `ns`, `us`, `ms`, `s`, `min`; more than 0, at most an hour)"
                    .to_string(),
            };
            let mut d = bad(t, reason.to_string(), "not a timeout", &help);
            if let (Some(meant), Some(_)) = (reason.meant(), t.inner) {
                d = d.with_fix(format!("write `{meant}`"), file, t.sub(0, t.value.len()), meant);
            }
            out.push(d);
        }
    }
    out
}

#[cfg(test)]
#[path = "check_tests.rs"]
mod tests;
