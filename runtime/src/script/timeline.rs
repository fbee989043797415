//! A script's events in time order, made lazily: every step is a source
//! (one event, a periodic event, a random section) and the timeline merges
//! them, dropping what a silence covers. Nothing is made before it is due,
//! so an hour of periodic events costs no memory.

use crate::stream::Generator;
use situ_compiler::bundle::{Content, Value};
use situ_compiler::spec::{ScriptSpec, ScriptStep};
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

#[cfg(test)]
mod tests {
    use super::*;
    use situ_compiler::spec;

    const SRC: &str = "states { A initial B }\n\
        agent S sensor { rate 10Hz stale after 300ms event HB event GO { n: i64 } }\n\
        agent T sensor { event PING }\n\
        rule go { when state == A and GO(n > 2) then B }\n\
        rule hb { when state == B and HB and PING then A }\n\
        script \"s\" {\n\
            every 100ms S.HB from 0s to 1s\n\
            at 250ms T.PING\n\
            silent S from 500ms to 700ms\n\
            at 800ms S.GO(n: 3)\n\
            random 1s seed 4 from 2s\n\
        }\n";

    fn program() -> (Arc<Content>, ScriptSpec) {
        let checked = situ_compiler::check_source("t.situ", SRC);
        let errors: Vec<_> =
            checked.diagnostics.iter().filter(|d| d.severity == situ_compiler::Severity::Error).collect();
        assert!(errors.is_empty(), "{errors:?}");
        (Arc::new(situ_compiler::bundle::build(&checked)), spec::scripts(&checked).remove(0))
    }

    #[test]
    fn events_come_in_time_order_without_the_silenced_ones() {
        let (c, s) = program();
        let mut t = Timeline::of_script(c.clone(), &s);
        let due: Vec<Due> = t.by_ref().collect();
        let times: Vec<u64> = due.iter().map(|d| d.time).collect();
        assert!(times.windows(2).all(|w| w[0] <= w[1]), "{times:?}");
        let name = |d: &Due| c.events[d.event as usize].name.clone();
        let heartbeats: Vec<u64> =
            due.iter().filter(|d| name(d) == "HB" && d.time < 1_000_000_000).map(|d| d.time).collect();
        // 0, 100, …, 900 ms less 500 and 600 (silent).
        let ms: Vec<u64> = heartbeats.iter().map(|t| t / 1_000_000).collect();
        assert_eq!(ms, [0, 100, 200, 300, 400, 700, 800, 900]);
        assert_eq!(t.silenced[c.agent_id("S").unwrap() as usize], 2);
        let ping = due.iter().find(|d| name(d) == "PING").unwrap();
        assert_eq!((ping.time, ping.step), (250_000_000, 1));
        // The GO at 800 ms comes after the heartbeat of 800 ms (step order).
        let at800: Vec<String> = due.iter().filter(|d| d.time == 800_000_000).map(name).collect();
        assert_eq!(at800, ["HB", "GO"]);
        // The random section stays in [2 s, 3 s) and is the same every time.
        let random: Vec<&Due> = due.iter().filter(|d| d.step == 4).collect();
        assert!(!random.is_empty());
        assert!(random.iter().all(|d| (2_000_000_000..3_000_000_000).contains(&d.time)));
        let again: Vec<Due> = Timeline::of_script(c.clone(), &s).filter(|d| d.step == 4).collect();
        assert_eq!(random.into_iter().cloned().collect::<Vec<_>>(), again);
    }

    #[test]
    fn a_whole_run_random_timeline_ends() {
        let (c, _) = program();
        let due: Vec<Due> = Timeline::random(c, 5_000_000_000, 9).collect();
        assert!(!due.is_empty() && due.iter().all(|d| d.time < 5_000_000_000));
    }
}
