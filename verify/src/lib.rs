//! `situ test`: scenario tests and properties (language reference §7, §8,
//! §10.9, §10.10), on the real Rete engine and the organisation.
//!
//! - [`scenario`] runs `test` blocks and reports every failed expectation
//!   with its place and what was found instead;
//! - [`monitor`] is the logic of properties: a property is checked point by
//!   point along a run by a small monitor whose state is part of the search;
//! - [`random`] searches runs at random (proptest, guided by the rules) and
//!   shrinks a failing run to a minimal one;
//! - [`promela`] writes the explored abstraction as a Promela model for spin;
//! - [`explore`] explores a finite abstraction of the system breadth first
//!   ([`abstraction`]): it proves a property, or finds its shortest
//!   counterexample, or says up to which depth it found none.
//! - [`bmc`] unrolls the circuit of [`model`] where the exploration stopped
//!   short (a wide file), so that its bound reaches `--depth` events.
//!
//! [`property`] runs them on each property and concludes: proved, violated
//! or undecided; [`suite`] is `situ test` as one call: the tests and the
//! properties of each file, the summary and the verdict (the command line
//! only renders it).
//!
//! Both checkers run the same [`System`]: the engine and the organisation,
//! driven as at runtime (the FSMs see an event before the rest for it, and
//! every change of the state at rest after it).

pub mod abstraction;
pub mod aig;
pub mod bmc;
pub mod explore;
pub mod findings;
pub mod ic3;
pub mod liveness;
pub mod model;
pub mod monitor;
pub mod promela;
pub mod property;
pub mod prove;
pub mod random;
pub mod scenario;
pub mod suite;

use situ_compiler::bundle::{Content, Value};
use situ_compiler::spec::{Pred, PropertySpec};
use situ_runtime::organise::Organisation;
use situ_runtime::rete::{format_time, passes, show_value, Engine, PostError, Step};
use std::sync::Arc;

/// The engine and the organisation, stepped together.
#[derive(Debug, Clone)]
pub struct System {
    pub engine: Engine,
    pub org: Organisation,
}

impl System {
    /// The initial state, no facts, FSMs in their initial states, now = 0.
    pub fn new(content: Arc<Content>) -> System {
        System { engine: Engine::new(content.clone()), org: Organisation::new(content) }
    }

    pub fn content(&self) -> &Arc<Content> {
        self.engine.content()
    }

    /// Posts one event as the runtime does: the agent's FSM sees it first,
    /// the network comes to rest, then the FSMs see the new state at rest.
    /// A refused event changes nothing.
    pub fn post(&mut self, event: u32, time: u64, payload: &[Value]) -> Result<Step, PostError> {
        self.engine.admit(event, time, payload)?;
        let agent = self.content().events[event as usize].agent;
        self.org.on_event(agent, event);
        let step = self.engine.step(event, time, payload).map_err(|e| self.engine.post_error(e));
        let state = self.engine.state();
        if state != self.org.state() {
            self.org.on_state(state);
        }
        step
    }

    /// Makes `self` a copy of `other`, reusing buffers.
    pub fn copy_from(&mut self, other: &System) {
        self.engine.copy_from(&other.engine);
        self.org.clone_from(&other.org);
    }

    /// Whether a predicate holds now (§8).
    pub fn holds(&self, p: &Pred) -> bool {
        match p {
            Pred::Or(ps) => ps.iter().any(|p| self.holds(p)),
            Pred::And(ps) => ps.iter().all(|p| self.holds(p)),
            Pred::Not(p) => !self.holds(p),
            Pred::Bool(b) => *b,
            Pred::State(states) => states.binary_search(&self.engine.state()).is_ok(),
            Pred::Mode { agent, mode } => self.org.mode(*agent) == *mode,
            Pred::Link { from, to } => self.org.has_link(*from, *to),
            Pred::Stale(agent) => self.engine.is_stale(*agent),
            Pred::Event { event, tests, min_run } => {
                let agent = self.content().events[*event as usize].agent;
                self.engine.fact_view(agent).is_some_and(|f| {
                    f.event == *event && f.run >= *min_run && tests.iter().all(|t| passes(t, f.payload))
                })
            }
        }
    }

    /// The premise (true without one) and the consequent's predicate of a property, now.
    pub fn point(&self, p: &PropertySpec) -> (bool, bool) {
        let mut preds = p.preds();
        let premise = if p.premise.is_some() { preds.next().is_some_and(|q| self.holds(q)) } else { true };
        let q = preds.last().is_some_and(|q| self.holds(q));
        (premise, q)
    }
}

/// One event of a run: what is posted, and how long after the previous one.
#[derive(Debug, Clone, PartialEq)]
pub struct RunStep {
    pub event: u32,
    pub payload: Vec<Value>,
    /// Nanoseconds after the previous event (after 0 for the first).
    pub gap: u64,
}

/// An event as written in situ: `LAOBS(distance: 12.0, height: 0.5)`.
pub fn show_event(c: &Content, event: u32, payload: &[Value]) -> String {
    let e = &c.events[event as usize];
    if e.fields.is_empty() {
        return e.name.clone();
    }
    let args: Vec<String> =
        e.fields.iter().zip(payload).map(|(f, v)| format!("{}: {}", f.name, show_value(&f.ty, *v))).collect();
    format!("{}({})", e.name, args.join(", "))
}

/// A duration as situ writes it, exactly: `500ms`, `300000001ns`.
pub fn show_duration(ns: u64) -> String {
    if ns / 1_000_000 * 1_000_000 == ns {
        format!("{}ms", ns / 1_000_000)
    } else if ns / 1_000 * 1_000 == ns {
        format!("{}us", ns / 1_000)
    } else {
        format!("{ns}ns")
    }
}

/// A run that breaks a property, replayed: each event with the state after
/// it and the rules that fired.
#[derive(Debug, Clone, PartialEq)]
pub struct Counterexample {
    pub steps: Vec<CexStep>,
    /// The point where the property fails: 0 is the start, i the system after event i.
    pub point: usize,
    /// Why it fails there.
    pub reason: String,
}

#[derive(Debug, Clone, PartialEq)]
pub struct CexStep {
    pub event: u32,
    pub payload: Vec<Value>,
    pub time: u64,
    /// The state at rest after the event.
    pub state: u32,
    /// The rules that fired, in order, with their places.
    pub fired: Vec<String>,
}

impl Counterexample {
    /// Replays `run` from the initial system and records what happened.
    pub fn replay(content: &Arc<Content>, run: &[RunStep], point: usize, reason: String) -> Counterexample {
        let mut sys = System::new(content.clone());
        let mut time = 0u64;
        let mut steps = Vec::new();
        for s in run {
            time = time.saturating_add(s.gap);
            let fired = match sys.post(s.event, time, &s.payload) {
                Ok(_) => sys
                    .engine
                    .last_change()
                    .firings
                    .iter()
                    .map(|f| {
                        let r = &content.rules[f.rule as usize];
                        format!("`{}` ({})", r.name, r.source)
                    })
                    .collect(),
                Err(e) => vec![e.describe(content)],
            };
            steps.push(CexStep { event: s.event, payload: s.payload.clone(), time, state: sys.engine.state(), fired });
        }
        Counterexample { steps, point, reason }
    }

    /// The run as a person reads it: one line per event.
    pub fn describe(&self, c: &Content) -> String {
        let mut out = String::new();
        let mut state = c.initial;
        out.push_str(&format!("  start   {:<44} {}\n", "", c.states[state as usize].name));
        for (i, s) in self.steps.iter().enumerate() {
            let change = if s.state == state {
                c.states[s.state as usize].name.clone()
            } else {
                format!("{} -> {}", c.states[state as usize].name, c.states[s.state as usize].name)
            };
            out.push_str(&format!(
                "  {:>2}. {:>8}  {:<40} {}",
                i + 1,
                format_time(s.time),
                show_event(c, s.event, &s.payload),
                change
            ));
            if !s.fired.is_empty() {
                out.push_str(&format!("   fired {}", s.fired.join(", ")));
            }
            out.push('\n');
            state = s.state;
        }
        let at = if self.point == 0 { "at the start".to_string() } else { format!("after event {}", self.point) };
        out.push_str(&format!("  fails {at}: {}\n", self.reason));
        out
    }

    /// The run as a `test` block to paste into the rule file.
    pub fn as_test(&self, c: &Content, property: &str) -> String {
        let mut out = format!("test \"counterexample: {}\" {{\n", property.replace('"', "'"));
        if !self.steps.is_empty() {
            let events: Vec<String> = self
                .steps
                .iter()
                .map(|s| format!("{} at {}", show_event(c, s.event, &s.payload), show_duration(s.time)))
                .collect();
            out.push_str(&format!("    on {}\n", events.join(",\n       ")));
        }
        let last = self.steps.last().map_or(c.initial, |s| s.state);
        out.push_str(&format!("    expect state {}\n", c.states[last as usize].name));
        out.push_str(&format!("    // property fails here: {}\n}}\n", self.reason));
        out
    }
}

/// What a checker found for one property.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// It holds on every run: the abstract space was explored whole and the
    /// abstraction is exact for this program.
    Proved {
        states: usize,
    },
    /// No counterexample in the whole abstract space, but the abstraction
    /// samples something (time gaps, values compared with variables): see `note`.
    Exhausted {
        states: usize,
        note: String,
    },
    /// No counterexample among the runs explored: up to `depth` events (exhaustive),
    /// or `runs` random runs.
    Bounded {
        depth: usize,
        states: usize,
        note: String,
    },
    /// No state of the abstraction that breaks it is reachable, in runs of
    /// any length and with any gaps: IC3 closed an inductive invariant of
    /// `clauses` clauses at frame `frames`. With `sampled`, the abstraction
    /// samples payloads (said there), so it is not a proof for every run.
    Inductive {
        frames: usize,
        clauses: usize,
        sampled: Option<String>,
    },
    /// The circuit's counterexample of `events` events does not break the
    /// property on the real engine: the two disagree (an error of situ).
    Disagree {
        events: usize,
    },
    /// No counterexample in `runs` random runs of up to `length` events.
    NotFound {
        runs: u64,
        length: usize,
        steps: u64,
    },
    /// IC3 stopped at a limit before it closed an invariant or found a run:
    /// no bad state of the circuit within `depth` steps, after `work` propagations.
    GaveUp {
        depth: usize,
        work: u64,
        stop: ic3::Stop,
    },
    Failed(Counterexample),
}

impl Verdict {
    pub fn failed(&self) -> bool {
        matches!(self, Verdict::Failed(_))
    }

    /// One line: what was shown.
    pub fn summary(&self) -> String {
        match self {
            Verdict::Proved { states } => format!("proved ({states} abstract states, every run)"),
            Verdict::Exhausted { states, note } => {
                format!("no counterexample in the whole abstract space ({states} states; {note})")
            }
            Verdict::Bounded { depth, states, note } => {
                format!("no counterexample up to {depth} events ({states} abstract states; {note})")
            }
            Verdict::NotFound { runs, length, steps } => {
                format!("no counterexample in {runs} random runs of up to {length} events ({steps} steps)")
            }
            Verdict::Inductive { frames, clauses, sampled: None } => {
                format!("proved for runs of any length (IC3: an inductive invariant of {clauses} clauses at frame {frames})")
            }
            Verdict::Inductive { frames, clauses, sampled: Some(note) } => format!(
                "no counterexample in runs of any length of the abstraction (IC3: {clauses} clauses at frame {frames}; {note})"
            ),
            Verdict::Disagree { events } => format!(
                "the symbolic model's counterexample of {events} events does not replay on the engine: an error of situ, please report it"
            ),
            Verdict::GaveUp { depth, work, stop } => {
                let why = match stop {
                    ic3::Stop::Frames => format!("the limit of {} frames", prove::MAX_FRAMES),
                    ic3::Stop::Work => "its work budget (`--prove-effort`)".to_string(),
                    ic3::Stop::Deadline => "the wall-clock guard (`--prove-timeout`)".to_string(),
                };
                format!(
                    "gave up at {why}: no counterexample of up to {depth} events, after {work} SAT propagations"
                )
            }
            Verdict::Failed(c) => format!("counterexample of {} events", c.steps.len()),
        }
    }
}
