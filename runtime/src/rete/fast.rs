//! The fast path: the same engine as the interpreter, the rules tested
//! directly instead of through the network's memories.
//!
//! Each agent has at most one fact, so whether a rule is activated is a
//! function of the working memory alone: the state, each agent's slot
//! (event, run length, payload), its stale flag, and, for a window, the
//! time at which its agent's fact was last evaluated (below). The
//! interpreter keeps that function's value in the network's memories and
//! updates it by propagation; the fast path evaluates it, and only where it
//! can have become true:
//! - at rest no rule is activated (that is what rest is);
//! - after agent `a`'s fact becomes an event `e` (a post): the rules that
//!   can be activated in the state, read `a`, and have no condition on `a`
//!   that `e` makes false (a positive pattern of another event of `a`, a
//!   positive `stale a`): `by_event[state][e]`;
//! - after `a`'s fact expires or one of its windows closes: the rules that
//!   can be activated in the state and read `a`: `by_agent[state][a]`;
//! - after a firing sets the state `s`: every rule that can be activated in
//!   `s`, `by_state[s]`;
//! - out of rest (a new engine, a `force_*`, a cascade error): the
//!   activated rules are computed whole into `Engine::active`, which is then
//!   not empty, and the next rest starts from `by_state[state]`.
//!
//! Each list is in the order rules fire in (salience, then specificity,
//! descending, then declaration order), so that the search for the rule
//! that fires first stops after the first group of equal salience and
//! specificity that has an activated rule (recency decides within it, then
//! declaration order: the interpreter's `best`).
//!
//! A rule is flattened from its chain of beta nodes: its state guards (the
//! guard minus its target) become the states whose lists hold it; every
//! other node is a [`Cond`]: an agent's event, run length, window and tests
//! (alpha and join tests together, every field resolved to its place in the
//! payload arena, as the interpreter reads it), or its staleness, either of
//! them negated. The working memory is also held as bits
//! ([`Engine::have`]: each agent's fact's event, the run-length thresholds
//! it reaches, a stale agent): a rule is first tested by
//! `have & mask == need`, and a condition its bit decides whole (no window,
//! no tests) is not among its conditions. Firings are recorded as the
//! interpreter's `record_firing` records them (`fast_record`, from the
//! program's per-rule tables), so that steps, recorded firings and
//! explanations are the same. A bundle is declined (the interpreter runs it) only if a state
//! or staleness node carries join tests (the compiler writes none), if its
//! lists would exceed [`MAX_LIST_ENTRIES`], or if an index of its network
//! is out of range (`Program::check`; a validated bundle has none).
//!
//! Windows: the interpreter evaluates an event alpha node's window when its
//! fact is inserted and when expiry refreshes it; in between, now may pass
//! a deadline without expiry (`advance_clock`, `force_fact`, then
//! `settle`), and the network's memory keeps the earlier value. The fast
//! path therefore tests a window against `Engine::checked[a]`, the now of
//! the agent's last evaluation, which equals now whenever expiry is due
//! on no deadline.

mod build;

use super::eval::{compare, float, in_range};
use super::net::NONE;
use super::{copy_payload, AgentRec, Engine, Slot, Step, StepError, AGENT};
use situ_bundle::{Cmp, Value};

/// The most entries the candidate lists of a bundle may take (u32 each):
/// beyond, the bundle is declined and the interpreter runs it.
pub const MAX_LIST_ENTRIES: usize = 1 << 22;

/// The largest run-length threshold that gets a bit of its own.
const MAX_RUN_BIT: u64 = 64;

/// `Cond::event` of a staleness test.
pub(in crate::rete) const STALE: u32 = u32::MAX - 1;

/// An operand: a constant, or a place in the payload arena.
#[derive(Debug, Clone, Copy)]
pub enum Arg {
    Value(Value),
    At(u32),
}

#[derive(Debug, Clone, Copy)]
pub(in crate::rete) enum Check2 {
    Compare { op: Cmp, rhs: Arg },
    Range { lo: Arg, hi: Arg, inclusive: bool },
}

/// A test of the payload value at a place `x` of the arena. A float field
/// against float constants, the usual test, has its own shape (the field's
/// type is known from its event; a value of another type, which the
/// payload check keeps out, would go to `compare` all the same).
#[derive(Debug, Clone, Copy)]
pub(in crate::rete) enum Test {
    F64 { x: u32, op: Cmp, c: f64 },
    F64Range { x: u32, lo: f64, hi: f64, inclusive: bool },
    Any { x: u32, check: Check2 },
}

/// One condition of a rule on one agent's fact.
#[derive(Debug, Clone, Copy)]
pub(in crate::rete) struct Cond {
    pub(in crate::rete) agent: u32,
    /// The event its fact must be, or `STALE`: the agent must be stale.
    pub(in crate::rete) event: u32,
    pub(in crate::rete) negative: bool,
    pub(in crate::rete) min_run: u64,
    /// The window, ns (`u64::MAX`: none).
    pub(in crate::rete) within: u64,
    /// Its tests, in `Program::tests`.
    pub(in crate::rete) tests: (u32, u32),
}

#[derive(Debug, Clone, Copy)]
pub(in crate::rete) struct Rule {
    /// Its conditions, in `Program::conds`, in the chain's order.
    pub(in crate::rete) conds: (u32, u32),
    /// The rank of its (salience, specificity) among the rules': a larger
    /// one fires first.
    pub(in crate::rete) group: u32,
    /// The bits of [`Engine::have`] its conditions read (`mask`) and the
    /// values they need (`need`): an event's bit (below 64) set for a
    /// positive pattern of it, a stale agent's bit set for a positive
    /// `stale`, either clear for a negated one. The rule cannot hold unless
    /// `have & mask == need`; a condition that the bits decide whole (no
    /// run length above 1, no window, no tests) is not in `conds`.
    pub(in crate::rete) need: u64,
    pub(in crate::rete) mask: u64,
}

/// What a firing of a rule reads (`Engine::fast_record`) and its recency.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fire {
    pub(in crate::rete) target: u32,
    /// The agents its positive patterns match (recency, the matched facts)
    /// and those it tests for staleness, in `Program::agents`.
    pub(in crate::rete) matches: (u32, u32),
    pub(in crate::rete) stale: (u32, u32),
}

/// The rules of a bundle flattened for the fast path.
#[derive(Debug, Clone, Default)]
pub(super) struct Program {
    pub(in crate::rete) ne: usize,
    pub(in crate::rete) na: usize,
    /// Per `state * events + event`, per `state * agents + agent`, per
    /// state: a list in `lists`.
    pub(in crate::rete) by_event: Vec<(u32, u32)>,
    pub(in crate::rete) by_agent: Vec<(u32, u32)>,
    pub(in crate::rete) by_state: Vec<(u32, u32)>,
    pub(in crate::rete) lists: Vec<u32>,
    pub(in crate::rete) rules: Vec<Rule>,
    /// Per rule, what its firing records.
    pub(in crate::rete) fires: Vec<Fire>,
    /// Per agent: its bit in [`Engine::have`] while it is stale (after the
    /// events': `ne + agent`, below 64; `0`: none).
    pub(in crate::rete) stale_bit: Vec<u64>,
    /// Per event, its bits in [`Engine::have`] by run length: its own, and
    /// one per run-length threshold `k` of its patterns (above 1, at most
    /// [`MAX_RUN_BIT`]; after the agents' bits, below 64), set while the
    /// event is its agent's fact with a run length of at least `k`.
    /// `run_at[e]` is (its first entry in `runs`, its largest threshold
    /// `cap`): the bits of `e`'s fact with run length `run` are
    /// `runs[first + min(run, cap)]`.
    pub(in crate::rete) run_at: Vec<(u32, u32)>,
    pub(in crate::rete) runs: Vec<u64>,
    pub(in crate::rete) conds: Vec<Cond>,
    pub(in crate::rete) tests: Vec<Test>,
    pub(in crate::rete) agents: Vec<u32>,
}

/// The activated rule that fires first among those seen so far (`rule`:
/// `NONE` before one), its group, and its recency once needed (`u64::MAX`:
/// not yet computed).
#[derive(Debug, Clone, Copy)]
pub struct Best {
    rule: u32,
    group: u32,
    recency: u64,
}

impl Best {
    /// No rule yet.
    pub const NONE: Best = Best { rule: NONE, group: 0, recency: u64::MAX };

    /// Whether no rule of rank `group`, and none after it in a list in
    /// firing order, can fire before `self`: the search of the list ends.
    #[inline(always)]
    pub fn cuts(&self, group: u32) -> bool {
        self.rule != NONE && group < self.group
    }
}

/// An event's bit in [`Engine::have`] (`0` from event 64 on: no bit).
#[inline(always)]
pub(super) fn bit(event: u32) -> u64 {
    1u64.checked_shl(event).unwrap_or(0)
}

/// `v[i]` without the bounds check.
///
/// # Safety
/// `i < v.len()`. Every index this module takes from the program (lists,
/// rules, conditions, tests, agents, places in the arena) is checked once
/// by [`Program::check`] when the program is built, against the engine's
/// tables, whose lengths never change after construction
/// `agents`: one per agent; `payload`: the arena's length); the
/// state is always a state of the bundle and the event of a step one the
/// payload check took.
#[inline(always)]
pub(super) unsafe fn at<T>(v: &[T], i: usize) -> &T {
    debug_assert!(i < v.len(), "{i} >= {}", v.len());
    // SAFETY: the caller's.
    unsafe { v.get_unchecked(i) }
}

/// `&mut v[i]` without the bounds check.
///
/// # Safety
/// As [`at`].
#[inline(always)]
unsafe fn at_mut<T>(v: &mut [T], i: usize) -> &mut T {
    debug_assert!(i < v.len(), "{i} >= {}", v.len());
    // SAFETY: the caller's.
    unsafe { v.get_unchecked_mut(i) }
}

impl Engine {
    /// [`accepted`](Self::accepted) on the fast path.
    #[inline(always)]
    pub(super) fn fast_accepted(&mut self, event: u32, time: u64, payload: &[Value]) -> Result<Step, StepError> {
        self.before_insert(time)?;
        self.fast_insert(event, time, payload);
        let late = self.after_insert();
        let mut best = Best::NONE;
        let st = self.state as usize;
        // SAFETY (`at`): the state and the event (taken by the payload
        // check) are the bundle's: `st * ne + event < ns * ne`.
        self.fast_best_in(unsafe { *at(&self.fp.by_event, st * self.fp.ne + event as usize) }, &mut best);
        self.rest_after(best, late, Self::fast_by_state, Self::fast_record)?;
        Ok(self.step_done())
    }

    /// What the step did.
    #[inline(always)]
    pub(super) fn step_done(&self) -> Step {
        Step { from: self.record.from, to: self.state, firings: self.record.firings.len() }
    }

    /// A step's work before its fact is inserted: the record begun, now
    /// moved to `time`, expiry, and the rest if expiry ran or the engine
    /// was not at rest.
    #[inline(always)]
    pub(super) fn before_insert(&mut self, time: u64) -> Result<(), StepError> {
        self.begin();
        if time > self.now {
            self.now = time;
        }
        // Expiry ran (facts may have expired), or not at rest.
        let expiry = self.now > self.next_deadline;
        if expiry {
            self.fast_expire();
        }
        if expiry || !self.active.is_empty() {
            self.fast_rest()?;
        }
        Ok(())
    }

    /// After the insert: the fact came late, it may be expired already
    /// (expiry runs); whether it ran.
    #[inline(always)]
    pub(super) fn after_insert(&mut self) -> bool {
        let late = self.now > self.next_deadline;
        if late {
            self.fast_expire();
        }
        late
    }

    /// The rest after a step's fact: `best` holds the rules of the new
    /// fact's search (the engine was at rest before the insert: a rest came
    /// first, or an error returned); if expiry ran after the insert
    /// (`late`), those of the agents in `touched` (else it is empty) are
    /// searched too; then the firings, each new state's rules searched by
    /// `by_state`.
    #[inline(always)]
    pub(super) fn rest_after(
        &mut self,
        mut best: Best,
        late: bool,
        by_state: impl Fn(&Engine, &mut Best),
        record: impl Fn(&mut Engine, u32) -> u32,
    ) -> Result<(), StepError> {
        if late {
            let st = self.state as usize;
            self.fast_best_touched(st, &mut best);
        }
        if best.rule == NONE {
            return Ok(());
        }
        self.fire_with(best, by_state, record)
    }

    /// [`insert`](Self::insert) without the network.
    #[inline(always)]
    pub(super) fn fast_insert(&mut self, event: u32, time: u64, payload: &[Value]) {
        // SAFETY (`at`): the event was taken by the payload check (it is
        // the bundle's, and `payload` fits it); its agent, its place and
        // its windows are checked (`Program::check`).
        let ev = unsafe { *at(&self.net.event, event as usize) };
        let window_at = self.fast_next_window(ev.windows, time);
        self.insert_with(event, time, payload, ev.agent, ev.stale_after, ev.payload_at, window_at, |fp, run| {
            // SAFETY (`at`): `run_at` has one entry per event, its range
            // in `runs` (`Program::check`).
            let (first, cap) = unsafe { *at(&fp.run_at, event as usize) };
            unsafe { *at(&fp.runs, first as usize + run.min(cap as u64) as usize) }
        });
    }

    /// The insert of `event`'s fact, given its event's agent, `stale
    /// after` and place in the arena, the deadline of its next window
    /// (`fast_next_window`), and its bits of `have` by run length. The one
    /// insert of the fast path and of native code (`native.rs`).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn insert_with(
        &mut self,
        event: u32,
        time: u64,
        payload: &[Value],
        agent: u32,
        stale_after: u64,
        payload_at: u32,
        window_at: u64,
        bits_of: impl FnOnce(&Program, u64) -> u64,
    ) {
        // `u64::MAX` (never) stays `u64::MAX`.
        let stale_at = time.saturating_add(stale_after);
        self.seq += 1;
        let (seq, now) = (self.seq, self.now);
        // SAFETY (`at_mut`): an event's agent is checked (`Program::check`;
        // native code: `Native`'s digest), and `agents` has one record per agent.
        let r = unsafe { at_mut(&mut self.agents, agent as usize) };
        let old = r.slot;
        let run = if old.event == event { old.run + 1 } else { 1 };
        r.slot = Slot { event, time, run, seq };
        let new_bit = bits_of(&self.fp, run);
        let old_bit = std::mem::replace(&mut r.bit, new_bit);
        // The agent's clock: a step's event is stamped at or after it
        // (`admit`); `force_fact` keeps the later of the two itself.
        r.last = time;
        r.stale = false;
        r.checked = now;
        r.stale_at = stale_at;
        r.window_at = window_at;
        self.have = (self.have & !old_bit) | new_bit;
        // SAFETY: the event's place and its fields fit in the arena
        // (`Program::check`; native code: `Native`'s digest), and `payload`
        // has as many values as it has fields (the payload check).
        copy_payload(unsafe { self.payload.get_unchecked_mut(payload_at as usize..) }, payload);
        self.next_deadline = self.next_deadline.min(stale_at).min(window_at);
    }

    /// The bits of `event`'s fact with run length `run` (`Program::runs`).
    pub(super) fn fast_run_bits(&self, event: u32, run: u64) -> u64 {
        let (first, cap) = self.fp.run_at[event as usize];
        self.fp.runs[first as usize + run.min(cap as u64) as usize]
    }

    /// [`next_window`](Self::next_window) with the windows read unchecked.
    #[inline(always)]
    fn fast_next_window(&self, (s, e): (u32, u32), time: u64) -> u64 {
        // SAFETY: an event's windows are in `windows` (`Program::check`).
        self.next_window_of(unsafe { self.net.windows.get_unchecked(s as usize..e as usize) }, time)
    }

    /// When the next of `windows` (ascending) closes for a fact stamped
    /// `time` (`u64::MAX`: none is still open); native code gives them as
    /// constants.
    #[inline(always)]
    pub(super) fn next_window_of(&self, windows: &[u64], time: u64) -> u64 {
        for &w in windows {
            let deadline = time.saturating_add(w);
            if deadline >= self.now {
                return deadline;
            }
        }
        u64::MAX
    }

    /// [`expire`](Self::expire) without the network: the agents whose fact
    /// expired or whose window closed are noted in `touched`.
    pub(super) fn fast_expire(&mut self) {
        let (now, mut next) = (self.now, u64::MAX);
        for i in 0..self.net.timed_agents.len() {
            // SAFETY (`at`, `at_mut`): the timed agents are agents
            // (`Program::check`), `agents` has one record per agent.
            let a = unsafe { *at(&self.net.timed_agents, i) } as usize;
            let r = unsafe { at_mut(&mut self.agents, a) };
            if r.stale_at < now {
                // SAFETY (`at`): `stale_bit` has one entry per agent (`Program::check`).
                let sb = unsafe { *at(&self.fp.stale_bit, a) };
                self.have = (self.have & !r.bit) | sb;
                *r = AgentRec { last: r.last, checked: r.checked, stale: true, bit: sb, ..AGENT };
                self.touched.push(a as u32);
            } else if r.window_at < now {
                let slot = r.slot;
                let window_at = self.fast_next_window(self.net.event[slot.event as usize].windows, slot.time);
                let r = unsafe { at_mut(&mut self.agents, a) };
                r.checked = now;
                r.window_at = window_at;
                self.touched.push(a as u32);
            }
            let r = unsafe { at(&self.agents, a) };
            next = next.min(r.stale_at).min(r.window_at);
        }
        self.next_deadline = next;
    }

    /// [`rest`](Self::rest) on the fast path, without a new fact: every
    /// rule of the state if the engine was not at rest (`active` not
    /// empty), else the rules of the agents in `touched`. Both are empty
    /// after it, so that in a step `touched` is not empty only if expiry
    /// ran in the step.
    #[inline(always)]
    pub(super) fn fast_rest(&mut self) -> Result<(), StepError> {
        let mut best = Best::NONE;
        let st = self.state as usize;
        if !self.active.is_empty() {
            // SAFETY (`at`): the state is a state of the bundle.
            self.fast_best_in(unsafe { *at(&self.fp.by_state, st) }, &mut best);
            self.active.clear();
            // Their rules are the state's.
            self.touched.clear();
        } else {
            self.fast_best_touched(st, &mut best);
        }
        if best.rule == NONE {
            return Ok(());
        }
        self.fast_fire(best)
    }

    /// The rules of the agents in `touched` (emptied) in state `st`.
    fn fast_best_touched(&mut self, st: usize, best: &mut Best) {
        for i in 0..self.touched.len() {
            let a = self.touched[i] as usize;
            self.fast_best_in(self.fp.by_agent[st * self.fp.na + a], best);
        }
        self.touched.clear();
    }

    /// Fires `best`, then the rule that fires first in each new state,
    /// until none is activated; the bound counts the firings of the step.
    #[inline(never)]
    fn fast_fire(&mut self, best: Best) -> Result<(), StepError> {
        self.fire_with(best, Self::fast_by_state, Self::fast_record)
    }

    /// The rules of the state the engine is in, from the program's lists.
    #[inline(always)]
    fn fast_by_state(&self, best: &mut Best) {
        self.fast_best_in(self.fp.by_state[self.state as usize], best);
    }

    /// [`fast_fire`](Self::fast_fire), each new state's rules searched by
    /// `by_state` (the lists of the program, or native code's).
    #[inline(never)]
    fn fire_with(
        &mut self,
        mut best: Best,
        by_state: impl Fn(&Engine, &mut Best),
        record: impl Fn(&mut Engine, u32) -> u32,
    ) -> Result<(), StepError> {
        while best.rule != NONE {
            if self.record.firings.len() == self.cascade_limit {
                self.fast_activate();
                return Err(StepError::Cascade { limit: self.cascade_limit });
            }
            self.state = record(self, best.rule);
            best = Best::NONE;
            by_state(self, &mut best);
        }
        Ok(())
    }

    /// The activated rule of the list `(s, e)` that fires first, if it fires
    /// before `best` (§10.4: salience, specificity, recency, declaration
    /// order, as [`best`](Self::best)).
    #[inline(always)]
    fn fast_best_in(&self, (s, e): (u32, u32), best: &mut Best) {
        let p = &*self.fp;
        let (mut i, e) = (s as usize, e as usize);
        while i < e {
            // SAFETY (`at`): lists and their entries are checked.
            let r = unsafe { *at(&p.lists, i) };
            let rule = unsafe { at(&p.rules, r as usize) };
            i += 1;
            // The list is in firing order: no later rule comes first.
            // (`best.cuts(rule.group)` is this test, but written so here:
            // the compiled loop measured 6 instructions an event more
            // through the method.)
            if best.rule != NONE && rule.group < best.group {
                return;
            }
            if self.have & rule.mask != rule.need || !self.fast_holds(rule) {
                continue;
            }
            self.take(best, r, rule.group);
        }
    }

    /// Rule `r` of rank `group` is activated: it becomes `best` if it
    /// fires before it (§10.4: salience and specificity by the rank, then
    /// recency, then the rule declared first). The one conflict resolution
    /// of the fast path and of native code (`native.rs`).
    #[inline(always)]
    pub(super) fn take(&self, best: &mut Best, r: u32, group: u32) {
        if best.rule == NONE || group > best.group {
            *best = Best { rule: r, group, recency: u64::MAX };
        } else {
            self.tie(best, r, group);
        }
    }

    /// [`take`](Self::take) of a rule of `best`'s salience and
    /// specificity: recency, then the rule declared first.
    #[inline(never)]
    fn tie(&self, best: &mut Best, r: u32, group: u32) {
        if best.recency == u64::MAX {
            best.recency = self.fast_recency(best.rule);
        }
        let recency = self.fast_recency(r);
        if recency > best.recency || (recency == best.recency && r < best.rule) {
            *best = Best { rule: r, group, recency };
        }
    }

    fn fast_recency(&self, r: u32) -> u64 {
        let (s, e) = self.fp.fires[r as usize].matches;
        self.fp.agents[s as usize..e as usize].iter().map(|&a| self.agents[a as usize].slot.seq).max().unwrap_or(0)
    }

    /// Whether the rule's conditions hold (its state guard is its lists').
    #[inline(always)]
    fn fast_holds(&self, rule: &Rule) -> bool {
        let (mut i, e) = (rule.conds.0 as usize, rule.conds.1 as usize);
        while i < e {
            // SAFETY (`at`): the rule's conditions are checked.
            if !self.fast_cond(unsafe { at(&self.fp.conds, i) }) {
                return false;
            }
            i += 1;
        }
        true
    }

    #[inline(always)]
    fn fast_cond(&self, c: &Cond) -> bool {
        if c.event == STALE {
            self.cond_stale(c.agent, c.negative)
        } else {
            self.cond_event(c.agent, c.event, c.negative, c.min_run, c.within, |e| {
                c.tests.0 == c.tests.1 || e.fast_tests(c.tests)
            })
        }
    }

    /// Whether agent `agent` is stale (`!=` `negative`).
    #[inline(always)]
    pub(super) fn cond_stale(&self, agent: u32, negative: bool) -> bool {
        // SAFETY (`at`): a condition's agent is checked (`Program::check`;
        // native code: `Native`'s digest), and `agents` has one record per agent.
        unsafe { at(&self.agents, agent as usize) }.stale != negative
    }

    /// Whether agent `agent`'s fact is `event` with a run length of at
    /// least `min_run`, evaluated within `within` ns of its stamp
    /// (`u64::MAX`: no window), and passes `tests` (`!=` `negative`).
    #[inline(always)]
    pub(super) fn cond_event(
        &self,
        agent: u32,
        event: u32,
        negative: bool,
        min_run: u64,
        within: u64,
        tests: impl FnOnce(&Engine) -> bool,
    ) -> bool {
        // SAFETY (`at`): as `cond_stale`.
        let r = unsafe { at(&self.agents, agent as usize) };
        let slot = &r.slot;
        let pos = slot.event == event
            && slot.run >= min_run
            && (within == u64::MAX || r.checked.saturating_sub(slot.time) <= within)
            && tests(self);
        pos != negative
    }

    fn fast_tests(&self, (s, e): (u32, u32)) -> bool {
        for i in s as usize..e as usize {
            // SAFETY (`at`): tests are checked.
            let pass = match unsafe { *at(&self.fp.tests, i) } {
                Test::F64 { x, op, c } => self.test_f64(x, op, c),
                Test::F64Range { x, lo, hi, inclusive } => self.test_f64_range(x, lo, hi, inclusive),
                Test::Any { x, check: Check2::Compare { op, rhs } } => self.test_compare(x, op, rhs),
                Test::Any { x, check: Check2::Range { lo, hi, inclusive } } => self.test_range(x, lo, hi, inclusive),
            };
            if !pass {
                return false;
            }
        }
        true
    }

    /// The payload value at place `x` of the arena.
    #[inline(always)]
    fn value_at(&self, x: u32) -> Value {
        // SAFETY (`at`): places in the arena are checked (`Program::check`;
        // native code: `Native`'s digest).
        unsafe { *at(&self.payload, x as usize) }
    }

    /// The value at `x` (of a float field) against a float constant.
    #[inline(always)]
    pub(super) fn test_f64(&self, x: u32, op: Cmp, c: f64) -> bool {
        match self.value_at(x) {
            Value::F64(v) => float(op, v, c),
            other => compare(op, other, Value::F64(c)),
        }
    }

    /// The value at `x` (of a float field) in a range of float constants.
    #[inline(always)]
    pub(super) fn test_f64_range(&self, x: u32, lo: f64, hi: f64, inclusive: bool) -> bool {
        match self.value_at(x) {
            Value::F64(v) => v >= lo && if inclusive { v <= hi } else { v < hi },
            other => in_range(other, Value::F64(lo), Value::F64(hi), inclusive),
        }
    }

    #[inline(always)]
    pub(super) fn test_compare(&self, x: u32, op: Cmp, rhs: Arg) -> bool {
        compare(op, self.value_at(x), self.arg(rhs))
    }

    #[inline(always)]
    pub(super) fn test_range(&self, x: u32, lo: Arg, hi: Arg, inclusive: bool) -> bool {
        in_range(self.value_at(x), self.arg(lo), self.arg(hi), inclusive)
    }

    #[inline(always)]
    fn arg(&self, a: Arg) -> Value {
        match a {
            Arg::Value(v) => v,
            Arg::At(i) => self.value_at(i),
        }
    }

    /// Out of rest: the activated rules, whole, into `active` (in
    /// declaration order), which the next rest starts from.
    pub(super) fn fast_activate(&mut self) {
        debug_assert!(self.agents.len() == self.fp.na);
        let mut active = std::mem::take(&mut self.active);
        active.clear();
        let (s, e) = self.fp.by_state[self.state as usize];
        for i in s as usize..e as usize {
            let r = self.fp.lists[i];
            let rule = &self.fp.rules[r as usize];
            if self.have & rule.mask == rule.need && self.fast_holds(rule) {
                active.push(r);
            }
        }
        active.sort_unstable();
        self.active = active;
    }
}
