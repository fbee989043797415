//! What the engine reports: the facts a firing matched, the firings of a
//! step and their explanation in source terms, why an event was refused,
//! and values and times as situ writes them.

use situ_bundle::{Content, FieldType, Value};

/// A fact as matched by a firing, for explanations.
#[derive(Debug, Clone, PartialEq)]
pub struct MatchedFact {
    pub agent: u32,
    pub event: u32,
    pub payload: Vec<Value>,
    pub time: u64,
    pub run: u64,
}

/// An agent's live fact, borrowed from the working memory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactView<'a> {
    pub event: u32,
    pub payload: &'a [Value],
    pub time: u64,
    pub run: u64,
    /// The posting sequence number: a later report has a larger one.
    pub seq: u64,
}

/// One rule firing.
#[derive(Debug, Clone, PartialEq)]
pub struct Firing {
    pub rule: u32,
    pub from: u32,
    pub to: u32,
    /// Now, when it fired.
    pub time: u64,
    /// The facts its positive patterns matched, in pattern order.
    pub matched: Vec<MatchedFact>,
    /// The agents its `stale A` tests found stale.
    pub stale: Vec<u32>,
}

/// What one event (or a settling) did: the rules that fired, in order.
#[derive(Debug, Clone, PartialEq)]
pub struct StateChange {
    /// The state at rest before, and after.
    pub from: u32,
    pub to: u32,
    pub time: u64,
    pub firings: Vec<Firing>,
}

impl StateChange {
    /// Whether the state at rest changed (a cascade may come back).
    pub fn changed(&self) -> bool {
        self.from != self.to
    }

    /// The change in source terms: every firing with its rule, where it is
    /// written, and the facts that made it hold.
    pub fn explain(&self, c: &Content) -> String {
        let mut out = format!(
            "{} -> {} at {}",
            c.states[self.from as usize].name,
            c.states[self.to as usize].name,
            format_time(self.time)
        );
        for f in &self.firings {
            let rule = &c.rules[f.rule as usize];
            out.push_str(&format!(
                "\n  rule `{}` ({}, salience {}) fired in {}: ",
                rule.name, rule.source, rule.salience, c.states[f.from as usize].name
            ));
            let mut why: Vec<String> = f.matched.iter().map(|m| describe_fact(c, m)).collect();
            why.extend(f.stale.iter().map(|&a| format!("{} stale", c.agents[a as usize].name)));
            if why.is_empty() {
                out.push_str("its state guard holds");
            } else {
                out.push_str(&why.join(", "));
            }
            out.push_str(&format!(" -> {}", c.states[f.to as usize].name));
        }
        out
    }
}

/// A fact as a person writes an event: `LAOBS(distance: 12.0, height: 0.5) x2 at 1.230s`.
pub fn describe_fact(c: &Content, m: &MatchedFact) -> String {
    let e = &c.events[m.event as usize];
    let mut s = e.name.clone();
    if !e.fields.is_empty() {
        let args: Vec<String> =
            e.fields.iter().zip(&m.payload).map(|(f, v)| format!("{}: {}", f.name, show_value(&f.ty, *v))).collect();
        s.push_str(&format!("({})", args.join(", ")));
    }
    if m.run > 1 {
        s.push_str(&format!(" x{}", m.run));
    }
    s.push_str(&format!(" at {}", format_time(m.time)));
    s
}

/// A value as written in situ.
pub fn show_value(ty: &FieldType, v: Value) -> String {
    match (ty, v) {
        (FieldType::Symbols(s), Value::Symbol(i)) => s.get(i as usize).cloned().unwrap_or_else(|| format!("#{i}")),
        (_, Value::F64(f)) if f.is_finite() && f.fract() == 0.0 && f.abs() < 1e15 => format!("{f:.1}"),
        (_, Value::F64(f)) => format!("{f}"),
        (_, Value::I64(i)) => i.to_string(),
        (_, Value::Bool(b)) => b.to_string(),
        (_, Value::Symbol(i)) => format!("#{i}"),
    }
}

/// Nanoseconds as seconds with millisecond precision: `1.230s`.
pub fn format_time(ns: u64) -> String {
    format!("{}.{:03}s", ns / 1_000_000_000, (ns / 1_000_000) % 1000)
}

/// Why [`Engine::step`](super::Engine::step) did not take an event, or
/// what went wrong while it was processed: [`PostError`] without what it
/// owns (a field's type, a cascade's firings), so that the hot path's
/// result needs no drop and a refusal no allocation.
/// [`Engine::post_error`](super::Engine::post_error) gives the
/// [`PostError`] (right after the step: a cascade's firings are the step's
/// record).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StepError {
    /// No event has this id in the bundle.
    UnknownEvent { event: u32 },
    /// The payload has the wrong number of values.
    Arity { event: u32, expected: usize, found: usize },
    /// A value does not fit its field's type.
    Type { event: u32, field: u32 },
    /// Stamped before the same agent's latest accepted event.
    OutOfOrder { event: u32, time: u64, last: u64 },
    /// Stamped more than the skew bound ahead of the clock it arrived at.
    FromTheFuture { event: u32, time: u64, clock: u64, max_skew: u64 },
    /// The network did not come to rest within the bound (the firings are
    /// the step's: [`Engine::last_change`](super::Engine::last_change)).
    Cascade { limit: usize },
}

/// Why an event was not taken, or what went wrong while it was processed.
#[derive(Debug, Clone, PartialEq)]
pub enum PostError {
    /// No event has this id in the bundle.
    UnknownEvent { event: u32 },
    /// The payload has the wrong number of values.
    Arity { event: u32, expected: usize, found: usize },
    /// A value does not fit its field's type.
    Type { event: u32, field: u32, expected: FieldType },
    /// Reported on the bus by another agent than the event's (the engine
    /// takes the agent from the event; the Bulletinboard's bus checks it).
    AnotherAgent { event: u32, agent: u32 },
    /// Stamped before the same agent's latest accepted event.
    OutOfOrder { event: u32, time: u64, last: u64 },
    /// Stamped more than the skew bound ahead of the clock it arrived at.
    FromTheFuture { event: u32, time: u64, clock: u64, max_skew: u64 },
    /// The network did not come to rest within the bound: the firings so
    /// far, which name the rules. The state is the last one reached.
    Cascade { limit: usize, firings: Vec<Firing> },
}

impl PostError {
    /// A short key for why an event was refused, the same in every count
    /// of refusals (a running stack's, `situ bench`'s): `unknown event`,
    /// `another agent's event`, `out of order`, `from the future`,
    /// `payload`.
    pub fn key(&self) -> &'static str {
        match self {
            PostError::UnknownEvent { .. } => "unknown event",
            PostError::AnotherAgent { .. } => "another agent's event",
            PostError::OutOfOrder { .. } => "out of order",
            PostError::FromTheFuture { .. } => "from the future",
            PostError::Arity { .. } | PostError::Type { .. } | PostError::Cascade { .. } => "payload",
        }
    }

    pub fn describe(&self, c: &Content) -> String {
        match self {
            PostError::UnknownEvent { event } => format!("unknown event id {event}"),
            PostError::Arity { event, expected, found } => format!(
                "event `{}` has {expected} payload field(s), {found} given",
                c.events.get(*event as usize).map_or("?", |e| &e.name)
            ),
            PostError::Type { event, field, expected } => {
                let e = &c.events[*event as usize];
                format!(
                    "field `{}.{}` is {}, the value is not",
                    e.name,
                    e.fields[*field as usize].name,
                    expected.describe()
                )
            }
            PostError::AnotherAgent { event, agent } => {
                let e = &c.events[*event as usize];
                let who = c.agents.get(*agent as usize).map_or("?", |a| a.name.as_str());
                format!("`{}` is an event of `{}`, not of `{who}`", e.name, c.agents[e.agent as usize].name)
            }
            PostError::OutOfOrder { time, last, .. } => {
                format!("out of order: at {time} ns, after an event of the same agent at {last} ns")
            }
            PostError::FromTheFuture { time, clock, max_skew, .. } => format!(
                "from the future: at {time} ns, {} ns ahead of the Bulletinboard's clock (at most {max_skew} ns)",
                time - clock
            ),
            PostError::Cascade { limit, firings } => {
                let mut names: Vec<&str> = firings.iter().map(|f| c.rules[f.rule as usize].name.as_str()).collect();
                names.dedup();
                format!(
                    "the rules did not come to rest within {limit} firings: {} (an oscillation: make their conditions exclude each other)",
                    names.join(", ")
                )
            }
        }
    }
}
