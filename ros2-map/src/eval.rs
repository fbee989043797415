//! The map's expressions evaluated on a decoded message, and the
//! [`Translator`]: built once from the rules and a checked map, it turns
//! each message of a topic into the events the map's entries produce, with
//! their payloads as the runtime takes them.
//!
//! Nothing here panics on a message. A value that is missing (an index
//! outside its array, `min` of an empty array, `find` or `index` with no
//! match), a message that does not decode, a division by zero, a NaN or an
//! integer overflow is a [`Problem`] of the outcome, and the entry produces
//! no event for that message.

mod funcs;

use crate::cdr::{self, Decoder};
use crate::check::check_parsed;
use crate::expr::{BinOp, Expr, Range, Reducer, Step};
use crate::map;
use crate::msgs::idl::ConstValue;
use crate::msgs::Registry;
use crate::types;
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
    pub why: Why,
}

/// The kinds of [`EvalError`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Why {
    /// A value the message does not have: an index outside its array, a
    /// reducer of an empty array, `find` or `index` with no match.
    Missing,
    /// A NaN field or result.
    NaN,
    /// Anything else: a division by zero, an overflow, a wrong type.
    Invalid,
}

fn fail<T>(range: Range, message: impl Into<String>) -> Result<T, EvalError> {
    Err(EvalError { message: message.into(), range, why: Why::Invalid })
}

/// A value the message does not have: every such case says `is missing`.
fn missing<T>(range: Range, why: impl std::fmt::Display) -> Result<T, EvalError> {
    Err(EvalError { message: format!("is missing: {why}"), range, why: Why::Missing })
}

fn nan<T>(range: Range) -> Result<T, EvalError> {
    Err(EvalError { message: "is NaN".into(), range, why: Why::NaN })
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
        cdr::Value::Float(f) if f.is_nan() => return nan(range),
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
        nan(range)
    } else {
        Ok(Val::Float(f))
    }
}

/// Where the names of an expression are read: the message, or one element
/// of an array inside `any(array, …)` and the other functions over elements.
#[derive(Debug, Clone, Copy)]
struct Scope<'a> {
    value: &'a cdr::Value,
    /// Inside a function over elements: `it` is the element.
    element: bool,
}

/// The value of `e` on the decoded message `msg`.
pub fn eval<'a>(e: &'a Expr, msg: &'a cdr::Value) -> Result<Val<'a>, EvalError> {
    ev(e, Scope { value: msg, element: false })
}

fn ev<'a>(e: &'a Expr, sc: Scope<'a>) -> Result<Val<'a>, EvalError> {
    match e {
        Expr::Number(n, _) if n.fract() == 0.0 && n.abs() <= EXACT => Ok(Val::Int(*n as i64)),
        Expr::Number(n, _) => Ok(Val::Float(*n)),
        Expr::Str(s, _) => Ok(Val::Str(s)),
        Expr::Bool(b, _) => Ok(Val::Bool(*b)),
        Expr::Path(steps, range) => path(steps, sc, *range),
        Expr::Neg(inner, r) => match ev(inner, sc)? {
            Val::Int(i) => i.checked_neg().map(Val::Int).map_or_else(|| fail(*r, "overflows an integer"), Ok),
            Val::Float(f) => Ok(Val::Float(-f)),
            v => fail(*r, format!("`-` of {}", describe(&v))),
        },
        Expr::Not(inner, r) => match ev(inner, sc)? {
            Val::Bool(b) => Ok(Val::Bool(!b)),
            v => fail(*r, format!("`not` of {}", describe(&v))),
        },
        Expr::Reduce(red, arg, r) => reduce(*red, ev(arg, sc)?, *r),
        Expr::Binary(op, l, r, range) => binary(*op, l, r, sc, *range),
        Expr::Call(f, args, r) => funcs::call(*f, args, sc, *r),
        Expr::Member(base, name, _, r) => match ev(base, sc)? {
            Val::Node(v) => match v.field(name) {
                Some(f) => leaf(f, *r),
                None => fail(*r, format!("the message has no field `{name}`")),
            },
            v => fail(*r, format!("`.{name}` of {}", describe(&v))),
        },
        Expr::At(base, index, r) => {
            let array = ev(base, sc)?;
            at(array, ev(index, sc)?, *r)
        }
    }
}

fn path<'a>(steps: &'a [Step], sc: Scope<'a>, range: Range) -> Result<Val<'a>, EvalError> {
    let steps = match steps.split_first() {
        // `it`: the element itself, unless the element has a field `it`.
        Some((Step::Field(name, _), rest)) if sc.element && name == "it" && sc.value.field("it").is_none() => rest,
        _ => steps,
    };
    let mut v = sc.value;
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
                    return missing((range.0, r.1), format!("index {i} is past the end of an array of {n}"));
                }
                (None, _) => return fail((range.0, r.1), "an index on a value that is not an array"),
            },
        };
    }
    leaf(v, range)
}

/// `array[index]` with an integer index; a negative one counts from the end.
fn at<'a>(array: Val<'a>, index: Val<'_>, r: Range) -> Result<Val<'a>, EvalError> {
    let Val::Node(cdr::Value::Array(items)) = array else {
        return fail(r, format!("an index on {}", describe(&array)));
    };
    let n = items.len();
    let i = match index {
        Val::Int(i) => i,
        // A whole literal too large for an integer: outside any array.
        Val::Float(f) if f.fract() == 0.0 && f > 0.0 => {
            return missing(r, format!("index {f} is past the end of an array of {n}"));
        }
        Val::Float(f) if f.fract() == 0.0 => {
            return missing(r, format!("index {f} is before the start of an array of {n}"));
        }
        v => return fail(r, format!("an index that is {}", describe(&v))),
    };
    let from = if i < 0 { i.checked_add(i64::try_from(n).unwrap_or(i64::MAX)) } else { Some(i) };
    match from.and_then(|k| usize::try_from(k).ok()).and_then(|k| items.get(k)) {
        Some(x) => leaf(x, r),
        None if i < 0 => missing(r, format!("index {i} is before the start of an array of {n}")),
        None => missing(r, format!("index {i} is past the end of an array of {n}")),
    }
}

/// The running `min`, `max` or `mean` of numbers.
struct Acc {
    red: Reducer,
    count: usize,
    sum: f64,
    best_int: Option<i64>,
    best: Option<f64>,
    floats: bool,
}

impl Acc {
    fn new(red: Reducer) -> Acc {
        Acc { red, count: 0, sum: 0.0, best_int: None, best: None, floats: false }
    }

    /// One more number; `false` for a value that is not a number. NaN is skipped.
    fn add(&mut self, v: Val<'_>) -> bool {
        let max = self.red == Reducer::Max;
        let x = match v {
            Val::Int(i) => {
                self.best_int = Some(self.best_int.map_or(i, |a| if max { a.max(i) } else { a.min(i) }));
                i as f64
            }
            Val::Float(f) if f.is_nan() => return true,
            Val::Float(f) => {
                self.floats = true;
                f
            }
            _ => return false,
        };
        self.best = Some(self.best.map_or(x, |a| if max { a.max(x) } else { a.min(x) }));
        self.count += 1;
        self.sum += x;
        true
    }

    /// The result over `n` values; missing when none was a number.
    fn finish(self, n: usize, r: Range) -> Result<Val<'static>, EvalError> {
        let name = self.red.name();
        match (self.red, self.best_int, self.best) {
            (_, _, None) => {
                let why = if n == 0 { "empty".to_string() } else { format!("all {n} NaN") };
                missing(r, format!("`{name}` of an array that is {why}"))
            }
            (Reducer::Mean, _, Some(_)) => number(self.sum / self.count as f64, r),
            (_, Some(i), Some(_)) if !self.floats => Ok(Val::Int(i)),
            (_, _, Some(f)) => number(f, r),
        }
    }
}

fn reduce(red: Reducer, arg: Val<'_>, r: Range) -> Result<Val<'static>, EvalError> {
    let Val::Node(cdr::Value::Array(items)) = arg else {
        return fail(r, format!("a reducer of {}", describe(&arg)));
    };
    if red == Reducer::Len {
        return Ok(Val::Int(i64::try_from(items.len()).unwrap_or(i64::MAX)));
    }
    // NaN elements are invalid readings (REP 117): they are skipped.
    let mut acc = Acc::new(red);
    for item in items {
        let v = match item {
            cdr::Value::Int(i) => Val::Int(*i),
            cdr::Value::Float(f) => Val::Float(*f),
            _ => Val::Bool(false),
        };
        if !acc.add(v) {
            return fail(r, format!("`{}` of an array that holds other things than numbers", red.name()));
        }
    }
    acc.finish(items.len(), r)
}

fn binary<'a>(op: BinOp, l: &'a Expr, r: &'a Expr, sc: Scope<'a>, range: Range) -> Result<Val<'a>, EvalError> {
    let lv = ev(l, sc)?;
    if let (BinOp::And | BinOp::Or, Val::Bool(a)) = (op, lv) {
        // Short-circuit: `len(status) > 0 and status[0].level >= 1`.
        if a == (op == BinOp::Or) {
            return Ok(Val::Bool(a));
        }
        return match ev(r, sc)? {
            Val::Bool(b) => Ok(Val::Bool(b)),
            v => fail(range, format!("`{}` of a boolean and {}", op.text(), describe(&v))),
        };
    }
    let rv = ev(r, sc)?;
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
    /// The map's warnings: it translates, but its author should know.
    warnings: Vec<Diagnostic>,
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
        let (errors, warnings): (Vec<Diagnostic>, Vec<Diagnostic>) =
            check_parsed(model, parsed, msgs, file).into_iter().partition(|d| d.severity == Severity::Error);
        if !errors.is_empty() {
            return Err(errors);
        }
        let mut topics: Vec<Topic> = Vec::new();
        for e in &parsed.events {
            let entry = entry(model, e, msgs, file).ok_or_else(|| {
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
        Ok(Translator { topics, stats: Stats::default(), warnings })
    }

    /// The map's warnings (W04xx), which do not stop the translation.
    pub fn warnings(&self) -> &[Diagnostic] {
        &self.warnings
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

/// The expression of `s` on messages of type `msg`, each path that names a
/// constant (as typing resolved it, scopes included) replaced by its value.
fn source(s: &map::Str, msg: &'static str, msgs: &Registry, file: FileId) -> Option<Source> {
    let typed = types::type_of(s, msg, msgs, file);
    let mut expr = typed.expr?;
    constants(&mut expr, &typed.constants);
    Some(Source { expr, text: s.value.clone() })
}

/// Replaces each path of `e` whose range is one of `found` by its value.
fn constants(e: &mut Expr, found: &[(Range, ConstValue)]) {
    if found.is_empty() {
        return;
    }
    match e {
        Expr::Path(_, range) => {
            let Some((_, value)) = found.iter().find(|(r, _)| r == range) else { return };
            let range = *range;
            *e = match value {
                ConstValue::Bool(b) => Expr::Bool(*b, range),
                ConstValue::Int(i) => Expr::Number(*i as f64, range),
                ConstValue::Float(f) => Expr::Number(*f, range),
                ConstValue::Str(s) => Expr::Str(s.clone(), range),
            };
        }
        Expr::Number(..) | Expr::Str(..) | Expr::Bool(..) => {}
        Expr::Neg(inner, _) | Expr::Not(inner, _) | Expr::Reduce(_, inner, _) | Expr::Member(inner, ..) => {
            constants(inner, found)
        }
        Expr::Binary(_, l, r, _) | Expr::At(l, r, _) => {
            constants(l, found);
            constants(r, found);
        }
        Expr::Call(_, args, _) => args.iter_mut().for_each(|a| constants(a, found)),
    }
}

/// The entry of a checked map's `[[event]]`; `None` only for a map that
/// did not pass the check.
fn entry(model: &Model, e: &map::EventEntry, msgs: &Registry, file: FileId) -> Option<Entry> {
    let msg = msgs.lookup(&e.ty.value)?;
    let source = |s: &map::Str| source(s, msg, msgs, file);
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
mod tests;
