//! E0302 / W0319: two rules of the same salience with different targets whose
//! conditions can hold at the same time. Which one fires then depends on
//! specificity, recency or the order in the file: rarely what was meant.

use super::transitions::Transitions;
use crate::codes;
use crate::model::{Model, Rule};
use serde_json::json;
use situ_grammar::diag::Diagnostic;
use std::collections::BTreeMap;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    // Only rules of equal salience can conflict: group them first.
    let mut groups: BTreeMap<i64, Vec<usize>> = BTreeMap::new();
    for (i, r) in model.rules.iter().enumerate() {
        if tr.situations[i].is_ok() {
            groups.entry(r.salience).or_default().push(i);
        }
    }
    let mut out = Vec::new();
    for rules in groups.values() {
        for (k, &a) in rules.iter().enumerate() {
            for &b in &rules[k + 1..] {
                if let Some(d) = pair(model, tr, a, b) {
                    out.push(d);
                }
            }
        }
    }
    out
}

fn pair(model: &Model, tr: &Transitions, a: usize, b: usize) -> Option<Diagnostic> {
    let (ra, rb): (&Rule, &Rule) = (&model.rules[a], &model.rules[b]);
    if ra.target == rb.target {
        return None;
    }
    let (Ok(sa), Ok(sb)) = (&tr.situations[a], &tr.situations[b]) else { return None };
    if sa.states.is_disjoint(&sb.states) {
        return None;
    }
    let mut both = sa.meet(model, sb).ok()?;
    // Both must be activated: the state is neither target.
    both.states.retain(|s| *s != ra.target && *s != rb.target);
    if both.states.is_empty() {
        return None;
    }
    let witness = both.witness(model).ok()?;
    let (code, message) = if witness.widened {
        (codes::MAY_CONFLICT, format!("rules `{}` and `{}` may conflict", ra.name, rb.name))
    } else {
        (codes::CONFLICTING_RULES, format!("rules `{}` and `{}` conflict", ra.name, rb.name))
    };
    let target = |r: &Rule| model.state(r.target).name.clone();
    let mut d = if witness.widened {
        Diagnostic::warning(code, message, rb.origin.file, rb.origin.span, format!("leads to {}", target(rb)))
    } else {
        Diagnostic::error(code, message, rb.origin.file, rb.origin.span, format!("leads to {}", target(rb)))
    };
    d = d.with_label(ra.origin.file, ra.origin.span, format!("leads to {}", target(ra)));
    let help = if witness.widened {
        format!(
            "they can hold together in {} (comparisons between variables were not decided exactly); give one a higher salience if it should win",
            witness.describe()
        )
    } else {
        format!(
            "both hold in {}, both have salience {}; give the one that should win a higher salience, or make their conditions exclusive",
            witness.describe(),
            ra.salience
        )
    };
    Some(d.with_help(help).with_witness(json!({
        "rules": [ra.name, rb.name],
        "targets": [target(ra), target(rb)],
        "memory": witness.json,
        "exact": !witness.widened,
    })))
}
