//! `situ replay F.mcap [--bundle B]`: feeds the events of a recording to a
//! bundle — the one that ran (attached to the recording) or another one —
//! and reports where the states differ from the recorded ones, so that a
//! rule change can be checked against yesterday's drive.
//!
//! What is fed: the accepted events of `/situ/events` and the heartbeats of
//! `/situ/ticks`, in the order they were recorded. Time comes from them
//! only, so the replay is exact: the same bundle gives the same changes.
//!
//! A `--random` run's new episode (a change that no rule made, from a
//! final state to the initial one) resets the replay's working memory as
//! it did the run's, when the replay is in a final state there too.
//!
//! A recording cut short (a run that was killed) is replayed up to the cut
//! and the report says so ([`ReplayReport::cut`]); a damaged recording, or
//! one with nothing of situ's in it, is an error.

use crate::record::mcap::{read_recording, topics, ReadError, Reading};
use crate::rete::{format_time, Engine};
use serde::Serialize;
use serde_json::Value as Json;
use situ_bundle::{Content, FieldType, Value};
use std::sync::Arc;

/// The channels of situ's own that a replay reads.
const OURS: [&str; 3] = [topics::EVENTS, topics::TICKS, topics::STATE];

/// Why a recording cannot be replayed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReplayError {
    /// The recording does not read (not MCAP, damaged).
    #[error(transparent)]
    Read(#[from] ReadError),
    /// Cut short before any message of situ's: why it was cut.
    #[error("nothing to replay before the cut: {0}")]
    NothingBeforeCut(String),
    /// Whole, but with no message on situ's own channels.
    #[error("no message on {}: not a recording of a situ run", OURS.join(", "))]
    NotASituRun,
}

/// A change of the state at rest.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Change {
    pub time_ns: u64,
    pub from: String,
    pub to: String,
    pub rules: Vec<String>,
}

impl std::fmt::Display for Change {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} {} -> {} ({})", format_time(self.time_ns), self.from, self.to, self.rules.join(", "))
    }
}

#[derive(Debug, Clone, Serialize)]
pub struct ReplayReport {
    pub events: usize,
    pub ticks: usize,
    /// Recorded events the bundle does not know (or whose payload no
    /// longer fits): skipped.
    pub skipped: Vec<String>,
    pub recorded: Vec<Change>,
    pub replayed: Vec<Change>,
    /// The index of the first change that differs.
    pub first_difference: Option<usize>,
    /// The recording ends abruptly (a run that was killed).
    pub cut: bool,
    /// Where and why it ends abruptly.
    pub cut_reason: Option<String>,
}

impl ReplayReport {
    pub fn same(&self) -> bool {
        self.first_difference.is_none()
    }

    /// What a person reads.
    pub fn describe(&self) -> String {
        let mut s = format!("{} events and {} heartbeats replayed", self.events, self.ticks);
        if self.cut {
            s.push_str(&format!(
                " (the recording ends abruptly: everything before the cut)\ncut short: {}",
                self.cut_reason.as_deref().unwrap_or("it ends abruptly")
            ));
        }
        if !self.skipped.is_empty() {
            s.push_str(&format!("\n{} recorded events skipped: {}", self.skipped.len(), summarize(&self.skipped)));
        }
        let beyond = self.replayed.len().saturating_sub(self.recorded.len());
        if self.cut && beyond > 0 {
            s.push_str(&format!(
                "\n{beyond} replayed changes after the last recorded one: not compared (the recording ends first)"
            ));
        }
        match self.first_difference {
            None if self.cut => s.push_str(&format!(
                "\nsame states up to the cut: {} changes, identical (what came after the cut is not in the recording)",
                self.recorded.len()
            )),
            None => s.push_str(&format!("\nsame states: {} changes, identical", self.recorded.len())),
            Some(i) => {
                s.push_str(&format!("\nthe states differ at change {} of {}:", i + 1, self.recorded.len()));
                match self.recorded.get(i) {
                    Some(c) => s.push_str(&format!("\n  recorded: {c}")),
                    None => s.push_str("\n  recorded: (no further change)"),
                }
                match self.replayed.get(i) {
                    Some(c) => s.push_str(&format!("\n  replayed: {c}")),
                    None => s.push_str("\n  replayed: (no further change)"),
                }
            }
        }
        s
    }
}

fn summarize(items: &[String]) -> String {
    let mut counts: std::collections::BTreeMap<&str, usize> = Default::default();
    for i in items {
        *counts.entry(i.as_str()).or_default() += 1;
    }
    counts.iter().map(|(k, n)| format!("{k} ×{n}")).collect::<Vec<_>>().join(", ")
}

/// Replays a recording's bytes on `content`.
pub fn replay(recording: &[u8], content: Arc<Content>) -> Result<ReplayReport, ReplayError> {
    replay_reading(&read_recording(recording)?, content)
}

/// Replays a recording read by [`read_recording`] on `content`; an error
/// when it holds no message of situ's own channels (nothing to replay).
pub fn replay_reading(reading: &Reading, content: Arc<Content>) -> Result<ReplayReport, ReplayError> {
    let messages = &reading.messages;
    if !messages.iter().any(|(topic, _, _)| OURS.contains(&topic.as_str())) {
        return Err(match &reading.cut {
            Some(why) => ReplayError::NothingBeforeCut(why.clone()),
            None => ReplayError::NotASituRun,
        });
    }
    let mut engine = Engine::new(content.clone());
    let mut report = ReplayReport {
        events: 0,
        ticks: 0,
        skipped: Vec::new(),
        recorded: Vec::new(),
        replayed: Vec::new(),
        first_difference: None,
        cut: reading.cut.is_some(),
        cut_reason: reading.cut.clone(),
    };
    let name = |s: u32| content.states[s as usize].name.clone();
    for (topic, time, msg) in messages {
        let outcome = match topic.as_str() {
            topics::EVENTS if msg["accepted"] == Json::Bool(true) => match event_of(&content, msg) {
                Ok((event, payload)) => {
                    report.events += 1;
                    engine.post(event, *time, &payload)
                }
                Err(why) => {
                    report.skipped.push(why);
                    continue;
                }
            },
            topics::TICKS => {
                report.ticks += 1;
                engine.advance(*time)
            }
            topics::STATE => {
                if msg["from"] != msg["state"] {
                    let change = Change {
                        time_ns: msg["time_ns"].as_u64().unwrap_or(*time),
                        from: msg["from"].as_str().unwrap_or("?").into(),
                        to: msg["state"].as_str().unwrap_or("?").into(),
                        rules: msg["rules"]
                            .as_array()
                            .map(|r| r.iter().filter_map(|x| x.as_str().map(String::from)).collect())
                            .unwrap_or_default(),
                    };
                    // A new episode of a `--random` run: no rule, from a
                    // final state to the initial one. The replay starts
                    // one too if its own state is final there.
                    let state = engine.state();
                    if change.rules.is_empty()
                        && content.states[state as usize].is_final
                        && change.to == name(content.initial)
                    {
                        engine.reset();
                        report.replayed.push(Change { from: name(state), ..change.clone() });
                    }
                    report.recorded.push(change);
                }
                continue;
            }
            _ => continue,
        };
        match outcome {
            Ok(Some(change)) if change.changed() => report.replayed.push(Change {
                time_ns: change.time,
                from: name(change.from),
                to: name(change.to),
                rules: change.firings.iter().map(|f| content.rules[f.rule as usize].name.clone()).collect(),
            }),
            Ok(_) => {}
            Err(e) => report.skipped.push(format!("cascade error: {}", e.describe(&content))),
        }
    }
    // Cut short, the recording may end between an event and the change it
    // made: changes replayed past the last recorded one are not compared.
    let n = if report.cut { report.recorded.len() } else { report.recorded.len().max(report.replayed.len()) };
    report.first_difference = (0..n).find(|&i| report.recorded.get(i) != report.replayed.get(i));
    Ok(report)
}

/// A recorded event as an event of `content`: by name, its payload by
/// field name and type.
fn event_of(c: &Content, msg: &Json) -> Result<(u32, Vec<Value>), String> {
    let name = msg["event"].as_str().unwrap_or("?");
    let id = c.event_id(name).ok_or_else(|| format!("`{name}` (not in this bundle)"))?;
    let def = &c.events[id as usize];
    let agent = msg["agent"].as_str().unwrap_or("?");
    if c.agents[def.agent as usize].name != agent {
        return Err(format!("`{name}` (now an event of another agent)"));
    }
    let mut payload = Vec::with_capacity(def.fields.len());
    for f in &def.fields {
        let v = &msg["payload"][&f.name];
        let value = match &f.ty {
            FieldType::F64 => v.as_f64().or_else(|| v.as_str().and_then(|s| s.parse().ok())).map(Value::F64),
            FieldType::I64 => v.as_i64().map(Value::I64),
            FieldType::Bool => v.as_bool().map(Value::Bool),
            FieldType::Symbols(s) => {
                v.as_str().and_then(|x| s.iter().position(|y| y == x)).map(|i| Value::Symbol(i as u32))
            }
        };
        payload.push(value.ok_or_else(|| format!("`{name}` (field `{}` missing or of another type)", f.name))?);
    }
    Ok((id, payload))
}
