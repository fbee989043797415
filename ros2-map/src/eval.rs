//! The map's expressions evaluated on a decoded message, and the
//! [`Translator`]: built once from the rules and a checked map, it turns
//! each message of a topic into the events the map's entries produce, with
//! their payloads as the runtime takes them.
//!
//! Nothing here panics on a message: a message that does not decode, an
//! index past the end of an array, `min` of an empty array, a division by
//! zero, a NaN or an integer overflow is a [`Problem`] of the outcome, and
//! the entry produces no event for that message.

use crate::cdr::{self, Decoder};
use crate::check::check_parsed;
use crate::expr::{self, BinOp, Expr, Range, Reducer, Step};
use crate::map;
use crate::msgs::idl::ConstValue;
use crate::msgs::Registry;
use situ_compiler::bundle::Value;
use situ_compiler::codes;
use situ_compiler::model::{Model, Type};
use situ_grammar::diag::{Diagnostic, FileId, Severity};

/// A value of an expression on a message.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Val<'a> {
    Int(i64),
    Float(f64),
    Bool(bool),
    Str(&'a str),
    /// A message or an array of the message (for `.f`, `[i]`, reducers).
    Node(&'a cdr::Value),
}

/// Why an expression has no value on a message, and where in its text.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalError {
    pub message: String,
    pub range: Range,
}

fn fail<T>(range: Range, message: impl Into<String>) -> Result<T, EvalError> {
    Err(EvalError { message: message.into(), range })
}

/// The largest integer a float holds exactly; whole literals up to it are integers.
const EXACT: f64 = 9_007_199_254_740_992.0;

fn describe(v: &Val<'_>) -> &'static str {
    match v {
        Val::Int(_) => "an integer",
        Val::Float(_) => "a number",
        Val::Bool(_) => "a boolean",
        Val::Str(_) => "a string",
        Val::Node(cdr::Value::Array(_)) => "an array",
        Val::Node(_) => "a message",
    }
}

fn leaf(v: &cdr::Value, range: Range) -> Result<Val<'_>, EvalError> {
    Ok(match v {
        cdr::Value::Int(i) => Val::Int(*i),
        cdr::Value::Float(f) if f.is_nan() => return fail(range, "is NaN"),
        cdr::Value::Float(f) => Val::Float(*f),
        cdr::Value::Bool(b) => Val::Bool(*b),
        cdr::Value::Str(s) => Val::Str(s),
        node => Val::Node(node),
    })
}

fn float(v: Val<'_>) -> Option<f64> {
    match v {
        Val::Int(i) => Some(i as f64),
        Val::Float(f) => Some(f),
        _ => None,
    }
}

fn number(f: f64, range: Range) -> Result<Val<'static>, EvalError> {
    if f.is_nan() {
        fail(range, "is NaN")
    } else {
        Ok(Val::Float(f))
    }
}

/// The value of `e` on the decoded message `msg`.
pub fn eval<'a>(e: &'a Expr, msg: &'a cdr::Value) -> Result<Val<'a>, EvalError> {
    match e {
        Expr::Number(n, _) if n.fract() == 0.0 && n.abs() <= EXACT => Ok(Val::Int(*n as i64)),
        Expr::Number(n, _) => Ok(Val::Float(*n)),
        Expr::Str(s, _) => Ok(Val::Str(s)),
        Expr::Bool(b, _) => Ok(Val::Bool(*b)),
        Expr::Path(steps, range) => path(steps, msg, *range),
        Expr::Neg(inner, r) => match eval(inner, msg)? {
            Val::Int(i) => i.checked_neg().map(Val::Int).map_or_else(|| fail(*r, "overflows an integer"), Ok),
            Val::Float(f) => Ok(Val::Float(-f)),
            v => fail(*r, format!("`-` of {}", describe(&v))),
        },
        Expr::Not(inner, r) => match eval(inner, msg)? {
            Val::Bool(b) => Ok(Val::Bool(!b)),
            v => fail(*r, format!("`not` of {}", describe(&v))),
        },
        Expr::Reduce(red, arg, r) => reduce(*red, eval(arg, msg)?, *r),
        Expr::Binary(op, l, r, range) => binary(*op, l, r, msg, *range),
    }
}

fn path<'a>(steps: &'a [Step], msg: &'a cdr::Value, range: Range) -> Result<Val<'a>, EvalError> {
    let mut v = msg;
    for step in steps {
        v = match step {
            Step::Field(name, r) => match v.field(name) {
                Some(f) => f,
                None => return fail((range.0, r.1), format!("the message has no field `{name}`")),
            },
            Step::Index(i, r) => match (v.index(*i), v) {
                (Some(x), _) => x,
                (None, cdr::Value::Array(items)) => {
                    let n = items.len();
                    return fail((range.0, r.1), format!("index {i} is past the end of an array of {n}"));
                }
                (None, _) => return fail((range.0, r.1), "an index on a value that is not an array"),
            },
        };
    }
    leaf(v, range)
}

fn reduce(red: Reducer, arg: Val<'_>, r: Range) -> Result<Val<'static>, EvalError> {
    let Val::Node(cdr::Value::Array(items)) = arg else {
        return fail(r, format!("a reducer of {}", describe(&arg)));
    };
    if red == Reducer::Len {
        return Ok(Val::Int(i64::try_from(items.len()).unwrap_or(i64::MAX)));
    }
    let name = match red {
        Reducer::Min => "min",
        Reducer::Max => "max",
        _ => "mean",
    };
    // NaN elements are invalid readings (REP 117): they are skipped.
    let (mut count, mut sum) = (0usize, 0f64);
    let (mut best_int, mut best) = (None::<i64>, None::<f64>);
    for item in items {
        let x = match item {
            cdr::Value::Int(i) => {
                best_int = Some(best_int.map_or(*i, |a| if red == Reducer::Max { a.max(*i) } else { a.min(*i) }));
                *i as f64
            }
            cdr::Value::Float(f) if f.is_nan() => continue,
            cdr::Value::Float(f) => *f,
            _ => return fail(r, format!("`{name}` of an array that holds other things than numbers")),
        };
        best = Some(best.map_or(x, |a| if red == Reducer::Max { a.max(x) } else { a.min(x) }));
        count += 1;
        sum += x;
    }
    match (red, best_int, best) {
        (_, _, None) => {
            let why = if items.is_empty() { "empty".to_string() } else { format!("all {} NaN", items.len()) };
            fail(r, format!("`{name}` of an array that is {why}"))
        }
        (Reducer::Mean, _, Some(_)) => number(sum / count as f64, r),
        // An array of integers (an array's elements are of one type).
        (_, Some(i), Some(_)) => Ok(Val::Int(i)),
        (_, None, Some(f)) => number(f, r),
    }
}

fn binary<'a>(op: BinOp, l: &'a Expr, r: &'a Expr, msg: &'a cdr::Value, range: Range) -> Result<Val<'a>, EvalError> {
    let lv = eval(l, msg)?;
    if let (BinOp::And | BinOp::Or, Val::Bool(a)) = (op, lv) {
        // Short-circuit: `len(status) > 0 and status[0].level >= 1`.
        if a == (op == BinOp::Or) {
            return Ok(Val::Bool(a));
        }
        return match eval(r, msg)? {
            Val::Bool(b) => Ok(Val::Bool(b)),
            v => fail(range, format!("`{}` of a boolean and {}", op.text(), describe(&v))),
        };
    }
    let rv = eval(r, msg)?;
    let mismatch = || fail(range, format!("`{}` of {} and {}", op.text(), describe(&lv), describe(&rv)));
    match op {
        BinOp::And | BinOp::Or => mismatch(),
        BinOp::Add | BinOp::Sub | BinOp::Mul => {
            if let (Val::Int(a), Val::Int(b)) = (lv, rv) {
                let v = match op {
                    BinOp::Add => a.checked_add(b),
                    BinOp::Sub => a.checked_sub(b),
                    _ => a.checked_mul(b),
                };
                return v.map(Val::Int).map_or_else(|| fail(range, "overflows an integer"), Ok);
            }
            let (Some(a), Some(b)) = (float(lv), float(rv)) else { return mismatch() };
            number(
                match op {
                    BinOp::Add => a + b,
                    BinOp::Sub => a - b,
                    _ => a * b,
                },
                range,
            )
        }
        BinOp::Div => {
            let (Some(a), Some(b)) = (float(lv), float(rv)) else { return mismatch() };
            if b == 0.0 {
                return fail(range, "division by zero");
            }
            number(a / b, range)
        }
        BinOp::Lt | BinOp::Le | BinOp::Gt | BinOp::Ge | BinOp::Eq | BinOp::Ne => {
            let ord = match (lv, rv) {
                (Val::Int(a), Val::Int(b)) => a.partial_cmp(&b),
                (Val::Str(a), Val::Str(b)) if matches!(op, BinOp::Eq | BinOp::Ne) => a.partial_cmp(b),
                (Val::Bool(a), Val::Bool(b)) if matches!(op, BinOp::Eq | BinOp::Ne) => a.partial_cmp(&b),
                _ => match (float(lv), float(rv)) {
                    (Some(a), Some(b)) => a.partial_cmp(&b),
                    _ => return mismatch(),
                },
            };
            let Some(ord) = ord else { return fail(range, "compares NaN") };
            Ok(Val::Bool(match op {
                BinOp::Lt => ord.is_lt(),
                BinOp::Le => ord.is_le(),
                BinOp::Gt => ord.is_gt(),
                BinOp::Ge => ord.is_ge(),
                BinOp::Eq => ord.is_eq(),
                _ => ord.is_ne(),
            }))
        }
    }
}

/// Why a value does not fit a payload field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PayloadError {
    #[error("is {0}, not a finite number")]
    NotFinite(f64),
    #[error("`{value}` is not one of {symbols}")]
    NotASymbol { value: String, symbols: String },
    #[error("is {found}, not {expected}")]
    WrongType { found: &'static str, expected: String },
}

/// A value as the runtime takes it for a payload field of type `ty`.
pub fn to_payload(v: Val<'_>, ty: &Type) -> Result<Value, PayloadError> {
    match (ty, v) {
        (Type::F64, Val::Int(i)) => Ok(Value::F64(i as f64)),
        (Type::F64, Val::Float(f)) if f.is_finite() => Ok(Value::F64(f)),
        (Type::F64, Val::Float(f)) => Err(PayloadError::NotFinite(f)),
        (Type::I64, Val::Int(i)) => Ok(Value::I64(i)),
        (Type::I64, Val::Float(f)) if f.fract() == 0.0 && f.abs() <= EXACT => Ok(Value::I64(f as i64)),
        (Type::Bool, Val::Bool(b)) => Ok(Value::Bool(b)),
        (Type::Symbols(symbols), Val::Str(s)) => match symbols.iter().position(|x| x == s) {
            Some(i) => Ok(Value::Symbol(u32::try_from(i).unwrap_or(u32::MAX))),
            None => Err(PayloadError::NotASymbol { value: s.to_string(), symbols: symbols.join(", ") }),
        },
        (ty, v) => Err(PayloadError::WrongType { found: describe(&v), expected: ty.describe() }),
    }
}

/// An event to report to the runtime.
#[derive(Debug, Clone, PartialEq)]
pub struct Produced {
    /// The agent's id (its index in the rules and the bundle).
    pub agent: u32,
    /// The event's id.
    pub event: u32,
    /// One value per field of the event, in the event's order.
    pub payload: Vec<Value>,
}

/// A message, or one entry on a message, that produced no event.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    pub topic: String,
    /// The event of the entry; `None` when the message itself is refused
    /// (it does not decode, or the map does not read the topic).
    pub event: Option<String>,
    pub message: String,
}

/// What one message gave.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outcome {
    pub produced: Vec<Produced>,
    pub problems: Vec<Problem>,
}

/// Counters over every message seen.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Stats {
    pub messages: u64,
    /// Messages that did not decode, or came on a topic the map does not read.
    pub refused: u64,
    /// Entries that could not be evaluated on a message.
    pub failed: u64,
    pub produced: u64,
}

/// An expression with its text, for the problems' messages.
#[derive(Debug, Clone)]
struct Source {
    expr: Expr,
    text: String,
}

impl Source {
    fn eval<'a>(&'a self, msg: &'a cdr::Value) -> Result<Val<'a>, String> {
        eval(&self.expr, msg).map_err(|e| format!("`{}` {}", self.excerpt(e.range), e.message))
    }

    /// The text of `range`, with the closing parentheses the parser's
    /// ranges leave out (`(a - b` of `x / (a - b)`).
    fn excerpt(&self, range: Range) -> &str {
        let Some(part) = self.text.get(range.0..range.1) else { return &self.text };
        let mut open = part.matches('(').count().saturating_sub(part.matches(')').count());
        let mut end = range.1;
        for (i, c) in self.text.get(range.1..).unwrap_or("").char_indices() {
            match c {
                _ if open == 0 => break,
                ')' => {
                    open -= 1;
                    end = range.1 + i + 1;
                }
                c if c.is_whitespace() => {}
                _ => break,
            }
        }
        self.text.get(range.0..end).unwrap_or(part)
    }
}

#[derive(Debug, Clone)]
struct Entry {
    agent: u32,
    event: u32,
    name: String,
    when: Option<Source>,
    /// One per field of the event, in its order.
    payload: Vec<(String, Type, Source)>,
}

impl Entry {
    fn produce(&self, msg: &cdr::Value) -> Result<Option<Produced>, String> {
        if let Some(when) = &self.when {
            match when.eval(msg).map_err(|e| format!("when: {e}"))? {
                Val::Bool(true) => {}
                Val::Bool(false) => return Ok(None),
                v => return Err(format!("when: is {}, not a condition", describe(&v))),
            }
        }
        let mut payload = Vec::with_capacity(self.payload.len());
        for (field, ty, src) in &self.payload {
            let v = src.eval(msg).map_err(|e| format!("{field}: {e}"))?;
            payload.push(to_payload(v, ty).map_err(|e| format!("{field}: `{}` {e}", src.text))?);
        }
        Ok(Some(Produced { agent: self.agent, event: self.event, payload }))
    }
}

#[derive(Debug, Clone)]
struct Topic {
    name: String,
    decoder: Decoder,
    entries: Vec<Entry>,
}

/// Turns the messages of the map's topics into events.
#[derive(Debug, Clone)]
pub struct Translator {
    topics: Vec<Topic>,
    stats: Stats,
}

impl Translator {
    /// The translator of the map `text` (file `file`) for the rules'
    /// `model`, its messages as `msgs` defines them; the map's error
    /// findings when it has any (warnings pass).
    pub fn new(model: &Model, text: &str, msgs: &Registry, file: FileId) -> Result<Translator, Vec<Diagnostic>> {
        let parsed = map::parse(text, file).map_err(|d| vec![*d])?;
        Translator::of(model, &parsed, msgs, file)
    }

    /// [`Translator::new`] of a map already parsed (from `file`).
    pub fn of(model: &Model, parsed: &map::Map, msgs: &Registry, file: FileId) -> Result<Translator, Vec<Diagnostic>> {
        let errors: Vec<Diagnostic> =
            check_parsed(model, parsed, msgs, file).into_iter().filter(|d| d.severity == Severity::Error).collect();
        if !errors.is_empty() {
            return Err(errors);
        }
        let mut topics: Vec<Topic> = Vec::new();
        for e in &parsed.events {
            let entry = entry(model, e, msgs).ok_or_else(|| {
                vec![Diagnostic::error(codes::ROS2_BAD_MAP, "entry not translatable", file, e.span, "")]
            })?;
            match topics.iter_mut().find(|t| t.name == e.topic.value) {
                Some(t) => t.entries.push(entry),
                None => {
                    let Some(decoder) = Decoder::new(msgs, &e.ty.value) else {
                        let d = Diagnostic::error(codes::ROS2_UNKNOWN_TYPE, "unknown type", file, e.ty.span, "");
                        return Err(vec![d]);
                    };
                    topics.push(Topic { name: e.topic.value.clone(), decoder, entries: vec![entry] });
                }
            }
        }
        Ok(Translator { topics, stats: Stats::default() })
    }

    /// Every topic the map reads, with the full name of its message type:
    /// what the bridge subscribes to.
    pub fn topics(&self) -> impl Iterator<Item = (&str, &'static str)> {
        self.topics.iter().map(|t| (t.name.as_str(), t.decoder.type_name()))
    }

    /// The counters so far.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// The events one message of `topic` (its CDR bytes, header included)
    /// produces, in the order of the map's entries, and the problems.
    pub fn on_message(&mut self, topic: &str, cdr: &[u8]) -> Outcome {
        self.stats.messages += 1;
        let mut out = Outcome::default();
        let problem = |event: Option<&str>, message: String| Problem {
            topic: topic.to_string(),
            event: event.map(str::to_string),
            message,
        };
        let Some(t) = self.topics.iter().find(|t| t.name == topic) else {
            self.stats.refused += 1;
            out.problems.push(problem(None, format!("the map reads no topic `{topic}`")));
            return out;
        };
        let msg = match t.decoder.decode(cdr) {
            Ok(msg) => msg,
            Err(e) => {
                self.stats.refused += 1;
                out.problems.push(problem(None, e.to_string()));
                return out;
            }
        };
        for entry in &t.entries {
            match entry.produce(&msg) {
                Ok(Some(p)) => out.produced.push(p),
                Ok(None) => {}
                Err(e) => out.problems.push(problem(Some(&entry.name), e)),
            }
        }
        self.stats.produced += out.produced.len() as u64;
        self.stats.failed += out.problems.len() as u64;
        out
    }
}

/// The expression of `s` on messages of type `msg`, the paths that name a
/// constant of the message replaced by its value.
fn source(s: &map::Str, msg: &str, msgs: &Registry) -> Option<Source> {
    let mut expr = expr::parse(&s.value).ok()?;
    constants(&mut expr, msg, msgs);
    Some(Source { expr, text: s.value.clone() })
}

/// Replaces each path of `e` that names a constant (`POWER_SUPPLY_STATUS_CHARGING`,
/// `DiagnosticStatus.ERROR`, see [`Registry::path_constant`]) by its value.
fn constants(e: &mut Expr, msg: &str, msgs: &Registry) {
    match e {
        Expr::Path(steps, range) => {
            let names: Option<Vec<&str>> = steps
                .iter()
                .map(|s| match s {
                    Step::Field(n, _) => Some(n.as_str()),
                    Step::Index(..) => None,
                })
                .collect();
            let Some(c) = names.and_then(|n| msgs.path_constant(msg, &n)) else { return };
            *e = match &c.value {
                ConstValue::Bool(b) => Expr::Bool(*b, *range),
                ConstValue::Int(i) => Expr::Number(*i as f64, *range),
                ConstValue::Float(f) => Expr::Number(*f, *range),
                ConstValue::Str(s) => Expr::Str(s.clone(), *range),
            };
        }
        Expr::Number(..) | Expr::Str(..) | Expr::Bool(..) => {}
        Expr::Neg(inner, _) | Expr::Not(inner, _) | Expr::Reduce(_, inner, _) => constants(inner, msg, msgs),
        Expr::Binary(_, l, r, _) => {
            constants(l, msg, msgs);
            constants(r, msg, msgs);
        }
    }
}

/// The entry of a checked map's `[[event]]`; `None` only for a map that
/// did not pass the check.
fn entry(model: &Model, e: &map::EventEntry, msgs: &Registry) -> Option<Entry> {
    let msg = msgs.lookup(&e.ty.value)?;
    let source = |s: &map::Str| source(s, msg, msgs);
    let agent = model.agent_id(&e.agent.value)?;
    let event = model.event_id(&e.event.value)?;
    let def = model.event(event);
    let when = match &e.when {
        Some(w) => Some(source(w)?),
        None => None,
    };
    let payload = def
        .fields
        .iter()
        .map(|f| {
            let (_, text) = e.payload.iter().find(|(k, _)| k.value == f.name)?;
            Some((f.name.clone(), f.ty.clone(), source(text)?))
        })
        .collect::<Option<Vec<_>>>()?;
    Some(Entry { agent: agent.0, event: event.0, name: def.name.clone(), when, payload })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cdr::Value as M;

    fn msg() -> M {
        let status = |level: i64, hw: &str| {
            M::Msg(vec![("level", M::Int(level)), ("hardware_id", M::Str(hw.into())), ("values", M::Array(vec![]))])
        };
        M::Msg(vec![
            ("ranges", M::Array(vec![M::Float(f64::NAN), M::Float(0.25), M::Float(f64::INFINITY)])),
            ("empty", M::Array(vec![])),
            ("nans", M::Array(vec![M::Float(f64::NAN)])),
            ("ints", M::Array(vec![M::Int(3), M::Int(-2)])),
            ("x", M::Float(2.0)),
            ("n", M::Int(i64::MAX)),
            ("nan", M::Float(f64::NAN)),
            ("ok", M::Bool(true)),
            ("status", M::Array(vec![status(2, "base")])),
            ("none", M::Array(vec![])),
        ])
    }

    fn run(text: &str) -> Result<Val<'static>, String> {
        let e = expr::parse(text).unwrap();
        let m = msg();
        let src = Source { expr: e, text: text.to_string() };
        src.eval(&m).map(|v| match v {
            Val::Int(i) => Val::Int(i),
            Val::Float(f) => Val::Float(f),
            Val::Bool(b) => Val::Bool(b),
            Val::Str(s) => Val::Str(if s == "base" { "base" } else { "?" }),
            Val::Node(_) => Val::Str("node"),
        })
    }

    #[test]
    fn values() {
        assert_eq!(run("min(ranges)"), Ok(Val::Float(0.25)));
        assert_eq!(run("max(ranges)"), Ok(Val::Float(f64::INFINITY)));
        assert_eq!(run("min(ints) * 2"), Ok(Val::Int(-4)));
        assert_eq!(run("max(ints)"), Ok(Val::Int(3)));
        assert_eq!(run("mean(ints)"), Ok(Val::Float(0.5)));
        assert_eq!(run("len(ranges) + len(empty)"), Ok(Val::Int(3)));
        assert_eq!(run("x * 3.6 - 1"), Ok(Val::Float(6.2)));
        assert_eq!(run("x / 4"), Ok(Val::Float(0.5)));
        assert_eq!(run("-x < 0 and not (ok == false)"), Ok(Val::Bool(true)));
        assert_eq!(run("status[0].hardware_id == 'base' and status[0].level >= 1"), Ok(Val::Bool(true)));
        assert_eq!(run("status[0].hardware_id"), Ok(Val::Str("base")));
        assert_eq!(run("len(status) > 1 or x > 1"), Ok(Val::Bool(true)));
    }

    #[test]
    fn short_circuit_guards_an_index() {
        assert_eq!(run("len(none) > 0 and none[0].level > 1"), Ok(Val::Bool(false)));
        assert_eq!(run("len(none) == 0 or none[0].level > 1"), Ok(Val::Bool(true)));
    }

    #[test]
    fn errors_are_values() {
        let err = |t: &str| run(t).unwrap_err();
        assert_eq!(err("min(empty)"), "`min(empty)` `min` of an array that is empty");
        assert_eq!(err("mean(nans) > 1"), "`mean(nans)` `mean` of an array that is all 1 NaN");
        assert_eq!(err("x / (x - 2)"), "`x / (x - 2)` division by zero");
        assert_eq!(err("nan + 1"), "`nan` is NaN");
        assert_eq!(err("n + 1"), "`n + 1` overflows an integer");
        assert_eq!(err("-n - 2"), "`-n - 2` overflows an integer");
        assert_eq!(err("none[0].level"), "`none[0]` index 0 is past the end of an array of 0");
        assert_eq!(err("max(ranges) - max(ranges) > 0"), "`max(ranges) - max(ranges)` is NaN");
        assert!(err("missing > 1").contains("no field `missing`"));
        assert!(err("ok + 1").contains("`+` of a boolean and an integer"));
    }

    #[test]
    fn constants_evaluate_to_their_values() {
        let reg = Registry::carried();
        let m = M::Msg(vec![("power_supply_status", M::Int(1)), ("present", M::Bool(true))]);
        let run = |msg: &str, text: &str| {
            let mut e = expr::parse(text).unwrap();
            constants(&mut e, msg, &reg);
            eval(&e, &m).map(|v| format!("{v:?}")).map_err(|e| e.message)
        };
        let battery = "sensor_msgs/msg/BatteryState";
        assert_eq!(run(battery, "power_supply_status == POWER_SUPPLY_STATUS_CHARGING"), Ok("Bool(true)".into()));
        assert_eq!(run(battery, "present and POWER_SUPPLY_STATUS_FULL - 1 > 2"), Ok("Bool(true)".into()));
        assert_eq!(run("diagnostic_msgs/msg/DiagnosticArray", "DiagnosticStatus.STALE"), Ok("Int(3)".into()));
        assert_eq!(run("action_msgs/msg/GoalStatusArray", "GoalStatus.STATUS_ABORTED"), Ok("Int(6)".into()));
        // A field of the name is the field, not a constant.
        assert_eq!(run(battery, "power_supply_status"), Ok("Int(1)".into()));
        assert_eq!(run(battery, "NOPE"), Err("the message has no field `NOPE`".into()));
    }

    #[test]
    fn payload_values() {
        let sym = Type::Symbols(vec!["warn".into(), "error".into()]);
        assert_eq!(to_payload(Val::Str("error"), &sym), Ok(Value::Symbol(1)));
        assert_eq!(to_payload(Val::Str("fatal"), &sym).unwrap_err().to_string(), "`fatal` is not one of warn, error");
        assert_eq!(to_payload(Val::Int(3), &Type::F64), Ok(Value::F64(3.0)));
        assert_eq!(to_payload(Val::Int(3), &Type::I64), Ok(Value::I64(3)));
        assert_eq!(to_payload(Val::Bool(true), &Type::Bool), Ok(Value::Bool(true)));
        assert!(to_payload(Val::Float(f64::INFINITY), &Type::F64).unwrap_err().to_string().contains("inf"));
        assert!(to_payload(Val::Float(0.5), &Type::I64).is_err());
    }

    const RULES: &str = include_str!("../../tests/ros2/delivery.situ");
    const MAP: &str = include_str!("../../tests/ros2/delivery.toml");

    /// A LaserScan of `ranges`, written by hand (little-endian).
    fn scan(ranges: &[f32]) -> Vec<u8> {
        let mut b = vec![0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0];
        b.extend([0u8; 28]);
        b.extend((ranges.len() as u32).to_le_bytes());
        ranges.iter().for_each(|r| b.extend(r.to_le_bytes()));
        b.extend([0u8; 4]);
        b
    }

    #[test]
    fn delivery_scan_by_hand() {
        let checked = situ_compiler::check_source("delivery.situ", RULES);
        let mut t = Translator::new(&checked.model, MAP, &Registry::carried(), FileId(1)).unwrap();
        let topics: Vec<_> = t.topics().collect();
        assert_eq!(topics[0], ("/scan", "sensor_msgs/msg/LaserScan"));
        let (lidar, obstacle, clear) = (
            checked.model.agent_id("Lidar").unwrap().0,
            checked.model.event_id("OBSTACLE").unwrap().0,
            checked.model.event_id("CLEAR").unwrap().0,
        );
        let out = t.on_message("/scan", &scan(&[1.0, 0.25, f32::NAN]));
        assert_eq!(out.produced, vec![Produced { agent: lidar, event: obstacle, payload: vec![Value::F64(0.25)] }]);
        let out = t.on_message("/scan", &scan(&[1.0, f32::INFINITY]));
        assert_eq!(out.produced, vec![Produced { agent: lidar, event: clear, payload: vec![] }]);
        let out = t.on_message("/scan", &scan(&[]));
        assert!(out.produced.is_empty());
        assert_eq!(out.problems.len(), 2, "{:?}", out.problems);
        assert_eq!(out.problems[0].event.as_deref(), Some("OBSTACLE"));
        assert_eq!(out.problems[0].message, "when: `min(ranges)` `min` of an array that is empty");
        let out = t.on_message("/scan", &scan(&[1.0])[..20]);
        assert_eq!(out.problems[0].event, None);
        assert!(out.problems[0].message.starts_with("LaserScan: "), "{:?}", out.problems);
        assert_eq!(t.on_message("/nowhere", &[]).problems[0].message, "the map reads no topic `/nowhere`");
        assert_eq!(t.stats(), Stats { messages: 5, refused: 2, failed: 2, produced: 2 });
    }

    #[test]
    fn a_map_with_errors_is_refused() {
        let checked = situ_compiler::check_source("delivery.situ", RULES);
        let bad = MAP.replace("min(ranges) < 0.5", "min(rangez) < 0.5");
        let errors = Translator::new(&checked.model, &bad, &Registry::carried(), FileId(1)).unwrap_err();
        assert!(errors.iter().any(|d| d.code == codes::ROS2_UNKNOWN_FIELD));
    }
}
