//! The simulated-time scheduler: one thread, a queue of timed tasks, and
//! the same seed gives the same run, bit for bit.
//!
//! - An agent with a rate (`rate 10Hz` in the rules, or the stack's
//!   configuration) is stepped every period from time 0; an agent without
//!   one is stepped when something arrives for it: data, or a new status.
//! - After every step the Bulletinboard takes the events of that step at
//!   the same time, and broadcasts each new state at rest.
//! - An urgent datum overtakes: its receiver is stepped at once (at the
//!   current time), not at its next period.
//! - The Bulletinboard's heartbeat moves its clock every `heartbeat` period,
//!   so that an agent that falls silent is seen stale within one period.

use crate::agent::Bound;
use crate::bus::inproc::{Capacity, InProc};
use crate::bus::Bus;
use crate::record::Sink;
use crate::rete::StateChange;
use crate::runner::{AgentRunner, BoardRunner, Shared};
use crate::summary::Summary;
use situ_bundle::Content;
use std::cmp::Reverse;
use std::collections::{BTreeMap, BinaryHeap};
use std::sync::Arc;

/// How a simulated run is set up.
#[derive(Debug, Clone)]
pub struct SimConfig {
    /// The Bulletinboard's heartbeat period (ns).
    pub heartbeat: u64,
    /// Rates (Hz) by agent name, over the rules file's `rate`.
    pub rates: BTreeMap<String, f64>,
    pub capacity: Capacity,
    /// End the run when the state at rest is final.
    pub stop_on_final: bool,
}

impl Default for SimConfig {
    fn default() -> Self {
        SimConfig { heartbeat: 10_000_000, rates: BTreeMap::new(), capacity: Capacity::default(), stop_on_final: true }
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Task {
    Heartbeat,
    /// The agent's periodic step.
    Tick(u32),
    /// A step on demand: input for an agent without a rate, or urgent data.
    Wake(u32),
}

pub struct SimRuntime {
    pub shared: Arc<Shared>,
    pub board: BoardRunner,
    agents: Vec<Option<AgentRunner>>,
    period: Vec<Option<u64>>,
    /// An event-driven (or urgent) step is already queued for the agent.
    pending: Vec<bool>,
    queue: BinaryHeap<Reverse<(u64, u64, Task)>>,
    seq: u64,
    now: u64,
    heartbeat: u64,
    stop_on_final: bool,
    finished: bool,
    summary: Summary,
}

impl SimRuntime {
    pub fn new(content: Arc<Content>, agents: Bound, sink: Option<Box<dyn Sink>>, config: SimConfig) -> SimRuntime {
        let n = content.agents.len();
        let bus: Arc<dyn Bus> = Arc::new(InProc::new(n, config.capacity));
        let shared = Arc::new(Shared::new(content.clone(), bus, sink));
        let period: Vec<Option<u64>> = content
            .agents
            .iter()
            .map(|a| {
                let hz = config.rates.get(&a.name).copied().or(a.rate_hz);
                hz.filter(|h| h.is_finite() && *h > 0.0).map(|h| ((1e9 / h).round() as u64).max(1))
            })
            .collect();
        let agents: Vec<Option<AgentRunner>> =
            agents.into_iter().enumerate().map(|(i, a)| a.map(|imp| AgentRunner::new(i as u32, imp))).collect();
        let mut rt = SimRuntime {
            board: BoardRunner::new(content.clone()),
            summary: Summary::new(&content),
            shared,
            agents,
            period,
            pending: vec![false; n],
            queue: BinaryHeap::new(),
            seq: 0,
            now: 0,
            heartbeat: config.heartbeat.max(1),
            stop_on_final: config.stop_on_final,
            finished: false,
        };
        rt.board.start(&rt.shared, 0);
        for a in 0..n as u32 {
            if rt.agents[a as usize].is_some() {
                if rt.period[a as usize].is_some() {
                    rt.push(0, Task::Tick(a));
                } else {
                    rt.pending[a as usize] = true;
                    rt.push(0, Task::Wake(a));
                }
            }
        }
        rt.push(rt.heartbeat, Task::Heartbeat);
        rt
    }

    fn push(&mut self, time: u64, task: Task) {
        self.seq += 1;
        self.queue.push(Reverse((time, self.seq, task)));
    }

    /// Simulated time (ns).
    pub fn now(&self) -> u64 {
        self.now
    }

    pub fn state(&self) -> u32 {
        self.board.board.state()
    }

    /// The time of the next task, if any.
    pub fn next_time(&self) -> Option<u64> {
        self.queue.peek().map(|Reverse((time, _, _))| *time)
    }

    /// Whether the run reached a final state (with `stop_on_final`).
    pub fn finished(&self) -> bool {
        self.finished
    }

    /// Runs until `until` (ns) or a final state; calls `on_change` for every
    /// change of the state at rest.
    pub fn run_until(&mut self, until: u64, on_change: &mut dyn FnMut(&StateChange)) {
        while !self.finished {
            let Some(&Reverse((time, _, _))) = self.queue.peek() else { break };
            if time > until {
                break;
            }
            self.step(on_change);
        }
        if !self.finished {
            self.now = self.now.max(until);
        }
    }

    /// Processes the next task.
    pub fn step(&mut self, on_change: &mut dyn FnMut(&StateChange)) {
        let Some(Reverse((time, _, task))) = self.queue.pop() else { return };
        self.now = time;
        let changes = match task {
            Task::Heartbeat => {
                self.push(time + self.heartbeat, Task::Heartbeat);
                self.board.tick(&self.shared, time).into_iter().collect()
            }
            Task::Tick(a) => {
                if let Some(p) = self.period[a as usize] {
                    self.push(time + p, Task::Tick(a));
                }
                self.step_agent(a, time)
            }
            Task::Wake(a) => {
                self.pending[a as usize] = false;
                self.step_agent(a, time)
            }
        };
        for c in &changes {
            self.summary.change(c);
            on_change(c);
            let state = &self.shared.content.states[c.to as usize];
            if self.stop_on_final && state.is_final {
                self.finished = true;
            }
        }
        if !changes.is_empty() {
            // A new status: the agents that step on input take it now.
            for a in 0..self.agents.len() as u32 {
                self.wake(a, time);
            }
        }
    }

    /// Starts a new mission from the initial state now (a `--random` run
    /// goes on after a final state): see [`BoardRunner::restart`]; the run
    /// is no longer finished, and every agent that steps on input takes
    /// the new status.
    pub fn restart(&mut self, on_change: &mut dyn FnMut(&StateChange)) {
        let now = self.now;
        self.finished = false;
        if let Some(c) = self.board.restart(&self.shared, now) {
            self.summary.change(&c);
            on_change(&c);
            for a in 0..self.agents.len() as u32 {
                self.wake(a, now);
            }
        }
    }

    /// Queues a step of the agent at `time` (not before now), once, whatever
    /// its rate: an agent with something to report steps when it happens
    /// (a scripted event, say), not at its next period.
    pub fn wake_at(&mut self, a: u32, time: u64) {
        if (a as usize) < self.agents.len() && self.agents[a as usize].is_some() && !self.pending[a as usize] {
            self.pending[a as usize] = true;
            self.push(time.max(self.now), Task::Wake(a));
        }
    }

    /// Steps an agent without a rate at `time`, once.
    fn wake(&mut self, a: u32, time: u64) {
        if self.period[a as usize].is_none() {
            self.wake_now(a, time);
        }
    }

    fn wake_now(&mut self, a: u32, time: u64) {
        if self.agents[a as usize].is_some() && !self.pending[a as usize] {
            self.pending[a as usize] = true;
            self.push(time, Task::Wake(a));
        }
    }

    fn step_agent(&mut self, a: u32, time: u64) -> Vec<StateChange> {
        let Some(runner) = self.agents[a as usize].as_mut() else { return Vec::new() };
        let cycle = runner.cycle(&self.shared, time);
        self.summary.stepped(a, cycle.stepped);
        for &to in &cycle.urgent_to {
            // Urgent: the receiver is stepped now, before its next period.
            self.wake_now(to, time);
        }
        for &to in &cycle.data_to {
            self.wake(to, time);
        }
        if cycle.reported {
            self.board.pump(&self.shared, time)
        } else {
            Vec::new()
        }
    }

    /// The figures of the run so far.
    pub fn summary(&self) -> Summary {
        let mut s = self.summary.clone();
        s.finish(
            self.now,
            self.state(),
            &self.board.counters,
            self.agents.iter().flatten().map(|r| (r.id, r.counters)).collect(),
            self.shared.bus.counters(),
        );
        s
    }

    /// Flushes and ends the recording.
    pub fn finish_recording(&self) -> std::io::Result<()> {
        let mut result = Ok(());
        self.shared.record(|s| result = s.finish());
        result
    }

    /// Makes the recording durable so far.
    pub fn flush_recording(&self) -> std::io::Result<()> {
        let mut result = Ok(());
        self.shared.record(|s| result = s.flush());
        result
    }
}
