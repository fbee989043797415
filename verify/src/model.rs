//! The abstraction of [`explore`](super::explore) as a circuit: the
//! symbolic model that [`prove`](super::prove) closes for runs of any
//! length and that `situ export --aiger` gives to other model checkers.
//!
//! One clock cycle of the circuit is one point of a run: its latches hold
//! the abstract state ([`Alphabet::key`]) — the state, each FSM's state,
//! per agent its fact (none, stale, or a letter with its run length and
//! age) — plus, per property, its monitor ([`Monitor`]) and the gap that
//! led to the point. Its inputs choose the next event (a letter of the
//! alphabet) and the gap before it. The next-state functions are the
//! engine's step (language reference §10.4) as [`System::post`] drives it:
//!
//! 1. the reporting agent's FSM sees its event;
//! 2. the clock advances by the gap: facts older than `stale after`
//!    expire, ages grow (capped); the rules come to rest;
//! 3. the fact replaces the agent's previous one (run length + 1 for the
//!    same event, else 1); the rules come to rest;
//! 4. if the state changed, every FSM sees the new state.
//!
//! Coming to rest is unrolled: one round fires the activated rule first
//! in (salience, specificity, declaration) order; after as many rounds as
//! there are states a rule still activated means a cascade that never
//! ends, the engine's runtime error, which every property treats as a
//! failure (as the explorer does). A program whose rules can tie on
//! recency is not modelled ([`Model::build`] says why): the circuit would
//! have to keep the order of reports.
//!
//! Each property's bad-state output is its monitor failing at the point,
//! or a cascade error. Unbounded `eventually` is a liveness property and
//! has no bad-state output: only the explorer searches it.
//!
//! The circuit is checked against the real engine by
//! [`Model::simulate`]: the tests walk random runs on both and compare the
//! abstract states point by point.

use super::abstraction::Alphabet;
use super::aig::{lit_value, not, Aig, Lit, Word, FALSE, TRUE};
use super::monitor::{Kind, Monitor};
use situ_compiler::bundle::{AlphaNode, Behaviour, BetaKind, Check, Content, Mode, Operand, Test, Trigger, Value};
use situ_compiler::spec::{Pred, PropertySpec};
use situ_runtime::rete::passes_with;

/// The most rounds of a rest the circuit unrolls (more states: not modelled).
const MAX_STATES: usize = 32;
/// The most (same-class rule pair × state) checks the rests may unroll.
const MAX_PAIR_ROUNDS: usize = 4_000_000;
/// The most letter combinations one join may enumerate.
const MAX_COMBINATIONS: usize = 200_000;

/// An agent's fact, in latches.
#[derive(Debug, Clone)]
struct Slot {
    /// 0 none, 1 stale, 2 a fact.
    kind: Word,
    letter: Word,
    /// Run length − 1.
    run: Word,
    /// Nanoseconds since the fact was posted, capped at `age_cap`.
    age: Word,
    /// The agent's letters (indices into the alphabet).
    letters: Vec<usize>,
    run_cap: u64,
    /// Ages beyond this one are alike.
    age_cap: u64,
    stale_after: Option<u64>,
}

/// A slot's value inside a step (after ageing, after the insertion).
#[derive(Debug, Clone)]
struct SlotVal {
    kind: Word,
    letter: Word,
    run: Word,
    age: Word,
}

const STALE: usize = 1;
const FACT: usize = 2;

/// The circuit of a program's abstraction and its properties.
#[derive(Debug, Clone)]
pub struct Model {
    pub aig: Aig,
    /// Per property: its bad-state output (`None`: a liveness property).
    pub bad: Vec<Option<Lit>>,
    letter_in: Word,
    gap_in: Word,
    state: Word,
    /// State id → its code (the initial state is 0).
    state_code: Vec<usize>,
    fsm: Vec<Option<Word>>,
    fsm_code: Vec<Vec<usize>>,
    slots: Vec<Slot>,
    order: Recency,
    err: Lit,
    n_letters: usize,
}

/// Why a program has no circuit.
#[derive(Debug, Clone, PartialEq)]
pub struct Unsupported(pub String);

/// The code of id `i` when `initial` must be 0: the two swap.
fn code(i: usize, initial: usize) -> usize {
    if i == initial {
        0
    } else if i == 0 {
        initial
    } else {
        i
    }
}

impl Model {
    /// Builds the circuit of the abstraction (`alphabet`) of `c` with the
    /// monitors of `properties`.
    pub fn build(c: &Content, alphabet: &Alphabet, properties: &[&PropertySpec]) -> Result<Model, Unsupported> {
        let n_states = c.states.len();
        if n_states > MAX_STATES {
            return Err(Unsupported(format!("more than {MAX_STATES} states")));
        }
        let mut b = Builder { c, alphabet, aig: Aig::new() };
        let aig = &mut b.aig;
        let n_letters = alphabet.letters.len();
        let letter_in = Word::inputs(aig, "letter", n_letters);
        // The gap is any number of nanoseconds: every duration of the
        // program and the properties fits below its largest value + 1,
        // and a longer gap acts as that one (every age is capped there).
        let max_cap = c
            .agents
            .iter()
            .enumerate()
            .map(|(a, _)| alphabet.age_cap(a as u32))
            .chain(alphabet.gaps.iter().copied())
            .max()
            .unwrap_or(0)
            .max(1);
        let gap_in = Word::inputs_upto(aig, "gap", max_cap);
        let state = Word::latches(aig, "state", n_states);
        let state_code: Vec<usize> = (0..n_states).map(|s| code(s, c.initial as usize)).collect();
        let mut fsm = Vec::new();
        let mut fsm_code = Vec::new();
        for (a, agent) in c.agents.iter().enumerate() {
            match &agent.behaviour {
                Behaviour::Fsm(f) => {
                    fsm.push(Some(Word::latches(aig, &format!("fsm{a}"), f.states.len())));
                    fsm_code.push((0..f.states.len()).map(|s| code(s, f.initial as usize)).collect());
                }
                _ => {
                    fsm.push(None);
                    fsm_code.push(Vec::new());
                }
            }
        }
        let mut slots = Vec::new();
        for (a, agent) in c.agents.iter().enumerate() {
            let letters: Vec<usize> =
                (0..n_letters).filter(|&l| c.events[alphabet.letters[l].event as usize].agent as usize == a).collect();
            let stale_after = agent.stale_after_ns;
            let cap = alphabet.age_cap(a as u32);
            let run_cap = alphabet.run_cap(a as u32);
            slots.push(Slot {
                kind: Word::latches(aig, &format!("kind{a}"), 3),
                letter: Word::latches(aig, &format!("letter{a}"), letters.len()),
                run: Word::latches(aig, &format!("run{a}"), run_cap as usize),
                age: Word::latches_upto(aig, &format!("age{a}"), cap),
                letters,
                run_cap,
                age_cap: cap,
                stale_after,
            });
        }
        let last_gap = Word::latches_upto(aig, "last_gap", max_cap);
        // The order of the latest reports of the agents it matters for:
        // one latch per pair, whether the first reported after the second.
        let order = Recency::latches(aig, alphabet.recency());
        let err = aig.latch("cascade");

        let lsel = letter_in.decode(aig, n_letters);

        // The point's predicates and monitors.
        let now: Vec<SlotVal> = slots.iter().map(|s| s.val()).collect();
        let mut bad = Vec::new();
        let mut monitor_next: Vec<(Word, Word)> = Vec::new();
        for (k, p) in properties.iter().enumerate() {
            let m = Monitor::new(p);
            if m.is_liveness() {
                bad.push(None);
                continue;
            }
            let (premise, q) = {
                let mut preds = p.preds();
                let premise = match &p.premise {
                    Some(_) => {
                        let pred = preds.next().expect("a premise");
                        b.pred(pred, &state, &state_code, &fsm, &fsm_code, &slots, &now)?
                    }
                    None => TRUE,
                };
                let pred = preds.last().expect("a consequent");
                (premise, b.pred(pred, &state, &state_code, &fsm, &fsm_code, &slots, &now)?)
            };
            let (fail, latches, next) = b.monitor(k, m, premise, q, &last_gap)?;
            monitor_next.push((latches, next));
            let bad_k = b.aig.or(fail, err);
            bad.push(Some(bad_k));
        }

        // 1. The reporting agent's FSM sees its event.
        let aig = &mut b.aig;
        let mut fsm1: Vec<Option<Word>> = Vec::new();
        for (a, agent) in c.agents.iter().enumerate() {
            let (Behaviour::Fsm(f), Some(w)) = (&agent.behaviour, &fsm[a]) else {
                fsm1.push(None);
                continue;
            };
            let cur = w.decode(aig, f.states.len());
            let mut cases = Vec::new();
            for (from_code, &at) in cur.iter().enumerate() {
                let from = fsm_code[a][from_code]; // the code map is its own inverse
                for l in &slots[a].letters {
                    let event = alphabet.letters[*l].event;
                    let to = f
                        .transitions
                        .iter()
                        .find(|t| t.from as usize == from && matches!(t.trigger, Trigger::Event(e) if e == event))
                        .map_or(from, |t| t.to as usize);
                    let cond = aig.and(at, lsel[*l]);
                    cases.push((cond, fsm_code[a][to]));
                }
                let mine = aig.or_all(slots[a].letters.iter().map(|&l| lsel[l]));
                let cond = aig.and(at, not(mine));
                cases.push((cond, fsm_code[a][from]));
            }
            fsm1.push(Some(Word::select(aig, w.bits.len(), &cases)));
        }

        // 2. Ageing and expiry, then rest.
        let aged: Vec<SlotVal> = slots.iter().map(|s| s.age(aig, &gap_in)).collect();
        let (s1, err1) = b.rest(&state, &state_code, &slots, &aged, &order)?;
        // 3. The new fact, then rest.
        let aig = &mut b.aig;
        let inserted: Vec<SlotVal> =
            slots.iter().zip(&aged).map(|(s, v)| s.insert(aig, v, &lsel, alphabet, c)).collect();
        let order2 = order.after(aig, &slots, &lsel);
        let (s2, err2) = b.rest(&s1, &state_code, &slots, &inserted, &order2)?;
        // 4. The FSMs see a new state.
        let aig = &mut b.aig;
        let s2_sel = s2.decode(aig, n_states);
        let old_sel = state.decode(aig, n_states);
        let same: Vec<Lit> = (0..n_states).map(|k| aig.and(s2_sel[k], old_sel[k])).collect();
        let changed = not(aig.or_all(same));
        let mut fsm2 = Vec::new();
        for (a, agent) in c.agents.iter().enumerate() {
            let (Behaviour::Fsm(f), Some(w)) = (&agent.behaviour, &fsm1[a]) else {
                fsm2.push(None);
                continue;
            };
            let cur = w.decode(aig, f.states.len());
            let mut cases = Vec::new();
            for (from_code, &at) in cur.iter().enumerate() {
                let from = fsm_code[a][from_code]; // the code map is its own inverse
                for s in 0..n_states {
                    let to = f
                        .transitions
                        .iter()
                        .find(|t| {
                            t.from as usize == from
                                && matches!(&t.trigger, Trigger::States(ss) if ss.contains(&(s as u32)))
                        })
                        .map_or(from, |t| t.to as usize);
                    let at_s = aig.and(at, s2_sel[state_code[s]]);
                    let moved = aig.and(at_s, changed);
                    let stay = aig.and(at_s, not(changed));
                    cases.push((moved, fsm_code[a][to]));
                    cases.push((stay, fsm_code[a][from]));
                }
            }
            fsm2.push(Some(Word::select(aig, w.bits.len(), &cases)));
        }

        // The next state of every latch.
        set_word(aig, &state, &s2);
        for (a, w) in fsm.iter().enumerate() {
            if let (Some(w), Some(n)) = (w, &fsm2[a]) {
                set_word(aig, w, n);
            }
        }
        for (s, v) in slots.iter().zip(&inserted) {
            set_word(aig, &s.kind, &v.kind);
            set_word(aig, &s.letter, &v.letter);
            set_word(aig, &s.run, &v.run);
            set_word(aig, &s.age, &v.age);
        }
        set_word(aig, &last_gap, &gap_in);
        for (l, n) in order.newer.iter().zip(&order2.newer) {
            aig.set_next(*l, *n);
        }
        let e = aig.or(err1, err2);
        let e = aig.or(e, err);
        aig.set_next(err, e);
        for (latches, next) in &monitor_next {
            set_word(aig, latches, next);
        }
        let aig = b.aig;
        Ok(Model { aig, bad, letter_in, gap_in, state, state_code, fsm, fsm_code, slots, order, err, n_letters })
    }

    /// The inputs that choose `letter` after a gap of `gap` ns (capped).
    pub fn inputs(&self, letter: usize, gap: u64) -> Vec<bool> {
        let w = self.gap_in.bits.len();
        let gap = if w >= 64 { gap } else { gap.min((1u64 << w) - 1) };
        let mut v = Vec::new();
        v.extend((0..self.letter_in.bits.len()).map(|i| letter >> i & 1 == 1));
        v.extend((0..w).map(|i| gap >> i & 1 == 1));
        v
    }

    /// Which letter (out-of-range values read as 0) and gap the inputs choose.
    pub fn choice(&self, inputs: &[bool]) -> (usize, u64) {
        let n = self.letter_in.bits.len();
        let l = inputs[..n].iter().enumerate().map(|(i, &b)| (b as usize) << i).sum::<usize>();
        let g = inputs[n..].iter().enumerate().map(|(i, &b)| (b as u64) << i).sum::<u64>();
        (if l < self.n_letters { l } else { 0 }, g)
    }

    /// One cycle: the latches after these inputs, and the value of every variable now.
    pub fn simulate(&self, latches: &[bool], inputs: &[bool]) -> (Vec<bool>, Vec<bool>) {
        let val = self.aig.eval(inputs, latches);
        let next = (0..self.aig.latches().len()).map(|i| lit_value(&val, self.aig.next_of(i))).collect();
        (next, val)
    }

    /// Whether a cascade error happened on the way to this point.
    pub fn cascade(&self, val: &[bool]) -> bool {
        lit_value(val, self.err)
    }

    /// The abstract state the latches hold, as [`Alphabet::key`] writes it.
    pub fn key(&self, c: &Content, alphabet: &Alphabet, val: &[bool], out: &mut Vec<u64>) {
        out.clear();
        let s = self.state.value(val);
        out.push(self.state_code.iter().position(|&k| k == s).unwrap_or(usize::MAX) as u64);
        for (a, slot) in self.slots.iter().enumerate() {
            if let Some(w) = &self.fsm[a] {
                let k = w.value(val);
                out.push(self.fsm_code[a].iter().position(|&x| x == k).unwrap_or(usize::MAX) as u64);
            }
            match slot.kind.value(val) {
                STALE => out.push(u64::MAX),
                FACT => {
                    let letter = &alphabet.letters[slot.letters[slot.letter.value(val)]];
                    out.push(letter.event as u64);
                    for (i, v) in letter.payload.iter().enumerate() {
                        out.push(alphabet.class_of(letter.event, i, *v).map_or(u64::MAX, |k| k as u64));
                    }
                    out.push(slot.run.value(val) as u64 + 1);
                    out.push(slot.age.value(val) as u64);
                }
                _ => out.push(u64::MAX - 1), // none
            }
        }
        // The agents of the order that hold a fact, oldest report first.
        let mut with: Vec<u32> =
            self.order.agents.iter().copied().filter(|&a| self.slots[a as usize].kind.value(val) == FACT).collect();
        with.sort_by(|&x, &y| {
            if x == y {
                std::cmp::Ordering::Equal
            } else if lit_value(val, self.order.newer(x, y)) {
                std::cmp::Ordering::Greater
            } else {
                std::cmp::Ordering::Less
            }
        });
        out.extend(with.iter().map(|&a| a as u64));
        let _ = c;
    }
}

fn set_word(aig: &mut Aig, latches: &Word, next: &Word) {
    for (l, n) in latches.bits.iter().zip(&next.bits) {
        aig.set_next(*l, *n);
    }
}

impl Slot {
    fn val(&self) -> SlotVal {
        SlotVal { kind: self.kind.clone(), letter: self.letter.clone(), run: self.run.clone(), age: self.age.clone() }
    }

    /// The slot after the clock moved by the gap.
    fn age(&self, aig: &mut Aig, gap: &Word) -> SlotVal {
        let is_fact = self.kind.eq(aig, FACT);
        let raw = self.age.add(aig, gap);
        let expired = match self.stale_after {
            Some(s) => raw.gt(aig, s),
            None => FALSE,
        };
        let expired = aig.and(expired, is_fact);
        let age = raw.min_const(aig, self.age_cap, self.age.bits.len());
        let keep = not(expired);
        let zero = |w: &Word| Word::constant(0, w.bits.len());
        let stale = Word::constant(STALE, 2);
        SlotVal {
            kind: Word::mux(aig, expired, &stale, &self.kind),
            letter: Word::mux(aig, keep, &self.letter, &zero(&self.letter)),
            run: Word::mux(aig, keep, &self.run, &zero(&self.run)),
            age: Word::mux(aig, keep, &age, &zero(&self.age)),
        }
    }

    /// The slot after the chosen letter was posted (unchanged for another agent's).
    fn insert(&self, aig: &mut Aig, v: &SlotVal, lsel: &[Lit], alphabet: &Alphabet, c: &Content) -> SlotVal {
        let mine: Vec<Lit> = self.letters.iter().map(|&l| lsel[l]).collect();
        let ins = aig.or_all(mine.iter().copied());
        let was_fact = v.kind.eq(aig, FACT);
        let cur = v.letter.decode(aig, self.letters.len());
        let mut same = Vec::new();
        for (j, &lj) in self.letters.iter().enumerate() {
            for (i, &li) in self.letters.iter().enumerate() {
                if alphabet.letters[lj].event == alphabet.letters[li].event {
                    let x = aig.and(cur[j], mine[i]);
                    same.push(x);
                }
            }
        }
        let same = aig.or_all(same);
        let same = aig.and(same, was_fact);
        let run_sel = v.run.decode(aig, self.run_cap as usize);
        let inc: Vec<(Lit, usize)> =
            run_sel.iter().enumerate().map(|(r, &at)| (at, (r + 1).min(self.run_cap as usize - 1))).collect();
        let inc = Word::select(aig, self.run.bits.len(), &inc);
        let one = Word::constant(0, self.run.bits.len());
        let new_run = Word::mux(aig, same, &inc, &one);
        let letter_cases: Vec<(Lit, usize)> = mine.iter().enumerate().map(|(i, &l)| (l, i)).collect();
        let new_letter = Word::select(aig, self.letter.bits.len(), &letter_cases);
        let _ = c;
        SlotVal {
            kind: Word::mux(aig, ins, &Word::constant(FACT, 2), &v.kind),
            letter: Word::mux(aig, ins, &new_letter, &v.letter),
            run: Word::mux(aig, ins, &new_run, &v.run),
            age: Word::mux(aig, ins, &Word::constant(0, self.age.bits.len()), &v.age),
        }
    }
}

struct Builder<'a> {
    c: &'a Content,
    alphabet: &'a Alphabet,
    aig: Aig,
}

impl Builder<'_> {
    /// The state at rest from `state` with the memory `mem`, and whether
    /// the rules never come to rest.
    fn rest(
        &mut self,
        state: &Word,
        codes: &[usize],
        slots: &[Slot],
        mem: &[SlotVal],
        order: &Recency,
    ) -> Result<(Word, Lit), Unsupported> {
        let c = self.c;
        let net = &c.network;
        // Per rule: the condition on the memory, and the states it allows.
        let mut conds = Vec::new();
        for t in &net.terminals {
            let mut states: Vec<(bool, Vec<u32>)> = Vec::new();
            let mut memory = Vec::new();
            let mut at = Some(t.beta);
            while let Some(bi) = at {
                let node = &net.beta[bi as usize];
                let positive = node.kind == BetaKind::Join;
                match &net.alpha[node.alpha as usize] {
                    AlphaNode::State { states: ss } => states.push((positive, ss.clone())),
                    AlphaNode::Stale { agent } => {
                        let s = mem[*agent as usize].kind.eq(&mut self.aig, STALE);
                        memory.push(if positive { s } else { not(s) });
                    }
                    AlphaNode::Event { event, tests, min_run, within_ns } => {
                        let m = self.pattern(*event, tests, &node.tests, *min_run, *within_ns, slots, mem)?;
                        memory.push(if positive { m } else { not(m) });
                    }
                }
                at = node.parent;
            }
            let mem_cond = self.aig.and_all(memory);
            conds.push((mem_cond, states));
        }
        let n = c.states.len();
        // Which rule beats which when both are activated, from the order of
        // reports where salience and specificity tie (§10.4).
        let class = |r: usize| (c.rules[r].salience, c.rules[r].specificity);
        let rules = c.rules.len();
        // The rules by class, highest first; within a class, which beats which.
        let mut classes: Vec<(i64, u32)> = (0..rules).map(class).collect();
        classes.sort_unstable_by(|a, b| b.cmp(a));
        classes.dedup();
        let members: Vec<Vec<usize>> =
            classes.iter().map(|k| (0..rules).filter(|&r| class(r) == *k).collect()).collect();
        let pairs: usize = members.iter().map(|m| m.len() * m.len()).sum();
        if pairs.saturating_mul(n) > MAX_PAIR_ROUNDS {
            return Err(Unsupported(format!(
                "{rules} rules in {} salience and specificity classes over {n} states: too large a circuit",
                classes.len()
            )));
        }
        let beats: Vec<Vec<Lit>> = members
            .iter()
            .map(|m| {
                let mut b = Vec::with_capacity(m.len() * m.len());
                for &x in m {
                    for &y in m {
                        b.push(if x == y {
                            FALSE
                        } else {
                            order.beats(&mut self.aig, &c.rules[x].matches, &c.rules[y].matches, x < y)
                        });
                    }
                }
                b
            })
            .collect();
        let mut s = state.clone();
        for _round in 0..n {
            let sel = s.decode(&mut self.aig, n);
            let acts: Vec<Lit> = (0..c.rules.len())
                .map(|r| {
                    let (mem_cond, states) = &conds[r];
                    let target = c.rules[r].target as usize;
                    let mut ok = vec![true; n];
                    for (positive, ss) in states {
                        for (x, allowed) in ok.iter_mut().enumerate() {
                            *allowed &= ss.contains(&(x as u32)) == *positive;
                        }
                    }
                    ok[target] = false;
                    let in_state = self.aig.or_all((0..n).filter(|&x| ok[x]).map(|x| sel[codes[x]]));
                    self.aig.and(*mem_cond, in_state)
                })
                .collect();
            let mut cases = Vec::new();
            // Whether a rule of a higher class is activated.
            let mut higher = FALSE;
            for (k, m) in members.iter().enumerate() {
                for (i, &r) in m.iter().enumerate() {
                    let same: Vec<Lit> = m
                        .iter()
                        .enumerate()
                        .filter(|&(_, &x)| x != r)
                        .map(|(j, &x)| self.aig.and(acts[x], beats[k][j * m.len() + i]))
                        .collect();
                    let same = self.aig.or_all(same);
                    let beaten = self.aig.or(higher, same);
                    let fires = self.aig.and(acts[r], not(beaten));
                    cases.push((fires, codes[c.rules[r].target as usize]));
                }
                let here = self.aig.or_all(m.iter().map(|&r| acts[r]));
                higher = self.aig.or(higher, here);
            }
            let any = self.aig.or_all(acts.iter().copied());
            let moved = Word::select(&mut self.aig, s.bits.len(), &cases);
            s = Word::mux(&mut self.aig, any, &moved, &s);
        }
        // Still activated after as many firings as states: it never rests.
        let sel = s.decode(&mut self.aig, n);
        let mut still = Vec::new();
        for (r, (mem_cond, states)) in conds.iter().enumerate() {
            let target = c.rules[r].target as usize;
            let mut ok = vec![true; n];
            for (positive, ss) in states {
                for (x, allowed) in ok.iter_mut().enumerate() {
                    *allowed &= ss.contains(&(x as u32)) == *positive;
                }
            }
            ok[target] = false;
            let in_state = self.aig.or_all((0..n).filter(|&x| ok[x]).map(|x| sel[codes[x]]));
            let act = self.aig.and(*mem_cond, in_state);
            still.push(act);
        }
        let err = self.aig.or_all(still);
        Ok((s, err))
    }

    /// Whether the agent of `event` holds a fact of it that passes the
    /// alpha tests, the join tests (against the other agents' facts), the
    /// run length and the window.
    #[allow(clippy::too_many_arguments)]
    fn pattern(
        &mut self,
        event: u32,
        tests: &[Test],
        joins: &[Test],
        min_run: u64,
        within: Option<u64>,
        slots: &[Slot],
        mem: &[SlotVal],
    ) -> Result<Lit, Unsupported> {
        let c = self.c;
        let a = c.events[event as usize].agent as usize;
        let slot = &slots[a];
        let v = &mem[a];
        // The other agents the join tests read.
        let mut others: Vec<usize> = Vec::new();
        for t in joins.iter().chain(tests) {
            for o in operands(&t.check) {
                if let Operand::Fact { agent, .. } = o {
                    if *agent as usize != a && !others.contains(&(*agent as usize)) {
                        others.push(*agent as usize);
                    }
                }
            }
        }
        let combos: usize = others.iter().map(|&o| slots[o].letters.len().max(1)).product();
        if combos.saturating_mul(slot.letters.len()) > MAX_COMBINATIONS {
            return Err(Unsupported("a join over too many combinations of values".into()));
        }
        let own_sel = v.letter.decode(&mut self.aig, slot.letters.len());
        let other_sel: Vec<Vec<Lit>> =
            others.iter().map(|&o| mem[o].letter.decode(&mut self.aig, slots[o].letters.len())).collect();
        let mut matches = Vec::new();
        for (j, &l) in slot.letters.iter().enumerate() {
            let letter = &self.alphabet.letters[l];
            if letter.event != event {
                continue;
            }
            let mut idx = vec![0usize; others.len()];
            loop {
                let fact = |agent: u32| -> Option<&[Value]> {
                    if agent as usize == a {
                        return Some(&letter.payload);
                    }
                    let k = others.iter().position(|&o| o == agent as usize)?;
                    let ol = *slots[others[k]].letters.get(idx[k])?;
                    Some(&self.alphabet.letters[ol].payload)
                };
                if tests.iter().chain(joins).all(|t| check(t, &letter.payload, &fact)) {
                    let mut conj = vec![own_sel[j]];
                    conj.extend(idx.iter().enumerate().map(|(k, &i)| other_sel[k].get(i).copied().unwrap_or(FALSE)));
                    let m = self.aig.and_all(conj);
                    matches.push(m);
                }
                // The next combination.
                let mut k = 0;
                while k < idx.len() {
                    idx[k] += 1;
                    if idx[k] < slots[others[k]].letters.len() {
                        break;
                    }
                    idx[k] = 0;
                    k += 1;
                }
                if k == idx.len() {
                    break;
                }
            }
        }
        let letter_ok = self.aig.or_all(matches);
        let is_fact = v.kind.eq(&mut self.aig, FACT);
        let run_sel = v.run.decode(&mut self.aig, slot.run_cap as usize);
        let run_ok =
            self.aig.or_all((0..slot.run_cap as usize).filter(|&r| r as u64 + 1 >= min_run).map(|r| run_sel[r]));
        let age_ok = match within {
            None => TRUE,
            Some(w) => not(v.age.gt(&mut self.aig, w)),
        };
        Ok(self.aig.and_all([is_fact, letter_ok, run_ok, age_ok]))
    }

    /// A predicate of a property at the point the latches hold.
    #[allow(clippy::too_many_arguments)]
    fn pred(
        &mut self,
        p: &Pred,
        state: &Word,
        codes: &[usize],
        fsm: &[Option<Word>],
        fsm_code: &[Vec<usize>],
        slots: &[Slot],
        mem: &[SlotVal],
    ) -> Result<Lit, Unsupported> {
        let c = self.c;
        Ok(match p {
            Pred::Or(ps) => {
                let ls = ps
                    .iter()
                    .map(|q| self.pred(q, state, codes, fsm, fsm_code, slots, mem))
                    .collect::<Result<Vec<_>, _>>()?;
                self.aig.or_all(ls)
            }
            Pred::And(ps) => {
                let ls = ps
                    .iter()
                    .map(|q| self.pred(q, state, codes, fsm, fsm_code, slots, mem))
                    .collect::<Result<Vec<_>, _>>()?;
                self.aig.and_all(ls)
            }
            Pred::Not(q) => not(self.pred(q, state, codes, fsm, fsm_code, slots, mem)?),
            Pred::Bool(b) => {
                if *b {
                    TRUE
                } else {
                    FALSE
                }
            }
            Pred::State(ss) => {
                let ls: Vec<Lit> = ss.iter().map(|&s| state.eq(&mut self.aig, codes[s as usize])).collect();
                self.aig.or_all(ls)
            }
            Pred::Mode { agent, mode } => {
                let m = *mode;
                self.action_holds(*agent, state, codes, fsm, fsm_code, |a| a.map_or(Mode::Sleeping, |a| a.mode) == m)
            }
            Pred::Link { from, to } => {
                let (from, to) = (*from, *to);
                let out = self.action_holds(from, state, codes, fsm, fsm_code, |a| {
                    a.is_some_and(|a| a.mode == Mode::Running && a.to.contains(&to))
                });
                let inc = self.action_holds(to, state, codes, fsm, fsm_code, |a| {
                    a.is_some_and(|a| a.mode == Mode::Running && a.from.contains(&from))
                });
                self.aig.or(out, inc)
            }
            Pred::Stale(a) => mem[*a as usize].kind.eq(&mut self.aig, STALE),
            Pred::Event { event, tests, min_run } => {
                let _ = c;
                self.pattern(*event, tests, &[], *min_run, None, slots, mem)?
            }
        })
    }

    /// Whether the agent's action now passes `f` (its table by the state,
    /// its FSM by its FSM state).
    fn action_holds(
        &mut self,
        agent: u32,
        state: &Word,
        codes: &[usize],
        fsm: &[Option<Word>],
        fsm_code: &[Vec<usize>],
        f: impl Fn(Option<&situ_compiler::bundle::Action>) -> bool,
    ) -> Lit {
        let c = self.c;
        match &c.agents[agent as usize].behaviour {
            Behaviour::Always => {
                let always = situ_compiler::bundle::Action {
                    mode: Mode::Running,
                    function: None,
                    from: Vec::new(),
                    to: Vec::new(),
                };
                if f(Some(&always)) {
                    TRUE
                } else {
                    FALSE
                }
            }
            Behaviour::Table { actions } => {
                let ls: Vec<Lit> = (0..c.states.len())
                    .filter(|&s| f(actions.get(s).and_then(|a| a.as_ref())))
                    .map(|s| state.eq(&mut self.aig, codes[s]))
                    .collect();
                self.aig.or_all(ls)
            }
            Behaviour::Fsm(m) => {
                let w = fsm[agent as usize].as_ref().expect("an FSM's latches");
                let ls: Vec<Lit> = (0..m.states.len())
                    .filter(|&s| f(Some(&m.states[s].action)))
                    .map(|s| w.eq(&mut self.aig, fsm_code[agent as usize][s]))
                    .collect();
                self.aig.or_all(ls)
            }
        }
    }

    /// A property's monitor: whether it fails at this point, its latches
    /// and their next values.
    fn monitor(
        &mut self,
        k: usize,
        m: Monitor,
        p: Lit,
        q: Lit,
        last_gap: &Word,
    ) -> Result<(Lit, Word, Word), Unsupported> {
        let aig = &mut self.aig;
        match m.kind {
            Kind::Now => {
                let fail = if m.never { aig.or(not(p), q) } else { aig.and(p, not(q)) };
                Ok((fail, Word::default(), Word::default()))
            }
            Kind::Next => {
                let pending = aig.latch(&format!("p{k}.pending"));
                let wrong = if m.never { q } else { not(q) };
                let late = aig.and(pending, wrong);
                let fail = if m.never { aig.or(late, not(p)) } else { late };
                Ok((fail, Word { bits: vec![pending] }, Word { bits: vec![p] }))
            }
            Kind::Eventually { events, nanos } => {
                let pending = aig.latch(&format!("p{k}.pending"));
                let ev_max = events.map_or(0, |n| n as usize + 1);
                let ev = Word::latches(aig, &format!("p{k}.events"), ev_max + 1);
                // The elapsed time, capped just past the bound.
                let ns_cap = nanos.map_or(0, |d| d.saturating_add(1));
                let ns = Word::latches_upto(aig, &format!("p{k}.nanos"), ns_cap);
                let ev_sel = ev.decode(aig, ev_max + 1);
                // Advanced counters.
                let ev_cases: Vec<(Lit, usize)> =
                    ev_sel.iter().enumerate().map(|(e, &at)| (at, (e + 1).min(ev_max))).collect();
                let ev_adv = Word::select(aig, ev.bits.len(), &ev_cases);
                let raw = ns.add(aig, last_gap);
                let ns_adv = raw.min_const(aig, ns_cap, ns.bits.len());
                let time_out = match nanos {
                    Some(d) => raw.gt(aig, d),
                    None => FALSE,
                };
                let ev_reached = |aig: &mut Aig, min: usize| {
                    let ls: Vec<Lit> = ev_sel
                        .iter()
                        .enumerate()
                        .filter(|(e, _)| (e + 1).min(ev_max) >= min)
                        .map(|(_, &l)| l)
                        .collect();
                    aig.or_all(ls)
                };
                let zero_ev = Word::constant(0, ev.bits.len());
                let zero_ns = Word::constant(0, ns.bits.len());
                if !m.never {
                    let count_out = match events {
                        Some(n) => ev_reached(aig, n as usize),
                        None => FALSE,
                    };
                    let t1 = aig.and(pending, time_out);
                    let t2a = aig.and(pending, not(time_out));
                    let t2b = aig.and(t2a, not(q));
                    let t2 = aig.and(t2b, count_out);
                    let fail = aig.or(t1, t2);
                    // Still pending after this point.
                    let keep = aig.and(t2b, not(count_out));
                    let start_a = aig.and(not(keep), p);
                    let start = aig.and(start_a, not(q));
                    let next_pending = aig.or(keep, start);
                    let ev_next = Word::mux(aig, keep, &ev_adv, &zero_ev);
                    let ns_next = Word::mux(aig, keep, &ns_adv, &zero_ns);
                    let mut latches = vec![pending];
                    latches.extend(&ev.bits);
                    latches.extend(&ns.bits);
                    let mut next = vec![next_pending];
                    next.extend(&ev_next.bits);
                    next.extend(&ns_next.bits);
                    Ok((fail, Word { bits: latches }, Word { bits: next }))
                } else {
                    let count_over = match events {
                        Some(n) => ev_reached(aig, n as usize + 1),
                        None => FALSE,
                    };
                    let expired = aig.or(time_out, count_over);
                    let live = aig.and(pending, not(expired));
                    let late = aig.and(live, q);
                    let f1 = aig.or(late, not(p));
                    let fail = aig.or(f1, q);
                    let mut latches = vec![pending];
                    latches.extend(&ev.bits);
                    latches.extend(&ns.bits);
                    let mut next = vec![TRUE];
                    next.extend(&zero_ev.bits);
                    next.extend(&zero_ns.bits);
                    Ok((fail, Word { bits: latches }, Word { bits: next }))
                }
            }
        }
    }
}

fn operands(ch: &Check) -> Vec<&Operand> {
    match ch {
        Check::Compare { rhs, .. } => vec![rhs],
        Check::Range { lo, hi, .. } => vec![lo, hi],
    }
}

/// A test on a fact's field, its operands read from the fact itself or
/// from other agents' facts (as the engine's join does).
fn check<'a>(t: &Test, own: &[Value], fact: &dyn Fn(u32) -> Option<&'a [Value]>) -> bool {
    passes_with(t, own, |agent, field| fact(agent).and_then(|p| p.get(field as usize).copied()))
}

/// The order of the latest reports of some agents: for each pair (a, b),
/// a < b, a latch that holds when a reported after b.
#[derive(Debug, Clone)]
struct Recency {
    agents: Vec<u32>,
    newer: Vec<Lit>,
}

impl Recency {
    fn latches(aig: &mut Aig, agents: &[u32]) -> Recency {
        let mut newer = Vec::new();
        for (i, a) in agents.iter().enumerate() {
            for b in &agents[i + 1..] {
                newer.push(aig.latch(&format!("newer{a}_{b}")));
            }
        }
        Recency { agents: agents.to_vec(), newer }
    }

    fn pair(&self, a: u32, b: u32) -> Option<usize> {
        let i = self.agents.iter().position(|&x| x == a)?;
        let j = self.agents.iter().position(|&x| x == b)?;
        let (i, j) = (i.min(j), i.max(j));
        let k = self.agents.len();
        Some(i * k - i * (i + 1) / 2 + (j - i - 1))
    }

    /// Whether `a` reported after `b` (both in the order).
    fn newer(&self, a: u32, b: u32) -> Lit {
        let ia = self.agents.iter().position(|&x| x == a);
        let ib = self.agents.iter().position(|&x| x == b);
        match (self.pair(a, b), ia < ib) {
            (Some(p), true) => self.newer[p],
            (Some(p), false) => not(self.newer[p]),
            (None, _) => FALSE,
        }
    }

    /// The order after the chosen letter's agent reported.
    fn after(&self, aig: &mut Aig, slots: &[Slot], lsel: &[Lit]) -> Recency {
        let reports: Vec<Lit> =
            self.agents.iter().map(|&a| aig.or_all(slots[a as usize].letters.iter().map(|&l| lsel[l]))).collect();
        let mut newer = Vec::new();
        for i in 0..self.agents.len() {
            for j in i + 1..self.agents.len() {
                let old = self.newer[newer.len()];
                // a_i reports: it is newer; a_j reports: it is; else unchanged.
                let x = aig.mux(reports[j], FALSE, old);
                newer.push(aig.mux(reports[i], TRUE, x));
            }
        }
        Recency { agents: self.agents.clone(), newer }
    }

    /// Whether rule x (matching the agents `mx`) beats rule y (`my`) of the
    /// same salience and specificity: the newest report among both is only
    /// x's (rules matching no fact come last), or neither's alone and x is
    /// declared first.
    fn beats(&self, aig: &mut Aig, mx: &[u32], my: &[u32], first: bool) -> Lit {
        let all: Vec<u32> = mx.iter().chain(my).copied().collect();
        let tracked = all.iter().all(|a| self.agents.contains(a));
        if !tracked {
            // These two never tie on recency (see `Alphabet::recency`).
            return if first { TRUE } else { FALSE };
        }
        let newest_only = |aig: &mut Aig, own: &[u32], other: &[u32]| {
            let cands: Vec<Lit> = own
                .iter()
                .filter(|a| !other.contains(a))
                .map(|&a| {
                    let ls: Vec<Lit> = all.iter().filter(|&&b| b != a).map(|&b| self.newer(a, b)).collect();
                    aig.and_all(ls)
                })
                .collect();
            aig.or_all(cands)
        };
        let x_wins = newest_only(aig, mx, my);
        let y_wins = newest_only(aig, my, mx);
        let tie = aig.and(not(x_wins), not(y_wins));
        let by_order = if first { tie } else { FALSE };
        aig.or(x_wins, by_order)
    }
}
