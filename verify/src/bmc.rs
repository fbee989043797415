//! Deeper than the exploration: bounded model checking of a property's
//! bad output on the [`Model`]'s circuit, in the property's cone of
//! influence.
//!
//! The exploration ([`explore`](super::explore)) posts every letter after
//! every gap at every node: on a file as wide as a drone's (11 agents, 31
//! letters, 5 gaps) its state budget runs out after 2 or 3 events, because
//! the abstract states of independent agents multiply. A SAT solver does not
//! enumerate them: the circuit is unrolled one copy per event, and the
//! solver is asked whether the property's bad output can hold after exactly
//! 0, 1, 2, … events, one depth after the other.
//!
//! **The cone of influence.** Only what the bad output depends on is
//! unrolled: its gates, the latches they read, and, for each such latch,
//! the gates of its next state, to a fixed point. Another property's
//! monitor, and anything else the property cannot see, is left out (it
//! constrains nothing the bad output reads, so leaving it out changes no
//! answer).
//!
//! **Why "no counterexample up to N events" is honest.** The unrolling of
//! depth t is the circuit's transition relation t times from the initial
//! state (every latch 0), with every input free at every step: every letter
//! and **every gap** (the circuit's time is exact, unlike the exploration's
//! grid of gaps). An unsatisfiable query at depth t says that no run of
//! exactly t events of the abstraction reaches a bad point; the search
//! says "clear up to N" only when every depth 0 … N was refuted. The
//! circuit is the abstraction (its steps are checked against the engine's
//! in `verify/tests/model.rs`); what the abstraction samples of payloads is
//! said in the verdict, as for IC3. A satisfiable query is a run: its
//! letters and gaps are replayed on the real engine, where the property
//! must fail too (else the verdict is [`Verdict::Disagree`]), then shrunk
//! as IC3's and the random search's are. As depths are tried in order, its
//! run is a shortest one (in events, for any gaps).
//!
//! The budget is work, not time: SAT propagations, checked between depths,
//! so that the same file and options reach the same depth on any machine.
//!
//! **Why not fewer interleavings.** Sleep sets (trying two commuting events
//! in one order only) keep every reachable abstract state, so they do not
//! lower the count that the state budget bounds; persistent sets would,
//! but where every event can move the state (which every property reads),
//! few events are invisible, and a bounded claim after such a reduction
//! needs runs permuted and lengthened, which is harder to make honest than
//! one SAT query per depth.

use super::abstraction::Alphabet;
use super::aig::{Aig, Lit};
use super::ic3::{Limits, Stop};
use super::model::Model;
use super::random;
use super::{Counterexample, RunStep, Verdict};
use batsat::{lbool, BasicSolver, Lit as SLit, SolverInterface};
use situ_compiler::bundle::Content;
use situ_compiler::spec::PropertySpec;
use std::cell::Cell;
use std::sync::Arc;
use std::time::Instant;

/// The share of `situ test`'s work budget (`--prove-effort`, 1 / SHARE of
/// it) that the bounded search may spend per property.
pub const SHARE: u64 = 4;

/// What the bounded search found.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// The inputs of each step of a shortest run from the initial state to
    /// a bad point.
    Counterexample(Vec<Vec<bool>>),
    /// No bad point after 0 … `depth` events (depth 0 is always decided);
    /// `stop` says which limit ended the search, `None` when it reached the
    /// depth asked for.
    Clear { depth: usize, work: u64, stop: Option<Stop> },
}

/// The variables in the cone of influence of `roots`: the gates they are
/// made of, the latches those read, those latches' next-state gates, and
/// so on to a fixed point. Inputs are marked too.
pub fn cone(aig: &Aig, roots: &[Lit]) -> Vec<bool> {
    let mut mark = vec![false; aig.len()];
    let latch_index: std::collections::HashMap<u32, usize> =
        aig.latches().iter().enumerate().map(|(i, &v)| (v, i)).collect();
    let mut stack: Vec<u32> = roots.iter().map(|&l| l >> 1).collect();
    while let Some(v) = stack.pop() {
        if v == 0 || mark[v as usize] {
            continue;
        }
        mark[v as usize] = true;
        if let Some((a, b)) = aig.gate(v) {
            stack.push(a >> 1);
            stack.push(b >> 1);
        } else if let Some(&i) = latch_index.get(&v) {
            stack.push(aig.next_of(i) >> 1);
        }
    }
    mark
}

/// Looks for a run of at most `limits.frames` events from the initial
/// state to a point where `bad` holds, one depth after the other, until
/// `limits`' work (SAT propagations, checked between depths) is spent or
/// its deadline passed. Only the cone of influence of `bad` is unrolled.
pub fn search(aig: &Aig, bad: Lit, limits: Limits) -> Outcome {
    let depth = limits.frames;
    let mark = cone(aig, &[bad]);
    let mut s = BasicSolver::default();
    let f = SLit::new(s.new_var_default(), true);
    s.add_clause_reuse(&mut vec![!f]);
    let lit = |frame: &[SLit], l: Lit| if l & 1 == 1 { !frame[(l >> 1) as usize] } else { frame[(l >> 1) as usize] };
    let mut frames: Vec<Vec<SLit>> = Vec::new();
    let mut work = 0u64;
    for t in 0..=depth {
        let mut m = vec![f; aig.len()];
        for &v in aig.inputs() {
            if mark[v as usize] {
                m[v as usize] = SLit::new(s.new_var_default(), true);
            }
        }
        if let Some(prev) = frames.last() {
            for (i, &v) in aig.latches().iter().enumerate() {
                if mark[v as usize] {
                    m[v as usize] = lit(prev, aig.next_of(i));
                }
            }
        }
        for v in 0..aig.len() as u32 {
            if !mark[v as usize] {
                continue;
            }
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
        let before = s.num_propagations();
        let sat = s.solve_limited(&[b]) == lbool::TRUE;
        // At least one unit per query, so that a budget bounds the queries too.
        work += (s.num_propagations() - before).max(1);
        if sat {
            let value = |m: &[SLit], v: u32| mark[v as usize] && s.value_lit(m[v as usize]) == lbool::TRUE;
            let inputs = frames[..t].iter().map(|m| aig.inputs().iter().map(|&v| value(m, v)).collect()).collect();
            return Outcome::Counterexample(inputs);
        }
        let stop = if work > limits.work {
            Some(Stop::Work)
        } else if limits.deadline.is_some_and(|d| Instant::now() >= d) {
            Some(Stop::Deadline)
        } else {
            None
        };
        if stop.is_some() && t < depth {
            return Outcome::Clear { depth: t, work, stop };
        }
    }
    Outcome::Clear { depth, work, stop: None }
}

/// The exploration's verdict on property `index`, made deeper by
/// [`search`] on the circuit when the exploration stopped short of
/// `limits.frames` events: a counterexample the exploration did not reach
/// (replayed on the engine and shrunk), or "no counterexample up to N
/// events" with N the deeper of the two. Any other verdict (a
/// counterexample, a closed space), a property without a bad output (an
/// unbounded `eventually`) or a program without a circuit is left as it is.
pub fn deepen(
    content: &Arc<Content>,
    alphabet: &Arc<Alphabet>,
    model: Option<&Model>,
    index: usize,
    property: &PropertySpec,
    verdict: Verdict,
    limits: Limits,
) -> Verdict {
    let depth = limits.frames;
    let Verdict::Bounded { depth: explored, states, .. } = &verdict else { return verdict };
    let (explored, states) = (*explored, *states);
    let Some(model) = model else { return verdict };
    let Some(bad) = model.bad.get(index).copied().flatten() else { return verdict };
    if explored >= depth {
        return verdict;
    }
    match search(&model.aig, bad, limits) {
        Outcome::Counterexample(inputs) => replayed(content, alphabet, property, model.run_of(alphabet, &inputs)),
        Outcome::Clear { depth: d, stop, .. } if d > explored => {
            let mut note = format!("explored to {explored} events, then the circuit unrolled to {d}, with any gaps");
            if let Some(stop) = stop {
                note.push_str(match stop {
                    Stop::Deadline => " (stopped by the wall-clock guard)",
                    _ => " (stopped by its work budget)",
                });
            }
            if let Some(sampled) = super::prove::sampled(alphabet) {
                note.push_str("; ");
                note.push_str(&sampled);
            }
            Verdict::Bounded { depth: d, states, note }
        }
        Outcome::Clear { .. } => verdict,
    }
}

/// The verdict of a run of the circuit: the property must fail on it on
/// the real engine, where the run is shrunk and replayed.
fn replayed(content: &Arc<Content>, alphabet: &Arc<Alphabet>, property: &PropertySpec, run: Vec<RunStep>) -> Verdict {
    let Err((point, _)) = random::check_run(content, property, &run, &Cell::new(0)) else {
        return Verdict::Disagree { events: run.len() };
    };
    let run = random::shrink(content, alphabet, property, run[..point].to_vec());
    let (point, reason) =
        random::check_run(content, property, &run, &Cell::new(0)).err().unwrap_or((run.len(), String::new()));
    Verdict::Failed(Counterexample::replay(content, &run[..point.min(run.len())], point, reason))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A two-bit counter that counts while its input holds (3 is bad), and
    /// a latch beside it that the bad output never reads.
    fn counter() -> (Aig, Lit) {
        let mut g = Aig::new();
        let go = g.input("go");
        let other = g.input("other");
        let b0 = g.latch("b0");
        let b1 = g.latch("b1");
        let aside = g.latch("aside");
        let n0 = g.xor(b0, go);
        let carry = g.and(b0, go);
        let n1 = g.xor(b1, carry);
        g.set_next(b0, n0);
        g.set_next(b1, n1);
        let n2 = g.xor(aside, other);
        g.set_next(aside, n2);
        let bad = g.and(b0, b1);
        (g, bad)
    }

    #[test]
    fn the_shortest_run_within_the_depth_and_the_depth_cleared() {
        let (g, bad) = counter();
        let clear = search(&g, bad, Limits::frames(2));
        assert!(matches!(clear, Outcome::Clear { depth: 2, stop: None, .. }), "{clear:?}");
        match search(&g, bad, Limits::frames(5)) {
            Outcome::Counterexample(run) => assert_eq!(run, vec![vec![true, false]; 3]),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn the_cone_leaves_out_what_the_bad_output_cannot_see() {
        let (g, bad) = counter();
        let mark = cone(&g, &[bad]);
        let aside = g.latches()[2];
        let other = g.inputs()[1];
        assert!(!mark[aside as usize] && !mark[other as usize]);
        assert!(g.latches()[..2].iter().all(|&v| mark[v as usize]));
    }

    #[test]
    fn a_work_budget_stops_at_the_same_depth_every_time() {
        let (g, bad) = counter();
        let limits = Limits { frames: 2, work: 0, deadline: None };
        let first = search(&g, bad, limits);
        assert!(matches!(first, Outcome::Clear { depth: 0, stop: Some(Stop::Work), .. }), "{first:?}");
        assert_eq!(first, search(&g, bad, limits));
    }
}
