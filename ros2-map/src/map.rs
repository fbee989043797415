//! The map file (TOML), parsed with the place of every value: which topic and
//! message type each event comes from, how its payload is read, and which
//! agents are played by ROS 2 lifecycle nodes.

use serde::Deserialize;
use situ_compiler::codes;
use situ_grammar::ast::Span;
use situ_grammar::diag::{Diagnostic, FileId};
use std::collections::BTreeMap;
use std::time::Duration;
use toml::Spanned;

/// A string of the map and where it is.
#[derive(Debug, Clone)]
pub struct Str {
    pub value: String,
    /// The whole value as written, quotes included.
    pub span: Span,
    /// Where the text of the value starts in the file, when it is written
    /// as is (no escapes, one line): expression errors then point inside it.
    pub inner: Option<usize>,
}

impl Str {
    /// The place of `start..end` of the value, or of the whole value.
    pub fn sub(&self, start: usize, end: usize) -> Span {
        match self.inner {
            Some(at) => Span::new(at + start.min(self.value.len()), at + end.min(self.value.len())),
            None => self.span,
        }
    }
}

/// One `[[event]]`: an event of the rules read from a topic.
#[derive(Debug, Clone)]
pub struct EventEntry {
    pub agent: Str,
    pub event: Str,
    pub topic: Str,
    pub ty: Str,
    pub when: Option<Str>,
    /// Payload field name and its expression, in the order of the file.
    pub payload: Vec<(Str, Str)>,
    /// The whole entry's header `[[event]]` is not spanned by TOML; the
    /// event name stands for the entry.
    pub span: Span,
}

/// One `[[node]]`: an agent played by a ROS 2 lifecycle node.
#[derive(Debug, Clone)]
pub struct NodeEntry {
    pub agent: Str,
    pub node: Str,
    /// The agent's event the bridge posts when a transition of the node
    /// fails or is not answered in time.
    pub failed: Option<Str>,
    /// How long the bridge waits for the node to answer a request
    /// (`500ms`, `2s`); see [`NodeEntry::timeout`].
    pub timeout: Option<Str>,
}

/// How long the bridge waits for a lifecycle node's answer when the map
/// does not say.
pub const DEFAULT_NODE_TIMEOUT: Duration = Duration::from_secs(1);

impl NodeEntry {
    /// The node's answer timeout: the map's, or [`DEFAULT_NODE_TIMEOUT`];
    /// `Err` with the reason when the map's is not a duration.
    pub fn timeout(&self) -> Result<Duration, DurationError> {
        match &self.timeout {
            None => Ok(DEFAULT_NODE_TIMEOUT),
            Some(t) => parse_duration(&t.value),
        }
    }
}

/// Why a map's timeout is not a duration.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DurationError {
    #[error("`{0}` is not a duration: write a whole number and `ms` or `s`")]
    NotADuration(String),
    #[error("`{0}` is out of range: a timeout is more than 0 and at most 1 hour")]
    OutOfRange(String),
}

/// A duration as the rules write one: a whole number and `ms` or `s`,
/// greater than zero and at most an hour.
pub fn parse_duration(text: &str) -> Result<Duration, DurationError> {
    let text = text.trim();
    let (digits, unit) = match text.strip_suffix("ms") {
        Some(d) => (d, 1u64),
        None => match text.strip_suffix('s') {
            Some(d) => (d, 1000u64),
            None => return Err(DurationError::NotADuration(text.to_string())),
        },
    };
    let n: u64 = digits.trim().parse().map_err(|_| DurationError::NotADuration(text.to_string()))?;
    let ms = n.saturating_mul(unit);
    if ms == 0 || ms > 3_600_000 {
        return Err(DurationError::OutOfRange(text.to_string()));
    }
    Ok(Duration::from_millis(ms))
}

/// A parsed map.
#[derive(Debug, Clone, Default)]
pub struct Map {
    /// `msg_path`: folders of message definitions, relative to the map file.
    pub msg_path: Vec<Str>,
    pub events: Vec<EventEntry>,
    pub nodes: Vec<NodeEntry>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMap {
    #[serde(default)]
    msg_path: Vec<Spanned<String>>,
    #[serde(default)]
    event: Vec<RawEvent>,
    #[serde(default)]
    node: Vec<RawNode>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawEvent {
    agent: Spanned<String>,
    event: Spanned<String>,
    topic: Spanned<String>,
    #[serde(rename = "type")]
    ty: Spanned<String>,
    when: Option<Spanned<String>>,
    #[serde(default)]
    payload: BTreeMap<Spanned<String>, Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawNode {
    agent: Spanned<String>,
    node: Spanned<String>,
    failed: Option<Spanned<String>>,
    timeout: Option<Spanned<String>>,
}

/// Parses a map; a text that is not TOML or not of this form is one
/// finding (E0401) at the place TOML gives.
pub fn parse(text: &str, file: FileId) -> Result<Map, Box<Diagnostic>> {
    let raw: RawMap = toml::from_str(text).map_err(|err| {
        let span = err.span().map_or(Span::new(0, 0), |r| Span::new(r.start, r.end));
        let message = err.message().trim().to_string();
        let label = message.lines().next().unwrap_or("here").to_string();
        let help = "see `docs/ros2.md`: `[[event]]` needs `agent`, `event`, `topic` and `type`; \
                    `[[node]]` needs `agent` and `node`";
        let d =
            Diagnostic::error(codes::ROS2_BAD_MAP, format!("the map is not a valid map: {label}"), file, span, label);
        Box::new(d.with_help(help))
    })?;
    let s = |v: Spanned<String>| str_of(text, v);
    let events = raw
        .event
        .into_iter()
        .map(|e| {
            let mut payload: Vec<(Str, Str)> = e.payload.into_iter().map(|(k, v)| (s(k), s(v))).collect();
            payload.sort_by_key(|(k, _)| k.span.start);
            let event = s(e.event);
            EventEntry {
                span: event.span,
                agent: s(e.agent),
                event,
                topic: s(e.topic),
                ty: s(e.ty),
                when: e.when.map(s),
                payload,
            }
        })
        .collect();
    let nodes = raw
        .node
        .into_iter()
        .map(|n| NodeEntry { agent: s(n.agent), node: s(n.node), failed: n.failed.map(s), timeout: n.timeout.map(s) })
        .collect();
    Ok(Map { msg_path: raw.msg_path.into_iter().map(s).collect(), events, nodes })
}

fn str_of(text: &str, v: Spanned<String>) -> Str {
    let range = v.span();
    let span = Span::new(range.start, range.end);
    let raw = text.get(range.clone()).unwrap_or("");
    let value = v.into_inner();
    let inner = ["\"", "'"].iter().find_map(|q| {
        let body = raw.strip_prefix(q)?.strip_suffix(q)?;
        (body == value && !value.contains('\n')).then_some(range.start + q.len())
    });
    // A bare key (`distance = …`) is its own text.
    let inner = inner.or((raw == value).then_some(range.start));
    Str { value, span, inner }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_keep_their_places() {
        let text = "[[event]]\nagent = \"A\"\nevent = 'E'\ntopic = \"/t\"\ntype = \"std_msgs/Bool\"\n\
                    when = \"data\"\n[event.payload]\nx = \"1 + 2\"\n";
        let map = parse(text, FileId(0)).unwrap();
        let e = &map.events[0];
        assert_eq!(&text[e.agent.span.start..e.agent.span.end], "\"A\"");
        assert_eq!(e.event.inner, Some(text.find("'E'").unwrap() + 1));
        let (k, v) = &e.payload[0];
        assert_eq!(&text[k.span.start..k.span.end], "x");
        assert_eq!(&text[v.sub(4, 5).start..v.sub(4, 5).end], "2");
    }

    #[test]
    fn escapes_point_at_the_whole_value() {
        let text = "[[node]]\nagent = \"A\\u0041\"\nnode = \"/n\"\n";
        let map = parse(text, FileId(0)).unwrap();
        assert_eq!(map.nodes[0].agent.value, "AA");
        assert_eq!(map.nodes[0].agent.inner, None);
    }

    #[test]
    fn timeouts_are_durations() {
        assert_eq!(parse_duration("500ms"), Ok(Duration::from_millis(500)));
        assert_eq!(parse_duration("2s"), Ok(Duration::from_secs(2)));
        for bad in ["", "0ms", "2", "1.5s", "-1s", "2h", "3601s", "99999999999999999999s"] {
            assert!(parse_duration(bad).is_err(), "{bad:?}");
        }
    }

    #[test]
    fn not_toml_and_missing_keys_have_places() {
        for text in ["[[event]\n", "[[event]]\nagent = \"A\"\n", "[[node]]\nagent = 3\nnode = \"/n\"\n", "x = 1\n"] {
            let d = parse(text, FileId(0)).unwrap_err();
            assert_eq!(d.code, codes::ROS2_BAD_MAP);
            assert!(d.primary.span.end <= text.len(), "{text:?}: {:?}", d.primary.span);
        }
    }
}
