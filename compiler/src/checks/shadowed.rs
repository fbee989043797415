//! W0303: a rule that can never win — every memory that activates it also
//! activates a rule of higher salience with another target.

use super::budget;
use super::escape::{avoiding, Outcome};
use super::situation::AgentReq;
use super::transitions::Transitions;
use crate::codes;
use crate::model::*;
use serde_json::json;
use situ_grammar::diag::Diagnostic;
use std::collections::BTreeMap;

/// The search budget per rule (branches of the falsification search).
const BUDGET: usize = 20_000;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    check_within(model, tr, BUDGET)
}

/// The check with a given search budget per rule. A rule whose search runs
/// out of it is undecided: one W0321 note names them all.
pub fn check_within(model: &Model, tr: &Transitions, per_rule: usize) -> Vec<Diagnostic> {
    // Index: per state, per target, the rules that can be activated there,
    // highest salience first. A rule only looks at other targets, and only
    // as far down as its own salience.
    let mut index: Vec<BTreeMap<StateId, Vec<usize>>> = vec![BTreeMap::new(); model.states.len()];
    for (i, sit) in tr.situations.iter().enumerate() {
        if let Ok(sit) = sit {
            let target = model.rules[i].target;
            for s in sit.states.iter().filter(|s| **s != target) {
                index[s.index()].entry(target).or_default().push(i);
            }
        }
    }
    for by_target in &mut index {
        for rules in by_target.values_mut() {
            rules.sort_by_key(|&i| std::cmp::Reverse(model.rules[i].salience));
        }
    }
    // Per rule, the agents of its patterns: a rival is only kept when all
    // of them can be forced to report (see `independent_dropped`), which
    // is decided before the costlier test that its facts fit.
    let pattern_agents: Vec<Vec<AgentId>> = model
        .rules
        .iter()
        .map(|r| {
            let mut a: Vec<AgentId> = r.patterns.iter().map(|p| model.event(p.event).agent).collect();
            a.sort_unstable();
            a.dedup();
            a
        })
        .collect();
    let mut forced = vec![false; model.agents.len()];
    let mut out = Vec::new();
    let mut undecided: Vec<&Rule> = Vec::new();
    let mut seen = vec![usize::MAX; model.rules.len()];
    let mut higher: Vec<usize> = Vec::new();
    for (i, rule) in model.rules.iter().enumerate() {
        let Ok(sit) = &tr.situations[i] else { continue };
        let mut own = sit.clone();
        own.states.remove(&rule.target); // activated only away from its target
        if own.states.is_empty() {
            continue;
        }
        // The rules that win over it somewhere: higher salience, another
        // target, a state in common.
        higher.clear();
        for s in &own.states {
            for (target, rules) in &index[s.index()] {
                if *target == rule.target {
                    continue;
                }
                for &h in rules.iter().take_while(|&&h| model.rules[h].salience > rule.salience) {
                    if seen[h] != i {
                        seen[h] = i;
                        higher.push(h);
                    }
                }
            }
        }
        let fits = |h: usize| tr.situations[h].as_ref().is_ok_and(|hs| own.compatible(hs));
        // Rules that can always be avoided on their own cannot shadow it:
        // a rival on an agent that neither this rule's facts nor a fitting
        // rival's `not` can force to report is dropped (exactly as
        // `independent_dropped` does, without testing its facts first).
        let mut touched: Vec<AgentId> =
            own.agents.iter().filter(|(_, r)| matches!(r, AgentReq::Fact(_))).map(|(a, _)| *a).collect();
        for &h in higher.iter().filter(|&&h| !model.rules[h].negations.is_empty()) {
            if fits(h) {
                touched.extend(model.rules[h].negations.iter().map(|n| model.event(n.event).agent));
            }
        }
        for a in &touched {
            forced[a.index()] = true;
        }
        let mut candidates: Vec<usize> = higher
            .iter()
            .copied()
            .filter(|&h| pattern_agents[h].iter().all(|a| forced[a.index()]) && fits(h))
            .collect();
        for a in &touched {
            forced[a.index()] = false;
        }
        candidates.sort_unstable(); // declaration order, for stable reports
        let avoid: Vec<&Rule> = candidates.iter().map(|&h| &model.rules[h]).collect();
        if avoid.is_empty() {
            continue;
        }
        let mut budget = per_rule;
        let outcome = avoiding(model, &own, &avoid, &mut budget);
        if matches!(outcome, Outcome::Unknown) && budget == 0 {
            undecided.push(rule);
        }
        if let Outcome::None = outcome {
            // Shadowed: name the rules that can be activated with it.
            let winners: Vec<&Rule> = avoid
                .iter()
                .copied()
                .filter(|hr| {
                    let h = situation_of(model, hr);
                    tr.situations[h].as_ref().is_ok_and(|hs| own.meet(model, hs).and_then(|m| m.witness(model)).is_ok())
                })
                .collect();
            let names: Vec<&str> = winners.iter().map(|h| h.name.as_str()).collect();
            let mut d = Diagnostic::warning(
                codes::SHADOWED_RULE,
                format!("rule `{}` can never win", rule.name),
                rule.origin.file,
                rule.origin.span,
                format!("salience {}: always beaten", rule.salience),
            );
            for h in &winners {
                d = d.with_label(
                    h.origin.file,
                    h.origin.span,
                    format!("salience {}, leads to {}", h.salience, model.state(h.target).name),
                );
            }
            out.push(
                d.with_help(format!(
                    "whenever it is activated, a rule of higher salience with another target is too ({}); raise its salience or remove it",
                    names.join(" or ")
                ))
                .with_witness(json!({ "rule": rule.name, "shadowed_by": names })),
            );
        }
    }
    out.extend(incomplete(&undecided, per_rule));
    out
}

/// W0321 for the rules whose search ran out of its budget.
fn incomplete(undecided: &[&Rule], per_rule: usize) -> Option<Diagnostic> {
    let (first, _) = undecided.split_first()?;
    let names: Vec<&str> = undecided.iter().map(|r| r.name.as_str()).collect();
    let n = undecided.len();
    Some(budget::stopped(
        codes::SHADOWED_RULE,
        format!(
            "the shadowing check (W0303) could not decide {n} rule{}, first `{}`",
            if n == 1 { "" } else { "s" },
            first.name
        ),
        first.origin,
        "not decided",
        format!(
            "no memory that activates it and none of its rivals of higher salience was found within {per_rule} branches, nor was one ruled out"
        ),
        json!({ "undecided": names, "budget_per_rule": per_rule }),
    ))
}

/// The index of a rule of the model.
fn situation_of(model: &Model, rule: &Rule) -> usize {
    model.rules.iter().position(|x| std::ptr::eq(x, rule)).expect("a rule of the model")
}
