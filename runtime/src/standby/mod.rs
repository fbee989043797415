//! The Bulletinboard without a single point of failure: a **log** of what
//! the board took, in its order, that followers apply and a journal keeps,
//! and the **election** of one leading board among a deployment's boards.
//!
//! The engine is deterministic: the same events and heartbeats in the same
//! order give the same state and facts (`situ replay` relies on it). So a
//! board that applies the leader's log holds the leader's state and facts,
//! and can lead in its place. What the log holds is what a recording's
//! `/situ/events` and `/situ/ticks` hold ([`Entry`]): every event the
//! leader took from its queue, accepted or refused, and every heartbeat
//! that the recording writes.
//!
//! - [`Entry`], [`Logged`], [`Batch`]: the log and how it travels;
//! - [`LogStore`]: every entry applied or written here, by index (a board
//!   that joins catches up from it);
//! - [`election::Election`]: when a follower leads, with which epoch; when a
//!   leader steps down (pure: times are given);
//! - [`replica::Replica`]: a follower's bookkeeping: which batch applies
//!   next, the events it heard from the agents that the leader has not yet
//!   sequenced (applied at a takeover, never twice);
//! - [`Peers`]: what a transport provides (Zenoh: `situ-bus-zenoh`);
//! - [`run`]: the board's thread, leading or following.
//!
//! **Epochs.** Every status a leader broadcasts carries its epoch; an agent
//! follows only the highest epoch it has seen, so two boards are never both
//! obeyed. A board that takes over picks an epoch above every epoch it has
//! seen and above the wall clock in milliseconds (so a board restarted alone
//! is followed again), times 256 plus its rank (two boards never pick the
//! same epoch).

pub mod election;
pub mod replica;
pub mod run;

use crate::bus::EventMsg;
use situ_bundle::Value;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

/// One entry of the board's log.
#[derive(Debug, Clone, PartialEq)]
pub enum Entry {
    /// An event the board took from its queue: accepted (it changed the
    /// working memory) or refused (logged so that a follower forgets it).
    Event { msg: EventMsg, accepted: bool },
    /// A heartbeat that moved the clock, as the recording writes it.
    Tick { time: u64 },
}

/// An entry with the epoch of the leader that wrote it.
#[derive(Debug, Clone, PartialEq)]
pub struct Logged {
    pub epoch: u64,
    pub entry: Entry,
}

/// Entries on their way from the leader: `entries[0]` has index `first`;
/// the entry before it (index `first - 1`, none when 1) was written in
/// epoch `prev_epoch`. An empty batch is a heartbeat that says how long
/// the leader's log is (`first - 1` entries).
#[derive(Debug, Clone, PartialEq)]
pub struct Batch {
    /// The epoch of the leader that sends it.
    pub epoch: u64,
    /// The leader's name (its process).
    pub board: String,
    pub first: u64,
    pub prev_epoch: u64,
    /// The index of the last entry behind a state the leader broadcast (0:
    /// none): a follower whose log is shorter lacks a decision the agents
    /// were told, and must not lead from it.
    pub decided: u64,
    pub entries: Vec<Logged>,
}

impl Batch {
    /// The index of the last entry (the length of the leader's log when
    /// the batch is its tail).
    pub fn last(&self) -> u64 {
        self.first - 1 + self.entries.len() as u64
    }
}

/// Every entry this board applied or wrote, from index 1.
#[derive(Debug, Default)]
pub struct LogStore {
    entries: Vec<Logged>,
    /// While this board leads: the index of the last entry behind a state
    /// it broadcast ([`Batch::decided`]).
    decided: u64,
}

impl LogStore {
    pub fn len(&self) -> u64 {
        self.entries.len() as u64
    }
    pub fn is_empty(&self) -> bool {
        self.entries.is_empty()
    }
    /// The epoch of entry `index` (0 for index 0, "before the log").
    pub fn epoch_at(&self, index: u64) -> Option<u64> {
        match index {
            0 => Some(0),
            i => self.entries.get(i as usize - 1).map(|l| l.epoch),
        }
    }
    pub fn push(&mut self, logged: Logged) {
        self.entries.push(logged);
    }
    /// The leader: the entries up to `index` are behind a state it
    /// broadcast (or is about to).
    pub fn decide(&mut self, index: u64) {
        self.decided = self.decided.max(index.min(self.len()));
    }
    pub fn decided(&self) -> u64 {
        self.decided
    }
    /// Forgets everything (a board that diverged starts again from the
    /// leader's log).
    pub fn clear(&mut self) {
        self.entries.clear();
        self.decided = 0;
    }
    /// Entries `from..` (at most `max`) as a batch of `epoch`'s leader.
    pub fn batch_from(&self, from: u64, max: usize, epoch: u64, board: &str) -> Batch {
        let from = from.max(1);
        let start = (from as usize - 1).min(self.entries.len());
        let end = start.saturating_add(max).min(self.entries.len());
        Batch {
            epoch,
            board: board.to_string(),
            first: start as u64 + 1,
            prev_epoch: self.epoch_at(start as u64).unwrap_or(0),
            decided: self.decided,
            entries: self.entries[start..end].to_vec(),
        }
    }
}

/// The log shared between the board's thread and the transport (which
/// answers a joining board's requests from it).
pub type SharedLog = Arc<Mutex<LogStore>>;

/// How a board of a standby group is configured.
#[derive(Debug, Clone)]
pub struct StandbyConfig {
    /// This board's name (its process).
    pub name: String,
    /// Its place among the boards (0 leads at start).
    pub rank: u32,
    /// A follower leads when it has heard nothing from a leader for this
    /// long (plus `stagger` per rank).
    pub lease: Duration,
    /// How much longer each rank waits than the one before.
    pub stagger: Duration,
    /// How often the leader says it is alive to the other boards.
    pub beat: Duration,
    /// How long the leader waits for the followers to have a change's
    /// entries before it broadcasts the change anyway.
    pub replicate_within: Duration,
    /// How long a follower that lacks a decision the agents were told
    /// (its log is shorter than the leader's [`Batch::decided`]) waits,
    /// past its lease, for a board that has it to lead; then it leads
    /// from the rules' initial state, as a single board that restarts.
    pub give_up: Duration,
}

impl StandbyConfig {
    /// The defaults for a status period of `status_every` (200 ms): the
    /// leader beats (its status to the agents, its log's length to the
    /// boards) every quarter period (50 ms); a follower leads after 2¼
    /// periods without a beat (450 ms), 50 ms more per rank. A killed
    /// leader is replaced within 600 ms (3 periods), and an agent hears a
    /// status within 600 ms across it: its last beat came at most 50 ms
    /// before the kill.
    pub fn new(name: &str, rank: u32, status_every: Duration) -> StandbyConfig {
        StandbyConfig {
            name: name.to_string(),
            rank,
            lease: status_every * 9 / 4,
            stagger: status_every / 4,
            beat: status_every / 4,
            replicate_within: Duration::from_millis(100),
            give_up: status_every * 25,
        }
    }
}

/// What a transport gives a board of a standby group.
pub trait Peers: Send + Sync {
    /// The leader: sends a batch of its log (or an empty one, a beat).
    fn publish(&self, batch: &Batch);
    /// The leader: waits until every follower that was in step (heard from
    /// lately, with entries up to `first - 1`) has acknowledged entry
    /// `last`, or `deadline`; whether they all have.
    fn wait_acks(&self, first: u64, last: u64, deadline: Instant) -> bool;
    /// The follower: the batches heard since the last call (from leaders
    /// of any epoch: the replica sorts them).
    fn take_batches(&self, out: &mut Vec<Batch>);
    /// The follower: says it has applied the log up to `index`.
    fn ack(&self, epoch: u64, index: u64);
    /// The follower: asks the leader for its log from `from` on; the
    /// answers arrive through [`take_batches`](Self::take_batches).
    fn request(&self, from: u64);
    /// The highest epoch heard from another board (its status, beats or
    /// batches), and when it was last heard.
    fn heard(&self) -> Option<(u64, Instant)>;
    /// This process leads at `epoch` (its status messages carry it) or,
    /// with `None`, follows (it broadcasts no status).
    fn set_leading(&self, epoch: Option<u64>);
    /// Whether this process has a link to another (a board that has none
    /// cannot tell "no leader" from "not connected yet", so it does not
    /// count its join time before).
    fn linked(&self) -> bool {
        true
    }
}

/// Whether two events are the same message (payloads compared bit for bit:
/// a NaN is the same NaN).
pub fn same_event(a: &EventMsg, b: &EventMsg) -> bool {
    a.agent == b.agent
        && a.event == b.event
        && a.time == b.time
        && a.urgent == b.urgent
        && a.payload.len() == b.payload.len()
        && a.payload.iter().zip(&b.payload).all(|(x, y)| same_value(x, y))
}

fn same_value(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::F64(x), Value::F64(y)) => x.to_bits() == y.to_bits(),
        _ => a == b,
    }
}

/// Where a board writes its log as it goes: a journal, the followers.
pub trait LogOut: Send {
    /// Takes the entries (draining them) in the order the board took them;
    /// `change`: a change of state is broadcast right after them, so they
    /// must be safe first (journaled, replicated).
    fn write(&mut self, entries: &mut Vec<Entry>, change: bool);
}

/// Whom a board tells that it leads or steps down.
pub type Tell = Arc<dyn Fn(&str) + Send + Sync>;

/// A board of a standby group: its configuration and its transport.
#[derive(Clone)]
pub struct Standby {
    pub config: StandbyConfig,
    pub peers: Arc<dyn Peers>,
    /// The log, shared with the transport (which answers catch-up requests
    /// from it).
    pub log: SharedLog,
    /// Told when this board leads or steps down, in words (the command
    /// line prints it); the recording has it too.
    pub tell: Option<Tell>,
}

impl std::fmt::Debug for Standby {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Standby").field("config", &self.config).finish_non_exhaustive()
    }
}
