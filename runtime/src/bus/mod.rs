//! The three streams of the paper (Zhang & Zhu 2005, §2.4), kept apart:
//!
//! - **data**, agent to agent, along the links of the wiring graph of the
//!   current state;
//! - **events**, every agent to the Bulletinboard;
//! - **status**, the Bulletinboard to every agent.
//!
//! [`Bus`] is the interface every transport implements: in one process
//! ([`inproc::InProc`]) or across processes. Its policies when a queue is
//! full are part of the interface:
//!
//! - data: **keep-latest** — the oldest datum of the receiver's queue is
//!   dropped (counted per receiver); a controller wants the newest reading;
//! - events: **never dropped silently** — an event that finds the
//!   Bulletinboard's queue full is dropped and counted, and the Bulletinboard
//!   learns how many were lost with the next drain (it raises `BUSOVF` if
//!   the rules declare it, and records the loss);
//! - status: only the latest matters — each agent keeps one.
//!
//! Urgent messages (ROBIX's urgent letters) go to a lane of their own that
//! is delivered before the queue, and wake a receiver waiting for its next
//! step.

pub mod inproc;

use crate::agent::Body;
use situ_bundle::Value;
use std::time::Instant;

/// An event on its way to the Bulletinboard.
#[derive(Debug, Clone, PartialEq)]
pub struct EventMsg {
    /// The reporting agent.
    pub agent: u32,
    pub event: u32,
    /// Nanoseconds.
    pub time: u64,
    pub payload: Vec<Value>,
    pub urgent: bool,
}

/// The state at rest, broadcast to every agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct StatusMsg {
    pub state: u32,
    pub time: u64,
    /// Increases with every broadcast.
    pub seq: u64,
}

/// A datum on its way from one agent to another.
#[derive(Debug, Clone)]
pub struct DataMsg {
    pub from: u32,
    pub to: u32,
    pub time: u64,
    pub urgent: bool,
    pub body: Body,
}

/// What a receiver waiting for its next step was woken by.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wake {
    /// Its time came.
    Deadline,
    /// An urgent message arrived first.
    Urgent,
    /// The bus is shutting down.
    Closed,
}

/// What arrived for an agent since it last looked (and is now cleared).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Attention {
    pub urgent: bool,
    /// Any data or a new status.
    pub input: bool,
}

/// A bell several agents' mailboxes ring: a worker thread that steps those
/// agents sleeps on it until their next period or until something arrives.
#[derive(Default)]
pub struct Doorbell {
    rung: std::sync::Mutex<bool>,
    bell: std::sync::Condvar,
}

impl Doorbell {
    pub fn ring(&self) {
        *self.rung.lock().unwrap_or_else(|p| p.into_inner()) = true;
        self.bell.notify_all();
    }

    /// Sleeps until rung or `deadline`; returns whether it was rung.
    pub fn wait_until(&self, deadline: Instant) -> bool {
        let mut rung = self.rung.lock().unwrap_or_else(|p| p.into_inner());
        loop {
            if std::mem::take(&mut *rung) {
                return true;
            }
            let now = Instant::now();
            if now >= deadline {
                return false;
            }
            rung = self.bell.wait_timeout(rung, deadline - now).unwrap_or_else(|p| p.into_inner()).0;
        }
    }
}

/// Counters of a bus's life.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct BusCounters {
    pub data_sent: u64,
    /// Data dropped to keep the latest in a full queue.
    pub data_overflow: u64,
    pub events_sent: u64,
    /// Events that found the Bulletinboard's queue full.
    pub events_overflow: u64,
    pub status_sent: u64,
    pub urgent: u64,
    /// Messages from other processes refused before they reached a queue
    /// (not a message of this protocol, a newer version, too big, …).
    pub rejected: u64,
    /// Data that cannot cross to another process (a local Rust value).
    pub unsendable: u64,
}

/// A transport of the three streams.
pub trait Bus: Send + Sync {
    /// Queues a datum for `msg.to`.
    fn send_data(&self, msg: DataMsg);
    /// Queues an event for the Bulletinboard.
    fn send_event(&self, msg: EventMsg);
    /// Broadcasts the status to every agent.
    fn send_status(&self, msg: StatusMsg);
    /// Moves the agent's queued data into `out` (urgent first).
    fn recv_data(&self, agent: u32, out: &mut Vec<DataMsg>);
    /// Drops the agent's queued data (an agent waking up starts afresh);
    /// returns how many were dropped.
    fn discard_data(&self, agent: u32) -> usize;
    /// Moves the queued events into `out` (urgent first); returns how many
    /// events were lost to a full queue since the previous call.
    fn recv_events(&self, out: &mut Vec<EventMsg>) -> u64;
    /// The latest status the agent has received.
    fn status(&self, agent: u32) -> Option<StatusMsg>;
    /// Waits until `deadline` or an urgent message for the agent, whichever
    /// comes first (real-time runs).
    fn wait(&self, agent: u32, deadline: Instant) -> Wake;
    /// Waits until `deadline` or any input for the agent: data (urgent or
    /// not) or a new status (agents that step on input, in real time).
    fn wait_input(&self, agent: u32, deadline: Instant) -> Wake;
    /// Waits until `deadline` or an event for the Bulletinboard.
    fn wait_events(&self, deadline: Instant) -> Wake;
    /// Rings `bell` whenever something arrives for `agent`.
    fn set_doorbell(&self, agent: u32, bell: std::sync::Arc<Doorbell>);
    /// What arrived for the agent since it last looked; clears it.
    fn attention(&self, agent: u32) -> Attention;
    /// Messages from other processes refused since the last call, in words
    /// (in process: none).
    fn take_refusals(&self) -> Vec<String> {
        Vec::new()
    }
    /// Wakes every waiter with [`Wake::Closed`].
    fn close(&self);
    fn counters(&self) -> BusCounters;
}
