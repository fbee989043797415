//! Scripted runs of any rules file (`situ run FILE --script S`, `--random N`):
//! the compiled bundle on the real runtime (the Bulletinboard, the
//! simulated-time scheduler at the rules' rates, the in-process bus, the
//! wiring of the moment), every agent played by a [`StandIn`] that follows
//! its table or FSM exactly and reports the events the script gives it, at
//! the times the script says.
//!
//! - [`timeline`]: the script's events in time order, made lazily (one
//!   event, periodic events, silences, seeded random sections that use the
//!   guided generator of [`crate::stream`]);
//! - [`explore`]: the closed-loop generator of `--random SEED`, steered by
//!   the state the stack is in towards the states least visited, a new
//!   episode from the initial state after each final state;
//! - [`standin`]: the agent that plays any agent of the rules;
//! - [`report`]: each agent's modes over time, its time running, waiting
//!   and sleeping and in each function; `metrics.json`;
//! - [`chart`]: `timeline.svg`, a band for the state and one per agent.
//!
//! The driver posts an event by queueing it in its agent's inbox and
//! stepping that agent at the event's time, so the event is reported by the
//! agent's own running cycle (a sleeping agent reports nothing; a waiting
//! one still does). Nothing reads a clock: one script and seed give the
//! same report to the byte.

pub mod chart;
pub mod explore;
pub mod report;
pub mod standin;
pub mod timeline;
pub mod wiring;

use crate::agent::{self, Agent};
use crate::record::{Sink, Tee};
use crate::sched::{SimConfig, SimRuntime};
use explore::Explorer;
use report::{agent_times, ScriptReport, Track};
use situ_bundle::spec::ScriptSpec;
use situ_bundle::Content;
use standin::{Inbox, StandIn};
use std::sync::Arc;
use timeline::{Due, Timeline};
use wiring::Snapshot;

/// How long a `--random` run lasts when not told (ns).
pub const DEFAULT_RANDOM_NS: u64 = 300_000_000_000;

/// What drives the agents.
#[derive(Debug, Clone)]
pub enum Driver {
    /// A `script` block of the rules.
    Script(ScriptSpec),
    /// The guided generator, for the whole run.
    Random { seed: u64 },
}

impl Driver {
    /// How the report names it.
    pub fn describe(&self) -> String {
        match self {
            Driver::Script(s) => format!("script \"{}\" ({})", s.name, s.place),
            Driver::Random { seed } => format!("random seed {seed}"),
        }
    }
}

/// What the live line shows.
#[derive(Debug, Clone)]
pub struct Progress {
    pub now: u64,
    pub end: u64,
    pub state: String,
    pub changes: u64,
    pub events: u64,
}

impl Progress {
    pub fn line(&self) -> String {
        let pct = if self.end > 0 { self.now as f64 / self.end as f64 * 100.0 } else { 100.0 };
        format!(
            "{:>8.1} s / {:.1} s ({pct:>3.0}%)  state {}  events {}  changes {}",
            self.now as f64 * 1e-9,
            self.end as f64 * 1e-9,
            self.state,
            self.events,
            self.changes
        )
    }
}

/// Where a run's events come from.
enum Feed {
    Script(Timeline),
    Explore(Box<Explorer>),
}

impl Feed {
    fn next(&mut self) -> Option<Due> {
        match self {
            Feed::Script(t) => t.next(),
            Feed::Explore(x) => x.next_due(),
        }
    }

    fn silenced(&self, agent: usize) -> u64 {
        match self {
            Feed::Script(t) => t.silenced[agent],
            Feed::Explore(_) => 0,
        }
    }
}

/// A scripted run in progress.
pub struct ScriptRun {
    content: Arc<Content>,
    rt: SimRuntime,
    inboxes: Vec<Inbox>,
    feed: Feed,
    next: Option<Due>,
    end: u64,
    track: Track,
    driver: String,
    changes: u64,
    /// The organisation as it was when each state was first at rest.
    snapshots: Vec<Option<Snapshot>>,
}

/// Simulated time between two calls of the progress callback (ns).
const PROGRESS_EVERY: u64 = 1_000_000_000;

impl ScriptRun {
    /// A run of `driver` on the rules, to `until` (ns; default: the script's
    /// end, or a minute of random events), with a recorder if given.
    pub fn new(content: Arc<Content>, driver: Driver, until: Option<u64>, sink: Option<Box<dyn Sink>>) -> ScriptRun {
        let n = content.agents.len();
        let inboxes: Vec<Inbox> = (0..n).map(|_| Inbox::default()).collect();
        let agents: Vec<Box<dyn Agent>> = (0..n as u32)
            .map(|a| Box::new(StandIn::new(&content, a, inboxes[a as usize].clone())) as Box<dyn Agent>)
            .collect();
        let bound = agent::bind(&content, agents, true).expect("a stand-in offers every function of its agent");
        let (feed, end) = match &driver {
            Driver::Script(s) => (Feed::Script(Timeline::of_script(content.clone(), s)), until.unwrap_or(s.end)),
            Driver::Random { seed } => {
                let end = until.unwrap_or(DEFAULT_RANDOM_NS);
                (Feed::Explore(Box::new(Explorer::new(content.clone(), *seed, end))), end)
            }
        };
        let track = Track::new(n);
        let mut sinks: Vec<Box<dyn Sink>> = vec![Box::new(track.clone())];
        sinks.extend(sink);
        let rt = SimRuntime::new(content.clone(), bound, Some(Box::new(Tee(sinks))), SimConfig::default());
        let mut snapshots = vec![None; content.states.len()];
        snapshots[rt.state() as usize] = Some(Snapshot::take(&rt.shared.org(), 0));
        ScriptRun {
            snapshots,
            content,
            rt,
            inboxes,
            feed,
            next: None,
            end,
            track,
            driver: driver.describe(),
            changes: 0,
        }
    }

    /// When the run ends (ns), unless a final state comes first.
    pub fn end(&self) -> u64 {
        self.end
    }

    /// Whether a final state ended the run (a `--random` run goes on with
    /// a new episode instead).
    pub fn finished(&self) -> bool {
        self.rt.finished()
    }

    /// The state at rest now.
    pub fn state(&self) -> &str {
        &self.content.states[self.rt.state() as usize].name
    }

    pub fn progress(&self) -> Progress {
        Progress {
            now: self.rt.now(),
            end: self.end,
            state: self.state().to_string(),
            changes: self.changes,
            events: self.rt.board.counters.accepted,
        }
    }

    /// Runs to the end (or a final state), calling `progress` about once a
    /// simulated second.
    pub fn run(&mut self, progress: &mut dyn FnMut(&ScriptRun)) {
        let mut mark = 0u64;
        while !self.rt.finished() && self.rt.now() < self.end {
            mark = mark.saturating_add(PROGRESS_EVERY).min(self.end);
            self.run_until(mark);
            progress(self);
        }
        if !self.rt.finished() {
            self.run_until(self.end);
        }
    }

    /// Runs every task and scripted event up to `until` (ns, included).
    pub fn run_until(&mut self, until: u64) {
        let until = until.min(self.end);
        loop {
            if self.next.is_none() {
                self.next = self.feed.next();
            }
            let Some(due) = self.next.take_if(|d| d.time <= until) else { break };
            // Queued first: a periodic step of the agent at that very time
            // reports it; otherwise the agent is stepped for it.
            let (agent, time) = (due.agent, due.time);
            self.inboxes[agent as usize].push(time, due.event, due.payload);
            self.advance(time);
            if self.rt.finished() {
                break;
            }
            if self.inboxes[agent as usize].due_by(time) {
                self.rt.wake_at(agent, time);
            }
        }
        if !self.rt.finished() {
            self.advance(until);
        }
    }

    /// The scheduler's tasks up to `until` (included), one at a time, so
    /// that the organisation is seen as each new state comes to rest.
    fn advance(&mut self, until: u64) {
        while !self.rt.finished() && self.rt.next_time().is_some_and(|t| t <= until) {
            let mut rests = Vec::new();
            self.rt.step(&mut |c| rests.push(c.to));
            self.changes += rests.len() as u64;
            let state = self.rt.state() as usize;
            if !rests.is_empty() && self.snapshots[state].is_none() {
                self.snapshots[state] = Some(Snapshot::take(&self.rt.shared.org(), self.rt.now()));
            }
            if let Feed::Explore(x) = &mut self.feed {
                rests.iter().for_each(|&s| x.visit(s));
                if self.rt.finished() {
                    // The episode ends; the run goes on with the next one.
                    let mut restarted = 0u64;
                    self.rt.restart(&mut |_| restarted += 1);
                    self.changes += restarted;
                    x.new_episode(self.rt.state());
                }
            }
        }
        if !self.rt.finished() {
            self.rt.run_until(until, &mut |_| {});
        }
    }

    /// The organisation when each state was first at rest (`None`: never visited).
    pub fn snapshots(&self) -> &[Option<Snapshot>] {
        &self.snapshots
    }

    /// Ends the run (and the recording): the report.
    pub fn finish(self) -> std::io::Result<ScriptReport> {
        let now = self.rt.now();
        let ended = if self.rt.finished() {
            format!("final state {} at {:.3} s", self.state(), now as f64 * 1e-9)
        } else {
            format!("end of the run at {:.3} s", now as f64 * 1e-9)
        };
        self.rt.finish_recording()?;
        let summary = self.rt.summary();
        let tracked = self.track.snapshot();
        let times = agent_times(&tracked, now);
        let agent_times = self
            .content
            .agents
            .iter()
            .enumerate()
            .zip(times)
            .map(|((a, def), mut t)| {
                t.scripted_events = self.inboxes[a].reported();
                t.asleep_events = self.inboxes[a].asleep(now.saturating_add(1));
                t.silenced_events = self.feed.silenced(a);
                (def.name.clone(), t)
            })
            .collect();
        let timeline = tracked
            .states
            .iter()
            .map(|&(t, s)| (t as f64 * 1e-9, self.content.states[s as usize].name.clone()))
            .collect();
        Ok(ScriptReport {
            rules: self.content.source.clone(),
            bundle_sha256: situ_bundle::codec::content_sha256(&self.content),
            driver: self.driver.clone(),
            ended,
            problems: tracked.problems.iter().map(|(t, p)| format!("{:.3} s: {p}", *t as f64 * 1e-9)).collect(),
            runtime: summary,
            agent_times,
            timeline,
            exploration: match &self.feed {
                Feed::Explore(x) => Some(x.coverage()),
                Feed::Script(_) => None,
            },
        })
    }

    /// What the chart needs: the tracked modes and states so far.
    pub fn tracked(&self) -> report::Tracked {
        self.track.snapshot()
    }

    pub fn now(&self) -> u64 {
        self.rt.now()
    }
}

/// Why no script was picked.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum PickError {
    /// No name was given and the rules have no `script` block.
    #[error("the rules have no `script` block")]
    NoScripts,
    /// No script has this name; `known` are the scripts there are.
    #[error("no script \"{name}\"{}", known_scripts(.known))]
    NoSuchScript { name: String, known: Vec<String> },
}

fn known_scripts(known: &[String]) -> String {
    if known.is_empty() {
        String::new()
    } else {
        let names: Vec<String> = known.iter().map(|n| format!("\"{n}\"")).collect();
        format!("; the scripts are: {}", names.join(", "))
    }
}

/// The script a run plays: the one named `name`, or the first of the rules
/// when no name is given.
pub fn pick<'a>(scripts: &'a [ScriptSpec], name: Option<&str>) -> Result<&'a ScriptSpec, PickError> {
    match name {
        None => scripts.first().ok_or(PickError::NoScripts),
        Some(n) => scripts.iter().find(|s| s.name == n).ok_or_else(|| PickError::NoSuchScript {
            name: n.to_string(),
            known: scripts.iter().map(|s| s.name.clone()).collect(),
        }),
    }
}
