//! The properties in the circuit: their predicates at the point the
//! latches hold, and their monitors ([`Monitor`]) as latches.

use super::{Builder, Obligation, Slot, SlotVal, Unsupported, STALE};
use crate::aig::{not, Aig, Lit, Word, FALSE, TRUE};
use crate::monitor::{Kind, Monitor};
use situ_compiler::bundle::{Behaviour, Mode};
use situ_compiler::spec::{Pred, PropertySpec};

impl Builder<'_> {
    /// A property's premise (true without one) and consequent's predicate
    /// at the point the latches hold.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn preds_of(
        &mut self,
        p: &PropertySpec,
        state: &Word,
        codes: &[usize],
        fsm: &[Option<Word>],
        fsm_code: &[Vec<usize>],
        slots: &[Slot],
        mem: &[SlotVal],
    ) -> Result<(Lit, Lit), Unsupported> {
        let mut preds = p.preds();
        let premise = match &p.premise {
            Some(_) => {
                let pred = preds.next().expect("a premise");
                self.pred(pred, state, codes, fsm, fsm_code, slots, mem)?
            }
            None => TRUE,
        };
        let pred = preds.last().expect("a consequent");
        Ok((premise, self.pred(pred, state, codes, fsm, fsm_code, slots, mem)?))
    }

    /// The obligation of `always (p -> eventually q)` without a bound, as
    /// [`Monitor::step`] keeps it: pending after a point where p held and q
    /// did not, until a point where q holds.
    pub(super) fn obligation(&mut self, k: usize, p: Lit, q: Lit) -> Obligation {
        let aig = &mut self.aig;
        let pending = aig.latch(&format!("p{k}.pending"));
        let either = aig.or(pending, p);
        let now = aig.and(either, not(q));
        aig.set_next(pending, now);
        Obligation { pending, now }
    }

    /// A predicate of a property at the point the latches hold.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn pred(
        &mut self,
        p: &Pred,
        state: &Word,
        codes: &[usize],
        fsm: &[Option<Word>],
        fsm_code: &[Vec<usize>],
        slots: &[Slot],
        mem: &[SlotVal],
    ) -> Result<Lit, Unsupported> {
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
            Pred::Event { event, tests, min_run } => self.pattern(*event, tests, &[], *min_run, None, slots, mem)?,
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
    pub(super) fn monitor(
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
