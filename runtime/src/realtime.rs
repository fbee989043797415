//! The real-time scheduler, on the wall clock (time is nanoseconds since
//! the Unix epoch, shared by the processes of a stack): the agents are shared among a few worker threads (one per
//! core by default), the Bulletinboard has a thread of its own.
//!
//! - An agent with a rate steps every period; an urgent datum interrupts
//!   its worker's sleep (ROBIX's Recvagent interrupting its receiver) and the
//!   agent steps at once. An agent without a rate steps when input arrives.
//! - A worker sleeps on one bell that its agents' mailboxes ring, until the
//!   next period of one of them: a status broadcast wakes a few workers, not
//!   a thread per agent.
//! - The Bulletinboard sleeps until an event arrives (urgent ones first) or
//!   its heartbeat is due.
//!
//! The same agents, bus and Bulletinboard as in simulated time
//! ([`crate::sched`]); only the clock and the threads differ. Runs are not
//! reproducible bit for bit here: use simulated time for that.

use crate::agent::Bound;
use crate::bus::inproc::{Capacity, InProc};
use crate::bus::{Bus, Doorbell};
use crate::record::Sink;
use crate::rete::StateChange;
use crate::runner::{AgentRunner, BoardRunner, Shared};
use crate::standby::{self, Standby};
use crate::summary::Summary;
use situ_bundle::Content;
use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

#[derive(Debug, Clone)]
pub struct RealtimeConfig {
    pub heartbeat: Duration,
    /// Rates (Hz) by agent name, over the rules file's `rate`.
    pub rates: BTreeMap<String, f64>,
    pub capacity: Capacity,
    pub stop_on_final: bool,
    /// Worker threads for the agents (0: one per core).
    pub workers: usize,
    /// Whether this process hosts the Bulletinboard (else it follows the
    /// status another process broadcasts).
    pub board: bool,
    /// How often the Bulletinboard repeats its status when nothing changes.
    pub status_every: Duration,
    /// A process without the Bulletinboard enters safe mode when no status
    /// came for this long, and leaves it when one comes.
    pub safe_after: Duration,
    /// Raised from outside (Ctrl-C, SIGTERM): the run ends cleanly.
    pub stop: Option<Arc<AtomicBool>>,
    /// How far ahead of the Bulletinboard's clock an event may be stamped
    /// (further is refused: it would age every other fact).
    pub max_skew: Duration,
    /// This process's board is one of a standby group (with `board`): it
    /// follows the leader's log until it leads ([`crate::standby`]).
    pub standby: Option<Standby>,
    /// The board's journal (with `board`, without `standby`): what it
    /// holds is applied before the board starts, and the board's log is
    /// written to it ([`crate::journal`]).
    pub journal: Option<crate::journal::Opened>,
    /// Run the agents' workers and the Bulletinboard's thread (the
    /// caller's, given back its policy at the end) under `SCHED_FIFO` at
    /// this priority ([`crate::priority`]). Refused by the kernel, it is
    /// said once in the recording and the run goes on.
    pub priority: Option<i32>,
}

impl Default for RealtimeConfig {
    fn default() -> Self {
        RealtimeConfig {
            heartbeat: Duration::from_millis(10),
            rates: BTreeMap::new(),
            capacity: Capacity::default(),
            stop_on_final: true,
            workers: 0,
            board: true,
            status_every: Duration::from_millis(200),
            safe_after: Duration::from_millis(600),
            stop: None,
            max_skew: Duration::from_nanos(crate::runner::DEFAULT_MAX_SKEW),
            standby: None,
            journal: None,
            priority: None,
        }
    }
}

/// One agent as a worker sees it.
struct Slot {
    runner: AgentRunner,
    period: Option<Duration>,
    next: Instant,
}

/// Runs the stack on the wall clock for `duration` (or until a final state
/// with `stop_on_final`); `on_change` sees every change of the state at rest
/// (from the Bulletinboard's thread).
pub fn run(
    content: Arc<Content>,
    agents: Bound,
    sink: Option<Box<dyn Sink>>,
    config: RealtimeConfig,
    duration: Duration,
    on_change: &mut (dyn FnMut(&StateChange) + Send),
) -> Summary {
    let bus: Arc<dyn Bus> = Arc::new(InProc::new(content.agents.len(), config.capacity));
    run_on(content, agents, sink, config, duration, bus, on_change)
}

/// As [`run`], on a given bus.
pub fn run_on(
    content: Arc<Content>,
    agents: Bound,
    sink: Option<Box<dyn Sink>>,
    config: RealtimeConfig,
    duration: Duration,
    bus: Arc<dyn Bus>,
    on_change: &mut (dyn FnMut(&StateChange) + Send),
) -> Summary {
    let mut shared = Shared::new(content.clone(), bus.clone(), sink);
    shared.remote_board = !config.board;
    let shared = Arc::new(shared);
    // Time is the wall clock (ns since the Unix epoch), so that processes
    // of one stack on synchronised hosts share it; it never goes back here.
    let start = Instant::now();
    let epoch = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64);
    let clock = move || epoch + start.elapsed().as_nanos() as u64;
    let stop = config.stop.clone().unwrap_or_else(|| Arc::new(AtomicBool::new(false)));
    let counters = Arc::new(Mutex::new(Vec::new()));
    // Steps of agents that were not sleeping, since the summary last took them.
    let steps = &AtomicU64::new(0);
    let mut board = BoardRunner::new(content.clone());
    board.set_max_skew(config.max_skew.as_nanos().min(u64::MAX as u128) as u64);
    let journal_failures = resume_from_journal(&config, &mut board, &shared, epoch);
    let mut summary = Summary::new(&content).starting_at(epoch).starting_in(board.board.state());
    if config.board {
        board.start(&shared, epoch);
    }

    let workers = match config.workers {
        0 => std::thread::available_parallelism().map_or(1, |n| n.get()),
        n => n,
    };
    let mut groups: Vec<Vec<Slot>> = (0..workers).map(|_| Vec::new()).collect();
    let mut k = 0;
    for (i, imp) in agents.into_iter().enumerate() {
        let Some(imp) = imp else { continue };
        let def = &content.agents[i];
        let hz = config.rates.get(&def.name).copied().or(def.rate_hz).filter(|h| h.is_finite() && *h > 0.0);
        let period = hz.map(|h| Duration::from_nanos(((1e9 / h).round() as u64).max(1)));
        groups[k % workers].push(Slot { runner: AgentRunner::new(i as u32, imp), period, next: start });
        k += 1;
    }
    let local: Vec<u32> = groups.iter().flatten().map(|s| s.runner.id).collect();
    // Under SCHED_FIFO when asked: a refusal said once, by the first
    // thread refused.
    let refused = &AtomicBool::new(false);
    let fifo = |whose: &str| -> Option<crate::priority::Previous> {
        let p = config.priority?;
        match crate::priority::enter(p) {
            Ok(previous) => Some(previous),
            Err(e) => {
                if !refused.swap(true, Ordering::AcqRel) {
                    let text = crate::priority::refused(p, whose, &e);
                    shared.record(|s| s.diagnostic(clock(), crate::record::Level::Warning, &text));
                }
                None
            }
        }
    };
    let board_thread = fifo(if config.board { "the Bulletinboard's thread" } else { "the status's thread" });

    std::thread::scope(|scope| {
        for mut group in groups.into_iter().filter(|g| !g.is_empty()) {
            let (shared, stop, counters) = (shared.clone(), stop.clone(), counters.clone());
            let bell = Arc::new(Doorbell::default());
            for slot in &group {
                shared.bus.set_doorbell(slot.runner.id, bell.clone());
            }
            let fifo = &fifo;
            scope.spawn(move || {
                fifo("an agents' worker");
                while !stop.load(Ordering::Acquire) {
                    let now = Instant::now();
                    for slot in &mut group {
                        let attention = shared.bus.attention(slot.runner.id);
                        let due = slot.period.is_some_and(|_| now >= slot.next);
                        if let (true, Some(p)) = (due, slot.period) {
                            slot.next += p;
                            if slot.next < now {
                                // Fell behind: skip the missed periods.
                                slot.next = now + p;
                            }
                        }
                        let on_input = slot.period.is_none() && attention.input;
                        let turn = due || attention.urgent || on_input;
                        if turn && slot.runner.cycle(&shared, clock()).stepped {
                            steps.fetch_add(1, Ordering::Relaxed);
                        }
                    }
                    let next = group.iter().filter(|s| s.period.is_some()).map(|s| s.next).min();
                    bell.wait_until(next.unwrap_or_else(|| Instant::now() + Duration::from_millis(100)));
                }
                let mut c = counters.lock().unwrap_or_else(|p| p.into_inner());
                c.extend(group.iter().map(|s| (s.runner.id, s.runner.counters)));
            });
        }
        let mut deliver = |changes: &[StateChange]| {
            for c in changes {
                summary.add_steps(steps.swap(0, Ordering::Relaxed));
                summary.change(c);
                on_change(c);
                if config.stop_on_final && content.states[c.to as usize].is_final {
                    stop.store(true, Ordering::Release);
                }
            }
        };
        if !config.board {
            follow(&shared, &local, &config, start + duration, &stop, &mut summary, steps, on_change, &clock);
        } else if let Some(sb) = &config.standby {
            let l = standby::run::BoardLoop {
                shared: &shared,
                board: &mut board,
                heartbeat: config.heartbeat,
                end: start + duration,
                stop: &stop,
                clock: &clock,
            };
            standby::run::run(sb, l, &mut deliver);
        } else {
            // The Bulletinboard, on this thread.
            let end = start + duration;
            let mut next_beat = start + config.heartbeat;
            let mut next_status = start + config.status_every;
            loop {
                let now = Instant::now();
                if now >= end || stop.load(Ordering::Acquire) {
                    break;
                }
                let _ = shared.bus.wait_events(next_beat.min(end));
                let mut changes = board.pump(&shared, clock());
                let now = Instant::now();
                if now >= next_beat {
                    next_beat += config.heartbeat;
                    // At most once a heartbeat: a flood of refusals is a
                    // few records a period, not one per message.
                    for why in shared.bus.take_refusals() {
                        shared.record(|s| {
                            s.diagnostic(clock(), crate::record::Level::Warning, &format!("message refused: {why}"))
                        });
                    }
                    changes.extend(board.tick(&shared, clock()));
                }
                board.flush_log(false);
                if let Some(e) =
                    journal_failures.as_ref().and_then(|f| f.lock().unwrap_or_else(|p| p.into_inner()).take())
                {
                    let text = format!("{e}: the board goes on without its journal");
                    shared.record(|s| s.diagnostic(clock(), crate::record::Level::Error, &text));
                }
                if now >= next_status {
                    next_status = now + config.status_every;
                    board.reassure(&shared, clock());
                }
                deliver(&changes);
            }
        }
        board.flush_log(false);
        stop.store(true, Ordering::Release);
        for why in shared.bus.take_refusals() {
            shared.record(|s| s.diagnostic(clock(), crate::record::Level::Warning, &format!("message refused: {why}")));
        }
        shared.bus.close();
    });
    if let Some(previous) = board_thread {
        crate::priority::leave(previous);
    }
    let agents = std::mem::take(&mut *counters.lock().unwrap_or_else(|p| p.into_inner()));
    let state = if config.board { board.board.state() } else { shared.org().state() };
    summary.add_steps(steps.swap(0, Ordering::Relaxed));
    summary.finish(clock(), state, &board.counters, agents, shared.bus.counters());
    shared.record(|s| {
        let _ = s.finish();
    });
    summary
}

/// The board of `config` with a journal: applies what it recovered, says
/// so in the recording and writes its log there from now on; where the
/// journal tells of a failed write.
fn resume_from_journal(
    config: &RealtimeConfig,
    board: &mut BoardRunner,
    shared: &Shared,
    now: u64,
) -> Option<Arc<Mutex<Option<crate::journal::JournalError>>>> {
    let opened = config.journal.as_ref()?;
    let (journal, recovered) = opened.take()?;
    let say = |level, text: &str| shared.record(|s| s.diagnostic(now, level, text));
    if !config.board || config.standby.is_some() {
        say(crate::record::Level::Warning, "the journal is kept by a single board: it is not used here");
        return None;
    }
    let text = crate::journal::recover(board, shared, &journal, &recovered);
    say(crate::record::Level::Info, &text);
    opened.tell(&text);
    let failures = journal.failures();
    board.set_log_out(Some(Box::new(journal)));
    Some(failures)
}

/// A process without the Bulletinboard: its organisation follows the status
/// broadcast from afar, and falls into safe mode when it stops coming.
#[allow(clippy::too_many_arguments)]
fn follow(
    shared: &Shared,
    local: &[u32],
    config: &RealtimeConfig,
    end: Instant,
    stop: &AtomicBool,
    summary: &mut Summary,
    steps: &AtomicU64,
    on_change: &mut (dyn FnMut(&StateChange) + Send),
    clock: &dyn Fn() -> u64,
) {
    let Some(&probe) = local.first() else { return };
    let (mut seq, mut heard, mut last_seen) = (0u64, 0u64, Instant::now());
    let mut safe = false;
    while Instant::now() < end && !stop.load(Ordering::Acquire) {
        std::thread::sleep(Duration::from_millis(5));
        let Some(status) = shared.bus.status(probe) else {
            continue;
        };
        if status.time != heard || status.seq != seq {
            heard = status.time;
            last_seen = Instant::now();
            if safe {
                safe = false;
                shared.org_mut().set_safe(false);
                shared.record(|s| {
                    s.diagnostic(clock(), crate::record::Level::Warning, "the Bulletinboard is back: safe mode ends")
                });
            }
        }
        // A change is a state other than the one followed: sequence numbers
        // start again with a restarted Bulletinboard, and a status missed
        // while reconnecting must not hide the next one.
        if status.seq != seq || status.state != shared.org().state() {
            seq = status.seq;
            let from = shared.org().state();
            if from != status.state {
                shared.org_mut().on_state(status.state);
                let change = StateChange { from, to: status.state, time: status.time, firings: Vec::new() };
                summary.add_steps(steps.swap(0, Ordering::Relaxed));
                summary.change(&change);
                on_change(&change);
                if config.stop_on_final && shared.content.states[status.state as usize].is_final {
                    stop.store(true, Ordering::Release);
                }
            }
        }
        if !safe && last_seen.elapsed() > config.safe_after {
            safe = true;
            shared.org_mut().set_safe(true);
            shared.record(|s| {
                s.diagnostic(
                    clock(),
                    crate::record::Level::Error,
                    "no status from the Bulletinboard: safe mode (every agent waits)",
                )
            });
        }
    }
}
