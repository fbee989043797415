//! Running the agents of a stack: agents stepping through their running cycle, and the
//! Bulletinboard turning their events into the state it broadcasts. The
//! pieces here are shared by the simulated-time scheduler (one thread,
//! deterministic) and the real-time one (a thread per agent):
//!
//! - [`Shared`]: the bundle, the organisation of the moment (the state at
//!   rest, each agent's table or FSM state), the bus and the recorder;
//! - [`AgentRunner`]: one agent's running cycle;
//! - [`BoardRunner`]: the Bulletinboard's events monitor: it checks every
//!   event (refusing, counting and recording the bad ones), lets the FSMs
//!   see their agents' events, posts to the engine, and broadcasts each new
//!   state at rest.

use crate::agent::{Agent, Context, Datum, Outgoing, Report};
use crate::bulletinboard::Bulletinboard;
use crate::bus::{Bus, DataMsg, EventMsg, StatusMsg};
use crate::organise::Organisation;
use crate::record::{DataRecord, EventRecord, Fate, Level, ModeRecord, Sink, Verdict};
use crate::rete::{PostError, StateChange};
use crate::standby::{Entry, LogOut};
use situ_bundle::{Content, Mode, Value};
use std::collections::BTreeMap;
use std::sync::{Arc, Mutex, RwLock};

/// What every part of a running stack shares.
pub struct Shared {
    pub content: Arc<Content>,
    pub org: RwLock<Organisation>,
    pub bus: Arc<dyn Bus>,
    pub sink: Mutex<Option<Box<dyn Sink>>>,
    /// Whether there is a sink (checked before building records).
    pub recording: bool,
    /// The Bulletinboard is in another process: the FSMs of this process's
    /// agents follow their own events here.
    pub remote_board: bool,
}

impl Shared {
    pub fn new(content: Arc<Content>, bus: Arc<dyn Bus>, sink: Option<Box<dyn Sink>>) -> Shared {
        let recording = sink.is_some();
        Shared {
            org: RwLock::new(Organisation::new(content.clone())),
            content,
            bus,
            sink: Mutex::new(sink),
            recording,
            remote_board: false,
        }
    }

    pub fn org(&self) -> std::sync::RwLockReadGuard<'_, Organisation> {
        self.org.read().unwrap_or_else(|p| p.into_inner())
    }

    pub fn org_mut(&self) -> std::sync::RwLockWriteGuard<'_, Organisation> {
        self.org.write().unwrap_or_else(|p| p.into_inner())
    }

    /// Calls the recorder, if there is one.
    pub fn record(&self, f: impl FnOnce(&mut dyn Sink)) {
        if let Some(sink) = self.sink.lock().unwrap_or_else(|p| p.into_inner()).as_mut() {
            f(sink.as_mut());
        }
    }

    /// Who gets a datum `from` sends now: the agents it sends to, and the
    /// running agents that read from it (§10.6, the wiring of the moment).
    pub fn receivers(&self, org: &Organisation, from: u32) -> Vec<u32> {
        let mut out = Vec::new();
        self.receivers_into(org, from, &mut out);
        out
    }

    /// As [`receivers`](Self::receivers), into a buffer.
    pub fn receivers_into(&self, org: &Organisation, from: u32, out: &mut Vec<u32>) {
        out.clear();
        if let Some(a) = org.action(from).filter(|_| org.mode(from) == Mode::Running) {
            out.extend_from_slice(&a.to);
        }
        for y in 0..self.content.agents.len() as u32 {
            if y != from && org.mode(y) == Mode::Running && org.action(y).is_some_and(|a| a.from.contains(&from)) {
                out.push(y);
            }
        }
        out.sort_unstable();
        out.dedup();
    }
}

/// What one agent did over a run.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
pub struct AgentCounters {
    pub steps: u64,
    pub data_in: u64,
    pub data_out: u64,
    /// Its data outputs while waiting (dropped).
    pub suppressed: u64,
    /// Its data to sleeping agents, or to agents it has no link to (dropped).
    pub undelivered: u64,
    /// Data queued for it while it slept, dropped when it woke.
    pub stale_inputs: u64,
    pub events: u64,
    /// Reports of events that are not its own (refused before the bus).
    pub bad_reports: u64,
}

/// One agent and its running cycle.
pub struct AgentRunner {
    pub id: u32,
    imp: Box<dyn Agent>,
    pub counters: AgentCounters,
    msgs: Vec<DataMsg>,
    inputs: Vec<Datum>,
    outputs: Vec<Outgoing>,
    reports: Vec<Report>,
    receivers: Vec<u32>,
}

/// What a cycle produced that a scheduler cares about.
#[derive(Debug, Default)]
pub struct Cycle {
    /// Whether the agent was stepped (not sleeping).
    pub stepped: bool,
    /// Agents that received an urgent datum.
    pub urgent_to: Vec<u32>,
    /// Agents that received any datum.
    pub data_to: Vec<u32>,
    /// Whether it reported events.
    pub reported: bool,
}

impl AgentRunner {
    pub fn new(id: u32, imp: Box<dyn Agent>) -> AgentRunner {
        AgentRunner {
            id,
            imp,
            counters: AgentCounters::default(),
            msgs: Vec::new(),
            inputs: Vec::new(),
            outputs: Vec::new(),
            reports: Vec::new(),
            receivers: Vec::new(),
        }
    }

    /// One running cycle at `now`: status → table/FSM → mode and function →
    /// inputs of the active links → step → outputs along the active links →
    /// events to the Bulletinboard. A sleeping agent is not stepped.
    pub fn cycle(&mut self, shared: &Shared, now: u64) -> Cycle {
        let mut out = Cycle::default();
        let content = &*shared.content;
        let (state, mode, function, safe) = {
            let org = shared.org();
            (org.state(), org.mode(self.id), org.action(self.id).and_then(|a| a.function), org.safe())
        };
        if mode == Mode::Sleeping {
            self.counters.stale_inputs += shared.bus.discard_data(self.id) as u64;
            return out;
        }
        self.msgs.clear();
        shared.bus.recv_data(self.id, &mut self.msgs);
        self.inputs.clear();
        self.inputs.extend(self.msgs.drain(..).map(|m| Datum {
            from: m.from,
            time: m.time,
            urgent: m.urgent,
            body: m.body,
        }));
        self.counters.data_in += self.inputs.len() as u64;
        self.outputs.clear();
        self.reports.clear();
        let def = &content.agents[self.id as usize];
        let function_name = function.and_then(|f| def.functions.get(f as usize)).map(|f| f.name.as_str());
        if mode == Mode::Running {
            shared.receivers_into(&shared.org(), self.id, &mut self.receivers);
        } else {
            self.receivers.clear();
        }
        {
            let mut cx = Context {
                receivers: &self.receivers,
                content,
                agent: self.id,
                now,
                state,
                mode,
                safe,
                function: function_name,
                inputs: &self.inputs,
                outputs: &mut self.outputs,
                reports: &mut self.reports,
            };
            self.imp.step(&mut cx);
        }
        self.counters.steps += 1;
        out.stepped = true;
        // Data along the links of the moment.
        if !self.outputs.is_empty() {
            let org = shared.org();
            shared.receivers_into(&org, self.id, &mut self.receivers);
            let mut outputs = std::mem::take(&mut self.outputs);
            for o in outputs.drain(..) {
                let single = [o.to.unwrap_or(u32::MAX)];
                let targets: &[u32] = match o.to {
                    None => &self.receivers,
                    Some(t) if self.receivers.contains(&t) => &single,
                    Some(_) => &[],
                };
                if mode == Mode::Waiting || targets.is_empty() {
                    let fate = if mode == Mode::Waiting { Fate::Suppressed } else { Fate::Unrouted };
                    match fate {
                        Fate::Suppressed => self.counters.suppressed += 1,
                        _ => self.counters.undelivered += 1,
                    }
                    if shared.recording {
                        let rec = DataRecord {
                            time: now,
                            from: self.id,
                            to: u32::MAX,
                            urgent: o.urgent,
                            size: o.body.size(),
                            fate,
                        };
                        shared.record(|s| s.data(&rec));
                    }
                    continue;
                }
                for &to in targets {
                    let fate = if org.mode(to) == Mode::Sleeping { Fate::ToSleeping } else { Fate::Delivered };
                    if shared.recording {
                        let rec =
                            DataRecord { time: now, from: self.id, to, urgent: o.urgent, size: o.body.size(), fate };
                        shared.record(|s| s.data(&rec));
                    }
                    if fate == Fate::ToSleeping {
                        self.counters.undelivered += 1;
                        continue;
                    }
                    self.counters.data_out += 1;
                    if o.urgent {
                        out.urgent_to.push(to);
                    }
                    out.data_to.push(to);
                    shared.bus.send_data(DataMsg {
                        from: self.id,
                        to,
                        time: now,
                        urgent: o.urgent,
                        body: o.body.clone(),
                    });
                }
            }
            self.outputs = outputs;
        }
        // Events to the Bulletinboard (running or waiting).
        for r in self.reports.drain(..) {
            self.counters.events += 1;
            out.reported = true;
            if shared.remote_board {
                shared.org_mut().on_event(self.id, r.event);
            }
            shared.bus.send_event(EventMsg {
                agent: self.id,
                event: r.event,
                time: now,
                payload: r.payload,
                urgent: r.urgent,
            });
        }
        out
    }
}

/// What the Bulletinboard did over a run.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct BoardCounters {
    pub accepted: u64,
    /// Refused events, by reason.
    pub refused: BTreeMap<String, u64>,
    /// Events lost to a full queue (told by the bus).
    pub lost: u64,
    pub firings: u64,
    pub changes: u64,
    pub status_sent: u64,
    pub cascade_errors: u64,
    /// Rules fired, by name.
    pub fired: BTreeMap<String, u64>,
}

/// How far ahead of the Bulletinboard's clock an event may be stamped, by
/// default (ns): the engine's acceptance rule ([`Engine::admit`]) holds it.
///
/// [`Engine::admit`]: crate::rete::Engine::admit
pub use crate::rete::DEFAULT_MAX_SKEW;

/// The events monitor of the Bulletinboard.
pub struct BoardRunner {
    pub board: Bulletinboard,
    pub counters: BoardCounters,
    /// A heartbeat that moved the clock without a change and is not yet in
    /// the recording: written before the next accepted event stamped
    /// earlier than it, so that a replay's clock is where the board's was.
    pending_tick: Option<u64>,
    events: Vec<EventMsg>,
    /// The `BUSOVF` event, if the rules declare it.
    overflow_event: Option<u32>,
    status_seq: u64,
    /// The modes last recorded, per agent.
    modes: Vec<Option<(Mode, Option<u32>)>>,
    /// Where the log goes (a journal, the followers), if anywhere; and the
    /// entries not yet written there.
    out: Option<Box<dyn LogOut>>,
    log: Vec<Entry>,
}

impl BoardRunner {
    pub fn new(content: Arc<Content>) -> BoardRunner {
        let overflow_event = content.event_id("BUSOVF");
        BoardRunner {
            pending_tick: None,
            modes: vec![None; content.agents.len()],
            board: Bulletinboard::new(content),
            counters: BoardCounters::default(),
            events: Vec::new(),
            overflow_event,
            status_seq: 0,
            out: None,
            log: Vec::new(),
        }
    }

    /// Writes the log to `out` from now on (a journal, the followers), or
    /// nowhere with `None`; entries not yet written are written first.
    pub fn set_log_out(&mut self, out: Option<Box<dyn LogOut>>) {
        self.flush_log(false);
        self.out = out;
    }

    /// Writes the entries taken since the last call to the log's output;
    /// `change`: a change of state is about to be broadcast after them.
    pub fn flush_log(&mut self, change: bool) {
        match &mut self.out {
            Some(out) => out.write(&mut self.log, change),
            None => self.log.clear(),
        }
    }

    /// Keeps an entry for the log's output, when there is one.
    fn logged(&mut self, entry: impl FnOnce() -> Entry) {
        if self.out.is_some() {
            self.log.push(entry());
        }
    }

    /// Broadcasts the state at rest as a new status (a board that has just
    /// taken over says so at once).
    pub fn announce(&mut self, shared: &Shared, now: u64) {
        self.broadcast(shared, now);
    }

    /// Forgets the state, the facts and the log not yet written, as a board
    /// that has just started (the FSMs too), and broadcasts the initial
    /// status here: a follower that starts again from the leader's log.
    pub fn start_again(&mut self, shared: &Shared, now: u64) {
        let skew = self.board.engine().max_skew();
        self.board = Bulletinboard::new(self.board.content().clone());
        self.board.set_max_skew(skew);
        self.pending_tick = None;
        self.status_seq = 0;
        self.log.clear();
        self.modes.fill(None);
        shared.org_mut().reset();
        self.start(shared, now);
    }

    /// The sequence number of the latest status broadcast.
    pub fn status_seq(&self) -> u64 {
        self.status_seq
    }

    /// Applies an entry of the leading board's log (a follower, or a
    /// journal read back): the same steps as the leader took, so the same
    /// state, facts and FSM states; the changes are broadcast to this
    /// process's agents as the leader's were to all. Returns the change.
    pub fn apply(&mut self, shared: &Shared, entry: &Entry) -> Option<StateChange> {
        self.pending_tick = None;
        match entry {
            Entry::Tick { time } => {
                self.logged(|| entry.clone());
                shared.record(|s| s.tick(*time));
                match self.board.advance(*time) {
                    Ok(Some(change)) => {
                        self.after(shared, &change, *time);
                        change.changed().then_some(change)
                    }
                    Ok(None) => None,
                    Err(e) => {
                        self.cascade(shared, &e, *time);
                        None
                    }
                }
            }
            Entry::Event { msg, accepted: false } => {
                self.logged(|| entry.clone());
                *self.counters.refused.entry("leader".into()).or_default() += 1;
                let rec = record_of(msg, Verdict::Refused("refused by the leading Bulletinboard".into()));
                shared.record(|s| s.event(&rec));
                None
            }
            Entry::Event { msg, accepted: true } => self.accept(shared, msg, msg.time),
        }
    }

    /// How far ahead of the Bulletinboard's clock (the `now` of
    /// [`pump`](Self::pump)) an event may be stamped; further is refused.
    pub fn set_max_skew(&mut self, ns: u64) {
        self.board.set_max_skew(ns);
    }

    /// Broadcasts the initial status and records the initial modes.
    pub fn start(&mut self, shared: &Shared, now: u64) {
        self.broadcast(shared, now);
    }

    /// A new mission (a `--random` run's next episode, after a final
    /// state): the working memory goes back to the initial state with no
    /// facts, as `situ bench`'s reset (now and each agent's latest stamp
    /// are kept), the FSMs to their initial states, and the initial status
    /// is broadcast. The change (no rule fired it) is recorded and
    /// returned, if the state was not already the initial one.
    pub fn restart(&mut self, shared: &Shared, now: u64) -> Option<StateChange> {
        let from = self.board.state();
        self.board.reset();
        shared.org_mut().reset();
        let change = StateChange { from, to: self.board.state(), time: now, firings: Vec::new() };
        shared.record(|s| s.change(&change));
        if !change.changed() {
            return None;
        }
        self.counters.changes += 1;
        self.broadcast(shared, now);
        Some(change)
    }

    /// Repeats the current status, unchanged (same sequence number), with
    /// the time of now: agents in other processes know the Bulletinboard
    /// is alive.
    pub fn reassure(&mut self, shared: &Shared, now: u64) {
        shared.bus.send_status(StatusMsg { state: self.board.state(), time: now, seq: self.status_seq });
    }

    /// Takes every queued event, in order (urgent first); returns the
    /// changes of the state at rest it broadcast.
    pub fn pump(&mut self, shared: &Shared, now: u64) -> Vec<StateChange> {
        let mut changes = Vec::new();
        self.events.clear();
        let lost = shared.bus.recv_events(&mut self.events);
        if lost > 0 {
            self.counters.lost += lost;
            let text = format!("{lost} event(s) lost: the Bulletinboard's queue was full");
            shared.record(|s| s.diagnostic(now, Level::Error, &text));
            if let Some(ev) = self.overflow_event {
                let payload = self.overflow_payload(&shared.content, ev, lost);
                let agent = shared.content.events[ev as usize].agent;
                self.events.insert(0, EventMsg { agent, event: ev, time: now, payload, urgent: true });
            }
        }
        let events = std::mem::take(&mut self.events);
        changes.extend(self.take_events(shared, &events, now));
        self.events = events;
        changes
    }

    /// Takes `events` in their order, as [`pump`](Self::pump) takes the
    /// queue's (a board that has just taken over takes the events no
    /// leader sequenced this way, before the queue); returns the changes.
    pub fn take_events(&mut self, shared: &Shared, events: &[EventMsg], now: u64) -> Vec<StateChange> {
        events.iter().filter_map(|msg| self.take(shared, msg, now)).collect()
    }

    /// The heartbeat: the clock moves to `now` without an event, so that a
    /// silent agent's fact expires within one period.
    pub fn tick(&mut self, shared: &Shared, now: u64) -> Option<StateChange> {
        match self.board.advance(now) {
            Ok(Some(change)) => {
                self.pending_tick = None;
                self.logged(|| Entry::Tick { time: now });
                shared.record(|s| s.tick(now));
                self.after(shared, &change, now);
                change.changed().then_some(change)
            }
            Ok(None) => {
                self.pending_tick = Some(now);
                None
            }
            Err(e) => {
                self.cascade(shared, &e, now);
                None
            }
        }
    }

    fn overflow_payload(&self, c: &Content, ev: u32, lost: u64) -> Vec<Value> {
        c.events[ev as usize]
            .fields
            .iter()
            .map(|f| match f.ty {
                situ_bundle::FieldType::I64 => Value::I64(lost.min(i64::MAX as u64) as i64),
                situ_bundle::FieldType::F64 => Value::F64(lost as f64),
                situ_bundle::FieldType::Bool => Value::Bool(true),
                situ_bundle::FieldType::Symbols(_) => Value::Symbol(0),
            })
            .collect()
    }

    /// Why an event is refused, if it is; `now` is the Bulletinboard's clock.
    /// Beyond the bus's own check (an agent reports only its own events),
    /// the engine's acceptance rule decides ([`Engine::admit`]: the payload's
    /// fields, out of order, from the future), so that a running stack takes
    /// exactly the events that `situ bench` and `situ test` take.
    ///
    /// [`Engine::admit`]: crate::rete::Engine::admit
    fn check(&mut self, c: &Content, msg: &EventMsg, now: u64) -> Option<PostError> {
        let Some(def) = c.events.get(msg.event as usize) else {
            return Some(PostError::UnknownEvent { event: msg.event });
        };
        if def.agent != msg.agent {
            return Some(PostError::AnotherAgent { event: msg.event, agent: msg.agent });
        }
        self.board.set_clock(now);
        self.board.engine().admit(msg.event, msg.time, &msg.payload).err()
    }

    fn take(&mut self, shared: &Shared, msg: &EventMsg, now: u64) -> Option<StateChange> {
        let c = shared.content.clone();
        if let Some(error) = self.check(&c, msg, now) {
            let key = error.key().to_string();
            let reason = error.describe(&c);
            *self.counters.refused.entry(key).or_default() += 1;
            self.logged(|| Entry::Event { msg: msg.clone(), accepted: false });
            let rec = record_of(msg, Verdict::Refused(reason.clone()));
            shared.record(|s| {
                s.event(&rec);
                s.diagnostic(msg.time, Level::Warning, &format!("event refused: {reason}"));
            });
            return None;
        }
        // An event that arrives after a heartbeat but is stamped before it
        // (real time: it was on its way) changes the state at the board's
        // clock, not at its stamp: the recording says where the clock was.
        if let Some(t) = self.pending_tick.take().filter(|&t| msg.time < t) {
            self.logged(|| Entry::Tick { time: t });
            shared.record(|s| s.tick(t));
        }
        self.accept(shared, msg, now)
    }

    /// Takes an accepted event (`clock`: the board's clock it arrived at).
    fn accept(&mut self, shared: &Shared, msg: &EventMsg, clock: u64) -> Option<StateChange> {
        self.counters.accepted += 1;
        self.logged(|| Entry::Event { msg: msg.clone(), accepted: true });
        let rec = record_of(msg, Verdict::Accepted);
        shared.record(|s| s.event(&rec));
        // The agent's FSM sees its own event before the Bulletinboard's rest.
        let moved = shared.org_mut().on_event(msg.agent, msg.event);
        if moved.is_some() {
            self.record_modes(shared, msg.time);
        }
        match self.board.post_at(clock, msg.event, msg.time, &msg.payload) {
            Ok(Some(change)) => {
                self.after(shared, &change, msg.time);
                change.changed().then_some(change)
            }
            Ok(None) => None,
            Err(e) => {
                self.cascade(shared, &e, msg.time);
                None
            }
        }
    }

    fn after(&mut self, shared: &Shared, change: &StateChange, now: u64) {
        self.counters.firings += change.firings.len() as u64;
        for f in &change.firings {
            *self.counters.fired.entry(shared.content.rules[f.rule as usize].name.clone()).or_default() += 1;
        }
        shared.record(|s| s.change(change));
        if change.changed() {
            self.counters.changes += 1;
            shared.org_mut().on_state(change.to);
            self.broadcast(shared, now);
        }
    }

    fn cascade(&mut self, shared: &Shared, e: &PostError, now: u64) {
        self.counters.cascade_errors += 1;
        let text = e.describe(&shared.content);
        shared.record(|s| s.diagnostic(now, Level::Error, &text));
        // The state reached is broadcast: the agents follow the Bulletinboard.
        if shared.org().state() != self.board.state() {
            let state = self.board.state();
            shared.org_mut().on_state(state);
            self.broadcast(shared, now);
        }
    }

    fn broadcast(&mut self, shared: &Shared, now: u64) {
        // What led to the change is safe (journaled, replicated) before the
        // change is said.
        self.flush_log(true);
        self.status_seq += 1;
        self.counters.status_sent += 1;
        shared.bus.send_status(StatusMsg { state: self.board.state(), time: now, seq: self.status_seq });
        self.record_modes(shared, now);
    }

    /// Records the agents whose mode or function changed.
    fn record_modes(&mut self, shared: &Shared, now: u64) {
        let org = shared.org();
        let mut recs = Vec::new();
        for a in 0..shared.content.agents.len() as u32 {
            let action = org.action(a);
            let now_mode = (action.map_or(Mode::Sleeping, |x| x.mode), action.and_then(|x| x.function));
            if self.modes[a as usize] != Some(now_mode) {
                self.modes[a as usize] = Some(now_mode);
                if now_mode.0 == Mode::Sleeping {
                    // Whatever it had not read is gone: when it wakes, it
                    // gets only what arrives after.
                    shared.bus.discard_data(a);
                }
                recs.push(ModeRecord {
                    time: now,
                    agent: a,
                    state: org.state(),
                    mode: now_mode.0,
                    function: org.function(a).map(str::to_string),
                });
            }
        }
        drop(org);
        shared.record(|s| recs.iter().for_each(|r| s.mode(r)));
    }
}

/// The record of an event the Bulletinboard received, with what became of it.
fn record_of(msg: &EventMsg, verdict: Verdict) -> EventRecord {
    EventRecord {
        time: msg.time,
        agent: msg.agent,
        event: msg.event,
        payload: msg.payload.clone(),
        urgent: msg.urgent,
        verdict,
    }
}
