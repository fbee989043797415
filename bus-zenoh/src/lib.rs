//! The three streams of a situ stack over Zenoh (peer to peer, optional
//! routers): the same agents and the same bundle as in one process, spread
//! over processes, hosts and languages.
//!
//! [`ZenohBus`] implements the runtime's [`Bus`]: the agents of this
//! process keep in-process mailboxes ([`InProc`]); what goes to an agent of
//! another process, or to a Bulletinboard in another process, is published
//! on the keys of [`wire`], and what arrives on them is checked and put in
//! the local mailboxes. Quality of service: events and status are sent with
//! `CongestionControl::Block` (never dropped by Zenoh), data with `Drop`
//! (keep-latest, as in process); urgent messages at `Priority::RealTime`,
//! status at `InteractiveHigh`, events and data at `Data`. Status, events
//! and urgent data are sent `express` (no batching: latency first); data
//! is batched (throughput first).

pub mod beats;
pub mod deploy;
pub mod limit;
pub mod standby;
pub mod wire;

use situ_compiler::bundle::Content;
use situ_runtime::agent::Body;
use situ_runtime::bus::inproc::{Capacity, InProc};
use situ_runtime::bus::{Attention, Bus, BusCounters, DataMsg, Doorbell, EventMsg, StatusMsg, Wake};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;
use wire::{DataWire, EventWire, StatusWire, VERSION};
use zenoh::qos::{CongestionControl, Priority};
use zenoh::Wait;

/// What runs where, for one process.
#[derive(Debug, Clone)]
pub struct Placement {
    pub robot: String,
    /// Per agent of the bundle: whether it runs in this process.
    pub local: Vec<bool>,
    /// Whether this process hosts the Bulletinboard.
    pub board: bool,
}

impl Placement {
    /// What the deployment `d` places in its process `p`: its agents (of
    /// `content`'s), and the Bulletinboard if it is marked `board`.
    pub fn of(d: &deploy::Deployment, p: &deploy::Process, content: &Content) -> Placement {
        let local = content.agents.iter().map(|a| p.agents.contains(&a.name)).collect();
        Placement { robot: d.robot.clone(), local, board: p.board }
    }
}

#[derive(Default)]
struct Counters {
    rejected: AtomicU64,
    unsendable: AtomicU64,
    published: AtomicU64,
}

/// The reasons kept between two [`Bus::take_refusals`], at most.
const REASONS_KEPT: usize = 100;

/// Refusals not yet reported: the first reasons word for word, how many
/// more there were, and per agent the events refused over its limit.
#[derive(Default)]
struct Refusals {
    reasons: Vec<String>,
    omitted: u64,
    flooded: Vec<u64>,
}

pub struct ZenohBus {
    local: Arc<InProc>,
    session: zenoh::Session,
    content: Arc<Content>,
    placement: Placement,
    counters: Arc<Counters>,
    /// The latest refusals, for whoever reports them.
    refusals: Arc<Mutex<Refusals>>,
    /// Per agent, the events refused for going over its limit.
    limits: Arc<Mutex<limit::EventLimits>>,
    /// The other boards, when this process's board is one of a standby group.
    peers: Option<Arc<standby::BoardPeers>>,
    /// Statuses of an epoch below the highest seen: an old leader's, ignored.
    old_epoch: Arc<AtomicU64>,
    _subscribers: Vec<zenoh::pubsub::Subscriber<()>>,
    _queryable: Option<zenoh::query::Queryable<()>>,
}

/// Why the bus could not start.
#[derive(Debug)]
pub struct BusError(pub String);

impl std::fmt::Display for BusError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for BusError {}

impl ZenohBus {
    /// Opens a Zenoh session with `config` (JSON5) and subscribes to what
    /// this process must receive.
    pub fn open(
        content: Arc<Content>,
        placement: Placement,
        config: &str,
        capacity: Capacity,
    ) -> Result<ZenohBus, BusError> {
        Self::open_in_group(content, placement, config, capacity, None)
    }

    /// As [`open`](Self::open), for a board of a standby group: it also
    /// hears the other boards (their status, log, acknowledgements) and
    /// answers their catch-up requests; it publishes its status only while
    /// it leads ([`standby::BoardPeers`], through [`peers`](Self::peers)).
    pub fn open_in_group(
        content: Arc<Content>,
        placement: Placement,
        config: &str,
        capacity: Capacity,
        group: Option<standby::BoardGroup>,
    ) -> Result<ZenohBus, BusError> {
        let config = zenoh::Config::from_json5(config).map_err(|e| BusError(format!("Zenoh configuration: {e}")))?;
        let session =
            zenoh::open(config).wait().map_err(|e| BusError(format!("cannot open the Zenoh session: {e}")))?;
        let local = Arc::new(InProc::new(content.agents.len(), capacity));
        let counters = Arc::new(Counters::default());
        let refusals = Arc::new(Mutex::new(Refusals { flooded: vec![0; content.agents.len()], ..Refusals::default() }));
        let limits = Arc::new(Mutex::new(limit::EventLimits::new(&content)));
        let robot = placement.robot.clone();
        let mut subscribers = Vec::new();
        let refuse = {
            let (counters, refusals) = (counters.clone(), refusals.clone());
            move |why: String| {
                counters.rejected.fetch_add(1, Ordering::Relaxed);
                let mut r = refusals.lock().unwrap_or_else(|p| p.into_inner());
                if r.reasons.len() < REASONS_KEPT {
                    r.reasons.push(why);
                } else {
                    r.omitted += 1;
                }
            }
        };
        // An event over its agent's limit: counted, and reported as one
        // line per agent (a flood must not become a flood of records).
        let flooded = {
            let (counters, refusals) = (counters.clone(), refusals.clone());
            move |agent: u32| {
                counters.rejected.fetch_add(1, Ordering::Relaxed);
                let mut r = refusals.lock().unwrap_or_else(|p| p.into_inner());
                if let Some(n) = r.flooded.get_mut(agent as usize) {
                    *n += 1;
                }
            }
        };
        if placement.board {
            let (local, content, refuse, limits) = (local.clone(), content.clone(), refuse.clone(), limits.clone());
            let prefix = format!("situ/{robot}/event/");
            let sub = session
                .declare_subscriber(format!("situ/{robot}/event/*"))
                .callback(move |sample| {
                    let key = sample.key_expr().as_str();
                    let key_agent = key.strip_prefix(&prefix).unwrap_or("");
                    let bytes = sample.payload().to_bytes();
                    match wire::parse::<EventWire>(&bytes) {
                        Ok(w) => match wire::event_of(&content, key_agent, &w) {
                            Ok((agent, event, payload)) => {
                                let within =
                                    limits.lock().unwrap_or_else(|p| p.into_inner()).take(agent, Instant::now());
                                if within {
                                    local.send_event(EventMsg {
                                        agent,
                                        event,
                                        time: w.time_ns,
                                        payload,
                                        urgent: w.urgent,
                                    })
                                } else {
                                    flooded(agent)
                                }
                            }
                            Err(e) => refuse(format!("{key}: {e}")),
                        },
                        Err(e) => refuse(format!("{key}: {e}")),
                    }
                })
                .wait()
                .map_err(|e| BusError(format!("cannot subscribe to events: {e}")))?;
            subscribers.push(sub);
        }
        let old_epoch = Arc::new(AtomicU64::new(0));
        let peers = match (&group, placement.board) {
            (Some(g), true) => {
                Some(Arc::new(standby::BoardPeers::new(g, &robot, session.clone(), content.clone(), local.clone())?))
            }
            _ => None,
        };
        let mut queryable = None;
        if let Some(peers) = &peers {
            // The other boards' status, log and acknowledgements.
            let p = peers.clone();
            let sub = session
                .declare_subscriber(wire::status_key(&robot))
                .callback(move |sample| {
                    if let Ok(w) = wire::parse::<StatusWire>(&sample.payload().to_bytes()) {
                        p.on_status(&w);
                    }
                })
                .wait()
                .map_err(|e| BusError(format!("cannot subscribe to the status: {e}")))?;
            subscribers.push(sub);
            let p = peers.clone();
            let sub = session
                .declare_subscriber(standby::log_key(&robot))
                .callback(move |sample| p.on_batch(&sample.payload().to_bytes()))
                .wait()
                .map_err(|e| BusError(format!("cannot subscribe to the boards' log: {e}")))?;
            subscribers.push(sub);
            let p = peers.clone();
            let sub = session
                .declare_subscriber(format!("situ/{robot}/board/ack/*"))
                .callback(move |sample| p.on_ack(&sample.payload().to_bytes()))
                .wait()
                .map_err(|e| BusError(format!("cannot subscribe to the boards' acknowledgements: {e}")))?;
            subscribers.push(sub);
            let p = peers.clone();
            let q = session
                .declare_queryable(format!("situ/{robot}/board/sync/*"))
                .callback(move |query| p.answer(&query))
                .wait()
                .map_err(|e| BusError(format!("cannot answer the boards' catch-up requests: {e}")))?;
            queryable = Some(q);
        } else if !placement.board {
            let (local, content, refuse) = (local.clone(), content.clone(), refuse.clone());
            // The highest epoch seen: a status of a lower one is an old
            // leader's (a board that has not yet learned it was replaced).
            let highest = Arc::new(AtomicU64::new(0));
            let old = old_epoch.clone();
            let sub = session
                .declare_subscriber(wire::status_key(&robot))
                .callback(move |sample| {
                    let bytes = sample.payload().to_bytes();
                    match wire::parse::<StatusWire>(&bytes) {
                        Ok(w) => match content.state_id(&w.state) {
                            Some(state) => {
                                if w.epoch < highest.fetch_max(w.epoch, Ordering::AcqRel) {
                                    old.fetch_add(1, Ordering::Relaxed);
                                    return;
                                }
                                local.send_status(StatusMsg { state, time: w.time_ns, seq: w.seq })
                            }
                            None => refuse(format!("status: unknown state `{}`", w.state)),
                        },
                        Err(e) => refuse(format!("status: {e}")),
                    }
                })
                .wait()
                .map_err(|e| BusError(format!("cannot subscribe to the status: {e}")))?;
            subscribers.push(sub);
        }
        for (i, a) in content.agents.iter().enumerate() {
            if !placement.local[i] {
                continue;
            }
            let (local, content, refuse) = (local.clone(), content.clone(), refuse.clone());
            let to = i as u32;
            let sub = session
                .declare_subscriber(format!("situ/{robot}/data/*/{}", a.name))
                .callback(move |sample| {
                    let bytes = sample.payload().to_bytes();
                    match wire::parse::<DataWire>(&bytes) {
                        Ok(w) => match content.agent_id(&w.from) {
                            Some(from) => local.send_data(DataMsg {
                                from,
                                to,
                                time: w.time_ns,
                                urgent: w.urgent,
                                body: Body::json(w.body),
                            }),
                            None => refuse(format!("data from unknown agent `{}`", w.from)),
                        },
                        Err(e) => refuse(format!("data: {e}")),
                    }
                })
                .wait()
                .map_err(|e| BusError(format!("cannot subscribe to data: {e}")))?;
            subscribers.push(sub);
        }
        Ok(ZenohBus {
            local,
            session,
            content,
            placement,
            counters,
            refusals,
            limits,
            peers,
            old_epoch,
            _subscribers: subscribers,
            _queryable: queryable,
        })
    }

    /// The other boards, when this process's board is one of a standby
    /// group (to give the runtime's [`situ_runtime::standby::run`]).
    pub fn peers(&self) -> Option<Arc<standby::BoardPeers>> {
        self.peers.clone()
    }

    /// Statuses ignored because an agent here had seen a higher epoch.
    pub fn old_epoch_statuses(&self) -> u64 {
        self.old_epoch.load(Ordering::Relaxed)
    }

    /// The Zenoh session under the bus, for a tool that puts or subscribes
    /// beside the three streams on the same links (a benchmark's reports).
    pub fn session(&self) -> &zenoh::Session {
        &self.session
    }

    /// Publishes; `express` messages skip Zenoh's batching (status,
    /// events, urgent data: latency first), the rest is batched (throughput).
    fn put(&self, key: String, bytes: Vec<u8>, congestion: CongestionControl, priority: Priority, express: bool) {
        self.counters.published.fetch_add(1, Ordering::Relaxed);
        let _ = self.session.put(key, bytes).congestion_control(congestion).priority(priority).express(express).wait();
    }
}

impl Bus for ZenohBus {
    fn send_data(&self, msg: DataMsg) {
        if self.placement.local.get(msg.to as usize).copied().unwrap_or(false) {
            return self.local.send_data(msg);
        }
        let Body::Json(body) = &msg.body else {
            self.counters.unsendable.fetch_add(1, Ordering::Relaxed);
            return;
        };
        let c = &self.content;
        let (from, to) = (&c.agents[msg.from as usize].name, &c.agents[msg.to as usize].name);
        let w = DataWire {
            v: VERSION,
            from: from.clone(),
            to: to.clone(),
            time_ns: msg.time,
            urgent: msg.urgent,
            body: (**body).clone(),
        };
        let priority = if msg.urgent { Priority::RealTime } else { Priority::Data };
        self.put(
            wire::data_key(&self.placement.robot, from, to),
            serde_json::to_vec(&w).expect("JSON"),
            CongestionControl::Drop,
            priority,
            msg.urgent,
        );
    }

    fn send_event(&self, msg: EventMsg) {
        if self.placement.board {
            return self.local.send_event(msg);
        }
        let w = wire::event_wire(&self.content, msg.agent, msg.event, msg.time, &msg.payload, msg.urgent);
        let key = wire::event_key(&self.placement.robot, &w.agent);
        let priority = if msg.urgent { Priority::RealTime } else { Priority::Data };
        self.put(key, serde_json::to_vec(&w).expect("JSON"), CongestionControl::Block, priority, true);
    }

    fn send_status(&self, msg: StatusMsg) {
        self.local.send_status(msg);
        // A board of a standby group speaks only while it leads.
        let (speaks, epoch, board) = match &self.peers {
            None => (self.placement.board, 0, None),
            Some(p) => match p.leading() {
                Some(epoch) => (true, epoch, Some(p.name().to_string())),
                None => (false, 0, None),
            },
        };
        if speaks {
            let w = StatusWire {
                v: VERSION,
                state: self.content.states[msg.state as usize].name.clone(),
                time_ns: msg.time,
                seq: msg.seq,
                epoch,
                board,
            };
            let key = wire::status_key(&self.placement.robot);
            self.put(
                key,
                serde_json::to_vec(&w).expect("JSON"),
                CongestionControl::Block,
                Priority::InteractiveHigh,
                true,
            );
        }
    }

    fn recv_data(&self, agent: u32, out: &mut Vec<DataMsg>) {
        self.local.recv_data(agent, out)
    }
    fn discard_data(&self, agent: u32) -> usize {
        self.local.discard_data(agent)
    }
    fn recv_events(&self, out: &mut Vec<EventMsg>) -> u64 {
        self.local.recv_events(out)
    }
    fn status(&self, agent: u32) -> Option<StatusMsg> {
        self.local.status(agent)
    }
    fn wait(&self, agent: u32, deadline: Instant) -> Wake {
        self.local.wait(agent, deadline)
    }
    fn wait_input(&self, agent: u32, deadline: Instant) -> Wake {
        self.local.wait_input(agent, deadline)
    }
    fn wait_events(&self, deadline: Instant) -> Wake {
        self.local.wait_events(deadline)
    }
    fn set_doorbell(&self, agent: u32, bell: Arc<Doorbell>) {
        self.local.set_doorbell(agent, bell)
    }
    fn attention(&self, agent: u32) -> Attention {
        self.local.attention(agent)
    }
    fn close(&self) {
        self.local.close();
    }
    /// The latest refused messages (at most 100 word for word between
    /// calls, then how many more), and one line per agent whose events
    /// went over its limit.
    fn take_refusals(&self) -> Vec<String> {
        let mut r = self.refusals.lock().unwrap_or_else(|p| p.into_inner());
        let mut out = std::mem::take(&mut r.reasons);
        if r.omitted > 0 {
            out.push(format!("and {} more message(s) refused", std::mem::take(&mut r.omitted)));
        }
        let limits = self.limits.lock().unwrap_or_else(|p| p.into_inner());
        for (a, n) in r.flooded.iter_mut().enumerate().filter(|(_, n)| **n > 0) {
            let per_s = limits.per_second(a as u32);
            out.push(format!(
                "{} event(s) of `{}` refused: over its limit of {per_s} per second (a flood)",
                std::mem::take(n),
                self.content.agents[a].name
            ));
        }
        out
    }
    fn counters(&self) -> BusCounters {
        let mut c = self.local.counters();
        c.rejected = self.counters.rejected.load(Ordering::Relaxed);
        c.unsendable = self.counters.unsendable.load(Ordering::Relaxed);
        c
    }
}

/// A process that only routes (`mode = "router"`, no agent, no
/// Bulletinboard): a Zenoh session in router mode that carries the other
/// processes' messages and keeps none. Closed when dropped.
pub struct Router {
    session: zenoh::Session,
}

impl Router {
    /// Opens the router's session with `config` (JSON5, `"mode": "router"`).
    pub fn open(config: &str) -> Result<Router, BusError> {
        let config = zenoh::Config::from_json5(config).map_err(|e| BusError(format!("Zenoh configuration: {e}")))?;
        let session = zenoh::open(config).wait().map_err(|e| BusError(format!("cannot open the Zenoh router: {e}")))?;
        Ok(Router { session })
    }
}

impl Drop for Router {
    fn drop(&mut self) {
        let _ = self.session.close().wait();
    }
}

impl Drop for ZenohBus {
    fn drop(&mut self) {
        let _ = self.session.close().wait();
    }
}
