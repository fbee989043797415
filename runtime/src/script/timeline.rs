//! A script's events in time order, made lazily: every step is a source
//! (one event, a periodic event, a random section) and the timeline merges
//! them, dropping what a silence covers. Nothing is made before it is due,
//! so an hour of periodic events costs no memory.

use crate::stream::Generator;
use situ_bundle::spec::{ScriptSpec, ScriptStep};
use situ_bundle::{Content, Value};
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::sync::Arc;

/// The most events one random section makes (whatever the rates say), so
/// that a run always ends.
pub const MAX_RANDOM_EVENTS: u64 = 10_000_000;

/// One event due at one time, from one step of the script.
#[derive(Debug, Clone, PartialEq)]
pub struct Due {
    pub time: u64,
    pub agent: u32,
    pub event: u32,
    pub payload: Vec<Value>,
    /// The index of the script step it comes from (`usize::MAX`: `--random`).
    pub step: usize,
}

/// What a source makes next.
enum Source {
    Once { time: u64, event: u32, payload: Vec<Value>, done: bool },
    Every { next: u64, period: u64, to: u64, event: u32, payload: Vec<Value> },
    Random { from: u64, end: u64, made: u64, generator: Box<Generator>, pending: Option<(u64, u32, Vec<Value>)> },
}

impl Source {
    /// The time of the next event, if any.
    fn peek(&mut self) -> Option<u64> {
        match self {
            Source::Once { time, done, .. } => (!*done).then_some(*time),
            Source::Every { next, to, .. } => (*next < *to).then_some(*next),
            Source::Random { from, end, made, generator, pending } => {
                if pending.is_none() && *made < MAX_RANDOM_EVENTS {
                    if let Some(e) = generator.next_event() {
                        let time = from.saturating_add(e.time);
                        if time < *end {
                            *pending = Some((time, e.event, e.payload));
                        }
                    }
                }
                pending.as_ref().map(|p| p.0)
            }
        }
    }

    /// Takes the next event (after `peek` said there is one).
    fn take(&mut self) -> Option<(u64, u32, Vec<Value>)> {
        match self {
            Source::Once { time, event, payload, done } => {
                *done = true;
                Some((*time, *event, payload.clone()))
            }
            Source::Every { next, period, event, payload, .. } => {
                let t = *next;
                *next = next.saturating_add(*period);
                if *next == t {
                    *next = u64::MAX;
                }
                Some((t, *event, payload.clone()))
            }
            Source::Random { made, pending, .. } => {
                *made += 1;
                pending.take()
            }
        }
    }
}

/// The merged, silenced events of a script.
pub struct Timeline {
    content: Arc<Content>,
    sources: Vec<Source>,
    heap: BinaryHeap<Reverse<(u64, usize)>>,
    /// Per agent, its silences `[from, to)`.
    silences: Vec<Vec<(u64, u64)>>,
    /// The source of each step index (`usize::MAX` for a whole-run random).
    steps: Vec<usize>,
    /// Events dropped because their agent was silent, per agent.
    pub silenced: Vec<u64>,
}

impl Timeline {
    /// The timeline of a script.
    pub fn of_script(content: Arc<Content>, script: &ScriptSpec) -> Timeline {
        let mut t = Timeline::empty(content.clone());
        for (i, step) in script.steps.iter().enumerate() {
            let source = match step {
                ScriptStep::At { time, event } => {
                    Source::Once { time: *time, event: event.event, payload: event.payload.clone(), done: false }
                }
                ScriptStep::Every { period, from, to, event } => Source::Every {
                    next: *from,
                    period: (*period).max(1),
                    to: *to,
                    event: event.event,
                    payload: event.payload.clone(),
                },
                ScriptStep::Silent { agent, from, to, .. } => {
                    if let Some(s) = t.silences.get_mut(*agent as usize) {
                        s.push((*from, *to));
                    }
                    continue;
                }
                ScriptStep::Random { from, length, seed, .. } => random(&content, *from, *length, *seed),
            };
            t.add(source, i);
        }
        t
    }

    /// The guided generator alone, from 0 for `length` (`--random SEED`).
    pub fn random(content: Arc<Content>, length: u64, seed: u64) -> Timeline {
        let mut t = Timeline::empty(content.clone());
        t.add(random(&content, 0, length, seed), usize::MAX);
        t
    }

    fn empty(content: Arc<Content>) -> Timeline {
        let n = content.agents.len();
        Timeline {
            content,
            sources: Vec::new(),
            heap: BinaryHeap::new(),
            silences: vec![Vec::new(); n],
            steps: Vec::new(),
            silenced: vec![0; n],
        }
    }

    fn add(&mut self, mut source: Source, step: usize) {
        let index = self.sources.len();
        if let Some(time) = source.peek() {
            self.heap.push(Reverse((time, index)));
        }
        self.sources.push(source);
        self.steps.push(step);
    }

    fn silent(&self, agent: u32, time: u64) -> bool {
        self.silences[agent as usize].iter().any(|&(from, to)| from <= time && time < to)
    }
}

impl Iterator for Timeline {
    type Item = Due;

    /// The next event in time order (ties: in the order of the steps).
    fn next(&mut self) -> Option<Due> {
        loop {
            let Reverse((_, index)) = self.heap.pop()?;
            let source = &mut self.sources[index];
            let (time, event, payload) = source.take()?;
            if let Some(next) = source.peek() {
                self.heap.push(Reverse((next, index)));
            }
            let agent = self.content.events[event as usize].agent;
            if self.silent(agent, time) {
                self.silenced[agent as usize] += 1;
                continue;
            }
            return Some(Due { time, agent, event, payload, step: self.steps[index] });
        }
    }
}

fn random(content: &Arc<Content>, from: u64, length: u64, seed: u64) -> Source {
    Source::Random {
        from,
        end: from.saturating_add(length),
        made: 0,
        generator: Box::new(Generator::new(content.clone(), seed).reset_on_final(false)),
        pending: None,
    }
}
