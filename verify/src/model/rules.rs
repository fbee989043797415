//! The rules in the circuit: each rule's condition on the agents' facts
//! (its patterns, join tests, run lengths, windows, staleness), and the
//! rest: rounds of firing the first activated rule.

use super::recency::Recency;
use super::{Builder, Slot, SlotVal, Unsupported, FACT, MAX_COMBINATIONS, MAX_PAIR_ROUNDS, STALE};
use crate::aig::{not, Lit, Word, FALSE, TRUE};
use situ_compiler::bundle::{AlphaNode, BetaKind, Check, Operand, Test, Value};
use situ_runtime::rete::passes_with;

impl Builder<'_> {
    /// The state at rest from `state` with the memory `mem`, and whether
    /// the rules never come to rest.
    pub(super) fn rest(
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
        // Per rule: the states it may fire in (its state tests, not its target).
        let allowed: Vec<Vec<usize>> = conds
            .iter()
            .enumerate()
            .map(|(r, (_, states))| {
                (0..n)
                    .filter(|&x| {
                        x != c.rules[r].target as usize
                            && states.iter().all(|(positive, ss)| ss.contains(&(x as u32)) == *positive)
                    })
                    .collect()
            })
            .collect();
        let mem: Vec<Lit> = conds.iter().map(|(m, _)| *m).collect();
        let mut s = state.clone();
        for _round in 0..n {
            let sel = s.decode(&mut self.aig, n);
            let acts = self.activated(&mem, &allowed, &sel, codes);
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
        let still = self.activated(&mem, &allowed, &sel, codes);
        let err = self.aig.or_all(still);
        Ok((s, err))
    }

    /// Per rule: whether it is activated in the state `sel` decodes, its
    /// condition on the memory holds and the state is one it may fire in.
    fn activated(&mut self, mem: &[Lit], allowed: &[Vec<usize>], sel: &[Lit], codes: &[usize]) -> Vec<Lit> {
        mem.iter()
            .zip(allowed)
            .map(|(mem_cond, states)| {
                let in_state = self.aig.or_all(states.iter().map(|&x| sel[codes[x]]));
                self.aig.and(*mem_cond, in_state)
            })
            .collect()
    }

    /// Whether the agent of `event` holds a fact of it that passes the
    /// alpha tests, the join tests (against the other agents' facts), the
    /// run length and the window.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn pattern(
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
