//! Memories in which a rule is activated but other rules are not: the
//! shared search behind shadowing (W0303) and oscillation (E0305). A rule is
//! not activated when one of its conditions fails, so for each rule to avoid
//! the search picks a condition to falsify, depth first, within a budget.

use super::situation::{AgentReq, Situation, Witness};
use crate::model::*;
use std::collections::BTreeSet;

/// How the search ended.
#[derive(Debug)]
pub enum Outcome {
    /// A memory in the situation where none of the rules is activated.
    Found(Witness),
    /// Every memory of the situation activates one of the rules.
    None,
    /// The budget ran out: undecided.
    Unknown,
}

/// Searches `sit` for a memory that activates none of `avoid` (in the state
/// of the memory; a rule whose target is that state is not activated).
pub fn avoiding(model: &Model, sit: &Situation, avoid: &[&Rule], budget: &mut usize) -> Outcome {
    search(model, sit, avoid, true, budget)
}

/// As [`avoiding`], with the state of the memory fixed by the caller: the
/// rules must fail on their events, not on their state guards.
pub fn avoiding_in_state(model: &Model, sit: &Situation, avoid: &[&Rule], budget: &mut usize) -> Outcome {
    search(model, sit, avoid, false, budget)
}

/// Drops the rules that can be avoided on their own, whatever the others
/// need: a rule with a pattern on an agent that neither the situation nor
/// any other rule's falsification can force to report is not activated when
/// that agent has no fact, and leaving an agent without a fact satisfies
/// every `not` pattern. This keeps the search small on large rule bases,
/// and it is exact.
pub fn independent_dropped<'a>(model: &Model, sit: &Situation, avoid: &[&'a Rule]) -> Vec<&'a Rule> {
    // Only a required fact makes an agent report: staleness never makes a
    // pattern match, and falsifying a rule's `not P` requires P.
    let mut forced: BTreeSet<AgentId> =
        sit.agents.iter().filter(|(_, r)| matches!(r, AgentReq::Fact(_))).map(|(a, _)| *a).collect();
    for r in avoid {
        forced.extend(r.negations.iter().map(|n| model.event(n.event).agent));
    }
    avoid.iter().filter(|r| r.patterns.iter().all(|p| forced.contains(&model.event(p.event).agent))).copied().collect()
}

fn search(model: &Model, sit: &Situation, avoid: &[&Rule], by_state: bool, budget: &mut usize) -> Outcome {
    let avoid = independent_dropped(model, sit, avoid);
    search_all(model, sit, &avoid, by_state, budget)
}

fn search_all(model: &Model, sit: &Situation, avoid: &[&Rule], by_state: bool, budget: &mut usize) -> Outcome {
    let mut sit = sit.clone();
    search_mut(model, &mut sit, avoid, by_state, budget)
}

/// The depth-first search, narrowing one situation in place and undoing
/// each narrowing on the way back (most options only add a negation).
fn search_mut(model: &Model, sit: &mut Situation, avoid: &[&Rule], by_state: bool, budget: &mut usize) -> Outcome {
    if *budget == 0 {
        return Outcome::Unknown;
    }
    *budget -= 1;
    let Some((rule, rest)) = avoid.split_first() else {
        return match sit.witness(model) {
            Ok(w) if w.widened => Outcome::Unknown,
            Ok(w) => Outcome::Found(w),
            Err(_) => Outcome::None,
        };
    };
    let mut unknown = false;
    let mut record = |outcome: Outcome| match outcome {
        Outcome::Found(w) => Some(Outcome::Found(w)),
        Outcome::Unknown => {
            unknown = true;
            None
        }
        Outcome::None => None,
    };
    // The state: outside the rule's guard, or the rule's own target.
    if by_state {
        let allowed = rule.allowed_states().unwrap_or_else(|| model.state_ids().collect());
        let kept: BTreeSet<StateId> =
            sit.states.iter().copied().filter(|st| !allowed.contains(st) || *st == rule.target).collect();
        if !kept.is_empty() {
            let saved = std::mem::replace(&mut sit.states, kept);
            let outcome = search_mut(model, sit, rest, by_state, budget);
            sit.states = saved;
            if let Some(found) = record(outcome) {
                return found;
            }
        }
    }
    // One of its patterns does not match (not one the situation's facts
    // surely match: that branch could only fail at its leaf).
    for p in &rule.patterns {
        if surely_matches(model, sit, p) {
            continue;
        }
        let widened = sit.widened;
        sit.widened |= p.tests.iter().any(|t| has_var(&t.check));
        sit.negations.push(p.clone());
        let outcome = search_mut(model, sit, rest, by_state, budget);
        sit.negations.pop();
        sit.widened = widened;
        if let Some(found) = record(outcome) {
            return found;
        }
    }
    // One of its negated patterns matches, or a staleness test fails.
    let mut others: Vec<Situation> = Vec::new();
    for n in &rule.negations {
        let mut s = sit.clone();
        if s.require_pattern(model, n).is_ok() {
            others.push(s);
        }
    }
    for t in &rule.stale {
        let mut s = sit.clone();
        if s.require_stale(model, t.agent, t.negated, t.origin).is_ok() {
            others.push(s);
        }
    }
    for mut s in others {
        if let Some(found) = record(search_mut(model, &mut s, rest, by_state, budget)) {
            return found;
        }
    }
    if unknown {
        Outcome::Unknown
    } else {
        Outcome::None
    }
}

/// Whether every memory of the situation matches the pattern: it tests
/// nothing but the event, and the situation requires that event as its
/// agent's latest fact.
fn surely_matches(model: &Model, sit: &Situation, p: &Pattern) -> bool {
    p.tests.is_empty()
        && p.run_length <= 1
        && p.within.is_none()
        && matches!(sit.agents.get(&model.event(p.event).agent), Some(AgentReq::Fact(f)) if f.event == p.event)
}

fn has_var(c: &FieldCheck) -> bool {
    match c {
        FieldCheck::Bind(_) => false,
        FieldCheck::Compare { rhs, .. } => matches!(rhs, Operand::Var(_)),
        FieldCheck::Range { lo, hi, .. } => matches!(lo, Operand::Var(_)) || matches!(hi, Operand::Var(_)),
    }
}
