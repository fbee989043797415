//! W0303: a rule that can never win — every memory that activates it also
//! activates a rule of higher salience with another target.

use super::escape::{avoiding, independent_dropped, Outcome};
use super::transitions::Transitions;
use crate::codes;
use crate::model::*;
use serde_json::json;
use situ_grammar::diag::Diagnostic;
use std::collections::BTreeMap;

/// The search budget per rule (branches of the falsification search).
const BUDGET: usize = 20_000;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
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
    let mut out = Vec::new();
    let mut seen = vec![usize::MAX; model.rules.len()];
    for (i, rule) in model.rules.iter().enumerate() {
        let Ok(sit) = &tr.situations[i] else { continue };
        let mut own = sit.clone();
        own.states.remove(&rule.target); // activated only away from its target
        if own.states.is_empty() {
            continue;
        }
        // The rules that win over it somewhere: higher salience, another
        // target, a state in common, and facts that can hold together.
        let mut candidates: Vec<usize> = Vec::new();
        for s in &own.states {
            for (target, rules) in &index[s.index()] {
                if *target == rule.target {
                    continue;
                }
                for &h in rules.iter().take_while(|&&h| model.rules[h].salience > rule.salience) {
                    if seen[h] == i {
                        continue;
                    }
                    seen[h] = i;
                    if tr.situations[h].as_ref().is_ok_and(|hs| own.compatible(hs)) {
                        candidates.push(h);
                    }
                }
            }
        }
        candidates.sort_unstable(); // declaration order, for stable reports
                                    // Rules that can always be avoided on their own cannot shadow it.
        let candidate_rules: Vec<&Rule> = candidates.iter().map(|&h| &model.rules[h]).collect();
        let avoid = independent_dropped(model, &own, &candidate_rules);
        if avoid.is_empty() {
            continue;
        }
        let mut budget = BUDGET;
        if let Outcome::None = avoiding(model, &own, &avoid, &mut budget) {
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
    out
}

/// The index of a rule of the model.
fn situation_of(model: &Model, rule: &Rule) -> usize {
    model.rules.iter().position(|x| std::ptr::eq(x, rule)).expect("a rule of the model")
}
