//! A run as the Supervisor's page draws it (`situ view`): the state
//! changes with their rules and explanations, the agents' modes, the
//! events refused and why, read from a recording ([`Timeline::read`]) or
//! message by message as a live run's recorder writes them ([`Entry::of`],
//! the live log of [`super::live`]).
//!
//! Only the rules' topics are read ([`TOPICS`]: not a simulation's pose,
//! not the `/events` log that repeats `/situ/events`). A message that names
//! a state or an agent the rules do not have means the recording was made
//! on other rules: an error ([`TimelineError::OtherRules`]).

use super::mcap::{topics, Reading};
use serde_json::{json, Value as Json};
use situ_bundle::Content;

/// The topics the page reads.
pub const TOPICS: [&str; 4] = [topics::STATE, topics::MODES, topics::EVENTS, topics::TICKS];

/// A state change of a run.
#[derive(Debug, Clone, PartialEq)]
pub struct Change {
    pub t: u64,
    pub from: String,
    pub to: String,
    pub rules: Vec<String>,
    pub explain: String,
}

/// An agent's mode as recorded.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeAt {
    pub t: u64,
    pub agent: String,
    pub function: String,
    pub mode: String,
}

/// An event the Bulletinboard refused, and why.
#[derive(Debug, Clone, PartialEq)]
pub struct Refusal {
    pub t: u64,
    pub agent: String,
    pub event: String,
    pub reason: String,
}

/// What the page draws of one message of a run (a recording's, or a live
/// run's as its recorder writes it).
#[derive(Debug, Clone, PartialEq)]
pub enum Entry {
    Change(Change),
    Mode(ModeAt),
    Refused(Refusal),
    /// A message of the run that moves only its clock: an accepted event,
    /// a tick, a state message that did not change the state.
    Time(u64),
}

/// Why a recording's messages do not make a timeline of these rules.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TimelineError {
    /// A message names what the rules do not have: `what` says it
    /// (`its state `X` is not a state`).
    #[error("recorded on other rules: {what}")]
    OtherRules { what: String },
    /// No message on the rules' topics.
    #[error("holds no message of a situ run (/state, /situ/events, /situ/modes)")]
    NothingOfSitu,
}

impl Entry {
    /// The entry of a message on `topic` at `time` (ns); `None` when the
    /// topic is not one of a situ run's (a simulation's pose, say).
    pub fn of(topic: &str, time: u64, msg: &Json) -> Option<Entry> {
        let text = |k: &str| msg[k].as_str().unwrap_or("").to_string();
        let t = msg["time_ns"].as_u64().unwrap_or(time);
        Some(match topic {
            topics::STATE if msg["from"] != msg["state"] => {
                let rules = msg["rules"]
                    .as_array()
                    .map(|r| r.iter().filter_map(|x| x.as_str().map(String::from)).collect())
                    .unwrap_or_default();
                Entry::Change(Change { t, from: text("from"), to: text("state"), rules, explain: text("explain") })
            }
            topics::MODES => {
                Entry::Mode(ModeAt { t, agent: text("agent"), function: text("function"), mode: text("mode") })
            }
            topics::EVENTS if msg["accepted"] == Json::Bool(false) => {
                Entry::Refused(Refusal { t, agent: text("agent"), event: text("event"), reason: text("reason") })
            }
            topics::STATE | topics::EVENTS | topics::TICKS => Entry::Time(t),
            _ => return None,
        })
    }

    /// What in the entry is not of `content` (a state, an agent), if anything.
    pub fn foreign(&self, content: &Content) -> Option<String> {
        match self {
            Entry::Change(c) => [&c.from, &c.to]
                .into_iter()
                .find(|s| content.state_id(s).is_none())
                .map(|s| format!("its state `{s}` is not a state")),
            Entry::Mode(m) => {
                content.agent_id(&m.agent).is_none().then(|| format!("its agent `{}` is not an agent", m.agent))
            }
            Entry::Refused(_) | Entry::Time(_) => None,
        }
    }

    pub fn time(&self) -> u64 {
        match self {
            Entry::Change(c) => c.t,
            Entry::Mode(m) => m.t,
            Entry::Refused(r) => r.t,
            Entry::Time(t) => *t,
        }
    }
}

impl Change {
    pub fn json(&self) -> Json {
        json!({ "t": self.t, "from": self.from, "to": self.to, "rules": self.rules, "explain": self.explain })
    }
}

impl ModeAt {
    pub fn json(&self) -> Json {
        json!({ "t": self.t, "agent": self.agent, "function": self.function, "mode": self.mode })
    }
}

impl Refusal {
    pub fn json(&self) -> Json {
        json!({ "t": self.t, "agent": self.agent, "event": self.event, "reason": self.reason })
    }
}

/// A recorded run, as the page draws it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Timeline {
    pub changes: Vec<Change>,
    pub modes: Vec<ModeAt>,
    pub refused: Vec<Refusal>,
    /// The latest time of any message (ns).
    pub end: u64,
    /// Why the recording stops before its end, when it does.
    pub cut: Option<String>,
}

impl Timeline {
    /// The timeline of a recording read with [`TOPICS`] kept, on the rules
    /// `content`.
    pub fn read(reading: &Reading, content: &Content) -> Result<Timeline, TimelineError> {
        let mut timeline = Timeline { end: reading.end, cut: reading.cut.clone(), ..Timeline::default() };
        let mut ours = 0usize;
        for (topic, time, msg) in &reading.messages {
            let Some(entry) = Entry::of(topic, *time, msg) else { continue };
            ours += 1;
            if let Some(what) = entry.foreign(content) {
                return Err(TimelineError::OtherRules { what });
            }
            match entry {
                Entry::Change(c) => timeline.changes.push(c),
                Entry::Mode(m) => timeline.modes.push(m),
                Entry::Refused(r) => timeline.refused.push(r),
                Entry::Time(_) => {}
            }
        }
        if ours == 0 {
            return Err(TimelineError::NothingOfSitu);
        }
        Ok(timeline)
    }

    /// The page's `/api/timeline` of a recording.
    pub fn json(&self) -> Json {
        json!({
            "recording": true,
            "end_ns": self.end,
            "cut": self.cut,
            "changes": self.changes.iter().map(Change::json).collect::<Vec<_>>(),
            "modes": self.modes.iter().map(ModeAt::json).collect::<Vec<_>>(),
            "refused": self.refused.iter().map(Refusal::json).collect::<Vec<_>>(),
        })
    }

    /// The state, the states visited, the last rules that fired and the
    /// agents' recorded modes at `at` (nanoseconds; none: the end of the
    /// run), starting from the initial state of `content`.
    pub fn state_at(&self, content: &Content, at: Option<u64>) -> Json {
        let c = content;
        let t = at.unwrap_or(u64::MAX);
        let mut state = c.states[c.initial as usize].name.clone();
        let mut visited = vec![state.clone()];
        let mut fired = Json::Null;
        for ch in self.changes.iter().take_while(|ch| ch.t <= t) {
            state = ch.to.clone();
            if !visited.contains(&state) {
                visited.push(state.clone());
            }
            fired = json!({ "t": ch.t, "rules": ch.rules, "explain": ch.explain });
        }
        let mut modes = serde_json::Map::new();
        for m in self.modes.iter().take_while(|m| m.t <= t) {
            modes.insert(m.agent.clone(), json!({ "mode": m.mode, "function": m.function }));
        }
        json!({ "at_ns": at, "state": state, "visited": visited, "fired": fired, "modes": modes })
    }
}
