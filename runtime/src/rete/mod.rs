//! The Rete interpreter: the inference machine of the Bulletinboard.
//!
//! The working memory is the state fact and, per agent, its latest event
//! (payload, time, run length, posting sequence), or nothing, or "stale"
//! (language reference §10.2). Because each agent has at most one fact, each
//! alpha memory holds at most one fact and each beta memory at most one
//! token: memories are flags, and a token's facts are the agents' current
//! facts. What stays Rete is the propagation: a change of the memory touches
//! only the alpha nodes of the event concerned and the beta nodes below
//! them, in topological order, never the whole network.
//!
//! [`Engine::admit`] is the one acceptance rule of situ (§10.4): the
//! engine, `situ bench`, `situ test` and the running stack's Bulletinboard
//! all take or refuse an event by it. An event is refused, and changes
//! nothing, when its payload does not fit its event's fields, when it is
//! stamped before its agent's latest accepted event (out of order), or, when
//! the clock it arrives at is known ([`Engine::set_clock`]), when it is
//! stamped more than the skew bound ahead of that clock (from the future). NaN and the infinities are values
//! like any other (§10.3 says what they match).
//!
//! [`Engine::post`] processes one accepted event (§10.4):
//! 1. now = max(now, t); facts older than their agent's `stale after`
//!    expire and windows close; the network is brought to rest;
//! 2. the new fact replaces the agent's previous one; rest again.
//!
//! Rest: among the activated rules (conditions hold, target differs from the
//! state), fire the first by salience, specificity, recency, declaration
//! order; set the state; repeat. More than [`Engine::cascade_limit`] firings
//! for one event is a [`PostError::Cascade`].
//!
//! [`Engine::new`] runs this on the fast path (`fast.rs`): the same working
//! memory, acceptance rule, expiry and recording, with each rule's
//! conditions tested directly from candidate lists instead of through the
//! network's memories. [`Engine::interpreted`] runs the network, the
//! reference that `runtime-tests/tests/differential.rs` holds the fast path
//! to; a bundle the fast path declines ([`Engine::fast_declined`]) runs on
//! the network too.

mod admit;
mod eval;
mod fast;
mod infer;
pub mod native;
mod net;
mod network;
mod report;

use net::{Net, NONE};
use situ_bundle::{Content, Value};
use std::sync::Arc;

pub use eval::{compare, in_range, passes, passes_with};
pub use report::{
    describe_fact, format_time, show_value, FactView, Firing, MatchedFact, PostError, StateChange, StepError,
};

/// The default bound of a cascade (§10.4).
pub const CASCADE_LIMIT: usize = 64;

pub use fast::MAX_LIST_ENTRIES;

/// How far ahead of the Bulletinboard's clock an event may be stamped, by
/// default (ns): hosts kept in time by NTP on a local network agree within
/// a few milliseconds, and 50 ms is a sixth of a typical `stale after`
/// (300 ms), so that the events it lets through age the other facts by
/// little (§10.7).
pub const DEFAULT_MAX_SKEW: u64 = 50_000_000;

/// An agent's latest fact.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Slot {
    /// `NONE`: no fact (never reported, expired, or reset).
    event: u32,
    time: u64,
    run: u64,
    /// The posting sequence number (recency).
    seq: u64,
}

const EMPTY: Slot = Slot { event: NONE, time: 0, run: 0, seq: 0 };

/// An agent's part of the working memory, in one record (one address for
/// the insert and the conditions instead of one per table).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct AgentRec {
    slot: Slot,
    /// Its bit of `Engine::have`: its fact's (`fast::bit(slot.event)`), or
    /// on the fast path its stale bit while it is stale
    /// (`fast::Program::stale_bit`), or 0.
    bit: u64,
    /// Timers: the time its fact expires and the next window that closes
    /// (`u64::MAX`: none).
    stale_at: u64,
    window_at: u64,
    /// The fast path's now of its fact's last evaluation (`fast.rs`).
    checked: u64,
    /// The stamp of its latest accepted event (kept by a reset: an agent's
    /// clock does not go back with a new mission).
    last: u64,
    stale: bool,
}

const AGENT: AgentRec =
    AgentRec { slot: EMPTY, bit: 0, stale_at: u64::MAX, window_at: u64::MAX, checked: 0, last: 0, stale: false };

/// The Rete network of a bundle with its working memory.
#[derive(Debug, Clone)]
pub struct Engine {
    content: Arc<Content>,
    net: Net,
    // Working memory.
    state: u32,
    /// Per agent: its fact, staleness, clock and timers, in one record.
    agents: Vec<AgentRec>,
    payload: Vec<Value>,
    now: u64,
    seq: u64,
    max_skew: u64,
    /// The Bulletinboard's clock the next events arrive at (`None`: at
    /// their stamps).
    clock: Option<u64>,
    /// The earliest of the agents' timers, possibly too early.
    next_deadline: u64,
    // Network memories.
    alpha_mem: Vec<bool>,
    beta_tok: Vec<bool>,
    dirty: Vec<u64>,
    dirty_lo: usize,
    dirty_hi: usize,
    /// Activated rules, and each rule's position in it (`NONE`: not activated).
    active: Vec<u32>,
    active_pos: Vec<u32>,
    cascade_limit: usize,
    record: Record,
    /// The network's memories in the initial state with no facts, which a
    /// [`reset`](Self::reset) restores.
    initial: Arc<Memories>,
    // The fast path (`fast.rs`): whether it runs, its program (empty when
    // it does not), and the agents whose fact expiry changed since the
    // last rest.
    fast: bool,
    fp: Arc<fast::Program>,
    touched: Vec<u32>,
    declined: Option<&'static str>,
    /// The events (below 64) that are an agent's fact now, and the stale
    /// agents (`fast::Program::stale_bit`), as bits: the `bit`s of the
    /// agents' records, or'd; kept on the fast path only.
    have: u64,
    /// Native code that runs the steps (`native.rs`), on the fast path.
    native: Option<&'static native::Native>,
}

/// The memories of the network (alpha, beta, activated rules).
#[derive(Debug, Clone, Default)]
struct Memories {
    alpha_mem: Vec<bool>,
    beta_tok: Vec<bool>,
    active: Vec<u32>,
    active_pos: Vec<u32>,
}

impl Engine {
    /// The engine of a validated bundle, in its initial state with no
    /// facts, on the fast path (`fast.rs`) unless the fast path declines
    /// the bundle ([`fast_declined`](Self::fast_declined)): then the
    /// interpreter.
    pub fn new(content: Arc<Content>) -> Engine {
        Engine::build(content, true)
    }

    /// The engine of a validated bundle on the Rete interpreter, the
    /// reference the fast path is held to (`runtime-tests/tests/differential.rs`).
    pub fn interpreted(content: Arc<Content>) -> Engine {
        Engine::build(content, false)
    }

    /// Whether the engine runs on the fast path.
    pub fn is_fast(&self) -> bool {
        self.fast
    }

    /// Why the fast path declined the bundle, if it did (an engine built
    /// by [`interpreted`](Self::interpreted) was not offered it).
    pub fn fast_declined(&self) -> Option<&'static str> {
        self.declined
    }

    fn build(content: Arc<Content>, fast: bool) -> Engine {
        let net = Net::new(&content);
        let (fp, declined) = if fast {
            match fast::Program::new(&content, &net) {
                Ok(p) => (Some(p), None),
                Err(why) => (None, Some(why)),
            }
        } else {
            (None, None)
        };
        let na = content.agents.len();
        let nb = net.beta.len();
        let mut e = Engine {
            state: content.initial,
            agents: vec![AGENT; na],
            payload: vec![Value::Bool(false); net.payload_len],
            now: 0,
            seq: 0,
            max_skew: DEFAULT_MAX_SKEW,
            clock: None,
            next_deadline: u64::MAX,
            alpha_mem: vec![false; net.alpha.len()],
            beta_tok: vec![false; nb],
            dirty: vec![0; nb.div_ceil(64).max(1)],
            dirty_lo: usize::MAX,
            dirty_hi: 0,
            active: Vec::new(),
            active_pos: vec![NONE; content.rules.len()],
            cascade_limit: CASCADE_LIMIT,
            record: Record::default(),
            initial: Arc::default(),
            fast: fp.is_some(),
            fp: Arc::new(fp.unwrap_or_default()),
            touched: Vec::with_capacity(na),
            declined,
            have: 0,
            native: None,
            content,
            net,
        };
        e.recompute();
        if e.fast {
            e.fast_activate();
        }
        e.initial = Arc::new(Memories {
            alpha_mem: e.alpha_mem.clone(),
            beta_tok: e.beta_tok.clone(),
            active: e.active.clone(),
            active_pos: e.active_pos.clone(),
        });
        e
    }

    pub fn content(&self) -> &Arc<Content> {
        &self.content
    }

    /// The current state.
    pub fn state(&self) -> u32 {
        self.state
    }

    /// The largest timestamp seen.
    pub fn now(&self) -> u64 {
        self.now
    }

    /// The cascade bound (default [`CASCADE_LIMIT`]).
    pub fn cascade_limit(&self) -> usize {
        self.cascade_limit
    }

    pub fn set_cascade_limit(&mut self, limit: usize) {
        self.cascade_limit = limit.max(1);
    }

    /// An agent's live fact: event, payload, time, run length.
    pub fn fact(&self, agent: u32) -> Option<MatchedFact> {
        let slot = &self.agents.get(agent as usize)?.slot;
        (slot.event != NONE).then(|| self.snapshot(agent))
    }

    /// An agent's live fact without copying it: event, payload, time, run
    /// length and posting sequence number (recency).
    pub fn fact_view(&self, agent: u32) -> Option<FactView<'_>> {
        let slot = &self.agents.get(agent as usize)?.slot;
        if slot.event == NONE {
            return None;
        }
        let n = self.content.events.get(slot.event as usize).map_or(0, |e| e.fields.len());
        let at = self.net.payload_at[agent as usize] as usize;
        Some(FactView {
            event: slot.event,
            payload: &self.payload[at..at + n],
            time: slot.time,
            run: slot.run,
            seq: slot.seq,
        })
    }

    /// Makes `self` a copy of `other` (an engine of the same bundle),
    /// reusing `self`'s buffers: the explorer of `verify` copies an engine
    /// per successor it tries.
    pub fn copy_from(&mut self, other: &Engine) {
        if !Arc::ptr_eq(&self.content, &other.content)
            || self.fast != other.fast
            || self.native.map(|n| n as *const _) != other.native.map(|n| n as *const _)
        {
            *self = other.clone();
            return;
        }
        self.state = other.state;
        self.agents.clone_from(&other.agents);
        self.payload.clone_from(&other.payload);
        self.now = other.now;
        self.seq = other.seq;
        self.max_skew = other.max_skew;
        self.clock = other.clock;
        self.next_deadline = other.next_deadline;
        self.alpha_mem.clone_from(&other.alpha_mem);
        self.beta_tok.clone_from(&other.beta_tok);
        self.dirty.clone_from(&other.dirty);
        self.dirty_lo = other.dirty_lo;
        self.dirty_hi = other.dirty_hi;
        self.active.clone_from(&other.active);
        self.active_pos.clone_from(&other.active_pos);
        self.cascade_limit = other.cascade_limit;
        self.touched.clone_from(&other.touched);
        self.have = other.have;
    }

    /// Whether the agent's fact has expired.
    pub fn is_stale(&self, agent: u32) -> bool {
        self.agents.get(agent as usize).is_some_and(|r| r.stale)
    }

    /// The rules activated now (at rest: none), in no particular order
    /// (the fast path's in declaration order).
    pub fn activated(&self) -> &[u32] {
        &self.active
    }

    /// Back to the initial state with no facts; now, and each agent's
    /// latest accepted time, are kept (§10.12: a mission ends in a final
    /// state, the clocks go on). The network's memories are those of the
    /// initial state with no facts, which depend on nothing else: they are
    /// copied back from the engine's construction, not propagated (no
    /// allocation: the buffers keep their capacity).
    pub fn reset(&mut self) {
        for r in &mut self.agents {
            // The agent's clock and the now of its last evaluation are kept.
            *r = AgentRec { last: r.last, checked: r.checked, ..AGENT };
        }
        self.next_deadline = u64::MAX;
        self.state = self.content.initial;
        let m = &*self.initial;
        self.touched.clear();
        self.have = 0;
        if self.fast {
            // The fast path keeps no network memories: only the activated rules.
            self.active.clone_from(&m.active);
            return;
        }
        self.alpha_mem.copy_from_slice(&m.alpha_mem);
        self.beta_tok.copy_from_slice(&m.beta_tok);
        self.active.clone_from(&m.active);
        self.active_pos.copy_from_slice(&m.active_pos);
        self.dirty.fill(0);
        self.dirty_lo = usize::MAX;
        self.dirty_hi = 0;
    }

    /// Processes one event: expiry, rest, the new fact, rest. Returns the
    /// firings, if any rule fired.
    pub fn post(&mut self, event: u32, time: u64, payload: &[Value]) -> Result<Option<StateChange>, PostError> {
        let step = self.step(event, time, payload).map_err(|e| self.post_error(e))?;
        Ok((step.firings > 0).then(|| self.last_change()))
    }

    /// As [`post`](Self::post), without building the [`StateChange`]: no
    /// allocation once the engine has warmed up. [`last_change`](Self::last_change)
    /// gives the details of the latest step, [`post_error`](Self::post_error)
    /// those of an error.
    #[inline]
    pub fn step(&mut self, event: u32, time: u64, payload: &[Value]) -> Result<Step, StepError> {
        // Native code's step of the event (an event the bundle does not
        // have is refused below).
        if let Some(step) = self.native.and_then(|n| n.steps.get(event as usize)) {
            return step(self, time, payload);
        }
        self.admitted(event, time, payload)?;
        if self.fast {
            self.fast_accepted(event, time, payload)
        } else {
            self.accepted(event, time, payload)
        }
    }

    /// Processes an event that [`admit`](Self::admit) accepted.
    fn accepted(&mut self, event: u32, time: u64, payload: &[Value]) -> Result<Step, StepError> {
        self.begin();
        if time > self.now {
            self.now = time;
        }
        if self.now > self.next_deadline {
            self.expire();
        }
        if !self.at_rest() {
            self.rest()?;
        }
        self.insert(event, time, payload);
        if self.now > self.next_deadline {
            // The fact came late: it may be expired already.
            self.expire();
        }
        if !self.at_rest() {
            self.rest()?;
        }
        Ok(Step { from: self.record.from, to: self.state, firings: self.record.firings.len() })
    }

    /// Moves now forward without an event (the Bulletinboard's heartbeat):
    /// facts older than their `stale after` expire and windows close, and
    /// the network is brought to rest. A clock that never goes back.
    pub fn advance(&mut self, now: u64) -> Result<Option<StateChange>, PostError> {
        self.begin();
        if now > self.now {
            self.now = now;
        }
        if self.fast {
            if self.now > self.next_deadline {
                self.fast_expire();
            }
            if !self.active.is_empty() || !self.touched.is_empty() {
                self.fast_rest().map_err(|e| self.post_error(e))?;
            }
        } else {
            if self.now > self.next_deadline {
                self.expire();
            }
            if !self.at_rest() {
                self.rest().map_err(|e| self.post_error(e))?;
            }
        }
        Ok((!self.record.firings.is_empty()).then(|| self.last_change()))
    }

    /// Brings the network to rest without an event (e.g. at start, for
    /// rules that hold with no facts).
    pub fn settle(&mut self) -> Result<Option<StateChange>, PostError> {
        self.begin();
        if self.fast {
            self.fast_rest().map_err(|e| self.post_error(e))?;
        } else {
            self.rest().map_err(|e| self.post_error(e))?;
        }
        Ok((!self.record.firings.is_empty()).then(|| self.last_change()))
    }

    /// The details of an error of the latest step: a field's type, a
    /// cascade's firings (those recorded by the step).
    #[cold]
    pub fn post_error(&self, e: StepError) -> PostError {
        match e {
            StepError::UnknownEvent { event } => PostError::UnknownEvent { event },
            StepError::Arity { event, expected, found } => PostError::Arity { event, expected, found },
            StepError::Type { event, field } => {
                let expected = self.content.events[event as usize].fields[field as usize].ty.clone();
                PostError::Type { event, field, expected }
            }
            StepError::OutOfOrder { event, time, last } => PostError::OutOfOrder { event, time, last },
            StepError::FromTheFuture { event, time, clock, max_skew } => {
                PostError::FromTheFuture { event, time, clock, max_skew }
            }
            StepError::Cascade { limit } => PostError::Cascade { limit, firings: self.last_change().firings },
        }
    }

    /// What the latest step fired, with the facts that made each rule hold.
    pub fn last_change(&self) -> StateChange {
        let r = &self.record;
        let firings = r
            .firings
            .iter()
            .map(|f| Firing {
                rule: f.rule,
                from: f.from,
                to: f.to,
                time: f.time,
                matched: r.facts[f.facts.0 as usize..f.facts.1 as usize]
                    .iter()
                    .map(|m| MatchedFact {
                        agent: m.agent,
                        event: m.event,
                        payload: r.values[m.values.0 as usize..m.values.1 as usize].to_vec(),
                        time: m.time,
                        run: m.run,
                    })
                    .collect(),
                stale: r.stale[f.stale.0 as usize..f.stale.1 as usize].to_vec(),
            })
            .collect();
        StateChange { from: r.from, to: self.state, time: self.now, firings }
    }

    #[inline]
    fn begin(&mut self) {
        let r = &mut self.record;
        r.from = self.state;
        // Facts, values and stale agents are recorded with a firing only.
        if !r.firings.is_empty() {
            r.firings.clear();
            r.facts.clear();
            r.values.clear();
            r.stale.clear();
        }
    }

    /// Sets the state without firing rules (tests' `given`, hot swap).
    pub fn force_state(&mut self, state: u32) {
        if (state as usize) >= self.content.states.len() {
            return;
        }
        if self.fast {
            self.state = state;
            self.fast_activate();
        } else {
            self.set_state(state);
        }
    }

    /// Sets an agent's fact without firing rules (tests' `given`): the
    /// event at `time` with run length `run`; now advances to `time`.
    pub fn force_fact(&mut self, event: u32, time: u64, payload: &[Value], run: u64) -> Result<(), PostError> {
        self.validate(event, payload)?;
        self.now = self.now.max(time);
        if self.fast {
            let agent = self.content.events[event as usize].agent as usize;
            let last = self.agents[agent].last;
            self.fast_insert(event, time, payload);
            self.agents[agent].last = last.max(time);
            self.agents[agent].slot.run = run.max(1);
            // The fact's bits with its run length.
            let bit = self.fast_run_bits(event, run.max(1));
            self.have = (self.have & !self.agents[agent].bit) | bit;
            self.agents[agent].bit = bit;
            self.fast_activate();
            return Ok(());
        }
        self.insert(event, time, payload);
        let agent = self.content.events[event as usize].agent as usize;
        self.agents[agent].slot.run = run.max(1);
        self.refresh_alpha(agent as u32);
        self.propagate();
        Ok(())
    }

    /// Moves now forward to `now` (a carried-over clock, at hot swap).
    pub fn advance_clock(&mut self, now: u64) {
        self.now = self.now.max(now);
    }

    /// Marks an agent stale without firing rules (its fact, if any, is gone).
    pub fn force_stale(&mut self, agent: u32) {
        let a = agent as usize;
        if a >= self.agents.len() {
            return;
        }
        if self.fast {
            let sb = self.fp.stale_bit[a];
            self.have = (self.have & !self.agents[a].bit) | sb;
            self.agents[a].slot = EMPTY;
            self.agents[a].bit = sb;
            self.agents[a].stale = true;
            self.agents[a].stale_at = u64::MAX;
            self.agents[a].window_at = u64::MAX;
            self.fast_activate();
            return;
        }
        let old = self.agents[a].slot.event;
        if old != NONE {
            self.clear_event_alpha(old);
        }
        self.agents[a].slot = EMPTY;
        self.agents[a].bit = 0;
        self.agents[a].stale = true;
        self.agents[a].stale_at = u64::MAX;
        self.agents[a].window_at = u64::MAX;
        self.set_stale_alpha(agent, true);
        self.propagate();
    }

    // ─── Working memory ────────────────────────────────────────────────

    fn snapshot(&self, agent: u32) -> MatchedFact {
        let slot = self.agents[agent as usize].slot;
        let n = self.content.events.get(slot.event as usize).map_or(0, |e| e.fields.len());
        let at = self.net.payload_at[agent as usize] as usize;
        MatchedFact {
            agent,
            event: slot.event,
            payload: self.payload[at..at + n].to_vec(),
            time: slot.time,
            run: slot.run,
        }
    }

    /// Replaces the agent's fact and updates its alpha memories (no propagation).
    #[inline(always)]
    fn insert(&mut self, event: u32, time: u64, payload: &[Value]) {
        let ev = self.net.event[event as usize];
        let agent = ev.agent;
        let a = agent as usize;
        let old = self.agents[a].slot;
        self.seq += 1;
        let run = if old.event == event { old.run + 1 } else { 1 };
        self.agents[a].slot = Slot { event, time, run, seq: self.seq };
        self.agents[a].bit = ev.bit;
        self.agents[a].last = self.agents[a].last.max(time);
        copy_payload(&mut self.payload[ev.payload_at as usize..], payload);
        if self.agents[a].stale {
            self.agents[a].stale = false;
            self.set_stale_alpha(agent, false);
        }
        if old.event != NONE && old.event != event {
            self.clear_event_alpha(old.event);
        }
        self.eval_event_alpha(ev.alpha);
        // Timers.
        let stale_at = if ev.stale_after == u64::MAX { u64::MAX } else { time.saturating_add(ev.stale_after) };
        let window_at = self.next_window(ev.windows, time);
        self.agents[a].stale_at = stale_at;
        self.agents[a].window_at = window_at;
        self.next_deadline = self.next_deadline.min(stale_at).min(window_at);
    }

    /// When the next window of a fact reported at `time` closes, its
    /// event's windows being `windows` (in `net.windows`): `time + w` for
    /// the smallest window `w` still open (`u64::MAX`: none).
    #[inline]
    fn next_window(&self, windows: (u32, u32), time: u64) -> u64 {
        let (s, e) = windows;
        if s == e {
            return u64::MAX;
        }
        self.net.windows[s as usize..e as usize]
            .iter()
            .map(|w| time.saturating_add(*w))
            .find(|&deadline| deadline >= self.now)
            .unwrap_or(u64::MAX)
    }

    /// Expires facts and closes windows whose time has passed.
    fn expire(&mut self) {
        let mut next = u64::MAX;
        for i in 0..self.net.timed_agents.len() {
            let a = self.net.timed_agents[i] as usize;
            if self.agents[a].stale_at < self.now {
                // `now - t > stale after`: the fact expires.
                let old = self.agents[a].slot.event;
                self.agents[a].slot = EMPTY;
                self.agents[a].bit = 0;
                self.clear_event_alpha(old);
                self.agents[a].stale = true;
                self.set_stale_alpha(a as u32, true);
                self.agents[a].stale_at = u64::MAX;
                self.agents[a].window_at = u64::MAX;
            } else if self.agents[a].window_at < self.now {
                self.refresh_alpha(a as u32);
                let slot = self.agents[a].slot;
                self.agents[a].window_at = self.next_window(self.net.event[slot.event as usize].windows, slot.time);
            }
            next = next.min(self.agents[a].stale_at).min(self.agents[a].window_at);
        }
        self.next_deadline = next;
    }
}

/// Copies an event's payload into its agent's place in the arena
/// (`dst` starts there and is at least as long); the usual zero, one or two
/// values without a call to `memcpy`.
#[inline(always)]
fn copy_payload(dst: &mut [Value], src: &[Value]) {
    match (src, dst) {
        ([], _) => {}
        ([x], [d, ..]) => *d = *x,
        ([x, y], [d, e, ..]) => {
            *d = *x;
            *e = *y;
        }
        (src, dst) => dst[..src.len()].copy_from_slice(src),
    }
}

/// What a step did, in short.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    /// The state at rest before, and after.
    pub from: u32,
    pub to: u32,
    /// How many rules fired.
    pub firings: usize,
}

/// The firings of the latest step, in buffers reused from step to step.
#[derive(Debug, Clone, Default)]
struct Record {
    from: u32,
    firings: Vec<FiringRec>,
    facts: Vec<FactRec>,
    values: Vec<Value>,
    stale: Vec<u32>,
}

#[derive(Debug, Clone, Copy)]
struct FiringRec {
    rule: u32,
    from: u32,
    to: u32,
    time: u64,
    facts: (u32, u32),
    stale: (u32, u32),
}

#[derive(Debug, Clone, Copy)]
struct FactRec {
    agent: u32,
    event: u32,
    time: u64,
    run: u64,
    values: (u32, u32),
}
