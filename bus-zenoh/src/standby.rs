//! The boards of a standby group over Zenoh (`situ_runtime::standby`):
//!
//! | key | message | who writes | who reads |
//! |---|---|---|---|
//! | `situ/<robot>/board/log` | [`BatchWire`] | the leading board | the other boards |
//! | `situ/<robot>/board/ack/<board>` | [`AckWire`] | each following board | the leading board |
//! | `situ/<robot>/board/sync/<from>` | a query, answered with [`BatchWire`]s | a board catching up | the leading board |
//!
//! A board also reads the status (`situ/<robot>/status`): a status of a
//! higher epoch from another board means that board leads. With `beats`
//! ([`crate::beats`]) the leader's beats also go as UDP datagrams, which
//! keep alive the leader heard here when TCP stalls.

use crate::beats::{BeatLink, Beats, Hears};
use crate::wire::{self, EventWire, StatusWire, VERSION};
use serde::{Deserialize, Serialize};
use situ_compiler::bundle::Content;
use situ_runtime::bus::inproc::InProc;
use situ_runtime::standby::{Batch, Entry, Logged, Peers, SharedLog};
use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};
use zenoh::qos::{CongestionControl, Priority};
use zenoh::Wait;

/// Entries in one answer to a catch-up request, at most.
const CHUNK: usize = 512;

/// How long a catch-up request waits for its answers.
const SYNC_TIMEOUT: Duration = Duration::from_secs(5);

pub fn log_key(robot: &str) -> String {
    format!("situ/{robot}/board/log")
}
pub fn ack_key(robot: &str, board: &str) -> String {
    format!("situ/{robot}/board/ack/{board}")
}
pub fn sync_key(robot: &str, from: u64) -> String {
    format!("situ/{robot}/board/sync/{from}")
}

/// A batch of the leader's log.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BatchWire {
    pub v: u32,
    pub epoch: u64,
    pub board: String,
    pub first: u64,
    pub prev_epoch: u64,
    /// The index of the last entry behind a state the leader broadcast
    /// (absent: 0, as a board of before it sends).
    #[serde(default)]
    pub decided: u64,
    #[serde(default)]
    pub entries: Vec<EntryWire>,
}

/// One entry: a heartbeat (`tick`) or an event with its verdict.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EntryWire {
    pub epoch: u64,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tick: Option<u64>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub event: Option<EventWire>,
    #[serde(default)]
    pub accepted: bool,
}

/// A follower has applied the log up to `index`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AckWire {
    pub v: u32,
    pub board: String,
    pub epoch: u64,
    pub index: u64,
}

/// A batch in the wire's form.
pub fn batch_wire(c: &Content, b: &Batch) -> BatchWire {
    let entries = b
        .entries
        .iter()
        .map(|l| match &l.entry {
            Entry::Tick { time } => EntryWire { epoch: l.epoch, tick: Some(*time), event: None, accepted: false },
            Entry::Event { msg, accepted } => EntryWire {
                epoch: l.epoch,
                tick: None,
                event: Some(wire::event_wire(c, msg.agent, msg.event, msg.time, &msg.payload, msg.urgent)),
                accepted: *accepted,
            },
        })
        .collect();
    BatchWire {
        v: VERSION,
        epoch: b.epoch,
        board: b.board.clone(),
        first: b.first,
        prev_epoch: b.prev_epoch,
        decided: b.decided,
        entries,
    }
}

/// A batch from the wire, checked against the bundle.
pub fn batch_of(c: &Content, w: &BatchWire) -> Result<Batch, wire::WireError> {
    if w.first == 0 {
        return Err(wire::WireError::Meaning("a batch that starts at entry 0 (the first is 1)".into()));
    }
    // `decided` may lie past the batch's last entry: a chunk of a
    // catch-up answer carries the leader's, for its whole log.
    let mut entries = Vec::with_capacity(w.entries.len());
    for e in &w.entries {
        let entry = match (&e.tick, &e.event) {
            (Some(time), None) => Entry::Tick { time: *time },
            (None, Some(ev)) => {
                let (agent, event, payload) = wire::event_of(c, &ev.agent, ev)?;
                let msg = situ_runtime::bus::EventMsg { agent, event, time: ev.time_ns, payload, urgent: ev.urgent };
                Entry::Event { msg, accepted: e.accepted }
            }
            _ => return Err(wire::WireError::Meaning("an entry is a `tick` or an `event`, one of them".into())),
        };
        entries.push(Logged { epoch: e.epoch, entry });
    }
    Ok(Batch {
        epoch: w.epoch,
        board: w.board.clone(),
        first: w.first,
        prev_epoch: w.prev_epoch,
        decided: w.decided,
        entries,
    })
}

/// How this process's board belongs to a standby group.
#[derive(Debug, Clone)]
pub struct BoardGroup {
    /// The board's name (its process).
    pub name: String,
    /// A follower not heard from for this long is not waited for.
    pub lease: Duration,
    pub log: SharedLog,
    /// Where it hears and sends the leader's beats over UDP, if it does.
    pub beats: Option<Beats>,
}

/// The leader last heard over Zenoh: its epoch, its name, when.
#[derive(Debug, Clone)]
struct Heard {
    epoch: u64,
    board: String,
    at: Instant,
}

/// What arrives from the other boards (also from Zenoh's threads, for
/// the answers to a request).
struct Inbox {
    name: String,
    content: Arc<Content>,
    local: Arc<InProc>,
    incoming: Mutex<Vec<Batch>>,
    heard: Mutex<Option<Heard>>,
    refused: AtomicU64,
    /// Beats heard over UDP, and those of them that renewed the leader.
    beats_heard: AtomicU64,
    beats_renewed: AtomicU64,
}

impl Hears for Inbox {
    /// A beat over UDP renews the leader heard over Zenoh, and only it:
    /// the same board at the same epoch ([`crate::beats`]).
    fn alive(&self, board: &str, epoch: u64) {
        self.beats_heard.fetch_add(1, Ordering::Relaxed);
        let mut h = self.heard.lock().unwrap_or_else(|p| p.into_inner());
        if let Some(heard) = h.as_mut().filter(|h| h.epoch == epoch && h.board == board) {
            heard.at = Instant::now();
            self.beats_renewed.fetch_add(1, Ordering::Relaxed);
        }
    }

    fn refused(&self) {
        self.refused.fetch_add(1, Ordering::Relaxed);
    }
}

impl Inbox {
    fn note(&self, board: &str, epoch: u64) {
        if board == self.name {
            return;
        }
        let mut h = self.heard.lock().unwrap_or_else(|p| p.into_inner());
        match &*h {
            Some(heard) if heard.epoch > epoch => {}
            _ => *h = Some(Heard { epoch, board: board.to_string(), at: Instant::now() }),
        }
    }

    fn on_batch(&self, bytes: &[u8]) {
        let batch = wire::parse::<BatchWire>(bytes).and_then(|w| batch_of(&self.content, &w));
        match batch {
            Ok(b) if b.board != self.name => {
                self.note(&b.board, b.epoch);
                self.incoming.lock().unwrap_or_else(|p| p.into_inner()).push(b);
                self.local.ring_board();
            }
            Ok(_) => {}
            Err(_) => {
                self.refused.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

/// This board's view of the others, fed by the bus's subscriptions.
pub struct BoardPeers {
    inbox: Arc<Inbox>,
    robot: String,
    session: zenoh::Session,
    content: Arc<Content>,
    log: SharedLog,
    lease: Duration,
    acks: Mutex<HashMap<String, (u64, Instant)>>,
    acked: Condvar,
    leading: AtomicBool,
    epoch: AtomicU64,
    beats: Option<BeatLink>,
}

impl BoardPeers {
    pub(crate) fn new(
        group: &BoardGroup,
        robot: &str,
        session: zenoh::Session,
        content: Arc<Content>,
        local: Arc<InProc>,
    ) -> Result<BoardPeers, crate::BusError> {
        let inbox = Inbox {
            name: group.name.clone(),
            content: content.clone(),
            local,
            incoming: Mutex::new(Vec::new()),
            heard: Mutex::new(None),
            refused: AtomicU64::new(0),
            beats_heard: AtomicU64::new(0),
            beats_renewed: AtomicU64::new(0),
        };
        let inbox = Arc::new(inbox);
        let beats =
            match &group.beats {
                Some(b) => Some(BeatLink::open(b, Arc::downgrade(&inbox)).map_err(|e| {
                    crate::BusError(format!("cannot hear the boards' beats on `udp/{}`: {e}", b.listen))
                })?),
                None => None,
            };
        Ok(BoardPeers {
            inbox,
            robot: robot.to_string(),
            session,
            content,
            log: group.log.clone(),
            lease: group.lease,
            acks: Mutex::new(HashMap::new()),
            acked: Condvar::new(),
            leading: AtomicBool::new(false),
            epoch: AtomicU64::new(0),
            beats,
        })
    }

    /// Where it hears the boards' beats over UDP, if it does.
    pub fn beats_addr(&self) -> Option<std::net::SocketAddr> {
        self.beats.as_ref().map(BeatLink::listen_addr)
    }

    /// The beats heard over UDP so far, and how many of them renewed the
    /// leader heard over Zenoh (the others were of another board or
    /// epoch); `None` without `beats`.
    pub fn beats_heard(&self) -> Option<(u64, u64)> {
        self.beats
            .as_ref()
            .map(|_| (self.inbox.beats_heard.load(Ordering::Relaxed), self.inbox.beats_renewed.load(Ordering::Relaxed)))
    }

    pub fn name(&self) -> &str {
        &self.inbox.name
    }

    /// Whether this board leads, and at which epoch.
    pub fn leading(&self) -> Option<u64> {
        self.leading.load(Ordering::Acquire).then(|| self.epoch.load(Ordering::Acquire))
    }

    /// Messages of other boards refused (not of this protocol, or naming
    /// what the bundle does not know).
    pub fn refused(&self) -> u64 {
        self.inbox.refused.load(Ordering::Relaxed)
    }

    /// A status heard on the status key.
    pub(crate) fn on_status(&self, w: &StatusWire) {
        if let Some(board) = &w.board {
            self.inbox.note(board, w.epoch);
        }
    }

    /// A batch heard on the log key.
    pub(crate) fn on_batch(&self, bytes: &[u8]) {
        self.inbox.on_batch(bytes)
    }

    /// An acknowledgement heard.
    pub(crate) fn on_ack(&self, bytes: &[u8]) {
        match wire::parse::<AckWire>(bytes) {
            Ok(a) if a.board != self.inbox.name => {
                let mut acks = self.acks.lock().unwrap_or_else(|p| p.into_inner());
                let e = acks.entry(a.board).or_insert((0, Instant::now()));
                *e = (a.index, Instant::now());
                drop(acks);
                self.acked.notify_all();
            }
            Ok(_) => {}
            Err(_) => {
                self.inbox.refused.fetch_add(1, Ordering::Relaxed);
            }
        }
    }

    /// A request for the log from `from` on: answered by the leader only.
    pub(crate) fn answer(&self, query: &zenoh::query::Query) {
        if self.leading().is_none() {
            return;
        }
        let key = query.key_expr().as_str();
        let Some(from) = key.rsplit('/').next().and_then(|f| f.parse::<u64>().ok()) else {
            self.inbox.refused.fetch_add(1, Ordering::Relaxed);
            return;
        };
        let epoch = self.epoch.load(Ordering::Acquire);
        // The log as it is now, in chunks; what comes after goes out as
        // batches anyway.
        let end = self.log.lock().unwrap_or_else(|p| p.into_inner()).len();
        let mut next = from.max(1);
        while next <= end {
            let batch = {
                let log = self.log.lock().unwrap_or_else(|p| p.into_inner());
                log.batch_from(next, CHUNK.min((end + 1 - next) as usize), epoch, &self.inbox.name)
            };
            if batch.entries.is_empty() {
                break;
            }
            next = batch.last() + 1;
            let bytes = serde_json::to_vec(&batch_wire(&self.content, &batch)).expect("JSON");
            if query.reply(query.key_expr().clone(), bytes).wait().is_err() {
                break;
            }
        }
    }

    fn put(&self, key: String, bytes: Vec<u8>) {
        let _ = self
            .session
            .put(key, bytes)
            .congestion_control(CongestionControl::Block)
            .priority(Priority::InteractiveHigh)
            .express(true)
            .wait();
    }
}

impl Peers for BoardPeers {
    fn publish(&self, batch: &Batch) {
        if batch.entries.is_empty() {
            // A beat: over UDP too, where nothing waits for a lost one;
            // first, as Zenoh's `put` may wait on a stalled link.
            if let Some(link) = &self.beats {
                link.beat(&self.inbox.name, batch.epoch);
            }
        }
        let bytes = serde_json::to_vec(&batch_wire(&self.content, batch)).expect("JSON");
        self.put(log_key(&self.robot), bytes);
    }

    fn wait_acks(&self, first: u64, last: u64, deadline: Instant) -> bool {
        let mut acks = self.acks.lock().unwrap_or_else(|p| p.into_inner());
        loop {
            let now = Instant::now();
            // The followers in step: heard within the lease, with the
            // entries before this batch.
            let behind = acks
                .values()
                .filter(|(index, at)| now.duration_since(*at) <= self.lease && *index + 1 >= first)
                .any(|(index, _)| *index < last);
            if !behind {
                return true;
            }
            if now >= deadline {
                return false;
            }
            acks = self.acked.wait_timeout(acks, deadline - now).unwrap_or_else(|p| p.into_inner()).0;
        }
    }

    fn take_batches(&self, out: &mut Vec<Batch>) {
        out.append(&mut self.inbox.incoming.lock().unwrap_or_else(|p| p.into_inner()));
    }

    fn ack(&self, epoch: u64, index: u64) {
        let w = AckWire { v: VERSION, board: self.inbox.name.clone(), epoch, index };
        self.put(ack_key(&self.robot, &self.inbox.name), serde_json::to_vec(&w).expect("JSON"));
    }

    fn request(&self, from: u64) {
        // The answers arrive on Zenoh's threads, into the inbox.
        let inbox = self.inbox.clone();
        let _ = self
            .session
            .get(sync_key(&self.robot, from))
            // Every chunk: they share one key, which Zenoh's default
            // consolidation would reduce to the latest.
            .consolidation(zenoh::query::ConsolidationMode::None)
            .timeout(SYNC_TIMEOUT)
            .callback(move |reply| {
                if let Ok(sample) = reply.result() {
                    inbox.on_batch(&sample.payload().to_bytes());
                }
            })
            .wait();
    }

    fn heard(&self) -> Option<(u64, Instant)> {
        self.inbox.heard.lock().unwrap_or_else(|p| p.into_inner()).as_ref().map(|h| (h.epoch, h.at))
    }

    fn linked(&self) -> bool {
        let info = self.session.info();
        info.peers_zid().wait().next().is_some() || info.routers_zid().wait().next().is_some()
    }

    fn set_leading(&self, epoch: Option<u64>) {
        if let Some(e) = epoch {
            self.epoch.store(e, Ordering::Release);
        }
        self.leading.store(epoch.is_some(), Ordering::Release);
    }
}
