//! The Bulletinboard of Zhang & Zhu (2005, Fig. 4): the rule base (a
//! bundle), the facts base and the inference machine (a [`rete::Engine`]),
//! and the events monitor that feeds it and broadcasts the new state.
//!
//! - [`Bulletinboard::post`] takes one event and returns what fired, with
//!   the reasons in source terms ([`StateChange::explain`]);
//! - [`Bulletinboard::subscribe`] gives a channel of every change of the
//!   state at rest (the status broadcast);
//! - [`Bulletinboard::history`] keeps the latest changes (a bounded ring:
//!   a long run does not grow the memory);
//! - [`Bulletinboard::swap`] replaces the rules of a running Bulletinboard
//!   atomically, carrying the working memory over.
//!
//! [`rete::Engine`]: crate::rete::Engine
//! [`Engine::admit`]: crate::rete::Engine::admit
//! [`Engine::set_clock`]: crate::rete::Engine::set_clock

use crate::rete::{Engine, PostError, StateChange};
use situ_bundle::{self as bundle, Content, Value};
use std::collections::VecDeque;
use std::sync::mpsc;
use std::sync::Arc;

/// How many state changes [`Bulletinboard::history`] keeps by default.
pub const HISTORY: usize = 4096;

/// Counters of a Bulletinboard's life.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    pub posted: u64,
    pub rejected: u64,
    pub firings: u64,
    pub changes: u64,
}

pub struct Bulletinboard {
    engine: Engine,
    history: VecDeque<StateChange>,
    capacity: usize,
    subscribers: Vec<mpsc::Sender<StateChange>>,
    counters: Counters,
}

/// What a hot swap carried over, and what it had to drop.
#[derive(Debug, Clone, PartialEq)]
pub struct SwapReport {
    /// Agents whose latest fact (or staleness) lives on under the new rules.
    pub carried: Vec<String>,
    /// Agents whose fact could not be carried, and why.
    pub dropped: Vec<(String, String)>,
    /// What the new rules fired on the carried memory.
    pub change: Option<StateChange>,
}

/// Why a hot swap was refused (the old rules keep running).
#[derive(Debug, Clone, PartialEq)]
pub enum SwapError {
    /// The current state does not exist in the new bundle.
    StateMissing { state: String },
    /// The new rules do not come to rest on the carried memory.
    Cascade(String),
}

impl std::fmt::Display for SwapError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SwapError::StateMissing { state } => {
                write!(f, "the current state `{state}` does not exist in the new bundle; the old rules keep running")
            }
            SwapError::Cascade(why) => write!(f, "{why}; the old rules keep running"),
        }
    }
}

impl std::error::Error for SwapError {}

impl Bulletinboard {
    pub fn new(content: Arc<Content>) -> Bulletinboard {
        Bulletinboard {
            engine: Engine::new(content),
            history: VecDeque::new(),
            capacity: HISTORY,
            subscribers: Vec::new(),
            counters: Counters::default(),
        }
    }

    /// A Bulletinboard for the bytes of a bundle file.
    pub fn load(bytes: &[u8]) -> Result<Bulletinboard, bundle::LoadError> {
        Ok(Bulletinboard::new(Arc::new(bundle::decode(bytes)?)))
    }

    pub fn content(&self) -> &Arc<Content> {
        self.engine.content()
    }

    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    pub fn state(&self) -> u32 {
        self.engine.state()
    }

    pub fn state_name(&self) -> &str {
        &self.content().states[self.engine.state() as usize].name
    }

    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// The Bulletinboard's clock the next events arrive at ([`Engine::set_clock`]).
    pub fn set_clock(&mut self, clock: u64) {
        self.engine.set_clock(Some(clock));
    }

    /// How far ahead of the clock it arrives at an event may be stamped
    /// ([`Engine::admit`]).
    pub fn set_max_skew(&mut self, ns: u64) {
        self.engine.set_max_skew(ns);
    }

    /// Keeps the latest `n` changes in [`history`](Self::history).
    pub fn set_history_capacity(&mut self, n: usize) {
        self.capacity = n;
        while self.history.len() > n {
            self.history.pop_front();
        }
    }

    /// Posts one event; returns the firings, if any rule fired. A refused
    /// event changes nothing and is counted.
    pub fn post(&mut self, event: u32, time: u64, payload: &[Value]) -> Result<Option<StateChange>, PostError> {
        self.counters.posted += 1;
        match self.engine.post(event, time, payload) {
            Ok(change) => {
                if let Some(c) = &change {
                    self.record(c);
                }
                Ok(change)
            }
            Err(e @ PostError::Cascade { .. }) => Err(e),
            Err(e) => {
                self.counters.rejected += 1;
                Err(e)
            }
        }
    }

    /// As [`post`](Self::post), for an event that arrived when the
    /// Bulletinboard's clock read `clock`: one stamped more than the skew
    /// bound ahead of it is refused ([`Engine::admit`]).
    pub fn post_at(
        &mut self,
        clock: u64,
        event: u32,
        time: u64,
        payload: &[Value],
    ) -> Result<Option<StateChange>, PostError> {
        self.engine.set_clock(Some(clock));
        self.post(event, time, payload)
    }

    /// Posts an event by name, its payload in field order.
    pub fn post_named(&mut self, event: &str, time: u64, payload: &[Value]) -> Result<Option<StateChange>, PostError> {
        let id = self.content().event_id(event).unwrap_or(u32::MAX);
        self.post(id, time, payload)
    }

    /// Moves the clock forward without an event (the heartbeat that notices
    /// silent agents); returns what fired.
    pub fn advance(&mut self, now: u64) -> Result<Option<StateChange>, PostError> {
        let change = self.engine.advance(now)?;
        if let Some(c) = &change {
            self.record(c);
        }
        Ok(change)
    }

    /// Brings the network to rest without an event (at start).
    pub fn settle(&mut self) -> Result<Option<StateChange>, PostError> {
        let change = self.engine.settle()?;
        if let Some(c) = &change {
            self.record(c);
        }
        Ok(change)
    }

    fn record(&mut self, change: &StateChange) {
        self.counters.firings += change.firings.len() as u64;
        if !change.changed() {
            return;
        }
        self.counters.changes += 1;
        self.subscribers.retain(|s| s.send(change.clone()).is_ok());
        if self.capacity > 0 {
            if self.history.len() == self.capacity {
                self.history.pop_front();
            }
            self.history.push_back(change.clone());
        }
    }

    /// A channel of every change of the state at rest, from now on.
    pub fn subscribe(&mut self) -> mpsc::Receiver<StateChange> {
        let (tx, rx) = mpsc::channel();
        self.subscribers.push(tx);
        rx
    }

    /// The latest changes of the state at rest, oldest first.
    pub fn history(&self) -> impl Iterator<Item = &StateChange> {
        self.history.iter()
    }

    /// A change in source terms.
    pub fn explain(&self, change: &StateChange) -> String {
        change.explain(self.content())
    }

    /// Back to the initial state with no facts (a new mission).
    pub fn reset(&mut self) {
        self.engine.reset();
    }

    /// Replaces the rules by a new bundle's, atomically: the state, and
    /// every agent's latest fact whose agent, event and payload fields
    /// (names and types) still exist, carry over; then the new rules are
    /// brought to rest. If anything fails, nothing changes.
    pub fn swap(&mut self, new: Arc<Content>) -> Result<SwapReport, SwapError> {
        let old = self.engine.content().clone();
        let state_name = &old.states[self.engine.state() as usize].name;
        let state = new.state_id(state_name).ok_or_else(|| SwapError::StateMissing { state: state_name.clone() })?;
        let mut engine = Engine::new(new.clone());
        engine.set_cascade_limit(self.engine.cascade_limit());
        engine.set_max_skew(self.engine.max_skew());
        engine.set_clock(self.engine.clock());
        engine.advance_clock(self.engine.now());
        engine.force_state(state);
        let mut carried = Vec::new();
        let mut dropped = Vec::new();
        for (i, agent) in old.agents.iter().enumerate() {
            let Some(new_agent) = new.agent_id(&agent.name) else {
                if self.engine.fact(i as u32).is_some() {
                    dropped.push((agent.name.clone(), "the agent is gone".into()));
                }
                continue;
            };
            // The agent's clock goes on: its events stamped before its
            // latest accepted one stay out of order under the new rules.
            engine.advance_agent_time(new_agent, self.engine.agent_time(i as u32));
            if self.engine.is_stale(i as u32) {
                engine.force_stale(new_agent);
                carried.push(agent.name.clone());
                continue;
            }
            let Some(fact) = self.engine.fact(i as u32) else { continue };
            match carry(&old, &new, new_agent, &fact) {
                Ok((event, payload)) => match engine.force_fact(event, fact.time, &payload, fact.run) {
                    Ok(()) => carried.push(agent.name.clone()),
                    Err(e) => dropped.push((agent.name.clone(), e.describe(&new))),
                },
                Err(why) => dropped.push((agent.name.clone(), why)),
            }
        }
        let change = engine.settle().map_err(|e| SwapError::Cascade(e.describe(&new)))?;
        self.engine = engine;
        if let Some(c) = &change {
            self.record(c);
        }
        Ok(SwapReport { carried, dropped, change })
    }
}

/// The fact of the old bundle as a fact of the new one: the same event name,
/// reported by the same agent, and every field of the new event found by
/// name in the old one with the same type.
fn carry(
    old: &Content,
    new: &Content,
    new_agent: u32,
    fact: &crate::rete::MatchedFact,
) -> Result<(u32, Vec<Value>), String> {
    let old_event = &old.events[fact.event as usize];
    let event = new.event_id(&old_event.name).ok_or_else(|| format!("event `{}` is gone", old_event.name))?;
    let new_event = &new.events[event as usize];
    if new_event.agent != new_agent {
        return Err(format!("event `{}` now belongs to another agent", old_event.name));
    }
    let mut payload = Vec::with_capacity(new_event.fields.len());
    for f in &new_event.fields {
        let Some(k) = old_event.fields.iter().position(|o| o.name == f.name && o.ty == f.ty) else {
            return Err(format!("field `{}.{}` is new or changed its type", new_event.name, f.name));
        };
        payload.push(fact.payload[k]);
    }
    Ok((event, payload))
}
