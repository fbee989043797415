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
    /// Not of the form of the rules' durations; with the form meant, when
    /// it is plain (`500 ms` → `500ms`, `2 sec` → `2s`).
    #[error("`{text}` is not a duration: write a number and a unit with no space (`500ms`, `1.5s`)")]
    NotADuration { text: String, meant: Option<String> },
    #[error("`{0}` is out of range: a timeout is more than 0 and at most 1 hour")]
    OutOfRange(String),
}

impl DurationError {
    /// The duration as it should have been written, when that is plain.
    pub fn meant(&self) -> Option<&str> {
        match self {
            DurationError::NotADuration { meant, .. } => meant.as_deref(),
            DurationError::OutOfRange(_) => None,
        }
    }
}

/// The longest timeout of a node, in nanoseconds: an hour.
const MAX_TIMEOUT_NS: u64 = 3_600_000_000_000;

/// The units of a duration, as the rules write them (`docs/language.md`
/// 2.6), with their nanoseconds.
const UNITS: [(&str, u64); 5] =
    [("ns", 1), ("us", 1_000), ("ms", 1_000_000), ("min", 60_000_000_000), ("s", 1_000_000_000)];

/// A duration as the rules write one: a number (`2`, `1.5`) immediately
/// followed by `ns`, `us`, `ms`, `s` or `min`, no space and no sign;
/// greater than zero and at most an hour.
pub fn parse_duration(text: &str) -> Result<Duration, DurationError> {
    let not_one = || DurationError::NotADuration { text: text.to_string(), meant: meant(text) };
    let nanos = exact(text).ok_or_else(not_one)?;
    match nanos {
        Some(n) if n > 0 && n <= MAX_TIMEOUT_NS => Ok(Duration::from_nanos(n)),
        _ => Err(DurationError::OutOfRange(text.to_string())),
    }
}

/// The nanoseconds of `text` written exactly as the rules write a
/// duration: `None` when it is not of that form, `Some(None)` when it is
/// but its value does not fit (or is finer than a nanosecond).
fn exact(text: &str) -> Option<Option<u64>> {
    let split = text.find(|c: char| !(c.is_ascii_digit() || c == '.'))?;
    let (number, unit) = text.split_at(split);
    let scale = UNITS.iter().find(|(u, _)| *u == unit)?.1;
    let (int, frac) = number.split_once('.').unwrap_or((number, ""));
    let well_formed = !int.is_empty()
        && int.bytes().all(|b| b.is_ascii_digit())
        && (!number.contains('.') || (!frac.is_empty() && frac.bytes().all(|b| b.is_ascii_digit())));
    if !well_formed {
        return None;
    }
    Some(scaled(int, frac, scale))
}

/// `int.frac × scale` in integers, exactly; `None` when it overflows or
/// has a non-zero digit finer than the unit `1`.
fn scaled(int: &str, frac: &str, scale: u64) -> Option<u64> {
    let mut total = int.parse::<u64>().ok()?.checked_mul(scale)?;
    let mut unit = scale;
    for d in frac.bytes() {
        unit /= 10;
        if unit == 0 {
            if d != b'0' {
                return None;
            }
            continue;
        }
        total = total.checked_add(u64::from(d - b'0') * unit)?;
    }
    Some(total)
}

/// What a timeout that is not a duration most likely meant: the same
/// number and unit without spaces, a unit's long name (`sec`, `millis`,
/// `seconds`) as its symbol, `,` as the decimal point.
fn meant(text: &str) -> Option<String> {
    let squeezed: String = text.chars().filter(|c| !c.is_whitespace()).collect::<String>().replace(',', ".");
    let split = squeezed.find(|c: char| !(c.is_ascii_digit() || c == '.'))?;
    let (number, unit) = squeezed.split_at(split);
    let unit = match unit.to_ascii_lowercase().as_str() {
        "ns" | "nsec" | "nanos" | "nanosecond" | "nanoseconds" => "ns",
        "us" | "µs" | "usec" | "micros" | "microsecond" | "microseconds" => "us",
        "ms" | "msec" | "msecs" | "millis" | "millisecond" | "milliseconds" => "ms",
        "s" | "sec" | "secs" | "second" | "seconds" => "s",
        "min" | "mins" | "minute" | "minutes" => "min",
        _ => return None,
    };
    let candidate = format!("{number}{unit}");
    let fits = matches!(exact(&candidate), Some(Some(n)) if n > 0 && n <= MAX_TIMEOUT_NS);
    (candidate != text && fits).then_some(candidate)
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
        let help = quote_help(text, span.start).unwrap_or(
            "see `docs/ros2.md`: `[[event]]` needs `agent`, `event`, `topic` and `type`; \
             `[[node]]` needs `agent` and `node`",
        );
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

/// The help of a TOML error on a line whose string a quote of the same kind
/// closed early (`when = "name == "motor""`).
fn quote_help(text: &str, at: usize) -> Option<&'static str> {
    let start = text.get(..at)?.rfind('\n').map_or(0, |i| i + 1);
    let end = text.get(at..)?.find('\n').map_or(text.len(), |i| at + i);
    let line = text.get(start..end)?;
    if line.matches('"').count() >= 3 {
        Some(
            "a `\"` inside a TOML string `\"…\"` ends it: write the expression's strings in single quotes \
             (`when = \"name == 'motor'\"`), or the whole expression as a TOML literal string \
             (`when = 'name == \"motor\"'`)",
        )
    } else if line.matches('\'').count() >= 3 {
        Some(
            "a `'` inside a TOML literal string `'…'` ends it: write the expression in double quotes and its \
             strings in single quotes (`when = \"name == 'motor'\"`)",
        )
    } else {
        None
    }
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
    fn timeouts_are_durations_as_the_rules_write_them() {
        assert_eq!(parse_duration("500ms"), Ok(Duration::from_millis(500)));
        assert_eq!(parse_duration("2s"), Ok(Duration::from_secs(2)));
        assert_eq!(parse_duration("1.5s"), Ok(Duration::from_millis(1500)));
        assert_eq!(parse_duration("0.25s"), Ok(Duration::from_millis(250)));
        assert_eq!(parse_duration("2min"), Ok(Duration::from_secs(120)));
        assert_eq!(parse_duration("60min"), Ok(Duration::from_secs(3600)));
        assert_eq!(parse_duration("750us"), Ok(Duration::from_micros(750)));
        assert_eq!(parse_duration("100ns"), Ok(Duration::from_nanos(100)));
        for bad in
            ["", "2", "s", ".5s", "1.s", "1..5s", "-1s", "+1s", "2h", "1e3ms", "500 ms", " 500ms", "500ms ", "2 S"]
        {
            assert!(matches!(parse_duration(bad), Err(DurationError::NotADuration { .. })), "{bad:?}");
        }
        for out in ["0ms", "0.0s", "3601s", "61min", "99999999999999999999s", "0.0000000001s"] {
            assert!(matches!(parse_duration(out), Err(DurationError::OutOfRange(_))), "{out:?}");
        }
    }

    #[test]
    fn a_timeout_that_is_not_a_duration_says_the_form_meant() {
        let meant = |t: &str| parse_duration(t).unwrap_err().meant().map(str::to_string);
        assert_eq!(meant("500 ms").as_deref(), Some("500ms"));
        assert_eq!(meant(" 2s ").as_deref(), Some("2s"));
        assert_eq!(meant("2 sec").as_deref(), Some("2s"));
        assert_eq!(meant("1,5 seconds").as_deref(), Some("1.5s"));
        assert_eq!(meant("250 millis").as_deref(), Some("250ms"));
        assert_eq!(meant("2 S").as_deref(), Some("2s"));
        for none in ["", "2", "2h", "fast", "-1s", "0 ms", "2 hours"] {
            assert_eq!(meant(none), None, "{none:?}");
        }
    }

    #[test]
    fn a_quote_that_ends_the_string_early_is_named() {
        for (text, fix) in [
            ("[[event]]\nwhen = \"find(status, name == \"motor\").level > 1\"\n", "single quotes"),
            ("[[event]]\nwhen = 'name == 'motor''\n", "in double quotes"),
        ] {
            let d = parse(text, FileId(0)).unwrap_err();
            assert_eq!(d.code, codes::ROS2_BAD_MAP);
            assert!(d.help.as_deref().is_some_and(|h| h.contains(fix)), "{text}: {d:?}");
        }
        let d = parse("[[event]\n", FileId(0)).unwrap_err();
        assert!(d.help.as_deref().is_some_and(|h| h.starts_with("see `docs/ros2.md`")), "{d:?}");
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
