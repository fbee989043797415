//! Event streams: a seeded random generator over a bundle's event alphabet,
//! and the text form of `bench/README.md` that every benchmarked engine reads.
//!
//! The generator is meant to exercise rules, not to be uniform:
//! - agents report in proportion to their `rate` (10 Hz when not given), at
//!   exponentially distributed intervals, so that the stale timers of the
//!   rules file are sometimes exceeded, as on a real bus;
//! - an agent repeats its previous event with probability 0.8, so that run
//!   lengths `xN` build up;
//! - numeric payloads are drawn near the constants the rules compare the
//!   field with (the thresholds) most of the time, else from a wide range;
//! - f64 values have 3 decimals and are what their text parses to, so that
//!   an engine reading the text form sees exactly the same numbers.
//!
//! The same seed gives the same stream, on every machine.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use situ_compiler::bundle::{AlphaNode, Check, Content, FieldType, Operand, Value};
use std::fmt::Write as _;
use std::sync::Arc;

/// One event of a stream.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    pub event: u32,
    /// Nanoseconds.
    pub time: u64,
    pub payload: Vec<Value>,
}

/// A seeded stream of events over a bundle's alphabet.
pub struct Generator {
    content: Arc<Content>,
    rng: ChaCha8Rng,
    /// Agents that report events, and the cumulative weights to pick one.
    agents: Vec<u32>,
    cumulative: Vec<f64>,
    /// Mean interval between two events, nanoseconds.
    mean_gap: f64,
    last: Vec<Option<u32>>,
    /// Per event, per field: the constants the rules compare it with.
    thresholds: Vec<Vec<Vec<f64>>>,
    now: u64,
}

impl Generator {
    pub fn new(content: Arc<Content>, seed: u64) -> Generator {
        let mut agents = Vec::new();
        let mut cumulative = Vec::new();
        let mut total = 0.0;
        for (i, a) in content.agents.iter().enumerate() {
            if a.events.is_empty() {
                continue;
            }
            total += a.rate_hz.filter(|r| r.is_finite() && *r > 0.0).unwrap_or(10.0);
            agents.push(i as u32);
            cumulative.push(total);
        }
        let mut thresholds: Vec<Vec<Vec<f64>>> =
            content.events.iter().map(|e| vec![Vec::new(); e.fields.len()]).collect();
        for node in &content.network.alpha {
            let AlphaNode::Event { event, tests, .. } = node else { continue };
            for t in tests {
                let mut add = |o: &Operand| {
                    let v = match o {
                        Operand::Value(Value::F64(f)) if f.is_finite() => *f,
                        Operand::Value(Value::I64(i)) => *i as f64,
                        _ => return,
                    };
                    thresholds[*event as usize][t.field as usize].push(v);
                };
                match &t.check {
                    Check::Compare { rhs, .. } => add(rhs),
                    Check::Range { lo, hi, .. } => {
                        add(lo);
                        add(hi);
                    }
                }
            }
        }
        let last = vec![None; content.agents.len()];
        Generator {
            rng: ChaCha8Rng::seed_from_u64(seed),
            mean_gap: if total > 0.0 { 1e9 / total } else { 1e8 },
            content,
            agents,
            cumulative,
            last,
            thresholds,
            now: 0,
        }
    }

    /// The next event, or `None` if no agent reports any event.
    pub fn next_event(&mut self) -> Option<Event> {
        let mut payload = Vec::new();
        let (event, time) = self.next_into(&mut payload)?;
        Some(Event { event, time, payload })
    }

    /// The next event, its payload appended to `payload` (no allocation
    /// once `payload` has grown): `(event, time)`.
    pub fn next_into(&mut self, payload: &mut Vec<Value>) -> Option<(u32, u64)> {
        let total = *self.cumulative.last()?;
        let pick = self.rng.random::<f64>() * total;
        let k = self.cumulative.partition_point(|&c| c <= pick).min(self.agents.len() - 1);
        let agent = self.agents[k];
        let events = &self.content.agents[agent as usize].events;
        let event = match self.last[agent as usize] {
            Some(e) if self.rng.random_bool(0.8) => e,
            _ => events[self.rng.random_range(0..events.len())],
        };
        self.last[agent as usize] = Some(event);
        // Exponential gaps; at least 1 ns.
        let u: f64 = self.rng.random::<f64>();
        let gap = (-(1.0 - u).ln() * self.mean_gap).clamp(1.0, 1e12) as u64;
        self.now += gap;
        let fields = self.content.events[event as usize].fields.len();
        for f in 0..fields {
            let v = self.value(event as usize, f);
            payload.push(v);
        }
        Some((event, self.now))
    }

    fn value(&mut self, event: usize, field: usize) -> Value {
        let ty = &self.content.events[event].fields[field].ty;
        let near = &self.thresholds[event][field];
        match ty {
            FieldType::F64 | FieldType::I64 => {
                let x = if !near.is_empty() && self.rng.random_bool(0.7) {
                    let c = near[self.rng.random_range(0..near.len())];
                    let deltas = [-1.0, -0.5, -0.001, 0.0, 0.0, 0.001, 0.5, 1.0];
                    let scale = c.abs().max(1.0) * 0.1;
                    c + deltas[self.rng.random_range(0..deltas.len())] * scale
                } else {
                    let (lo, hi) =
                        near.iter().fold((0.0f64, 100.0f64), |(l, h), &c| (l.min(c - 10.0), h.max(c + 10.0)));
                    lo + self.rng.random::<f64>() * (hi - lo)
                };
                match ty {
                    FieldType::I64 => Value::I64(x.round().clamp(-1e15, 1e15) as i64),
                    _ => Value::F64(decimal3(x)),
                }
            }
            FieldType::Bool => Value::Bool(self.rng.random_bool(0.5)),
            FieldType::Symbols(s) => Value::Symbol(self.rng.random_range(0..s.len().max(1)) as u32),
        }
    }
}

/// `x` rounded to 3 decimals, exactly as the text `{x:.3}` parses back.
fn decimal3(x: f64) -> f64 {
    let x = x.clamp(-1e12, 1e12);
    format!("{x:.3}").parse().unwrap_or(0.0)
}

/// The header line of a stream file.
pub fn header(source: &str, seed: u64) -> String {
    format!("# situ events v1 {source} seed={seed}\n")
}

/// Appends one event as a line of the text form.
pub fn write_line(c: &Content, out: &mut String, event: u32, time: u64, payload: &[Value]) {
    let e = &c.events[event as usize];
    let _ = write!(out, "{time} {}", e.name);
    for (f, v) in e.fields.iter().zip(payload) {
        let _ = match (v, &f.ty) {
            (Value::F64(x), _) => write!(out, " {x:.3}"),
            (Value::I64(i), _) => write!(out, " {i}"),
            (Value::Bool(b), _) => write!(out, " {b}"),
            (Value::Symbol(k), FieldType::Symbols(s)) => write!(out, " {}", s[*k as usize]),
            (Value::Symbol(k), _) => write!(out, " #{k}"),
        };
    }
    out.push('\n');
}

/// Why a line of a stream file is not an event.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct StreamError {
    /// 1-based.
    pub line: usize,
    pub message: String,
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "line {}: {}", self.line, self.message)
    }
}

/// Reads a stream's text; comments and blank lines are skipped.
pub fn parse(c: &Content, text: &str) -> Result<Vec<Event>, StreamError> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let err = |message: String| StreamError { line: line_no, message };
        let mut words = line.split_whitespace();
        let time: u64 = words
            .next()
            .and_then(|w| w.parse().ok())
            .ok_or_else(|| err("expected a timestamp in nanoseconds".into()))?;
        let name = words.next().ok_or_else(|| err("expected an event name after the timestamp".into()))?;
        let event = c.event_id(name).ok_or_else(|| err(format!("unknown event `{name}`")))?;
        let fields = &c.events[event as usize].fields;
        let mut payload = Vec::with_capacity(fields.len());
        for f in fields {
            let w = words.next().ok_or_else(|| err(format!("`{name}` needs a value for `{}`", f.name)))?;
            let bad = || err(format!("`{w}` is not a {} for `{name}.{}`", f.ty.describe(), f.name));
            let v = match &f.ty {
                FieldType::F64 => Value::F64(w.parse().map_err(|_| bad())?),
                FieldType::I64 => Value::I64(w.parse().map_err(|_| bad())?),
                FieldType::Bool => Value::Bool(w.parse().map_err(|_| bad())?),
                FieldType::Symbols(s) => Value::Symbol(s.iter().position(|x| x == w).ok_or_else(bad)? as u32),
            };
            payload.push(v);
        }
        if let Some(extra) = words.next() {
            return Err(err(format!("unexpected `{extra}` after the payload of `{name}`")));
        }
        out.push(Event { event, time, payload });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn outdoor() -> Arc<Content> {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
        let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("readable");
        Arc::new(situ_compiler::bundle::build(&checked))
    }

    #[test]
    fn the_same_seed_gives_the_same_stream() {
        let c = outdoor();
        let a: Vec<Event> = (0..500).map_while(|_| Generator::new(c.clone(), 7).next_event()).collect();
        let mut g1 = Generator::new(c.clone(), 7);
        let mut g2 = Generator::new(c.clone(), 7);
        let mut g3 = Generator::new(c, 8);
        let s1: Vec<Event> = (0..500).filter_map(|_| g1.next_event()).collect();
        let s2: Vec<Event> = (0..500).filter_map(|_| g2.next_event()).collect();
        let s3: Vec<Event> = (0..500).filter_map(|_| g3.next_event()).collect();
        assert_eq!(s1, s2);
        assert_ne!(s1, s3);
        assert_eq!(a.len(), 500);
        assert!(s1.windows(2).all(|w| w[0].time < w[1].time), "time moves forward");
    }

    #[test]
    fn the_text_form_reads_back_exactly() {
        let c = outdoor();
        let mut g = Generator::new(c.clone(), 1);
        let events: Vec<Event> = (0..2000).filter_map(|_| g.next_event()).collect();
        let mut text = header("outdoor.situ", 1);
        for e in &events {
            write_line(&c, &mut text, e.event, e.time, &e.payload);
        }
        assert_eq!(parse(&c, &text).unwrap(), events);
        // Thresholds are hit exactly, so the boundaries of the rules are exercised.
        let laobs = c.event_id("LAOBS").unwrap();
        let at_30 = events.iter().filter(|e| e.event == laobs && e.payload[0] == Value::F64(30.0)).count();
        assert!(at_30 > 0, "LAOBS(distance: 30.000) never drawn");
    }

    #[test]
    fn bad_lines_say_where_and_why() {
        let c = outdoor();
        let cases = [
            ("10 NOPE", "unknown event `NOPE`"),
            ("x LAOBN", "expected a timestamp"),
            ("10 LAOBS 1.0", "needs a value for `height`"),
            ("10 LAOBS 1.0 high", "`high` is not a f64"),
            ("10 LAOBN 3", "unexpected `3`"),
            ("10 PLF maybe", "`maybe` is not a {no_path, blocked, timeout}"),
        ];
        for (line, want) in cases {
            let e = parse(&c, &format!("# header\n\n{line}\n")).unwrap_err();
            assert_eq!(e.line, 3, "{line}");
            assert!(e.message.contains(want), "{line}: {}", e.message);
        }
    }
}
