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
//! in (salience, specificity, recency, declaration) order, recency read
//! from latches that keep the order of the latest reports of the agents
//! whose rules may tie ([`recency`]); after as many rounds as there are
//! states a rule still activated means a cascade that never ends, the
//! engine's runtime error, which every property treats as a failure (as
//! the explorer does).
//!
//! - [`rules`]: the rules' conditions on the memory, and the rests;
//! - [`props`]: the properties' predicates and monitors;
//! - [`recency`]: the order of reports.
//!
//! Each property's bad-state output is its monitor failing at the point,
//! or a cascade error. Unbounded `always (P -> eventually Q)` is a
//! liveness property and has no bad-state output: the circuit keeps its
//! obligation ([`Obligation`], P seen and Q not yet), which
//! [`liveness`](super::liveness) turns into a safety check of a larger
//! circuit.
//!
//! The circuit is checked against the real engine by
//! [`Model::simulate`]: the tests walk random runs on both and compare the
//! abstract states point by point.

mod props;
mod recency;
mod rules;

use super::abstraction::Alphabet;
use super::aig::{lit_value, not, Aig, Lit, Word, FALSE};
use super::monitor::Monitor;
use recency::Recency;
use situ_compiler::bundle::{Behaviour, Content, Trigger};
use situ_compiler::spec::PropertySpec;

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
    /// Per property: the obligation of `always (P -> eventually Q)` without
    /// a bound (`None` for every other property).
    pub live: Vec<Option<Obligation>>,
    /// The latches of the abstract state, on which every later point
    /// depends: not the monitors, the last gap or the cascade latch.
    pub system: Vec<Lit>,
    /// The cascade latch: a cascade happened on the way to this point.
    pub err: Lit,
    letter_in: Word,
    gap_in: Word,
    state: Word,
    /// State id → its code (the initial state is 0).
    state_code: Vec<usize>,
    fsm: Vec<Option<Word>>,
    fsm_code: Vec<Vec<usize>>,
    slots: Vec<Slot>,
    order: Recency,
    n_letters: usize,
}

/// The pending obligation of a liveness property in the circuit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Obligation {
    /// The latch: pending after the previous point.
    pub pending: Lit,
    /// Pending after this point: ¬Q ∧ (pending ∨ P), a function of the latches.
    pub now: Lit,
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
        let mut live = Vec::new();
        let mut monitor_next: Vec<(Word, Word)> = Vec::new();
        for (k, p) in properties.iter().enumerate() {
            let m = Monitor::new(p);
            if m.is_liveness() {
                bad.push(None);
                // A predicate the circuit cannot say leaves the property to the explorer.
                let ob = match m.never {
                    true => None,
                    false => b.preds_of(p, &state, &state_code, &fsm, &fsm_code, &slots, &now).ok(),
                };
                live.push(ob.map(|(premise, q)| b.obligation(k, premise, q)));
                continue;
            }
            live.push(None);
            let (premise, q) = b.preds_of(p, &state, &state_code, &fsm, &fsm_code, &slots, &now)?;
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
        let inserted: Vec<SlotVal> = slots.iter().zip(&aged).map(|(s, v)| s.insert(aig, v, &lsel, alphabet)).collect();
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
        let mut system = state.bits.clone();
        system.extend(fsm.iter().flatten().flat_map(|w| w.bits.iter().copied()));
        for s in &slots {
            for w in [&s.kind, &s.letter, &s.run, &s.age] {
                system.extend(&w.bits);
            }
        }
        system.extend(&order.newer);
        Ok(Model {
            aig,
            bad,
            live,
            system,
            err,
            letter_in,
            gap_in,
            state,
            state_code,
            fsm,
            fsm_code,
            slots,
            order,
            n_letters,
        })
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

    /// Which letter (out-of-range values read as 0) and gap the inputs choose
    /// (inputs past the model's own, added by a larger circuit, are ignored).
    pub fn choice(&self, inputs: &[bool]) -> (usize, u64) {
        let n = self.letter_in.bits.len();
        let inputs = &inputs[..(n + self.gap_in.bits.len()).min(inputs.len())];
        let l = inputs[..n].iter().enumerate().map(|(i, &b)| (b as usize) << i).sum::<usize>();
        let g = inputs[n..].iter().enumerate().map(|(i, &b)| (b as u64) << i).sum::<u64>();
        (if l < self.n_letters { l } else { 0 }, g)
    }

    /// The run that a circuit's inputs choose, one event per cycle.
    pub fn run_of(&self, alphabet: &Alphabet, inputs: &[Vec<bool>]) -> Vec<crate::RunStep> {
        inputs
            .iter()
            .map(|i| {
                let (l, gap) = self.choice(i);
                let letter = &alphabet.letters[l];
                crate::RunStep { event: letter.event, payload: letter.payload.clone(), gap }
            })
            .collect()
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
    pub fn key(&self, alphabet: &Alphabet, val: &[bool], out: &mut Vec<u64>) {
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
    fn insert(&self, aig: &mut Aig, v: &SlotVal, lsel: &[Lit], alphabet: &Alphabet) -> SlotVal {
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
