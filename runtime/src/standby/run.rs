//! The thread of a board of a standby group: it follows the leader's log
//! until the election says it leads, then runs as the Bulletinboard does
//! (events, heartbeats, status) and writes its log to the followers; it
//! follows again when a higher epoch leads.

use super::election::{Decision, Election};
use super::replica::{Offer, Replica};
use super::{Batch, Entry, LogOut, Logged, Peers, SharedLog, Standby};
use crate::bus::EventMsg;
use crate::record::Level;
use crate::rete::StateChange;
use crate::runner::{BoardRunner, Shared};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// How long a follower holds an event the leader has not sequenced.
const HOLD: Duration = Duration::from_secs(5);

/// What the board's thread needs from the real-time run.
pub struct BoardLoop<'a> {
    pub shared: &'a Shared,
    pub board: &'a mut BoardRunner,
    /// The engine's heartbeat period (the clock moves without events).
    pub heartbeat: Duration,
    pub end: Instant,
    pub stop: &'a AtomicBool,
    /// The wall clock, ns since the Unix epoch.
    pub clock: &'a (dyn Fn() -> u64 + Sync),
}

/// The leader's output: every entry into the shared log, then to the
/// followers; before a change is broadcast, the followers' acknowledgement
/// (for `within` at most).
struct ToFollowers {
    log: SharedLog,
    peers: Arc<dyn Peers>,
    epoch: u64,
    name: String,
    within: Duration,
    /// Changes broadcast before every follower had their entries.
    unacknowledged: Arc<std::sync::atomic::AtomicU64>,
    /// The entries up to here were waited for.
    waited: u64,
}

impl LogOut for ToFollowers {
    fn write(&mut self, entries: &mut Vec<Entry>, change: bool) {
        if entries.is_empty() && !change {
            return;
        }
        let logged: Vec<Logged> = entries.drain(..).map(|entry| Logged { epoch: self.epoch, entry }).collect();
        let (first, prev_epoch, last, decided) = {
            let mut log = self.log.lock().unwrap_or_else(|p| p.into_inner());
            let first = log.len() + 1;
            let prev_epoch = log.epoch_at(first - 1).unwrap_or(0);
            for l in &logged {
                log.push(l.clone());
            }
            (first, prev_epoch, log.len(), log.decided())
        };
        if !logged.is_empty() {
            let batch =
                Batch { epoch: self.epoch, board: self.name.clone(), first, prev_epoch, decided, entries: logged };
            self.peers.publish(&batch);
        }
        if change && last > self.waited {
            if !self.peers.wait_acks(self.waited + 1, last, Instant::now() + self.within) {
                self.unacknowledged.fetch_add(1, Ordering::Relaxed);
            }
            self.waited = last;
        }
        if change {
            // The change is broadcast when this returns: the entries up to
            // here are behind a decision (the next batch or beat says so).
            self.log.lock().unwrap_or_else(|p| p.into_inner()).decide(last);
        }
    }
}

/// Runs the board's thread until `end` or `stop`; `deliver` sees the
/// changes of the state at rest this board made or applied.
pub fn run(standby: &Standby, l: BoardLoop<'_>, deliver: &mut dyn FnMut(&[StateChange])) {
    let BoardLoop { shared, board, heartbeat, end, stop, clock } = l;
    let cfg = &standby.config;
    let peers = &standby.peers;
    let origin = Instant::now();
    let ns = |i: Instant| i.saturating_duration_since(origin).as_nanos() as u64;
    // A board of a standby group has no journal: it knows no epoch at start.
    let mut election = Election::new(cfg, 0, 0);
    let mut replica = Replica::new(HOLD.as_nanos() as u64);
    let unacknowledged = Arc::new(std::sync::atomic::AtomicU64::new(0));
    let (mut events, mut batches): (Vec<EventMsg>, Vec<Batch>) = (Vec::new(), Vec::new());
    let mut changes: Vec<StateChange> = Vec::new();
    let mut next_beat = Instant::now();
    let mut next_tick = Instant::now() + heartbeat;
    // A catch-up request in flight: from where, and when it was sent.
    let mut asked: Option<(u64, Instant)> = None;
    // The highest epoch's last word on its decisions (`Batch::decided`): a
    // log shorter than this lacks a state the agents were told.
    let mut decided: (u64, u64) = (0, 0);
    let mut told_waiting = false;
    let say = |level: Level, text: String| shared.record(|s| s.diagnostic(clock(), level, &text));
    let tell = |text: String| {
        if let Some(t) = &standby.tell {
            t(&text);
        }
        say(Level::Warning, text);
    };
    peers.set_leading(None);
    let mut reported_unacked = 0;
    // A board with no link yet cannot tell "no leader" from "not connected".
    let mut linked = false;
    loop {
        let now = Instant::now();
        if now >= end || stop.load(Ordering::Acquire) {
            break;
        }
        if let Some((epoch, at)) = peers.heard() {
            if let Some(Decision::StepDown { higher }) = election.heard(epoch, ns(at)) {
                peers.set_leading(None);
                board.set_log_out(None);
                tell(format!("board `{}` steps down: epoch {higher} leads", cfg.name));
            }
        }
        match election.leading() {
            Some(epoch) => {
                let _ = shared.bus.wait_events(next_tick.min(next_beat).min(end));
                changes.extend(board.pump(shared, clock()));
                let now = Instant::now();
                if now >= next_tick {
                    next_tick = now + heartbeat;
                    for why in shared.bus.take_refusals() {
                        say(Level::Warning, format!("message refused: {why}"));
                    }
                    changes.extend(board.tick(shared, clock()));
                }
                board.flush_log(false);
                if now >= next_beat {
                    next_beat = now + cfg.beat;
                    // The beat: the status to the agents, the log's length
                    // to the boards.
                    board.reassure(shared, clock());
                    let beat = {
                        let log = standby.log.lock().unwrap_or_else(|p| p.into_inner());
                        log.batch_from(log.len() + 1, 0, epoch, &cfg.name)
                    };
                    peers.publish(&beat);
                }
                let n = unacknowledged.load(Ordering::Relaxed);
                if n > reported_unacked {
                    reported_unacked = n;
                    say(
                        Level::Warning,
                        format!(
                            "{n} change(s) broadcast before every follower acknowledged them (within {:?})",
                            cfg.replicate_within
                        ),
                    );
                }
            }
            None => {
                let _ = shared.bus.wait_events(now + heartbeat.min(Duration::from_millis(10)));
                events.clear();
                let _ = shared.bus.recv_events(&mut events);
                let t = ns(Instant::now());
                for m in events.drain(..) {
                    replica.hold(m, t);
                }
                peers.take_batches(&mut batches);
                for b in batches.drain(..) {
                    if b.epoch < election.highest() {
                        continue; // an old leader's
                    }
                    election.heard(b.epoch, ns(Instant::now()));
                    decided = match decided {
                        (e, d) if e == b.epoch => (e, d.max(b.decided)),
                        (e, _) if b.epoch > e => (b.epoch, b.decided),
                        kept => kept,
                    };
                    let offer = {
                        let log = standby.log.lock().unwrap_or_else(|p| p.into_inner());
                        replica.offer(&b, &log)
                    };
                    match offer {
                        Offer::Apply(entries) => {
                            for l in entries {
                                if let Entry::Event { msg, .. } = &l.entry {
                                    replica.sequenced(msg, ns(Instant::now()));
                                }
                                changes.extend(board.apply(shared, &l.entry));
                                standby.log.lock().unwrap_or_else(|p| p.into_inner()).push(l);
                            }
                            board.flush_log(false);
                            let len = standby.log.lock().unwrap_or_else(|p| p.into_inner()).len();
                            peers.ack(b.epoch, len);
                            asked = None;
                        }
                        Offer::Nothing => {
                            let len = standby.log.lock().unwrap_or_else(|p| p.into_inner()).len();
                            peers.ack(b.epoch, len);
                        }
                        Offer::Behind { from } => {
                            if asked.is_none_or(|(f, at)| f != from || at.elapsed() > cfg.lease) {
                                say(
                                    Level::Info,
                                    format!("board `{}` asks `{}` for the log from entry {from}", cfg.name, b.board),
                                );
                                peers.request(from);
                                asked = Some((from, Instant::now()));
                            }
                        }
                        Offer::Diverged => {
                            say(
                                Level::Warning,
                                format!(
                                    "board `{}` holds entries that the leader (`{}`) does not: it starts again from the leader's log",
                                    cfg.name, b.board
                                ),
                            );
                            start_again(shared, board, &standby.log, &mut replica, clock());
                            peers.request(1);
                            asked = Some((1, Instant::now()));
                        }
                    }
                }
                if !linked && peers.linked() {
                    linked = true;
                    election.linked(ns(Instant::now()));
                }
                if !linked {
                    continue;
                }
                let applied = standby.log.lock().unwrap_or_else(|p| p.into_inner()).len();
                let ready = applied >= decided.1;
                let decision = election.poll(ns(Instant::now()), clock() / 1_000_000, ready);
                if election.waiting() && !told_waiting {
                    told_waiting = true;
                    tell(format!(
                        "board `{}` cannot lead yet: it has {applied} entries of the log, and the agents were told \
                         the state of entry {}; it waits {:?} for a board that has them, then leads from the initial \
                         state",
                        cfg.name, decided.1, cfg.give_up
                    ));
                }
                if !election.waiting() {
                    told_waiting = false;
                }
                let afresh = matches!(decision, Some(Decision::LeadFromStart(_)));
                if let Some(Decision::Lead(epoch) | Decision::LeadFromStart(epoch)) = decision {
                    if afresh {
                        // No board that holds the decisions led: this one
                        // starts the group again from the rules' initial
                        // state (the events it holds are taken after).
                        standby.log.lock().unwrap_or_else(|p| p.into_inner()).clear();
                        board.start_again(shared, clock());
                        tell(format!(
                            "board `{}` starts from the initial state: no board that has the log up to entry {} led \
                             within {:?}",
                            cfg.name, decided.1, cfg.give_up
                        ));
                    }
                    // What came in since the last look is held too: the
                    // held events go first, in the order they came.
                    let _ = shared.bus.recv_events(&mut events);
                    let t = ns(Instant::now());
                    for m in events.drain(..) {
                        replica.hold(m, t);
                    }
                    let held = take_over(board, standby, epoch, &mut replica, t, &unacknowledged);
                    tell(format!(
                        "board `{}` leads at epoch {epoch}, from entry {} of the log{}",
                        cfg.name,
                        standby.log.lock().unwrap_or_else(|p| p.into_inner()).len(),
                        if held.is_empty() {
                            String::new()
                        } else {
                            format!(", and {} event(s) no leader took", held.len())
                        }
                    ));
                    // The state the log gives (the old leader's last word),
                    // then what the events no leader took make of it.
                    board.announce(shared, clock());
                    changes.extend(board.take_events(shared, &held, clock()));
                    next_beat = Instant::now();
                    next_tick = Instant::now();
                }
            }
        }
        if !changes.is_empty() {
            deliver(&changes);
            changes.clear();
        }
    }
    board.flush_log(false);
}

/// This board leads at `epoch`: the log goes to the followers. Returns
/// the events no leader sequenced, in the order they came, for the board to
/// take before its queue.
fn take_over(
    board: &mut BoardRunner,
    standby: &Standby,
    epoch: u64,
    replica: &mut Replica,
    now: u64,
    unacknowledged: &Arc<std::sync::atomic::AtomicU64>,
) -> Vec<EventMsg> {
    standby.peers.set_leading(Some(epoch));
    let waited = {
        let mut log = standby.log.lock().unwrap_or_else(|p| p.into_inner());
        // The state the log gives is broadcast at once: all of it is
        // behind a decision.
        let len = log.len();
        log.decide(len);
        len
    };
    board.set_log_out(Some(Box::new(ToFollowers {
        waited,
        log: standby.log.clone(),
        peers: standby.peers.clone(),
        epoch,
        name: standby.config.name.clone(),
        within: standby.config.replicate_within,
        unacknowledged: unacknowledged.clone(),
    })));
    replica.take_unsequenced(now)
}

/// Forgets this board's log, state and facts: it applies the leader's log
/// from its first entry.
fn start_again(shared: &Shared, board: &mut BoardRunner, log: &SharedLog, replica: &mut Replica, now: u64) {
    log.lock().unwrap_or_else(|p| p.into_inner()).clear();
    replica.clear();
    board.start_again(shared, now);
}
