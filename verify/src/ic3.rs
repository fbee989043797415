//! Unbounded safety checking of an [`Aig`]: IC3 / property-directed
//! reachability (Bradley 2011; Eén, Mishchenko, Brayton 2011) on the
//! `batsat` SAT solver.
//!
//! Frames F₀ = Init (every latch 0), F₁, …, Fₖ over-approximate the states
//! reachable in 0, ≤ 1, …, ≤ k steps. A state of Fₖ that reaches the bad
//! output is blocked, recursively, by clauses learnt from unsatisfiable
//! one-step queries (relative induction, the query's core shrinking the
//! cube, then one literal at a time). When a frame's clauses all propagate
//! to the next frame, that frame is an inductive invariant that excludes
//! the bad states: the property holds on runs of any length. A blocked
//! cube that reaches F₀ gives a run from the initial state: the inputs of
//! each step, which the caller replays on the real engine.

use super::aig::{Aig, Lit as ALit};
use batsat::{lbool, BasicSolver, Lit, SolverInterface, Var};
use std::collections::BinaryHeap;
use std::time::Instant;

/// How much IC3 may do before it gives up. `frames` and `work` are
/// deterministic: the same circuit and limits give the same outcome on any
/// machine under any load. `deadline` is an outer guard in wall-clock time;
/// reaching it is said as such ([`Stop::Deadline`]).
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// The most frames opened.
    pub frames: usize,
    /// The most work, in SAT propagations summed over every query.
    pub work: u64,
    pub deadline: Option<Instant>,
}

impl Limits {
    /// Frames only (no work budget, no deadline).
    pub fn frames(frames: usize) -> Limits {
        Limits { frames, work: u64::MAX, deadline: None }
    }
}

/// Which limit stopped IC3.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stop {
    Frames,
    Work,
    Deadline,
}

/// What IC3 found.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// No reachable state is bad; `frames` is the depth of the invariant.
    Proved { frames: usize, clauses: usize },
    /// The inputs of each step of a run from the initial state to a bad state.
    Counterexample(Vec<Vec<bool>>),
    /// Stopped at a limit: no bad state is reachable in `depth` steps or
    /// fewer (every frame up to it was cleared), after `work` propagations.
    Unknown { depth: usize, work: u64, stop: Stop },
}

/// A cube: literals over latches (index, value), sorted by index.
type Cube = Vec<(usize, bool)>;

/// The circuit in one solver: one variable per AIG variable.
struct Copy {
    solver: BasicSolver,
    vars: Vec<Var>,
    act: Vec<Lit>,
    /// SAT propagations spent by this copy's queries.
    work: u64,
}

impl Copy {
    fn new(aig: &Aig) -> Copy {
        let mut solver = BasicSolver::default();
        let vars: Vec<Var> = (0..aig.len()).map(|_| solver.new_var_default()).collect();
        let mut c = Copy { solver, vars, act: Vec::new(), work: 0 };
        // Variable 0 is false.
        let f = c.lit(0);
        c.clause(&[!f]);
        for v in 0..aig.len() as u32 {
            if let Some((a, b)) = aig.gate(v) {
                let (x, la, lb) = (c.lit(2 * v), c.lit(a), c.lit(b));
                c.clause(&[!x, la]);
                c.clause(&[!x, lb]);
                c.clause(&[x, !la, !lb]);
            }
        }
        c
    }

    fn lit(&self, l: ALit) -> Lit {
        Lit::new(self.vars[(l >> 1) as usize], l & 1 == 0)
    }

    fn clause(&mut self, ls: &[Lit]) {
        let mut v = ls.to_vec();
        self.solver.add_clause_reuse(&mut v);
    }

    fn solve(&mut self, assumptions: &[Lit]) -> bool {
        let before = self.solver.num_propagations();
        let sat = self.solver.solve_limited(assumptions) == lbool::TRUE;
        // At least one unit per query, so that a budget bounds the queries too.
        self.work += (self.solver.num_propagations() - before).max(1);
        sat
    }

    fn value(&self, l: Lit) -> bool {
        self.solver.value_lit(l) == lbool::TRUE
    }

    /// A fresh literal that switches a temporary clause on.
    fn activation(&mut self) -> Lit {
        let v = self.solver.new_var_default();
        let l = Lit::new(v, true);
        self.act.push(l);
        l
    }

    fn in_core(&self, l: Lit) -> bool {
        self.solver.unsat_core_contains_var(l.var())
    }
}

struct Ic3<'a> {
    aig: &'a Aig,
    bad: ALit,
    /// Per frame k ≥ 1: the clauses (negated cubes) learnt at exactly k.
    delta: Vec<Vec<Cube>>,
    /// One solver per frame (index 0: the initial frame).
    solvers: Vec<Copy>,
    /// For lifting: the circuit alone.
    lift: Copy,
}

#[derive(PartialEq, Eq)]
struct Obligation {
    frame: usize,
    depth: usize,
    cube: Cube,
    /// The obligation this one must reach, and the inputs of that step.
    next: Option<usize>,
}

impl Ord for Obligation {
    fn cmp(&self, o: &Self) -> std::cmp::Ordering {
        // Lowest frame first (a max-heap, so reversed), then shallowest.
        o.frame.cmp(&self.frame).then(o.depth.cmp(&self.depth))
    }
}
impl PartialOrd for Obligation {
    fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(o))
    }
}

/// Checks that `bad` (a function of the latches) never holds; gives up
/// (unknown) at the first limit reached.
pub fn check(aig: &Aig, bad: ALit, limits: Limits) -> Outcome {
    let over = |ic3: &Ic3| -> Option<Stop> {
        if ic3.work() > limits.work {
            Some(Stop::Work)
        } else if limits.deadline.is_some_and(|d| Instant::now() >= d) {
            Some(Stop::Deadline)
        } else {
            None
        }
    };
    let mut ic3 = Ic3 { aig, bad, delta: vec![Vec::new()], solvers: Vec::new(), lift: Copy::new(aig) };
    ic3.push_frame(); // F0
                      // Is an initial state bad?
    let b = ic3.solvers[0].lit(bad);
    if ic3.solvers[0].solve(&[b]) {
        return Outcome::Counterexample(Vec::new());
    }
    ic3.push_frame(); // F1
    let mut trace_inputs: Vec<(Vec<bool>, Option<usize>)> = Vec::new();
    loop {
        let k = ic3.solvers.len() - 1;
        // Block every bad state of F_k.
        while let Some(cube) = ic3.bad_cube(k) {
            let mut heap = BinaryHeap::new();
            let mut store: Vec<(Cube, Option<usize>)> = Vec::new();
            trace_inputs.clear();
            store.push((cube.clone(), None));
            trace_inputs.push((Vec::new(), None));
            heap.push(Obligation { frame: k, depth: 0, cube, next: Some(0) });
            while let Some(ob) = heap.pop() {
                if let Some(stop) = over(&ic3) {
                    return Outcome::Unknown { depth: k - 1, work: ic3.work(), stop };
                }
                let id = ob.next.expect("an id");
                if ob.frame == 0 || Ic3::initial(&ob.cube) {
                    // The cube holds the initial state: a run.
                    let mut inputs = Vec::new();
                    let mut at = Some(id);
                    while let Some(i) = at {
                        let (ins, next) = &trace_inputs[i];
                        if next.is_some() || !ins.is_empty() {
                            inputs.push(ins.clone());
                        }
                        at = *next;
                    }
                    return Outcome::Counterexample(inputs);
                }
                if ic3.blocked_at(&ob.cube, ob.frame) {
                    if ob.frame < k {
                        heap.push(Obligation { frame: ob.frame + 1, ..ob });
                    }
                    continue;
                }
                match ic3.predecessor(&ob.cube, ob.frame) {
                    Some((pred, inputs)) => {
                        let pid = trace_inputs.len();
                        trace_inputs.push((inputs, Some(id)));
                        store.push((pred.clone(), Some(id)));
                        heap.push(Obligation { frame: ob.frame - 1, depth: ob.depth + 1, cube: pred, next: Some(pid) });
                        heap.push(ob);
                    }
                    None => {
                        let g = ic3.generalize(&ob.cube, ob.frame);
                        ic3.add_blocked(g, ob.frame);
                        if ob.frame < k {
                            heap.push(Obligation { frame: ob.frame + 1, ..ob });
                        }
                    }
                }
            }
        }
        if k >= limits.frames {
            return Outcome::Unknown { depth: k, work: ic3.work(), stop: Stop::Frames };
        }
        if let Some(stop) = over(&ic3) {
            return Outcome::Unknown { depth: k, work: ic3.work(), stop };
        }
        ic3.push_frame();
        // Propagate clauses forward; an empty delta closes the proof.
        for j in 1..=k {
            let cubes = std::mem::take(&mut ic3.delta[j]);
            let mut keep = Vec::new();
            for c in cubes {
                if ic3.inductive_at(&c, j) {
                    ic3.add_blocked_only(c, j + 1);
                } else {
                    keep.push(c);
                }
            }
            ic3.delta[j] = keep;
            if ic3.delta[j].is_empty() {
                let clauses = ic3.delta[j + 1..].iter().map(Vec::len).sum();
                return Outcome::Proved { frames: j, clauses };
            }
        }
    }
}

impl Ic3<'_> {
    /// The propagations spent so far by every query.
    fn work(&self) -> u64 {
        self.solvers.iter().map(|s| s.work).sum::<u64>() + self.lift.work
    }

    fn latch_lit(&self, s: &Copy, i: usize, value: bool) -> Lit {
        let l = s.lit(2 * self.aig.latches()[i]);
        if value {
            l
        } else {
            !l
        }
    }

    fn push_frame(&mut self) {
        let mut s = Copy::new(self.aig);
        let k = self.solvers.len();
        if k == 0 {
            for i in 0..self.aig.latches().len() {
                let l = self.latch_lit(&s, i, false);
                s.clause(&[l]);
            }
        } else {
            self.delta.push(Vec::new());
            // F_k holds the clauses of every later frame: none yet.
        }
        self.solvers.push(s);
    }

    /// A bad state of F_k, lifted to a cube.
    fn bad_cube(&mut self, k: usize) -> Option<Cube> {
        let b = self.solvers[k].lit(self.bad);
        if !self.solvers[k].solve(&[b]) {
            return None;
        }
        let full: Cube = (0..self.aig.latches().len())
            .map(|i| {
                let l = self.latch_lit(&self.solvers[k], i, true);
                (i, self.solvers[k].value(l))
            })
            .collect();
        // Lift: the latches that force `bad` on their own.
        let nb = !self.lift.lit(self.bad);
        let assumptions: Vec<Lit> = full.iter().map(|&(i, v)| self.latch_lit(&self.lift, i, v)).collect();
        let mut a = assumptions.clone();
        a.push(nb);
        if self.lift.solve(&a) {
            return Some(full);
        }
        let cube = full.into_iter().zip(&assumptions).filter(|(_, l)| self.lift.in_core(**l)).map(|(c, _)| c).collect();
        Some(cube)
    }

    /// Whether F_k already excludes the cube (syntactically: a learnt clause subsumes it).
    fn blocked_at(&self, cube: &Cube, k: usize) -> bool {
        self.delta[k..].iter().flatten().any(|c| c.iter().all(|x| cube.contains(x)))
    }

    /// A state of F_{k-1} (not in the cube) with inputs that step into the
    /// cube, both lifted; `None` when there is none.
    fn predecessor(&mut self, cube: &Cube, k: usize) -> Option<(Cube, Vec<bool>)> {
        let s = &mut self.solvers[k - 1];
        let act = s.activation();
        let mut clause: Vec<Lit> = vec![!act];
        clause.extend(cube.iter().map(|&(i, v)| !Self::latch_of(self.aig, s, i, v)));
        s.clause(&clause);
        let mut assumptions = vec![act];
        assumptions.extend(cube.iter().map(|&(i, v)| Self::next_of(self.aig, s, i, v)));
        let sat = s.solve(&assumptions);
        let out = if sat {
            let inputs: Vec<bool> = self.aig.inputs().iter().map(|&v| s.value(s.lit(2 * v))).collect();
            let full: Cube =
                (0..self.aig.latches().len()).map(|i| (i, s.value(Self::latch_of(self.aig, s, i, true)))).collect();
            Some((full, inputs))
        } else {
            None
        };
        s.clause(&[!act]);
        let (full, inputs) = out?;
        // Lift: the predecessor's latches that, with these inputs, force the cube.
        let l = &mut self.lift;
        let act = l.activation();
        let mut clause = vec![!act];
        clause.extend(cube.iter().map(|&(i, v)| !Self::next_of(self.aig, l, i, v)));
        l.clause(&clause);
        let mut assumptions = vec![act];
        assumptions.extend(self.aig.inputs().iter().zip(&inputs).map(|(&v, &b)| {
            let x = l.lit(2 * v);
            if b {
                x
            } else {
                !x
            }
        }));
        let latch_lits: Vec<Lit> = full.iter().map(|&(i, v)| Self::latch_of(self.aig, l, i, v)).collect();
        assumptions.extend(&latch_lits);
        let lifted = if l.solve(&assumptions) {
            full
        } else {
            full.into_iter().zip(&latch_lits).filter(|(_, x)| l.in_core(**x)).map(|(c, _)| c).collect()
        };
        l.clause(&[!act]);
        Some((lifted, inputs))
    }

    fn latch_of(aig: &Aig, s: &Copy, i: usize, v: bool) -> Lit {
        let l = s.lit(2 * aig.latches()[i]);
        if v {
            l
        } else {
            !l
        }
    }

    fn next_of(aig: &Aig, s: &Copy, i: usize, v: bool) -> Lit {
        let l = s.lit(aig.next_of(i));
        if v {
            l
        } else {
            !l
        }
    }

    /// Whether ¬cube is inductive relative to F_{k-1}: no step from
    /// F_{k-1} ∧ ¬cube enters the cube. The core of the query is kept in `used`.
    fn relative(&mut self, cube: &Cube, k: usize, used: Option<&mut Vec<bool>>) -> bool {
        let s = &mut self.solvers[k - 1];
        let act = s.activation();
        let mut clause: Vec<Lit> = vec![!act];
        clause.extend(cube.iter().map(|&(i, v)| !Self::latch_of(self.aig, s, i, v)));
        s.clause(&clause);
        let nexts: Vec<Lit> = cube.iter().map(|&(i, v)| Self::next_of(self.aig, s, i, v)).collect();
        let mut assumptions = vec![act];
        assumptions.extend(&nexts);
        let sat = s.solve(&assumptions);
        if !sat {
            if let Some(used) = used {
                *used = nexts.iter().map(|&l| s.in_core(l)).collect();
            }
        }
        s.clause(&[!act]);
        !sat
    }

    /// Whether a cube meets the initial state (every latch 0).
    fn initial(cube: &Cube) -> bool {
        cube.iter().all(|&(_, v)| !v)
    }

    /// A smaller cube still blocked at frame k and disjoint from Init.
    fn generalize(&mut self, cube: &Cube, k: usize) -> Cube {
        let mut used = Vec::new();
        let mut c = cube.clone();
        if self.relative(&c, k, Some(&mut used)) {
            let core: Cube = c.iter().zip(&used).filter(|(_, &u)| u).map(|(x, _)| *x).collect();
            if !Self::initial(&core) && !core.is_empty() {
                c = core;
            } else if let Some(&pos) = c.iter().find(|&&(_, v)| v) {
                let mut with: Cube = core;
                if !with.contains(&pos) {
                    with.push(pos);
                    with.sort_unstable();
                }
                if self.relative(&with, k, None) {
                    c = with;
                }
            }
        }
        // Drop literals one at a time while it stays blocked.
        let mut i = 0;
        while i < c.len() && c.len() > 1 {
            let mut t = c.clone();
            t.remove(i);
            if !Self::initial(&t) && self.relative(&t, k, None) {
                c = t;
            } else {
                i += 1;
            }
        }
        c
    }

    /// Learns ¬cube in frames 1..=k.
    fn add_blocked(&mut self, cube: Cube, k: usize) {
        // Push it as far as it goes.
        let mut k = k;
        while k < self.solvers.len() - 1 && self.relative(&cube, k + 1, None) {
            k += 1;
        }
        self.add_blocked_only(cube, k);
    }

    fn add_blocked_only(&mut self, cube: Cube, k: usize) {
        for j in 1..=k {
            let s = &mut self.solvers[j];
            let clause: Vec<Lit> = cube.iter().map(|&(i, v)| !Self::latch_of(self.aig, s, i, v)).collect();
            s.clause(&clause);
        }
        self.delta[k].push(cube);
    }

    /// Whether the clause ¬cube of frame j holds after a step from F_j.
    fn inductive_at(&mut self, cube: &Cube, j: usize) -> bool {
        let s = &mut self.solvers[j];
        let nexts: Vec<Lit> = cube.iter().map(|&(i, v)| Self::next_of(self.aig, s, i, v)).collect();
        !s.solve(&nexts)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::aig::Word;

    /// A 3-bit counter that counts up when `go` and wraps at 6.
    fn counter(bad_at: usize) -> (Aig, ALit) {
        let mut g = Aig::new();
        let go = g.input("go");
        let w = Word::latches(&mut g, "n", 8);
        let one = Word { bits: vec![go] };
        let sum = w.add(&mut g, &one);
        let six = sum.eq(&mut g, 6);
        let mut next = sum.min_const(&mut g, 7, 3);
        next = Word::mux(&mut g, six, &Word::constant(0, 3), &next);
        for (l, n) in w.bits.iter().zip(&next.bits) {
            g.set_next(*l, *n);
        }
        let bad = w.eq(&mut g, bad_at);
        (g, bad)
    }

    #[test]
    fn a_reachable_bad_state_gives_the_inputs_of_a_run() {
        let (g, bad) = counter(4);
        match check(&g, bad, Limits::frames(20)) {
            Outcome::Counterexample(ins) => {
                assert_eq!(ins.len(), 4, "{ins:?}");
                assert!(ins.iter().all(|i| i == &[true]));
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_unreachable_bad_state_is_proved() {
        let (g, bad) = counter(7);
        assert!(matches!(check(&g, bad, Limits::frames(20)), Outcome::Proved { .. }));
        let (g, _) = counter(0);
        assert!(matches!(check(&g, crate::aig::FALSE, Limits::frames(20)), Outcome::Proved { .. }));
    }

    #[test]
    fn a_work_budget_stops_ic3_at_the_same_point_every_time() {
        // The counter needs 5 steps to reach 5: a tiny budget stops it first.
        let (g, bad) = counter(5);
        let limits = Limits { frames: 20, work: 10, deadline: None };
        let first = check(&g, bad, limits);
        assert!(matches!(first, Outcome::Unknown { stop: Stop::Work, .. }), "{first:?}");
        for _ in 0..5 {
            assert_eq!(check(&g, bad, limits), first);
        }
        // With enough work the same circuit gives its run.
        assert!(matches!(check(&g, bad, Limits::frames(20)), Outcome::Counterexample(_)));
    }

    #[test]
    fn a_past_deadline_is_said_as_such() {
        let (g, bad) = counter(5);
        let limits = Limits { frames: 20, work: u64::MAX, deadline: Some(Instant::now()) };
        assert!(matches!(check(&g, bad, limits), Outcome::Unknown { stop: Stop::Deadline, .. }));
    }
}
