//! The checks of a map's names and of what it reads against what the bridge
//! writes: topic names (E0415), a lifecycle node given to two agents
//! (E0416), entries that repeat each other (W0417), and the bridge's own
//! topics read back (E0418 for `/situ/…`, W0421 for `/diagnostics`).

use crate::expr::{self, BinOp, Expr, Func, Step};
use crate::map::{EventEntry, Map, NodeEntry, Str};
use crate::msgs::{self, Registry};
use situ_compiler::codes;
use situ_compiler::model::Model;
use situ_grammar::diag::{Diagnostic, FileId};

/// The longest fully qualified topic name ROS 2 accepts: 255 bytes less 8
/// kept for the middleware's prefixes (`RMW_TOPIC_MAX_NAME_LENGTH`).
pub const MAX_TOPIC_LEN: usize = 255 - 8;

/// The topics the bridge writes itself (`bridge-ros2/src/dds.rs`); the
/// `/situ` namespace is the bridge's.
pub const BRIDGE_NAMESPACE: &str = "/situ";
/// Where the bridge reports its own status, beside every node of the robot.
pub const DIAGNOSTICS: &str = "/diagnostics";
/// The `hardware_id` of every status the bridge writes on `/diagnostics`.
pub const BRIDGE_HARDWARE_ID: &str = "situ";

/// Why a name is not a topic name the bridge can read: what is wrong, and
/// where in the name (a byte range).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NameProblem {
    pub message: String,
    pub label: String,
    pub range: (usize, usize),
}

fn problem(message: impl Into<String>, label: impl Into<String>, range: (usize, usize)) -> Option<NameProblem> {
    Some(NameProblem { message: message.into(), label: label.into(), range })
}

/// The first reason `name` is not a fully qualified ROS 2 topic name
/// (design.ros2.org, "Topic and Service name mapping to DDS"): `/` then
/// tokens of `[A-Za-z0-9_]` separated by single `/`, no token starting
/// with a digit, no `__`, no `/` at the end, at most [`MAX_TOPIC_LEN`]
/// bytes. Relative names, `~` and `{…}` substitutions are refused: the
/// bridge subscribes with the name as written, from the root namespace.
pub fn topic_problem(name: &str) -> Option<NameProblem> {
    let all = (0, name.len());
    if name.is_empty() {
        return problem("the topic name is empty", "no topic", all);
    }
    if name.starts_with('~') {
        return problem(
            format!("`{name}` is a private name: `~` stands for the bridge's own node, not the robot's"),
            "a private name",
            (0, 1),
        );
    }
    if let Some(open) = name.find(['{', '}']) {
        let close = name[open..].find('}').map_or(name.len(), |c| open + c + 1);
        return problem(
            format!("`{name}` has a substitution: the bridge substitutes nothing"),
            "a substitution",
            (open, close),
        );
    }
    if !name.starts_with('/') {
        return problem(
            format!("`{name}` is a relative topic name: the bridge reads fully qualified names only"),
            "a relative name",
            all,
        );
    }
    if let Some((at, c)) = name.char_indices().find(|&(_, c)| !(c.is_ascii_alphanumeric() || c == '_' || c == '/')) {
        let shown = if c.is_whitespace() { "a space".to_string() } else { format!("`{c}`") };
        return problem(
            format!("`{name}` is not a ROS 2 topic name: {shown} is not allowed in a name"),
            format!("{shown} not allowed"),
            (at, at + c.len_utf8()),
        );
    }
    if name == "/" {
        return problem("`/` alone is a namespace, not a topic", "no topic name", all);
    }
    if let Some(at) = name.find("//") {
        return problem(format!("`{name}` has an empty token (`//`)"), "`//`", (at, at + 2));
    }
    if name.ends_with('/') {
        return problem(format!("`{name}` ends with `/`"), "a trailing `/`", (name.len() - 1, name.len()));
    }
    if let Some(at) = name.find("__") {
        return problem(format!("`{name}` has a double underscore (`__`)"), "`__`", (at, at + 2));
    }
    let mut start = 0;
    for token in name.split('/') {
        if token.starts_with(|c: char| c.is_ascii_digit()) {
            return problem(
                format!("`{name}` has a token that starts with a digit (`{token}`)"),
                "starts with a digit",
                (start, start + token.len()),
            );
        }
        start += token.len() + 1;
    }
    if name.len() > MAX_TOPIC_LEN {
        return problem(
            format!("`{}…` is {} bytes long; ROS 2 allows {MAX_TOPIC_LEN}", &name[..16], name.len()),
            "too long",
            all,
        );
    }
    None
}

/// The name that `name` was most likely meant to be, when a mechanical
/// correction gives a valid one: `/` in front of a relative name, `_` for
/// each run of characters a name cannot have, single `/` and `_`, no `/`
/// at the end. `~`, substitutions and tokens that start with a digit have
/// no mechanical correction.
pub fn corrected_topic(name: &str) -> Option<String> {
    let name = name.trim();
    if name.starts_with('~') || name.contains(['{', '}']) {
        return None;
    }
    let mut out = String::from("/");
    for c in name.chars() {
        let c = if c.is_ascii_alphanumeric() || c == '/' { c } else { '_' };
        let last = out.chars().last();
        if (c == '/' || c == '_') && last == Some(c) {
            continue;
        }
        out.push(c);
    }
    while out.len() > 1 && out.ends_with('/') {
        out.pop();
    }
    (topic_problem(&out).is_none()).then_some(out)
}

/// E0415: a `topic` that is not a fully qualified ROS 2 topic name.
pub fn bad_topics(_: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in &map.events {
        let name = &e.topic.value;
        let Some(p) = topic_problem(name) else { continue };
        let corrected = corrected_topic(name).filter(|c| c != name);
        let help = match (&corrected, name.trim_start().chars().next()) {
            (Some(c), Some('/')) => format!("write `topic = \"{c}\"`: letters, digits and single `_` between `/`"),
            (Some(c), _) => format!(
                "write `topic = \"{c}\"`: the bridge's node is in the root namespace, and a relative name \
                 resolves there to a DDS topic no ROS 2 node writes"
            ),
            (None, Some('~')) => "write the full name of the topic its publisher writes, as \
                                  `ros2 topic list` shows it, e.g. `/wrist/range`"
                .to_string(),
            (None, _) if p.label == "a substitution" => {
                "write the name the substitution stands for, e.g. `/robot1/scan`".to_string()
            }
            (None, _) => "write the topic as its publisher names it (`ros2 topic list`): `/` then tokens of \
                          letters, digits and `_`, none starting with a digit, e.g. `/scan`, `/arm/pick_2`"
                .to_string(),
        };
        let span = if e.topic.inner.is_some() && p.range.1 > p.range.0 {
            e.topic.sub(p.range.0, p.range.1)
        } else {
            e.topic.span
        };
        let mut d = Diagnostic::error(codes::ROS2_BAD_TOPIC, p.message, file, span, p.label).with_help(help);
        if let (Some(c), Some(_)) = (corrected, e.topic.inner) {
            d = d.with_fix(format!("write `{c}`"), file, e.topic.sub(0, name.len()), c);
        }
        out.push(d);
    }
    out
}

/// E0416: one lifecycle node given to two agents of the rules (an agent
/// the rules do not have is E0405, most often a misspelling of the other).
pub fn shared_nodes(model: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let known = |n: &NodeEntry| model.agents.iter().any(|a| a.name == n.agent.value);
    let mut out = Vec::new();
    for (i, n) in map.nodes.iter().enumerate().filter(|(_, n)| known(n)) {
        let first =
            map.nodes[..i].iter().find(|m| known(m) && m.node.value == n.node.value && m.agent.value != n.agent.value);
        let Some(first) = first else { continue };
        out.push(
            Diagnostic::error(
                codes::ROS2_SHARED_NODE,
                format!("`{}` plays `{}` and `{}`", n.node.value, first.agent.value, n.agent.value),
                file,
                n.node.span,
                format!("given to `{}` here", n.agent.value),
            )
            .with_label(file, first.node.span, format!("given to `{}` here", first.agent.value))
            .with_help(format!(
                "a lifecycle node plays one agent: give `{}` its own node, or remove one `[[node]]`",
                n.agent.value
            )),
        );
    }
    out
}

/// An expression's text with its insignificant spaces dropped, string
/// literals kept as written: `min(ranges)<0.5` and `min(ranges) < 0.5`
/// are the same text.
pub fn normalized(text: &str) -> String {
    let word = |c: char| c.is_ascii_alphanumeric() || c == '_' || c == '.';
    let mut out = String::with_capacity(text.len());
    let mut quote: Option<char> = None;
    let mut space = false;
    for c in text.chars() {
        if let Some(q) = quote {
            out.push(c);
            if c == q {
                quote = None;
            }
            continue;
        }
        if c.is_whitespace() {
            space = true;
            continue;
        }
        if space && out.chars().last().is_some_and(word) && word(c) {
            out.push(' ');
        }
        space = false;
        if c == '\'' || c == '"' {
            quote = Some(c);
        }
        out.push(c);
    }
    out
}

/// What makes two `[[event]]` entries the same source: agent, event, topic,
/// type (short and long forms alike) and `when`.
fn source(e: &EventEntry) -> (&str, &str, &str, String, Option<String>) {
    let ty = msgs::full_name(&e.ty.value).unwrap_or_else(|| e.ty.value.clone());
    (&e.agent.value, &e.event.value, &e.topic.value, ty, e.when.as_ref().map(|w| normalized(&w.value)))
}

fn payload(e: &EventEntry) -> Vec<(&str, String)> {
    let mut p: Vec<_> = e.payload.iter().map(|(k, v)| (k.value.as_str(), normalized(&v.value))).collect();
    p.sort();
    p
}

/// W0417: entries that repeat each other. Two `[[event]]` of the same
/// agent, event, topic, type and `when` post the event twice for every
/// message (with two payloads when theirs differ); two identical
/// `[[node]]` say one thing twice.
pub fn duplicates(_: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for (i, e) in map.events.iter().enumerate() {
        let Some(first) = map.events[..i].iter().find(|m| source(m) == source(e)) else { continue };
        let same_payload = payload(first) == payload(e);
        let (message, help) = if same_payload {
            (
                format!(
                    "this entry repeats another: every message on `{}` posts `{}` twice",
                    e.topic.value, e.event.value
                ),
                "remove one of the two entries".to_string(),
            )
        } else {
            (
                format!(
                    "two entries post `{}` for every message on `{}`, with two payloads",
                    e.event.value, e.topic.value
                ),
                "remove one of the two entries, or give them `when`s that exclude each other".to_string(),
            )
        };
        out.push(
            Diagnostic::warning(codes::ROS2_DUPLICATE_ENTRY, message, file, e.span, "the second entry")
                .with_label(file, first.span, "the first entry")
                .with_help(help),
        );
    }
    for (i, n) in map.nodes.iter().enumerate() {
        let Some(first) = map.nodes[..i].iter().find(|m| same_node(m, n)) else { continue };
        out.push(
            Diagnostic::warning(
                codes::ROS2_DUPLICATE_ENTRY,
                format!("this `[[node]]` repeats another: `{}` plays `{}`", n.node.value, n.agent.value),
                file,
                n.agent.span,
                "the second entry",
            )
            .with_label(file, first.agent.span, "the first entry")
            .with_help("remove one of the two entries"),
        );
    }
    out
}

/// Whether two `[[node]]` say exactly the same: agent, node, failure event
/// and timeout.
pub fn same_node(a: &NodeEntry, b: &NodeEntry) -> bool {
    let opt = |s: &Option<Str>| s.as_ref().map(|s| s.value.clone());
    a.agent.value == b.agent.value
        && a.node.value == b.node.value
        && opt(&a.failed) == opt(&b.failed)
        && opt(&a.timeout) == opt(&b.timeout)
}

/// Whether `topic` is in the bridge's own namespace (`/situ`, `/situ/…`).
pub fn is_bridge_topic(topic: &str) -> bool {
    topic.strip_prefix(BRIDGE_NAMESPACE).is_some_and(|rest| rest.is_empty() || rest.starts_with('/'))
}

/// E0418: an entry that reads the bridge's own topics, `/situ/…`.
pub fn own_topics(_: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in map.events.iter().filter(|e| is_bridge_topic(&e.topic.value)) {
        out.push(
            Diagnostic::error(
                codes::ROS2_BRIDGE_TOPIC,
                format!("`{}` is the bridge's own output: the rules would read what they wrote", e.topic.value),
                file,
                e.topic.span,
                "written by the bridge",
            )
            .with_help(
                "map the robot's topic that reports the event; the state the rules are in is `state == …` \
                 in the rules themselves, not an event (`/situ/state`, `/situ/agents` and the rest of \
                 `/situ` are the bridge's)",
            ),
        );
    }
    out
}

/// Whether a `when` names the reporter of a status so that no status the
/// bridge writes can match it: one of its `and`-ed conditions is
/// `….hardware_id == 'x'` or `….name == 'x'` with `x` not the bridge's, or
/// `….hardware_id != 'situ'`, or `any(status, c)` where `c` does, or an
/// `or` of which each side does.
pub fn names_its_reporter(when: &str) -> bool {
    expr::parse(when).is_ok_and(|e| names_reporter(&e))
}

fn names_reporter(e: &Expr) -> bool {
    let mut conjuncts = vec![e];
    let mut found = false;
    while let Some(c) = conjuncts.pop() {
        match c {
            Expr::Binary(BinOp::And, l, r, _) => conjuncts.extend([l.as_ref(), r.as_ref()]),
            Expr::Binary(BinOp::Or, l, r, _) => found |= names_reporter(l) && names_reporter(r),
            Expr::Call(Func::Any, args, _) => found |= args.get(1).is_some_and(names_reporter),
            Expr::Binary(op @ (BinOp::Eq | BinOp::Ne), l, r, _) => {
                let (path, lit) = match (l.as_ref(), r.as_ref()) {
                    (Expr::Path(p, _), Expr::Str(s, _)) | (Expr::Str(s, _), Expr::Path(p, _)) => (p, s),
                    _ => continue,
                };
                let field = match path.last() {
                    Some(Step::Field(f, _)) => f.as_str(),
                    _ => continue,
                };
                let bridge_name = lit.starts_with("situ:");
                found |= match (op, field) {
                    (BinOp::Eq, "hardware_id") => lit != BRIDGE_HARDWARE_ID,
                    (BinOp::Eq, "name") => !bridge_name,
                    (BinOp::Ne, "hardware_id") => lit == BRIDGE_HARDWARE_ID,
                    _ => false,
                };
            }
            _ => {}
        }
    }
    found
}

/// W0421: an entry that reads `/diagnostics`, where the bridge reports its
/// own status, without naming the reporter of the status it reads.
pub fn bridge_diagnostics(_: &Model, map: &Map, _: &Registry, file: FileId) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for e in map.events.iter().filter(|e| e.topic.value == DIAGNOSTICS) {
        if e.when.as_ref().is_some_and(|w| names_its_reporter(&w.value)) {
            continue;
        }
        out.push(
            Diagnostic::warning(
                codes::ROS2_BRIDGE_DIAGNOSTICS,
                format!(
                    "`{DIAGNOSTICS}` is also where the bridge reports its own status (once a second, \
                     `hardware_id` `{BRIDGE_HARDWARE_ID}`), and this entry does not tell them apart"
                ),
                file,
                e.topic.span,
                "the bridge writes here too",
            )
            .with_help(
                "the bridge ignores the messages of its own writers, but not another situ bridge's on the \
                 domain: name the reporter in `when`, e.g. `any(status, level >= 2 and hardware_id != 'situ')` \
                 or `and status[0].hardware_id == 'base'`, or read the aggregator's `/diagnostics_agg`",
            ),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn topic_names_follow_ros2() {
        for good in ["/scan", "/a/b_c/D9", "/_hidden", "/robot1/arm/pick_2", "/diagnostics"] {
            assert_eq!(topic_problem(good), None, "{good}");
        }
        let cases = [
            ("", "no topic"),
            ("scan", "a relative name"),
            ("~/range", "a private name"),
            ("/{robot}/scan", "a substitution"),
            ("/wrist-range", "`-` not allowed"),
            ("/e stop", "a space not allowed"),
            ("/é", "`é` not allowed"),
            ("/", "no topic name"),
            ("/a//b", "`//`"),
            ("/a/", "a trailing `/`"),
            ("/a__b", "`__`"),
            ("/2pick", "starts with a digit"),
            ("/arm/9", "starts with a digit"),
        ];
        for (bad, label) in cases {
            let p = topic_problem(bad).unwrap_or_else(|| panic!("{bad:?} passes"));
            assert_eq!(p.label, label, "{bad:?}");
            assert!(p.range.0 <= p.range.1 && p.range.1 <= bad.len(), "{bad:?}: {:?}", p.range);
        }
        assert_eq!(topic_problem("/2pick").unwrap().range, (1, 6));
        assert_eq!(topic_problem("/wrist-range").unwrap().range, (6, 7));
        let long = format!("/{}", "a".repeat(MAX_TOPIC_LEN));
        assert_eq!(topic_problem(&long).map(|p| p.label), Some("too long".to_string()));
        assert_eq!(topic_problem(&long[..MAX_TOPIC_LEN]), None);
    }

    #[test]
    fn corrections_are_valid_names() {
        let cases = [
            ("/wrist-range", Some("/wrist_range")),
            ("/e stop", Some("/e_stop")),
            ("scan", Some("/scan")),
            ("/a//b/", Some("/a/b")),
            ("/a__b", Some("/a_b")),
            ("/a - b", Some("/a_b")),
            ("/2pick", None),
            ("~/range", None),
            ("/{ns}/scan", None),
            ("", None),
        ];
        for (name, want) in cases {
            assert_eq!(corrected_topic(name).as_deref(), want, "{name:?}");
        }
    }

    #[test]
    fn expressions_compare_without_their_spaces() {
        assert_eq!(normalized("min(ranges)<0.5"), normalized(" min( ranges ) < 0.5 "));
        assert_eq!(normalized("not  data"), "not data");
        assert_ne!(normalized("not data"), normalized("notdata"));
        assert_ne!(normalized("name == 'a b'"), normalized("name == 'ab'"));
        assert_eq!(normalized("a and b"), normalized("a\tand\nb"));
    }

    #[test]
    fn a_reporter_is_named_by_a_conjunct() {
        for named in [
            "status[0].hardware_id == 'base'",
            "len(status) > 0 and status[0].level >= 1 and status[0].hardware_id == 'base'",
            "'lidar' == status[0].name and status[0].level >= 2",
            "status[0].level >= 0 and status[0].hardware_id != 'situ'",
            "any(status, level >= 2 and hardware_id != 'situ')",
            "any(status, hardware_id == 'arm' and (level >= 2 or any(values, key == 'fault')))",
            "any(status, name == 'motor' or name == 'lidar') and len(status) > 0",
        ] {
            assert!(names_its_reporter(named), "{named}");
        }
        for unnamed in [
            "status[0].level >= 0",
            "status[0].hardware_id == 'situ'",
            "status[0].name == 'situ: bridge'",
            "status[0].hardware_id == 'base' or status[0].level >= 2",
            "not (status[0].hardware_id == 'base')",
            "status[0].hardware_id != 'base'",
            "status[0].level >=",
            "any(status, level >= 2)",
            "any(status, level >= 2 or hardware_id == 'arm')",
            "all(status, hardware_id == 'arm')",
            "not any(status, hardware_id == 'arm')",
        ] {
            assert!(!names_its_reporter(unnamed), "{unnamed}");
        }
    }

    #[test]
    fn the_bridge_namespace_is_situ() {
        for own in ["/situ", "/situ/state", "/situ/agents", "/situ/x/y"] {
            assert!(is_bridge_topic(own), "{own}");
        }
        for other in ["/situation", "/situs/state", "/robot/situ/state", "/diagnostics"] {
            assert!(!is_bridge_topic(other), "{other}");
        }
    }
}
