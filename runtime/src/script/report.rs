//! What a scripted run shows: every agent's modes and functions over time
//! (kept by a [`Track`] sink as the Bulletinboard records them), the time
//! each agent spent running, waiting and sleeping and in each function, and
//! the report `metrics.json` holds. Nothing here reads a clock.

use crate::record::{DataRecord, EventRecord, Level, ModeRecord, Sink};
use crate::rete::StateChange;
use crate::summary::Summary;
use serde::Serialize;
use situ_bundle::{Content, Mode};
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::sync::{Arc, Mutex};

/// One stretch of an agent's organisation: from `time` on, this mode and function.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Stretch {
    pub time: u64,
    pub mode: Mode,
    pub function: Option<String>,
}

/// The modes of every agent and the states, as they changed.
#[derive(Debug, Clone, Default)]
pub struct Tracked {
    /// Per agent, its stretches in time order.
    pub agents: Vec<Vec<Stretch>>,
    /// `(time, state)` of every change of the state at rest.
    pub states: Vec<(u64, u32)>,
    /// Refused events and cascade errors, as the Bulletinboard said them.
    pub problems: Vec<(u64, String)>,
}

/// A sink that keeps only what the timeline and the per-agent figures need.
#[derive(Clone, Default)]
pub struct Track(pub Arc<Mutex<Tracked>>);

impl Track {
    pub fn new(agents: usize) -> Track {
        Track(Arc::new(Mutex::new(Tracked { agents: vec![Vec::new(); agents], ..Tracked::default() })))
    }

    pub fn snapshot(&self) -> Tracked {
        self.0.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }
}

/// At most this many problems are kept word for word (all are counted).
const MAX_PROBLEMS: usize = 100;

impl Sink for Track {
    fn event(&mut self, _rec: &EventRecord) {}
    fn change(&mut self, change: &StateChange) {
        if change.changed() {
            self.0.lock().unwrap_or_else(|p| p.into_inner()).states.push((change.time, change.to));
        }
    }
    fn data(&mut self, _rec: &DataRecord) {}
    fn mode(&mut self, rec: &ModeRecord) {
        let mut t = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(list) = t.agents.get_mut(rec.agent as usize) {
            list.push(Stretch { time: rec.time, mode: rec.mode, function: rec.function.clone() });
        }
    }
    fn diagnostic(&mut self, time: u64, level: Level, text: &str) {
        let mut t = self.0.lock().unwrap_or_else(|p| p.into_inner());
        if level != Level::Info && t.problems.len() < MAX_PROBLEMS {
            t.problems.push((time, text.to_string()));
        }
    }
    fn tick(&mut self, _time: u64) {}
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
    fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Where one agent's time went.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct AgentTimes {
    pub running_s: f64,
    pub waiting_s: f64,
    pub sleeping_s: f64,
    /// Seconds per function chosen (running or waiting with it).
    pub functions: BTreeMap<String, f64>,
    /// Events its script gave it that it reported.
    pub scripted_events: u64,
    /// Events its script gave it while it slept (not reported).
    pub asleep_events: u64,
    /// Events its script gave it inside a `silent` step (not reported).
    pub silenced_events: u64,
}

/// Per agent, where its time went over `[0, end)`.
pub fn agent_times(tracked: &Tracked, end: u64) -> Vec<AgentTimes> {
    tracked
        .agents
        .iter()
        .map(|stretches| {
            let mut t = AgentTimes::default();
            for (i, s) in stretches.iter().enumerate() {
                let until = stretches.get(i + 1).map_or(end, |n| n.time).min(end);
                let dt = until.saturating_sub(s.time) as f64 * 1e-9;
                match s.mode {
                    Mode::Running => t.running_s += dt,
                    Mode::Waiting => t.waiting_s += dt,
                    Mode::Sleeping => t.sleeping_s += dt,
                }
                if let Some(f) = &s.function {
                    if s.mode != Mode::Sleeping {
                        *t.functions.entry(f.clone()).or_default() += dt;
                    }
                }
            }
            t
        })
        .collect()
}

/// What `metrics.json` of a scripted run holds.
#[derive(Debug, Clone, Serialize)]
pub struct ScriptReport {
    /// The rules' source name and the bundle's hash.
    pub rules: String,
    pub bundle_sha256: String,
    /// `script "NAME"`, or `random seed N`.
    pub driver: String,
    /// Why the run ended: the end of the script, a final state, `--until`.
    pub ended: String,
    /// Problems the Bulletinboard reported (refused events, cascades).
    pub problems: Vec<String>,
    pub runtime: Summary,
    /// Per agent, by name.
    pub agent_times: BTreeMap<String, AgentTimes>,
    /// Each change of the state at rest: `(seconds, state)`.
    pub timeline: Vec<(f64, String)>,
    /// What a `--random` run explored: episodes, states visited.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub exploration: Option<super::explore::Coverage>,
}

impl ScriptReport {
    /// Whether the rules took every event without a fault: no refused event,
    /// no cascade error.
    pub fn clean(&self) -> bool {
        self.runtime.board.refused.is_empty() && self.runtime.board.cascade_errors == 0
    }

    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }

    /// The per-agent table a person reads after the runtime's summary.
    pub fn agents_table(&self, content: &Content) -> String {
        let width = content.agents.iter().map(|a| a.name.chars().count()).max().unwrap_or(5).max(5);
        let mut s = String::new();
        let _ = writeln!(
            s,
            "  {:<width$}  running (s)  waiting (s)  sleeping (s)  events  asleep  silenced  functions (s)",
            "agent"
        );
        for a in &content.agents {
            let Some(t) = self.agent_times.get(&a.name) else { continue };
            let functions: Vec<String> = t.functions.iter().map(|(f, s)| format!("{f} {s:.1}")).collect();
            let _ = writeln!(
                s,
                "  {:<width$}  {:>11.1}  {:>11.1}  {:>12.1}  {:>6}  {:>6}  {:>8}  {}",
                a.name,
                t.running_s,
                t.waiting_s,
                t.sleeping_s,
                t.scripted_events,
                t.asleep_events,
                t.silenced_events,
                if functions.is_empty() { "-".to_string() } else { functions.join(", ") }
            );
        }
        s
    }
}
