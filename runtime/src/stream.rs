//! Event streams: a seeded random generator over a bundle's event alphabet,
//! and the text form of `bench/README.md` that every benchmarked engine reads.
//!
//! The generator is meant to exercise rules, not to be uniform. A uniform
//! stream over `outdoor.situ` spends nearly all its time in IT: leaving it
//! needs ten `LOFIX` in a row and three other reports, while a `TCTAKE` ends
//! the mission every few dozen events. So:
//! - **guided events** (half of them): the generator runs the rules itself (a
//!   [`rete::Engine`](crate::rete::Engine) fed with its own stream) and picks
//!   a rule that can fire in the current state, then an event of one of its
//!   patterns with a payload that passes the pattern's tests when it can
//!   find one; repeated picks build the run lengths. Rules of the state's
//!   lowest salience band (the mission flow) are picked ten times more
//!   often than the next band (stops, emergencies), and so on. The missions
//!   so walk through the states;
//! - **random events** (the other half): agents report in proportion to
//!   their `rate` (10 Hz when not given); an agent picks one of its events
//!   with a weight that halves for each salience band above the lowest (of
//!   the whole file) of the rules that name the event: the reports that
//!   only emergency rules read (`PLF`, `TCTAKE`) are rare, as on a road;
//! - events are spaced by exponentially distributed intervals (the mean is
//!   one over the sum of the rates), so that the stale timers and windows of
//!   the rules are sometimes exceeded, as on a real bus;
//! - numeric payloads are drawn near the constants the rules compare the
//!   field with (the thresholds) most of the time, else from a wide range;
//! - f64 values have 3 decimals and are what their text parses to, so that
//!   an engine reading the text form sees exactly the same numbers.
//!
//! The same seed gives the same stream, on every machine.

use crate::rete::{passes, Engine};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use situ_bundle::{AlphaNode, BetaKind, Check, Content, FieldType, Operand, Value};
use std::fmt::Write as _;
use std::sync::Arc;

/// One event of a stream.
#[derive(Debug, Clone, PartialEq)]
pub struct Event {
    pub event: u32,
    /// Nanoseconds.
    pub time: u64,
    pub payload: Vec<Value>,
    /// The Bulletinboard's clock when the event arrived (`@CLOCK` at the end
    /// of its line), when the stream says it; otherwise the event arrived at
    /// its stamp. An event stamped more than the skew bound ahead of its
    /// clock is refused (`Engine::admit`).
    pub clock: Option<u64>,
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
    /// Per agent, the cumulative weights of its events for random picks.
    event_weights: Vec<Vec<f64>>,
    now: u64,
    guide: Guide,
}

/// The share of guided events.
const GUIDED: f64 = 0.5;

/// What steers the guided events: the rules run on the stream itself.
struct Guide {
    engine: Engine,
    /// Per state, the rules that can fire in it.
    by_state: Vec<Vec<u32>>,
    /// Per rule, the alpha nodes of its positive patterns.
    patterns: Vec<Vec<u32>>,
    reset_on_final: bool,
}

impl Guide {
    fn new(content: &Arc<Content>) -> Guide {
        let net = &content.network;
        let mut by_state = vec![Vec::new(); content.states.len()];
        let mut patterns = Vec::with_capacity(net.terminals.len());
        for t in &net.terminals {
            let mut own = Vec::new();
            let mut at = Some(t.beta);
            while let Some(b) = at {
                let node = &net.beta[b as usize];
                match &net.alpha[node.alpha as usize] {
                    AlphaNode::State { states } => {
                        for &s in states {
                            by_state[s as usize].push(t.rule);
                        }
                    }
                    AlphaNode::Event { .. } if node.kind == BetaKind::Join => own.push(node.alpha),
                    _ => {}
                }
                at = node.parent;
            }
            patterns.push(own);
        }
        Guide { engine: Engine::new(content.clone()), by_state, patterns, reset_on_final: true }
    }
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
        let guide = Guide::new(&content);
        // Salience bands of the file, and each event's lowest.
        let mut bands: Vec<i64> = content.rules.iter().map(|r| r.salience).collect();
        bands.sort_unstable();
        bands.dedup();
        let mut lowest: Vec<Option<usize>> = vec![None; content.events.len()];
        for (r, own) in guide.patterns.iter().enumerate() {
            let band = bands.iter().position(|&b| b == content.rules[r].salience).unwrap_or(0);
            for &a in own {
                if let AlphaNode::Event { event, .. } = &content.network.alpha[a as usize] {
                    let l = &mut lowest[*event as usize];
                    *l = Some(l.map_or(band, |x| x.min(band)));
                }
            }
        }
        let event_weights = content
            .agents
            .iter()
            .map(|a| {
                let mut acc = 0.0;
                a.events
                    .iter()
                    .map(|&e| {
                        acc += 0.25f64.powi(lowest[e as usize].unwrap_or(0) as i32);
                        acc
                    })
                    .collect()
            })
            .collect();
        Generator {
            guide,
            rng: ChaCha8Rng::seed_from_u64(seed),
            mean_gap: if total > 0.0 { 1e9 / total } else { 1e8 },
            content,
            agents,
            cumulative,
            last,
            thresholds,
            event_weights,
            now: 0,
        }
    }

    /// Whether the stream's consumer resets after a final state (as `situ
    /// bench` does by default): the guide then does too.
    pub fn reset_on_final(mut self, reset: bool) -> Self {
        self.guide.reset_on_final = reset;
        self
    }

    /// The next event, or `None` if no agent reports any event.
    pub fn next_event(&mut self) -> Option<Event> {
        let mut payload = Vec::new();
        let (event, time) = self.next_into(&mut payload)?;
        Some(Event { event, time, payload, clock: None })
    }

    /// The next event, its payload appended to `payload` (no allocation
    /// once `payload` has grown): `(event, time)`.
    pub fn next_into(&mut self, payload: &mut Vec<Value>) -> Option<(u32, u64)> {
        let total = *self.cumulative.last()?;
        let start = payload.len();
        let guided = if self.rng.random_bool(GUIDED) { self.guided(payload) } else { None };
        let event = match guided {
            Some(e) => e,
            None => self.random_event(total, payload),
        };
        let agent = self.content.events[event as usize].agent;
        self.last[agent as usize] = Some(event);
        self.now += self.gap();
        let _ = self.guide.engine.post(event, self.now, &payload[start..]);
        if self.guide.reset_on_final {
            self.guide.engine.reset_if_final();
        }
        Some((event, self.now))
    }

    /// The sum of the reporting agents' rates (`None`: no agent reports).
    pub(crate) fn total_rate(&self) -> Option<f64> {
        self.cumulative.last().copied()
    }

    /// Per rule, the alpha nodes of its positive event patterns.
    pub(crate) fn patterns(&self) -> &[Vec<u32>] {
        &self.guide.patterns
    }

    pub(crate) fn rng(&mut self) -> &mut ChaCha8Rng {
        &mut self.rng
    }

    /// An event of an agent picked in proportion to the rates (`total`: the
    /// sum of them), its payload appended.
    pub(crate) fn random_event(&mut self, total: f64, payload: &mut Vec<Value>) -> u32 {
        let pick = self.rng.random::<f64>() * total;
        let k = self.cumulative.partition_point(|&c| c <= pick).min(self.agents.len() - 1);
        let agent = self.agents[k];
        let events = &self.content.agents[agent as usize].events;
        let weights = &self.event_weights[agent as usize];
        let pick = self.rng.random::<f64>() * weights[weights.len() - 1];
        let event = events[weights.partition_point(|&w| w <= pick).min(events.len() - 1)];
        for f in 0..self.content.events[event as usize].fields.len() {
            let v = self.value(event as usize, f);
            payload.push(v);
        }
        event
    }

    /// The interval to the next event (ns): exponential, at least 1 ns.
    pub(crate) fn gap(&mut self) -> u64 {
        let u: f64 = self.rng.random::<f64>();
        (-(1.0 - u).ln() * self.mean_gap).clamp(1.0, 1e12) as u64
    }

    /// An event of a pattern of a rule that can fire in the guide's state,
    /// its payload appended; `None` when no rule can fire there.
    fn guided(&mut self, payload: &mut Vec<Value>) -> Option<u32> {
        let state = self.guide.engine.state() as usize;
        let rules = &self.guide.by_state[state];
        if rules.is_empty() {
            return None;
        }
        // Mission flow before emergencies: each salience band above the
        // lowest of the state is ten times less likely.
        let salience = |r: u32| self.content.rules[r as usize].salience;
        let mut bands: Vec<i64> = rules.iter().map(|&r| salience(r)).collect();
        bands.sort_unstable();
        bands.dedup();
        let weight = |r: u32| 0.01f64.powi(bands.iter().position(|&b| b == salience(r)).unwrap_or(0) as i32);
        let total: f64 = rules.iter().map(|&r| weight(r)).sum();
        let mut pick = self.rng.random::<f64>() * total;
        let mut rule = rules[rules.len() - 1] as usize;
        for &r in rules {
            pick -= weight(r);
            if pick < 0.0 {
                rule = r as usize;
                break;
            }
        }
        let patterns = &self.guide.patterns[rule];
        if patterns.is_empty() {
            return None;
        }
        let alpha = patterns[self.rng.random_range(0..patterns.len())] as usize;
        self.payload_for(alpha, payload)
    }

    /// The event of the alpha node `alpha`, with a payload appended that
    /// passes its tests when one of 16 draws does; `None` if `alpha` is not
    /// an event's node.
    pub(crate) fn payload_for(&mut self, alpha: usize, payload: &mut Vec<Value>) -> Option<u32> {
        let AlphaNode::Event { event, tests, .. } = &self.content.network.alpha[alpha] else { return None };
        let (event, tests) = (*event, tests.clone());
        let n = self.content.events[event as usize].fields.len();
        let start = payload.len();
        for _ in 0..16 {
            payload.truncate(start);
            for f in 0..n {
                let v = self.value(event as usize, f);
                payload.push(v);
            }
            if tests.iter().all(|t| passes(t, &payload[start..])) {
                break;
            }
        }
        Some(event)
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

/// Appends one event as a line of the text form, with the clock it arrived
/// at (`@CLOCK`) when given.
pub fn write_event(c: &Content, out: &mut String, e: &Event) {
    write_line(c, out, e.event, e.time, &e.payload);
    if let Some(clock) = e.clock {
        out.pop();
        let _ = writeln!(out, " @{clock}");
    }
}

/// Appends one event as a line of the text form.
pub fn write_line(c: &Content, out: &mut String, event: u32, time: u64, payload: &[Value]) {
    let Some(e) = c.events.get(event as usize) else {
        // An event of no name: a stream line's unknown event, as read.
        let _ = writeln!(out, "{time} #{event}");
        return;
    };
    let _ = write!(out, "{time} {}", e.name);
    for (f, v) in e.fields.iter().zip(payload) {
        let _ = match (v, &f.ty) {
            (Value::F64(x), _) if !x.is_finite() => write!(out, " {x}"),
            (Value::F64(x), _) => write!(out, " {x:.3}"),
            (Value::I64(i), _) => write!(out, " {i}"),
            (Value::Bool(b), _) => write!(out, " {b}"),
            (Value::Symbol(k), FieldType::Symbols(s)) if (*k as usize) < s.len() => write!(out, " {}", s[*k as usize]),
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
///
/// A line with a timestamp and a name is an event, and is read as it is
/// written, whether or not it fits: its event (an unknown name is the id
/// [`Content::events`]`.len()`, which no event has) and its payload values
/// (a value that is not of its field's type, or an unknown symbol, is one
/// that no field takes). The acceptance rule then refuses those, as every
/// part of situ does (`Engine::admit`, language reference §10.4): a
/// missing or extra value, a value of another type, an unknown symbol, an
/// unknown event. The errors are for a line that is not an event: no
/// timestamp, no name, a bad `@CLOCK` or words after it.
pub fn parse(c: &Content, text: &str) -> Result<Vec<Event>, StreamError> {
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let err = |message: String| StreamError { line: line_no, message };
        let mut words = line.split_whitespace().peekable();
        let time: u64 = words
            .next()
            .and_then(|w| w.parse().ok())
            .ok_or_else(|| err("expected a timestamp in nanoseconds (0 to 2^64 - 1)".into()))?;
        let name = words.next().ok_or_else(|| err("expected an event name after the timestamp".into()))?;
        let event = c.event_id(name).unwrap_or(c.events.len() as u32);
        let fields = c.events.get(event as usize).map_or(&[][..], |e| &e.fields[..]);
        let mut payload = Vec::with_capacity(fields.len());
        while let Some(w) = words.next_if(|w| !w.starts_with('@')) {
            payload.push(fields.get(payload.len()).map_or(MISFIT, |f| value(&f.ty, w)));
        }
        let mut clock = None;
        if let Some(at) = words.next().and_then(|w| w.strip_prefix('@')) {
            clock = Some(at.parse().map_err(|_| err(format!("`@{at}` is not a clock in nanoseconds")))?);
        }
        if let Some(extra) = words.next() {
            return Err(err(format!("unexpected `{extra}` after the clock of `{name}`")));
        }
        out.push(Event { event, time, payload, clock });
    }
    Ok(out)
}

/// A value that no field takes (the acceptance rule refuses it): a symbol
/// past every list.
const MISFIT: Value = Value::Symbol(u32::MAX);

/// A payload word read as its field's type, or [`MISFIT`].
fn value(ty: &FieldType, w: &str) -> Value {
    let v = match ty {
        FieldType::F64 => w.parse().ok().map(Value::F64),
        FieldType::I64 => w.parse().ok().map(Value::I64),
        FieldType::Bool => w.parse().ok().map(Value::Bool),
        FieldType::Symbols(s) => s.iter().position(|x| x == w).map(|i| Value::Symbol(i as u32)),
    };
    v.unwrap_or(MISFIT)
}

/// The 1-based line of the `index`-th event (0-based) of a stream's text.
pub fn line_of(text: &str, index: u64) -> Option<usize> {
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim().starts_with('#'))
        .nth(usize::try_from(index).ok()?)
        .map(|(i, _)| i + 1)
}
