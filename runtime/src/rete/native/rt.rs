//! What generated modules call: the fast path's pieces (`fast.rs`), each
//! taking as constants what the fast path reads from its tables. Not an
//! API for people: only code that [`generate`](super::generate) wrote, and
//! that [`Engine::with_native`] checked was written for the engine's
//! bundle, may call these (the indexes it passes are trusted as the
//! fast path trusts its checked tables).

pub use super::{Native, StepFn};
pub use crate::rete::fast::{Arg, Best};
pub use crate::rete::{Engine, Step, StepError};
pub use situ_bundle::{Cmp, Value};

/// A step the generated payload check did not take, or of an event it
/// does not know: the fast path's step, which refuses it as the engine
/// does (or, should the generated check be stricter than the engine's,
/// takes it).
#[cold]
#[inline(never)]
pub fn fallback(e: &mut Engine, event: u32, time: u64, payload: &[Value]) -> Result<Step, StepError> {
    e.admitted(event, time, payload)?;
    e.fast_accepted(event, time, payload)
}

/// The acceptance rule's time part, for `event` of `agent`.
#[inline(always)]
pub fn admit_time(e: &Engine, event: u32, agent: u32, time: u64) -> Result<(), StepError> {
    e.admitted_time(event, agent, time)
}

/// The step before the insert: now, expiry, a rest.
#[inline(always)]
pub fn before(e: &mut Engine, time: u64) -> Result<(), StepError> {
    e.before_insert(time)
}

/// The insert of `event`'s fact: its agent, `stale after` (ns,
/// `u64::MAX`: never), place in the arena, windows (ns, ascending), and
/// its bits by run length (`runs[min(run, runs.len() - 1)]`, not empty).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub fn insert(
    e: &mut Engine,
    event: u32,
    time: u64,
    payload: &[Value],
    agent: u32,
    stale_after: u64,
    payload_at: u32,
    windows: &[u64],
    runs: &[u64],
) {
    let window_at = e.next_window_of(windows, time);
    e.insert_with(event, time, payload, agent, stale_after, payload_at, window_at, |_, run| {
        let i = run.min(runs.len() as u64 - 1) as usize;
        // SAFETY: `i < runs.len()`.
        unsafe { *runs.get_unchecked(i) }
    });
}

/// Expiry after the insert; whether it ran.
#[inline(always)]
pub fn after(e: &mut Engine) -> bool {
    e.after_insert()
}

/// The end of a step: the rest after the insert (`best`: the new fact's
/// search), each new state's rules searched by `by_state`, each firing
/// recorded by `fire`.
#[inline(always)]
pub fn finish(
    e: &mut Engine,
    best: Best,
    late: bool,
    by_state: impl Fn(&Engine, &mut Best),
    fire: impl Fn(&mut Engine, u32) -> u32,
) -> Result<Step, StepError> {
    e.rest_after(best, late, by_state, fire)?;
    Ok(e.step_done())
}

#[inline(always)]
pub fn state(e: &Engine) -> u32 {
    e.state
}

/// The working memory's bits (`have`).
#[inline(always)]
pub fn have(e: &Engine) -> u64 {
    e.have
}

/// Whether a list's search ends before a rule of rank `group`.
#[inline(always)]
pub fn cut(best: &Best, group: u32) -> bool {
    best.cuts(group)
}

/// Rule `r` of rank `group` is activated.
#[inline(always)]
pub fn take(e: &Engine, best: &mut Best, r: u32, group: u32) {
    e.take(best, r, group)
}

#[inline(always)]
pub fn stale(e: &Engine, agent: u32, negative: bool) -> bool {
    e.cond_stale(agent, negative)
}

#[inline(always)]
pub fn event(
    e: &Engine,
    agent: u32,
    event: u32,
    negative: bool,
    min_run: u64,
    within: u64,
    tests: impl FnOnce(&Engine) -> bool,
) -> bool {
    e.cond_event(agent, event, negative, min_run, within, tests)
}

#[inline(always)]
pub fn f64(e: &Engine, x: u32, op: Cmp, c: f64) -> bool {
    e.test_f64(x, op, c)
}

#[inline(always)]
pub fn f64_range(e: &Engine, x: u32, lo: f64, hi: f64, inclusive: bool) -> bool {
    e.test_f64_range(x, lo, hi, inclusive)
}

#[inline(always)]
pub fn compare(e: &Engine, x: u32, op: Cmp, rhs: Arg) -> bool {
    e.test_compare(x, op, rhs)
}

#[inline(always)]
pub fn range(e: &Engine, x: u32, lo: Arg, hi: Arg, inclusive: bool) -> bool {
    e.test_range(x, lo, hi, inclusive)
}

/// Records the firing of rule `r` to `target`, the agents its positive
/// patterns match being `matches` and those it tests for staleness
/// `stale`; returns `target`.
#[inline(always)]
pub fn record(e: &mut Engine, r: u32, target: u32, matches: &[u32], stale: &[u32]) -> u32 {
    e.record_with(r, target, matches, stale)
}

/// Whether the engine runs the module `native`.
#[inline(always)]
pub fn runs(e: &Engine, native: &'static Native) -> bool {
    e.native.is_some_and(|n| std::ptr::eq(n, native))
}

/// `Engine::step` of an engine that does not run the module calling.
#[cold]
#[inline(never)]
pub fn step(e: &mut Engine, event: u32, time: u64, payload: &[Value]) -> Result<Step, StepError> {
    e.step(event, time, payload)
}
