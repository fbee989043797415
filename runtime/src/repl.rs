//! `situ repl`: stepping through the rules by hand, in the language's own
//! terms. A [`Session`] holds a Bulletinboard and the organisation around
//! it, and takes one command line at a time:
//!
//! | command | does |
//! |---|---|
//! | `LAOBS distance=12 height=0.5`, `LADAR.LAOBS …`, `LAOBN x3` | posts the event now (N times) |
//! | `wait 300ms` | lets time pass (staleness, windows) |
//! | `state`, `why`, `agents`, `facts` | the state; the last change in source terms; every agent's mode, function and links; the working memory |
//! | `undo` | takes back the last post or wait |
//! | `reload`, `save FILE` | asks the caller to reload the rules or save the session ([`Reply`]) |
//! | `help`, `quit` | |
//!
//! The organisation follows the events as the runtime's does: an agent's
//! FSM sees its own event before the Bulletinboard posts it, and every FSM
//! sees each new state at rest. The session does no I/O: reloading and
//! saving are asked of the caller, which reads and writes the files.

use crate::local::{LocalBoard, NotTaken, Taken};
use crate::rete::{describe_fact, format_time, show_value};
use situ_bundle::suggest::suggest;
use situ_bundle::{Content, FieldType, Mode, Value};
use std::fmt::Write as _;
use std::sync::Arc;

/// What the caller does with a command's result.
#[derive(Debug, Clone, PartialEq)]
pub enum Reply {
    /// Print this.
    Text(String),
    /// Reload the rules from their file and call [`Session::reload`].
    Reload,
    /// Write [`Session::test_block`] to this file.
    Save(String),
    Quit,
}

/// One thing that moved the session on, kept for `undo` and `save`.
#[derive(Debug, Clone, PartialEq)]
enum Step {
    Post { event: u32, payload: Vec<Value>, time: u64, state: u32 },
    Wait { to: u64, state: u32 },
}

/// The most copies one `E xN` posts.
const MAX_REPEAT: u64 = 10_000;
/// The longest `wait` (a day), so that time stays far from overflow.
const MAX_WAIT_NS: u64 = 86_400_000_000_000;

pub struct Session {
    content: Arc<Content>,
    /// The board and organisation, with the admission rule every caller
    /// that reports on the agents' behalf shares.
    local: LocalBoard,
    steps: Vec<Step>,
}

impl Session {
    pub fn new(content: Arc<Content>) -> Session {
        Session { local: LocalBoard::new(content.clone()), content, steps: Vec::new() }
    }

    pub fn content(&self) -> &Arc<Content> {
        &self.content
    }

    /// The state at rest now.
    pub fn state(&self) -> &str {
        self.local.state_name()
    }

    /// Names to complete: commands, agents, events, `field=` of every event, symbols.
    pub fn words(&self) -> Vec<String> {
        let c = &self.content;
        let mut w: Vec<String> = ["wait", "state", "why", "agents", "facts", "undo", "reload", "save", "help", "quit"]
            .map(String::from)
            .into();
        w.extend(c.agents.iter().map(|a| a.name.clone()));
        for e in &c.events {
            w.push(e.name.clone());
            w.push(format!("{}.{}", c.agents[e.agent as usize].name, e.name));
            for f in &e.fields {
                w.push(format!("{}=", f.name));
                if let FieldType::Symbols(s) = &f.ty {
                    w.extend(s.iter().map(|x| format!("{}={x}", f.name)));
                }
            }
        }
        w.sort();
        w.dedup();
        w
    }

    /// Runs one command line; an error is a message for the person, and
    /// the session goes on unchanged.
    pub fn execute(&mut self, line: &str) -> Result<Reply, ReplError> {
        let line = line.split("//").next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        let Some(first) = words.next() else { return Ok(Reply::Text(String::new())) };
        let rest: Vec<&str> = words.collect();
        let none = |r: &[&str], what: &str| -> Result<(), ReplError> {
            if r.is_empty() {
                Ok(())
            } else {
                Err(ReplError::TakesNothing(what.to_string()))
            }
        };
        match first {
            "state" => none(&rest, first)
                .map(|()| Reply::Text(format!("{} at {}", self.state(), format_time(self.local.now())))),
            "why" => none(&rest, first).map(|()| Reply::Text(self.why())),
            "agents" => none(&rest, first).map(|()| Reply::Text(self.agents())),
            "facts" => none(&rest, first).map(|()| Reply::Text(self.facts())),
            "undo" => none(&rest, first).and_then(|()| self.undo()).map(Reply::Text),
            "reload" => none(&rest, first).map(|()| Reply::Reload),
            "help" => Ok(Reply::Text(HELP.trim_end().to_string())),
            "quit" | "exit" => Ok(Reply::Quit),
            "save" => match rest.as_slice() {
                [file] => Ok(Reply::Save(file.to_string())),
                _ => Err(ReplError::SaveUsage),
            },
            "wait" => match rest.as_slice() {
                [d] => self.wait(parse_duration(d)?).map(Reply::Text),
                _ => Err(ReplError::WaitUsage),
            },
            _ => self.post_line(first, &rest).map(Reply::Text),
        }
    }

    fn post_line(&mut self, name: &str, args: &[&str]) -> Result<String, ReplError> {
        let c = self.content.clone();
        let (agent, event_name) = match name.split_once('.') {
            Some((a, e)) => (Some(a), e),
            None => (None, name),
        };
        let Some(event) = c.event_id(event_name) else {
            let suggestion = suggest(event_name, c.events.iter().map(|e| e.name.as_str())).map(str::to_string);
            return Err(ReplError::Unknown { name: name.to_string(), suggestion });
        };
        let def = &c.events[event as usize];
        if let Some(a) = agent {
            let owner = &c.agents[def.agent as usize].name;
            if a != owner {
                let (event, owner, agent) = (event_name.to_string(), owner.clone(), a.to_string());
                return Err(ReplError::NotItsAgent { event, owner, agent });
            }
        }
        let mut payload: Vec<Option<Value>> = vec![None; def.fields.len()];
        let mut repeat = 1u64;
        for arg in args {
            if let Some(n) = arg.strip_prefix('x').and_then(|n| n.parse::<u64>().ok()) {
                if n == 0 || n > MAX_REPEAT {
                    return Err(ReplError::Repeat(n));
                }
                repeat = n;
                continue;
            }
            let Some((field, value)) = arg.split_once('=') else {
                return Err(ReplError::NotAField(arg.to_string()));
            };
            let Some(i) = def.fields.iter().position(|f| f.name == field) else {
                let names: Vec<&str> = def.fields.iter().map(|f| f.name.as_str()).collect();
                let suggestion = suggest(field, names.iter().copied()).map(str::to_string);
                return Err(ReplError::NoField { event: event_name.to_string(), field: field.to_string(), suggestion });
            };
            if payload[i].is_some() {
                return Err(ReplError::Twice(field.to_string()));
            }
            payload[i] = Some(parse_value(&def.fields[i].ty, field, value)?);
        }
        let missing: Vec<&str> =
            def.fields.iter().zip(&payload).filter(|(_, v)| v.is_none()).map(|(f, _)| f.name.as_str()).collect();
        if !missing.is_empty() {
            let missing = missing.into_iter().map(str::to_string).collect();
            return Err(ReplError::Missing { event: event_name.to_string(), missing });
        }
        let payload: Vec<Value> = payload.into_iter().flatten().collect();
        let mut out = Vec::new();
        for i in 0..repeat {
            if let Some(why) = self.not_taken(event, &payload) {
                out.push(if repeat > 1 { format!("{why} ({} of the {repeat} not posted)", repeat - i) } else { why });
                break;
            }
            out.push(self.post(event, payload.clone()));
        }
        Ok(out.into_iter().filter(|s| !s.is_empty()).collect::<Vec<_>>().join("\n"))
    }

    /// Why a run would not take this event now, if it would not, as the
    /// line that says so: its agent sleeps (a sleeping agent is not
    /// stepped, so it reports nothing: language reference §10.7, §10.11),
    /// or the acceptance rule of every part of situ refuses it (§10.4).
    /// The rule is [`LocalBoard::not_taken`]'s. Nothing changes.
    fn not_taken(&mut self, event: u32, payload: &[Value]) -> Option<String> {
        let why = self.local.not_taken(event, self.local.now(), payload)?;
        let verb = match why {
            NotTaken::Sleeping { .. } => "dropped",
            NotTaken::Refused(_) => "refused",
        };
        Some(format!("{verb}: {}; nothing changed", why.describe(&self.content, self.state())))
    }

    /// Posts one event now that [`not_taken`](Self::not_taken) lets
    /// through, as the runtime does: the agent's FSM first, then the rules,
    /// then every FSM on a new state.
    fn post(&mut self, event: u32, payload: Vec<Value>) -> String {
        let time = self.local.now();
        let text = match self.local.post(event, time, &payload) {
            Ok(taken) => self.after(taken),
            Err(why) => format!("not taken: {}", why.describe(&self.content, self.state())),
        };
        self.steps.push(Step::Post { event, payload, time, state: self.local.state() });
        text
    }

    fn wait(&mut self, d: u64) -> Result<String, ReplError> {
        if d > MAX_WAIT_NS {
            return Err(ReplError::WaitTooLong);
        }
        let to = self.local.now() + d;
        let taken = self.local.advance(to);
        let text = self.after(taken);
        self.steps.push(Step::Wait { to, state: self.local.state() });
        Ok(if text.is_empty() { format!("{} at {}", self.state(), format_time(to)) } else { text })
    }

    fn after(&self, taken: Taken) -> String {
        if let Some(e) = taken.error {
            return format!("error: {} (now in {})", e.describe(&self.content), self.state());
        }
        match self.local.last_change().filter(|_| taken.changed) {
            Some(change) => format!(
                "{} -> {} ({})",
                self.content.states[change.from as usize].name,
                self.content.states[change.to as usize].name,
                change
                    .firings
                    .iter()
                    .map(|f| self.content.rules[f.rule as usize].name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            _ => String::new(),
        }
    }

    fn why(&self) -> String {
        match self.local.last_change() {
            None => format!("{} is the initial state: no rule has fired yet", self.state()),
            Some(change) => {
                let mut s = change.explain(&self.content);
                for f in &change.firings {
                    let rule = &self.content.rules[f.rule as usize];
                    let _ =
                        write!(s, "\n  {}:{}: {}", rule.source.file, rule.source.line, first_line(&rule.source.text));
                }
                s
            }
        }
    }

    fn agents(&self) -> String {
        let c = &self.content;
        let width = c.agents.iter().map(|a| a.name.chars().count()).max().unwrap_or(0);
        let mut s = String::new();
        for (a, def) in c.agents.iter().enumerate() {
            let a = a as u32;
            let mode = self.local.organisation().mode(a);
            let mut line = format!("{:<width$}  {}", def.name, mode.adjective());
            if let Some(f) = self.local.organisation().function(a).filter(|_| mode != Mode::Sleeping) {
                let _ = write!(line, " {f}()");
            }
            if let Some(action) = self.local.organisation().action(a).filter(|_| mode == Mode::Running) {
                let names = |ids: &[u32]| {
                    ids.iter().map(|&i| c.agents[i as usize].name.as_str()).collect::<Vec<_>>().join(", ")
                };
                if !action.from.is_empty() {
                    let _ = write!(line, " from {}", names(&action.from));
                }
                if !action.to.is_empty() {
                    let _ = write!(line, " to {}", names(&action.to));
                }
            }
            let _ = writeln!(s, "{line}");
        }
        let links: Vec<String> = self
            .local
            .organisation()
            .links()
            .iter()
            .map(|&(x, y)| format!("{} -> {}", c.agents[x as usize].name, c.agents[y as usize].name))
            .collect();
        let _ =
            write!(s, "links in {}: {}", self.state(), if links.is_empty() { "none".into() } else { links.join(", ") });
        s
    }

    fn facts(&self) -> String {
        let c = &self.content;
        let engine = self.local.bulletinboard().engine();
        let mut lines = Vec::new();
        for (a, def) in c.agents.iter().enumerate() {
            let a = a as u32;
            if engine.is_stale(a) {
                lines.push(format!("{}: stale", def.name));
            } else if let Some(f) = engine.fact(a) {
                let age = self.local.now().saturating_sub(f.time);
                lines.push(format!("{}: {} (age {})", def.name, describe_fact(c, &f), format_time(age)));
            }
        }
        if lines.is_empty() {
            return format!("no facts at {}", format_time(self.local.now()));
        }
        lines.join("\n")
    }

    /// Takes back the last post or wait: the session is replayed without it.
    fn undo(&mut self) -> Result<String, ReplError> {
        let Some(undone) = self.steps.pop() else { return Err(ReplError::NothingToUndo) };
        let steps = std::mem::take(&mut self.steps);
        self.replay_steps(steps);
        let what = match undone {
            Step::Post { event, .. } => format!("took back {}", self.content.events[event as usize].name),
            Step::Wait { .. } => "took back a wait".to_string(),
        };
        Ok(format!("{what}; {} at {}", self.state(), format_time(self.local.now())))
    }

    fn replay_steps(&mut self, steps: Vec<Step>) {
        self.local = LocalBoard::new(self.content.clone());
        for step in steps {
            match step {
                Step::Post { event, payload, time, .. } => {
                    // Taken before, but the rules may have been reloaded
                    // since: one no longer taken is left out.
                    if self.local.post(event, time, &payload).is_ok() {
                        self.steps.push(Step::Post { event, payload, time, state: self.local.state() });
                    }
                }
                Step::Wait { to, .. } => {
                    self.local.advance(to);
                    self.steps.push(Step::Wait { to, state: self.local.state() });
                }
            }
        }
    }

    /// Takes new rules, keeping the facts (a hot swap), and says what
    /// changed; on failure the old rules stay.
    pub fn reload(&mut self, new: Arc<Content>) -> Result<String, ReplError> {
        let old = self.content.clone();
        // The history in the new rules' ids, by name, for `undo` and `save`.
        let steps: Option<Vec<Step>> = self.steps.iter().map(|s| remap(&old, &new, s)).collect();
        let report = self.local.reload(new.clone()).map_err(ReplError::Swap)?;
        self.content = new.clone();
        let mut out = Vec::new();
        let rules = |c: &Content| c.rules.iter().map(|r| (r.name.clone(), r.source.text.clone())).collect::<Vec<_>>();
        let (was, now) = (rules(&old), rules(&new));
        for (name, text) in &now {
            match was.iter().find(|(n, _)| n == name) {
                None => out.push(format!("rule `{name}` added")),
                Some((_, t)) if t != text => out.push(format!("rule `{name}` changed")),
                _ => {}
            }
        }
        out.extend(
            was.iter().filter(|(n, _)| !now.iter().any(|(m, _)| m == n)).map(|(n, _)| format!("rule `{n}` removed")),
        );
        if out.is_empty() {
            out.push("no rule changed".into());
        }
        if !report.carried.is_empty() {
            out.push(format!("facts kept: {}", report.carried.join(", ")));
        }
        for (agent, why) in &report.dropped {
            out.push(format!("fact of {agent} dropped: {why}"));
        }
        if let Some(c) = report.change.as_ref().filter(|c| c.changed()) {
            out.push(format!(
                "the new rules fired: {} -> {}",
                new.states[c.from as usize].name, new.states[c.to as usize].name
            ));
        }
        match steps {
            Some(s) => self.steps = s,
            None => {
                self.steps.clear();
                out.push("the history could not be carried over: `undo` and `save` start from here".into());
            }
        }
        Ok(out.join("\n"))
    }

    /// The session as a `test` block that reproduces it (preceded by
    /// `include_line`, e.g. `include "rules.situ"`, when given).
    pub fn test_block(&self, name: &str, include_line: Option<&str>) -> String {
        let c = &self.content;
        let mut s = String::new();
        if let Some(inc) = include_line {
            let _ = writeln!(s, "{inc}\n");
        }
        let _ = writeln!(s, "test \"{}\" {{", name.replace('\\', "\\\\").replace('"', "\\\""));
        let mut state = c.initial;
        let mut pending_wait = None;
        for step in &self.steps {
            match step {
                Step::Post { event, payload, time, state: after } => {
                    let def = &c.events[*event as usize];
                    let mut text = def.name.clone();
                    if !def.fields.is_empty() {
                        let args: Vec<String> = def
                            .fields
                            .iter()
                            .zip(payload)
                            .map(|(f, v)| format!("{}: {}", f.name, show_value(&f.ty, *v)))
                            .collect();
                        text = format!("{text}({})", args.join(", "));
                    }
                    let _ = writeln!(s, "    on {text} at {}", duration(*time));
                    if *after != state || pending_wait.take().is_some() {
                        let _ = writeln!(s, "    expect state {}", c.states[*after as usize].name);
                    }
                    state = *after;
                }
                Step::Wait { to, state: after } => {
                    let _ = writeln!(s, "    // wait to {}: {}", duration(*to), c.states[*after as usize].name);
                    if *after != state {
                        pending_wait = Some(*after);
                    }
                    state = *after;
                }
            }
        }
        if self.steps.is_empty() {
            let _ = writeln!(s, "    expect state {}", c.states[c.initial as usize].name);
        }
        s.push_str("}\n");
        s
    }
}

fn remap(old: &Content, new: &Content, step: &Step) -> Option<Step> {
    let state = |s: u32| new.state_id(&old.states[s as usize].name);
    Some(match step {
        Step::Post { event, payload, time, state: st } => {
            let e = &old.events[*event as usize];
            let id = new.event_id(&e.name)?;
            let ne = &new.events[id as usize];
            let mut p = Vec::new();
            for f in &ne.fields {
                let i = e.fields.iter().position(|g| g.name == f.name && g.ty == f.ty)?;
                p.push(payload[i]);
            }
            Step::Post { event: id, payload: p, time: *time, state: state(*st).unwrap_or(new.initial) }
        }
        Step::Wait { to, state: st } => Step::Wait { to: *to, state: state(*st).unwrap_or(new.initial) },
    })
}

/// `300ms`, `1.5s`, `2min`, `10us`, `5ns`.
pub fn parse_duration(text: &str) -> Result<u64, DurationError> {
    let split = text.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(text.len());
    let (number, unit) = text.split_at(split);
    let scale: f64 = match unit {
        "ns" => 1.0,
        "us" => 1e3,
        "ms" => 1e6,
        "s" => 1e9,
        "min" => 60e9,
        _ => return Err(DurationError::NoUnit(text.to_string())),
    };
    let value: f64 = number.parse().map_err(|_| DurationError::NotANumber(text.to_string()))?;
    let ns = (value * scale).round();
    if !(ns.is_finite() && (0.0..=MAX_WAIT_NS as f64).contains(&ns)) {
        return Err(DurationError::TooLong(text.to_string()));
    }
    Ok(ns as u64)
}

fn parse_value(ty: &FieldType, field: &str, text: &str) -> Result<Value, ReplError> {
    let bad = |what: &str| ReplError::BadValue {
        field: field.to_string(),
        expected: what.to_string(),
        text: text.to_string(),
    };
    match ty {
        FieldType::F64 => match text.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(Value::F64(v)),
            _ => Err(bad("a number (f64)")),
        },
        FieldType::I64 => text.parse::<i64>().map(Value::I64).map_err(|_| bad("an integer (i64)")),
        FieldType::Bool => match text {
            "true" => Ok(Value::Bool(true)),
            "false" => Ok(Value::Bool(false)),
            _ => Err(bad("`true` or `false`")),
        },
        FieldType::Symbols(symbols) => match symbols.iter().position(|s| s == text) {
            Some(i) => Ok(Value::Symbol(i as u32)),
            None => Err(bad(&format!("one of {}", symbols.join(", ")))),
        },
    }
}

/// A time as a test writes it: `1500ms`, or in nanoseconds when finer.
fn duration(ns: u64) -> String {
    if ns.is_multiple_of(1_000_000) {
        format!("{}ms", ns / 1_000_000)
    } else {
        format!("{ns}ns")
    }
}

fn first_line(text: &str) -> &str {
    text.lines().next().unwrap_or("")
}

/// Why a command line was not taken; the session goes on unchanged. Its
/// text is the message for the person at the prompt.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ReplError {
    #[error("`{0}` takes nothing after it")]
    TakesNothing(String),
    #[error("`save FILE`: one file name")]
    SaveUsage,
    #[error("`wait DURATION`, e.g. `wait 300ms`")]
    WaitUsage,
    #[error("no event or command `{name}`{} (`help` lists the commands)", did_you_mean(.suggestion))]
    Unknown { name: String, suggestion: Option<String> },
    #[error("`{event}` is an event of `{owner}`, not of `{agent}`")]
    NotItsAgent { event: String, owner: String, agent: String },
    #[error("a repeat count is 1 to {MAX_REPEAT}, not {0}")]
    Repeat(u64),
    #[error("`{0}`: write each field as `name=value`, a repeat as `x3`")]
    NotAField(String),
    #[error("`{event}` has no field `{field}`{}", did_you_mean(.suggestion))]
    NoField { event: String, field: String, suggestion: Option<String> },
    #[error("`{0}` is given twice")]
    Twice(String),
    #[error("`{field}` is {expected}, not `{text}`")]
    BadValue { field: String, expected: String, text: String },
    #[error("`{event}` needs every field: {} missing", .missing.join(", "))]
    Missing { event: String, missing: Vec<String> },
    #[error("wait at most a day at a time")]
    WaitTooLong,
    #[error(transparent)]
    Duration(#[from] DurationError),
    #[error("nothing to undo")]
    NothingToUndo,
    #[error("{0:?}; the old rules stay")]
    Swap(crate::bulletinboard::SwapError),
}

/// Why a text is not a duration of the session.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DurationError {
    #[error("`{0}` is not a duration: a number and ns, us, ms, s or min (`300ms`)")]
    NoUnit(String),
    #[error("`{0}` is not a duration (`300ms`)")]
    NotANumber(String),
    #[error("`{0}`: wait at most a day at a time")]
    TooLong(String),
}

fn did_you_mean(suggestion: &Option<String>) -> String {
    suggestion.as_ref().map_or(String::new(), |s| format!("; did you mean `{s}`?"))
}

const HELP: &str = "\
EVENT field=value … [xN]   post an event now (also AGENT.EVENT), N times
wait DURATION              let time pass: wait 300ms, wait 2s
state                      the state at rest and the time
why                        the last change: the rules, their lines, the facts they matched
agents                     every agent's mode, function and links now
facts                      every agent's latest fact (or staleness) and its age
undo                       take back the last event or wait
reload                     read the rules again, keep the facts, say what changed
save FILE                  write the session as a `test` block that reproduces it
help, quit
";
