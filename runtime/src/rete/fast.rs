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
const STALE: u32 = u32::MAX - 1;

/// An operand: a constant, or a place in the payload arena.
#[derive(Debug, Clone, Copy)]
enum Arg {
    Value(Value),
    At(u32),
}

#[derive(Debug, Clone, Copy)]
enum Check2 {
    Compare { op: Cmp, rhs: Arg },
    Range { lo: Arg, hi: Arg, inclusive: bool },
}

/// A test of the payload value at a place `x` of the arena. A float field
/// against float constants, the usual test, has its own shape (the field's
/// type is known from its event; a value of another type, which the
/// payload check keeps out, would go to `compare` all the same).
#[derive(Debug, Clone, Copy)]
enum Test {
    F64 { x: u32, op: Cmp, c: f64 },
    F64Range { x: u32, lo: f64, hi: f64, inclusive: bool },
    Any { x: u32, check: Check2 },
}

/// One condition of a rule on one agent's fact.
#[derive(Debug, Clone, Copy)]
struct Cond {
    agent: u32,
    /// The event its fact must be, or `STALE`: the agent must be stale.
    event: u32,
    negative: bool,
    min_run: u64,
    /// The window, ns (`u64::MAX`: none).
    within: u64,
    /// Its tests, in `Program::tests`.
    tests: (u32, u32),
}

#[derive(Debug, Clone, Copy)]
struct Rule {
    /// Its conditions, in `Program::conds`, in the chain's order.
    conds: (u32, u32),
    /// The rank of its (salience, specificity) among the rules': a larger
    /// one fires first.
    group: u32,
    /// The bits of [`Engine::have`] its conditions read (`mask`) and the
    /// values they need (`need`): an event's bit (below 64) set for a
    /// positive pattern of it, a stale agent's bit set for a positive
    /// `stale`, either clear for a negated one. The rule cannot hold unless
    /// `have & mask == need`; a condition that the bits decide whole (no
    /// run length above 1, no window, no tests) is not in `conds`.
    need: u64,
    mask: u64,
}

/// What a firing of a rule reads (`Engine::fast_record`) and its recency.
#[derive(Debug, Clone, Copy)]
pub(super) struct Fire {
    pub(super) target: u32,
    /// The agents its positive patterns match (recency, the matched facts)
    /// and those it tests for staleness, in `Program::agents`.
    pub(super) matches: (u32, u32),
    pub(super) stale: (u32, u32),
}

/// The rules of a bundle flattened for the fast path.
#[derive(Debug, Clone, Default)]
pub(super) struct Program {
    ne: usize,
    na: usize,
    /// Per `state * events + event`, per `state * agents + agent`, per
    /// state: a list in `lists`.
    by_event: Vec<(u32, u32)>,
    by_agent: Vec<(u32, u32)>,
    by_state: Vec<(u32, u32)>,
    lists: Vec<u32>,
    rules: Vec<Rule>,
    /// Per rule, what its firing records.
    pub(super) fires: Vec<Fire>,
    /// Per agent: its bit in [`Engine::have`] while it is stale (after the
    /// events': `ne + agent`, below 64; `0`: none).
    pub(super) stale_bit: Vec<u64>,
    /// Per event, its bits in [`Engine::have`] by run length: its own, and
    /// one per run-length threshold `k` of its patterns (above 1, at most
    /// [`MAX_RUN_BIT`]; after the agents' bits, below 64), set while the
    /// event is its agent's fact with a run length of at least `k`.
    /// `run_at[e]` is (its first entry in `runs`, its largest threshold
    /// `cap`): the bits of `e`'s fact with run length `run` are
    /// `runs[first + min(run, cap)]`.
    run_at: Vec<(u32, u32)>,
    runs: Vec<u64>,
    conds: Vec<Cond>,
    tests: Vec<Test>,
    pub(super) agents: Vec<u32>,
}

/// The activated rule that fires first among those seen so far (`rule`:
/// `NONE` before one), its group, and its recency once needed (`u64::MAX`:
/// not yet computed).
#[derive(Debug, Clone, Copy)]
struct Best {
    rule: u32,
    group: u32,
    recency: u64,
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
        self.fast_insert(event, time, payload);
        // The fact came late: it may be expired already.
        let late = self.now > self.next_deadline;
        if late {
            self.fast_expire();
        }
        self.fast_rest_after(event, late)?;
        Ok(Step { from: self.record.from, to: self.state, firings: self.record.firings.len() })
    }

    /// [`insert`](Self::insert) without the network.
    #[inline(always)]
    pub(super) fn fast_insert(&mut self, event: u32, time: u64, payload: &[Value]) {
        // SAFETY (`at`, `at_mut`): the event was taken by the payload check
        // (it is the bundle's, and `payload` fits it); its agent, its
        // place and its windows are checked (`Program::check`); the tables
        // indexed by agent have one entry per agent.
        let ev = unsafe { *at(&self.net.event, event as usize) };
        let a = ev.agent as usize;
        // `u64::MAX` (never) stays `u64::MAX`.
        let stale_at = time.saturating_add(ev.stale_after);
        let window_at = self.fast_next_window(ev.windows, time);
        self.seq += 1;
        let (seq, now) = (self.seq, self.now);
        let r = unsafe { at_mut(&mut self.agents, a) };
        let old = r.slot;
        let run = if old.event == event { old.run + 1 } else { 1 };
        r.slot = Slot { event, time, run, seq };
        // SAFETY (`at`): `run_at` has one entry per event, its range in
        // `runs` (`Program::check`).
        let (first, cap) = unsafe { *at(&self.fp.run_at, event as usize) };
        let new_bit = unsafe { *at(&self.fp.runs, first as usize + run.min(cap as u64) as usize) };
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
        // (`Program::check`), and `payload` has as many values as it has
        // fields (the payload check).
        copy_payload(unsafe { self.payload.get_unchecked_mut(ev.payload_at as usize..) }, payload);
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
        let mut i = s as usize;
        while i < e as usize {
            // SAFETY (`at`): an event's windows are in `windows`
            // (`Program::check`).
            let deadline = time.saturating_add(unsafe { *at(&self.net.windows, i) });
            if deadline >= self.now {
                return deadline;
            }
            i += 1;
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
        let mut best = Best { rule: NONE, group: 0, recency: u64::MAX };
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

    /// The rest after a step's fact of `event`: the engine was at rest
    /// before it was inserted (a rest came first, or an error returned), so
    /// the rules of `event`'s new fact, and if expiry ran after the insert
    /// (`late`), those of the agents in `touched` (else it is empty).
    #[inline(always)]
    fn fast_rest_after(&mut self, event: u32, late: bool) -> Result<(), StepError> {
        let mut best = Best { rule: NONE, group: 0, recency: u64::MAX };
        let st = self.state as usize;
        // SAFETY (`at`): the state and the event (taken by the payload
        // check) are the bundle's: `st * ne + event < ns * ne`.
        let list = unsafe { *at(&self.fp.by_event, st * self.fp.ne + event as usize) };
        self.fast_best_in(list, &mut best);
        if late {
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
    fn fast_fire(&mut self, mut best: Best) -> Result<(), StepError> {
        while best.rule != NONE {
            if self.record.firings.len() == self.cascade_limit {
                self.fast_activate();
                return Err(StepError::Cascade { limit: self.cascade_limit });
            }
            self.state = self.fast_record(best.rule);
            best = Best { rule: NONE, group: 0, recency: u64::MAX };
            self.fast_best_in(self.fp.by_state[self.state as usize], &mut best);
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
            if best.rule != NONE && rule.group < best.group {
                // The list is in firing order: no later rule comes first.
                return;
            }
            if self.have & rule.mask != rule.need || !self.fast_holds(rule) {
                continue;
            }
            if best.rule == NONE || rule.group > best.group {
                *best = Best { rule: r, group: rule.group, recency: u64::MAX };
                continue;
            }
            // The same salience and specificity: recency, then the rule
            // declared first.
            if best.recency == u64::MAX {
                best.recency = self.fast_recency(best.rule);
            }
            let recency = self.fast_recency(r);
            if recency > best.recency || (recency == best.recency && r < best.rule) {
                *best = Best { rule: r, group: rule.group, recency };
            }
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
        let a = c.agent as usize;
        // SAFETY (`at`): a condition's agent is checked, and `agents` has
        // one record per agent.
        let r = unsafe { at(&self.agents, a) };
        let pos = if c.event == STALE {
            r.stale
        } else {
            let slot = &r.slot;
            slot.event == c.event
                && slot.run >= c.min_run
                && (c.within == u64::MAX || r.checked.saturating_sub(slot.time) <= c.within)
                && (c.tests.0 == c.tests.1 || self.fast_tests(c.tests))
        };
        pos != c.negative
    }

    fn fast_tests(&self, (s, e): (u32, u32)) -> bool {
        for i in s as usize..e as usize {
            // SAFETY (`at`): tests and their places in the arena are checked.
            let pass = match unsafe { *at(&self.fp.tests, i) } {
                Test::F64 { x, op, c } => match unsafe { *at(&self.payload, x as usize) } {
                    Value::F64(v) => float(op, v, c),
                    other => compare(op, other, Value::F64(c)),
                },
                Test::F64Range { x, lo, hi, inclusive } => match unsafe { *at(&self.payload, x as usize) } {
                    Value::F64(v) => v >= lo && if inclusive { v <= hi } else { v < hi },
                    other => in_range(other, Value::F64(lo), Value::F64(hi), inclusive),
                },
                Test::Any { x, check } => {
                    let x = unsafe { *at(&self.payload, x as usize) };
                    match check {
                        Check2::Compare { op, rhs } => compare(op, x, self.arg(rhs)),
                        Check2::Range { lo, hi, inclusive } => in_range(x, self.arg(lo), self.arg(hi), inclusive),
                    }
                }
            };
            if !pass {
                return false;
            }
        }
        true
    }

    #[inline]
    fn arg(&self, a: Arg) -> Value {
        match a {
            Arg::Value(v) => v,
            // SAFETY (`at`): places in the arena are checked.
            Arg::At(i) => unsafe { *at(&self.payload, i as usize) },
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
