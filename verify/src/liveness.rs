//! Proofs of liveness for runs of any length: `always (P -> eventually Q)`
//! without a bound, by the liveness-to-safety reduction (Biere, Artho,
//! Schuppan 2002) of the [`Model`]'s circuit, checked by [`ic3`].
//!
//! The property is broken by an infinite run with a point where P holds
//! and no point from there on where Q holds. The circuit keeps the
//! obligation ([`Obligation`]): `now` is whether it is pending after the
//! current point (¬Q ∧ (pending ∨ P)). The reduction adds to the circuit
//!
//! - a free input `save` and a latch `saved`: at the first cycle where
//!   `save` holds, a shadow latch copies each latch of the abstract state
//!   ([`Model::system`]: the state, FSM states, facts with their run
//!   lengths and capped ages, the order of reports);
//! - a latch that holds while the obligation was pending after every point
//!   since the save (`now` at the save and at each later point);
//!
//! and its bad output is: saved, pending since (and so the `pending` latch,
//! said as well, so that IC3 can block a loop by the obligation alone), and
//! the abstract state equal to its shadow — a loop of one or more points along which the
//! obligation stays pending — or a cascade (which breaks every property,
//! as in the explorer).
//!
//! **Why a loop of the circuit is an infinite run of the engine.** The
//! circuit's next state is a function of its abstract state and its inputs
//! (a letter and a gap); the predicates P and Q are functions of the
//! abstract state (the tests of [`Model::simulate`] check both against
//! the engine, point by point). Time is exact, not sampled: an age is a
//! number of nanoseconds capped just past the largest duration that
//! concerns the agent, and past the cap every threshold is crossed alike;
//! a gap is any number of nanoseconds (longer gaps act as the longest).
//! So if the run u v reaches the abstract state s after u and again after
//! u v, then u v v v … reaches s after every copy of v on the engine too,
//! with the same predicates at the same places of each copy: the real ages
//! grow past the cap, which the capped ones stand for. Q fails at every
//! point of the loop, so the obligation, pending after u and at every
//! point of v, stays pending for ever. The run may keep time still (every
//! gap of v zero): the engine takes events at the same time, and no
//! fairness on time is assumed, as in the explorer. Conversely a run that
//! breaks the property has finitely many abstract states, so one repeats
//! while the obligation is pending: the circuit has the loop. Hence IC3's
//! invariant (no such loop is reachable) proves the property on every
//! infinite run of the abstraction — of every run when the abstraction is
//! exact (payload classes, [`prove::sampled`]).
//!
//! Before the reduction, IC3 spends a tenth of the budget on the model's
//! circuit alone on whether the obligation can arise at all: where Q holds
//! wherever P does, that settles it, and the shadow latches make the same
//! fact much harder for IC3 to find. Then short loops are looked for by
//! bounded model checking of the loop circuit (up to [`BMC_DEPTH`] cycles,
//! another tenth of the budget): IC3 finds a loop slowly, because a bad
//! state fixes every latch and its shadow and IC3 walks back from it one
//! state at a time.
//!
//! A loop that IC3 or the bounded search finds is confirmed on the real
//! engine (as the explorer's lassos, up to its abstract state): the prefix, then
//! the loop three times, must keep the obligation pending from the loop's
//! first point on and come back to the same abstract state
//! ([`Alphabet::key`]) after each copy; otherwise the verdict is
//! [`Verdict::Disagree`], never a proof. A confirmed lasso is simplified
//! (events of the prefix removed, the prefix's gaps made 0 or whole
//! milliseconds, the loop's whole milliseconds but not 0), each step
//! confirmed again.

use super::abstraction::Alphabet;
use super::aig::Lit as ALit;
use super::aig::{lit_value, not, Aig, Lit};
use super::ic3::{self, Limits, Outcome};
use super::model::{Model, Obligation};
use super::monitor::{Monitor, MonitorState};
use super::prove;
use super::random;
use super::{Counterexample, RunStep, System, Verdict};
use batsat::{lbool, BasicSolver, Lit as SLit, SolverInterface};
use situ_compiler::bundle::Content;
use situ_compiler::spec::PropertySpec;
use std::cell::Cell;
use std::sync::Arc;
use std::time::Instant;

/// The share of the budget (1 / QUICK) spent first on whether the
/// obligation can arise at all.
const QUICK: u64 = 10;

/// The most cycles of the loop circuit unrolled to look for a short loop.
const BMC_DEPTH: usize = 12;

/// How many times a loop is replayed on the engine to confirm it.
const CONFIRM: usize = 3;

/// The liveness-to-safety circuit of one property.
pub struct Reduction {
    pub aig: Aig,
    /// A cascade, or a loop along which the obligation stays pending.
    pub bad: Lit,
    save: Lit,
    saved: Lit,
}

impl Reduction {
    /// The model's circuit with the loop detector of `ob`.
    pub fn new(model: &Model, ob: Obligation) -> Reduction {
        let mut aig = model.aig.clone();
        let save = aig.input("l2s.save");
        let saved = aig.latch("l2s.saved");
        let since = aig.latch("l2s.pending_since");
        let first = aig.and(save, not(saved));
        let saved_next = aig.or(saved, save);
        aig.set_next(saved, saved_next);
        let kept = aig.and(since, ob.now);
        let since_next = aig.mux(first, ob.now, kept);
        aig.set_next(since, since_next);
        let mut same = Vec::with_capacity(model.system.len());
        for (i, &l) in model.system.iter().enumerate() {
            let shadow = aig.latch(&format!("l2s.shadow{i}"));
            let next = aig.mux(first, l, shadow);
            aig.set_next(shadow, next);
            let differ = aig.xor(l, shadow);
            same.push(not(differ));
        }
        let same = aig.and_all(same);
        // `pending` follows from `since` after the save; said here, it lets
        // IC3 block a loop by the obligation alone.
        let looped = aig.and_all([saved, since, ob.pending, same]);
        let bad = aig.or(looped, model.err);
        Reduction { aig, bad, save, saved }
    }

    /// The cycle at which a run of these inputs saved its state, if it did.
    fn saved_at(&self, inputs: &[Vec<bool>]) -> Option<usize> {
        let mut latches = vec![false; self.aig.latches().len()];
        for (t, ins) in inputs.iter().enumerate() {
            let val = self.aig.eval(ins, &latches);
            if lit_value(&val, self.save) && !lit_value(&val, self.saved) {
                return Some(t);
            }
            latches = (0..latches.len()).map(|i| lit_value(&val, self.aig.next_of(i))).collect();
        }
        None
    }
}

/// Proves liveness property `index` of the model on every infinite run, or
/// finds a lasso (replayed on the engine), or says where IC3 gave up;
/// `None` when the circuit keeps no obligation for it (not a liveness
/// property, or a predicate the circuit cannot say).
pub fn check(
    content: &Arc<Content>,
    alphabet: &Arc<Alphabet>,
    model: &Model,
    index: usize,
    property: &PropertySpec,
    limits: Limits,
) -> Option<Verdict> {
    let ob = model.live.get(index).copied().flatten()?;
    // An obligation that never arises (Q holds wherever P does) needs no
    // loop: a tenth of the budget on the model alone, where it is easy.
    let quick = Limits { work: limits.work / QUICK, ..limits };
    if let Outcome::Proved { frames, clauses } = ic3::check(&model.aig, ob.now, quick) {
        return Some(Verdict::Inductive { frames, clauses, sampled: prove::sampled(alphabet) });
    }
    let r = Reduction::new(model, ob);
    // Short loops first: IC3 walks back from a loop one state at a time.
    let outcome = match bmc(&r.aig, r.bad, BMC_DEPTH, Limits { work: limits.work / QUICK, ..limits }) {
        Some(inputs) => Outcome::Counterexample(inputs),
        None => ic3::check(&r.aig, r.bad, limits),
    };
    Some(match outcome {
        Outcome::Proved { frames, clauses } => {
            Verdict::Inductive { frames, clauses, sampled: prove::sampled(alphabet) }
        }
        Outcome::Unknown { depth, work, stop } => Verdict::GaveUp { depth, work, stop },
        Outcome::Counterexample(inputs) => {
            let run: Vec<RunStep> = model.run_of(alphabet, &inputs);
            // The liveness monitor fails at no point: a failure is a cascade.
            if random::check_run(content, property, &run, &Cell::new(0)).is_err() {
                return Some(cascade(content, alphabet, property, run));
            }
            match r.saved_at(&inputs) {
                Some(start) if start < run.len() => lasso(content, alphabet, property, &run, start),
                _ => Verdict::Disagree { events: run.len() },
            }
        }
    })
}

/// Bounded model checking: the inputs of a run of at most `depth` cycles
/// from the initial state to a `bad` state, looked for one depth after the
/// other until the limits' work (SAT propagations) is spent or their
/// deadline passed (checked between depths).
fn bmc(aig: &Aig, bad: Lit, depth: usize, limits: Limits) -> Option<Vec<Vec<bool>>> {
    let mut s = BasicSolver::default();
    let f = SLit::new(s.new_var_default(), true);
    s.add_clause_reuse(&mut vec![!f]);
    let lit = |frame: &[SLit], l: ALit| if l & 1 == 1 { !frame[(l >> 1) as usize] } else { frame[(l >> 1) as usize] };
    let mut frames: Vec<Vec<SLit>> = Vec::new();
    let start = s.num_propagations();
    for t in 0..=depth {
        let mut m = vec![f; aig.len()];
        for &v in aig.inputs() {
            m[v as usize] = SLit::new(s.new_var_default(), true);
        }
        for (i, &v) in aig.latches().iter().enumerate() {
            m[v as usize] = match frames.last() {
                None => f,
                Some(prev) => lit(prev, aig.next_of(i)),
            };
        }
        for v in 0..aig.len() as u32 {
            if let Some((a, b)) = aig.gate(v) {
                let x = SLit::new(s.new_var_default(), true);
                let (la, lb) = (lit(&m, a), lit(&m, b));
                s.add_clause_reuse(&mut vec![!x, la]);
                s.add_clause_reuse(&mut vec![!x, lb]);
                s.add_clause_reuse(&mut vec![x, !la, !lb]);
                m[v as usize] = x;
            }
        }
        let b = lit(&m, bad);
        frames.push(m);
        if s.solve_limited(&[b]) == lbool::TRUE {
            let inputs = frames[..t]
                .iter()
                .map(|m| aig.inputs().iter().map(|&v| s.value_lit(m[v as usize]) == lbool::TRUE).collect())
                .collect();
            return Some(inputs);
        }
        let late = limits.deadline.is_some_and(|d| Instant::now() >= d);
        if s.num_propagations() - start > limits.work || late {
            return None;
        }
    }
    None
}

/// A run that breaks the property at a point (a cascade), shrunk.
fn cascade(content: &Arc<Content>, alphabet: &Arc<Alphabet>, property: &PropertySpec, run: Vec<RunStep>) -> Verdict {
    match random::check_run(content, property, &run, &Cell::new(0)) {
        Err((point, _)) => {
            let run = random::shrink(content, alphabet, property, run[..point].to_vec());
            let (point, reason) =
                random::check_run(content, property, &run, &Cell::new(0)).err().unwrap_or((run.len(), String::new()));
            Verdict::Failed(Counterexample::replay(content, &run[..point.min(run.len())], point, reason))
        }
        Ok(()) => Verdict::Disagree { events: run.len() },
    }
}

/// The lasso `run[..start]` then `run[start..]` for ever, if the engine
/// confirms it.
fn lasso(
    content: &Arc<Content>,
    alphabet: &Alphabet,
    property: &PropertySpec,
    run: &[RunStep],
    start: usize,
) -> Verdict {
    let (prefix, cycle) = run.split_at(start);
    if !confirmed(content, alphabet, property, prefix, cycle) {
        return Verdict::Disagree { events: run.len() };
    }
    let (prefix, cycle) = simplify(content, alphabet, property, prefix.to_vec(), cycle.to_vec());
    let start = prefix.len();
    let mut run = prefix;
    run.extend(cycle);
    let reason = format!(
        "the premise held and the consequent never comes: events {} to {} repeat forever",
        start + 1,
        run.len()
    );
    Verdict::Failed(Counterexample::replay(content, &run, run.len(), reason))
}

/// A confirmed lasso made easier to read, each change kept only if the
/// engine still confirms it: events of the prefix removed one at a time,
/// then each gap made 0, or else rounded down to the millisecond.
fn simplify(
    content: &Arc<Content>,
    alphabet: &Alphabet,
    property: &PropertySpec,
    mut prefix: Vec<RunStep>,
    mut cycle: Vec<RunStep>,
) -> (Vec<RunStep>, Vec<RunStep>) {
    let ok = |p: &[RunStep], c: &[RunStep]| confirmed(content, alphabet, property, p, c);
    let mut i = 0;
    while i < prefix.len() {
        let mut fewer = prefix.clone();
        fewer.remove(i);
        if ok(&fewer, &cycle) {
            prefix = fewer;
        } else {
            i += 1;
        }
    }
    for k in 0..prefix.len() + cycle.len() {
        let in_cycle = k >= prefix.len();
        let gap = if in_cycle { cycle[k - prefix.len()].gap } else { prefix[k].gap };
        let ms = gap / 1_000_000 * 1_000_000;
        // A gap of the cycle stays positive: the loop does not stop time
        // where IC3's did not.
        let candidates: &[u64] = if in_cycle { &[ms] } else { &[0, ms] };
        for &g in candidates {
            if g == gap || (in_cycle && g == 0) {
                break;
            }
            let (mut p, mut c) = (prefix.clone(), cycle.clone());
            if k < p.len() {
                p[k].gap = g;
            } else {
                c[k - p.len()].gap = g;
            }
            if ok(&p, &c) {
                (prefix, cycle) = (p, c);
                break;
            }
        }
    }
    (prefix, cycle)
}

/// Whether the engine, after `prefix` then `cycle` [`CONFIRM`] times,
/// keeps the obligation pending from the end of the prefix on (the cycle's
/// first point is the prefix's last), no event refused and no cascade, and
/// comes back to the prefix's abstract state after each copy of the cycle.
pub fn confirmed(
    content: &Arc<Content>,
    alphabet: &Alphabet,
    property: &PropertySpec,
    prefix: &[RunStep],
    cycle: &[RunStep],
) -> bool {
    if cycle.is_empty() {
        return false;
    }
    let monitor = Monitor::new(property);
    let mut sys = System::new(content.clone());
    let mut st = MonitorState::default();
    let (p, q) = sys.point(property);
    if monitor.step(&mut st, p, q, 0).is_some() {
        return false;
    }
    let mut time = 0u64;
    let mut post = |sys: &mut System, st: &mut MonitorState, s: &RunStep| -> bool {
        time = time.saturating_add(s.gap);
        if sys.post(s.event, time, &s.payload).is_err() {
            return false;
        }
        let (p, q) = sys.point(property);
        monitor.step(st, p, q, s.gap).is_none()
    };
    for s in prefix {
        if !post(&mut sys, &mut st, s) {
            return false;
        }
    }
    let (mut home, mut key) = (Vec::new(), Vec::new());
    alphabet.key(&sys, &mut home);
    if !st.pending {
        return false;
    }
    for _ in 0..CONFIRM {
        for s in cycle {
            if !post(&mut sys, &mut st, s) || !st.pending {
                return false;
            }
        }
        alphabet.key(&sys, &mut key);
        if key != home {
            return false;
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-bit counter that counts while its input holds: 3 is bad.
    fn counter() -> (Aig, Lit) {
        let mut g = Aig::new();
        let go = g.input("go");
        let b0 = g.latch("b0");
        let b1 = g.latch("b1");
        let n0 = g.xor(b0, go);
        let carry = g.and(b0, go);
        let n1 = g.xor(b1, carry);
        g.set_next(b0, n0);
        g.set_next(b1, n1);
        let bad = g.and(b0, b1);
        (g, bad)
    }

    #[test]
    fn bounded_search_finds_the_shortest_run_within_its_depth() {
        let (g, bad) = counter();
        assert_eq!(bmc(&g, bad, 2, Limits::frames(0)), None);
        let run = bmc(&g, bad, 5, Limits::frames(0)).expect("a run");
        assert_eq!(run, vec![vec![true]; 3]);
    }
}
