//! The stand-in: an agent of any rules file with no implementation of its
//! own. The runtime does its running cycle as for any agent (its table or
//! FSM chooses its mode, function and links); in each step the stand-in
//! forwards one datum along the links of the moment, so that the bus's
//! counters and the wiring mean something, and reports the events its
//! script has due now.

use crate::agent::{Agent, Body, Context};
use situ_bundle::{Content, Mode, Value};
use std::collections::VecDeque;
use std::sync::{Arc, Mutex};

/// The events a stand-in has to report, in time order.
#[derive(Clone, Default)]
pub struct Inbox(Arc<Mutex<InboxState>>);

#[derive(Default)]
struct InboxState {
    due: VecDeque<(u64, u32, Vec<Value>)>,
    /// Events that were due while the agent slept (a sleeping agent is not
    /// stepped, so it reports nothing).
    asleep: u64,
    /// Events it reported.
    reported: u64,
}

impl Inbox {
    /// An event the agent reports at `time`.
    pub fn push(&self, time: u64, event: u32, payload: Vec<Value>) {
        self.lock().due.push_back((time, event, payload));
    }

    /// Whether an event due at or before `time` is still to be reported.
    pub fn due_by(&self, time: u64) -> bool {
        self.lock().due.front().is_some_and(|d| d.0 <= time)
    }

    /// Events dropped because the agent slept when they were due; counts
    /// what is still queued before `now` too.
    pub fn asleep(&self, now: u64) -> u64 {
        let s = self.lock();
        s.asleep + s.due.iter().filter(|d| d.0 < now).count() as u64
    }

    /// Events the agent reported.
    pub fn reported(&self) -> u64 {
        self.lock().reported
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, InboxState> {
        self.0.lock().unwrap_or_else(|p| p.into_inner())
    }
}

/// An agent that follows its table or FSM and reports what it is told.
pub struct StandIn {
    name: String,
    functions: Vec<String>,
    inbox: Inbox,
    sent: u64,
    /// When it last sent: at most one datum per instant, so that agents
    /// without a rate that feed each other (a data cycle) do not wake each
    /// other for ever at one time.
    last_sent: Option<u64>,
}

impl StandIn {
    pub fn new(content: &Content, agent: u32, inbox: Inbox) -> StandIn {
        let def = &content.agents[agent as usize];
        StandIn {
            name: def.name.clone(),
            functions: def.functions.iter().map(|f| f.name.clone()).collect(),
            inbox,
            sent: 0,
            last_sent: None,
        }
    }
}

impl Agent for StandIn {
    fn name(&self) -> &str {
        &self.name
    }

    fn functions(&self) -> Vec<String> {
        self.functions.clone()
    }

    fn step(&mut self, cx: &mut Context<'_>) {
        let now = cx.now();
        // One datum per step along the links of the moment, when there
        // are any (and at most one per instant).
        if cx.mode() == Mode::Running && !cx.receivers().is_empty() && self.last_sent != Some(now) {
            self.last_sent = Some(now);
            self.sent += 1;
            let body = serde_json::json!({
                "from": self.name,
                "function": cx.function(),
                "state": cx.state(),
                "seq": self.sent,
                "inputs": cx.inputs().len(),
            });
            cx.send(Body::json(body));
        }
        let mut inbox = self.inbox.lock();
        while inbox.due.front().is_some_and(|d| d.0 <= now) {
            let Some((time, event, payload)) = inbox.due.pop_front() else { break };
            if time < now {
                // Due while the agent slept: it was not stepped then.
                inbox.asleep += 1;
                continue;
            }
            let name = cx.content.events[event as usize].name.clone();
            if cx.report(&name, &payload).is_ok() {
                inbox.reported += 1;
            }
        }
    }
}
