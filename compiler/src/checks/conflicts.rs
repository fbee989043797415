//! E0302 / W0319: two rules of the same salience with different targets whose
//! conditions can hold at the same time. Which one fires then depends on
//! specificity, recency or the order in the file: rarely what was meant.
//!
//! The witness is a memory in which the two rules are the ones that decide:
//! no rule of higher salience is activated there too (it would fire first
//! and mask them). When every memory of the two rules activates a rule of
//! higher salience, they never compete, and there is no finding.

use super::escape::{avoiding, independent_dropped, Outcome};
use super::situation::Situation;
use super::transitions::Transitions;
use crate::codes;
use crate::model::{Model, Rule};
use serde_json::json;
use situ_grammar::diag::Diagnostic;
use std::collections::BTreeMap;

/// The search budget per pair for a memory that no rule of higher salience
/// masks (branches of the falsification search, as for W0303).
const BUDGET: usize = 20_000;

/// The conflicts reported with one rule (the first of the pair): a state
/// that fans out to thousands of others with the same condition would
/// otherwise give a finding per pair of them, millions.
pub const MAX_PER_RULE: usize = 10;

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
        // Rules with the same target never conflict: a run of them (in
        // order) is stepped over at once, so that thousands of rules
        // leading to one state are not compared pair by pair.
        let mut run_end = vec![rules.len(); rules.len()];
        for k in (0..rules.len().saturating_sub(1)).rev() {
            if model.rules[rules[k]].target == model.rules[rules[k + 1]].target {
                run_end[k] = run_end[k + 1];
            } else {
                run_end[k] = k + 1;
            }
        }
        for (k, &a) in rules.iter().enumerate() {
            let mut found = 0;
            let mut j = k + 1;
            while j < rules.len() {
                let b = rules[j];
                if model.rules[b].target == model.rules[a].target {
                    j = run_end[j];
                    continue;
                }
                if let Some(mut d) = pair(model, tr, a, b) {
                    found += 1;
                    if found == MAX_PER_RULE {
                        let more = format!(
                            "; `{}` is not compared with the rules after `{}`: {MAX_PER_RULE} conflicts with one rule are enough to show",
                            model.rules[a].name, model.rules[b].name
                        );
                        d.help = Some(d.help.unwrap_or_default() + &more);
                        out.push(d);
                        break;
                    }
                    out.push(d);
                }
                j += 1;
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
    // The rules of higher salience that can be activated with both: a
    // memory where one of them is activated does not show the conflict.
    let higher: Vec<usize> = (0..model.rules.len())
        .filter(|&h| {
            model.rules[h].salience > ra.salience && tr.situations[h].as_ref().is_ok_and(|s| both.compatible(s))
        })
        .collect();
    let higher_rules: Vec<&Rule> = higher.iter().map(|&h| &model.rules[h]).collect();
    let mut masking: Vec<&Rule> = Vec::new();
    let witness = if independent_dropped(model, &both, &higher_rules).is_empty() {
        both.witness(model).ok()?
    } else {
        let mut budget = BUDGET;
        match avoiding(model, &both, &higher_rules, &mut budget) {
            Outcome::Found(w) => w,
            // Every memory where both are activated activates a rule of
            // higher salience: they never decide.
            Outcome::None => return None,
            // Undecided (budget, or comparisons between variables): a
            // candidate memory, reported as "may", with the rules that may
            // mask it.
            Outcome::Unknown => {
                let mut w = both.witness(model).ok()?;
                w.widened = true;
                masking = higher
                    .iter()
                    .filter(|&&h| {
                        let meets = |hs: &Situation| both.meet(model, hs).and_then(|m| m.witness(model)).is_ok();
                        tr.situations[h].as_ref().is_ok_and(meets)
                    })
                    .map(|&h| &model.rules[h])
                    .collect();
                w
            }
        }
    };
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
    for h in &masking {
        d = d.with_label(
            h.origin.file,
            h.origin.span,
            format!("salience {}, leads to {}: may fire first", h.salience, target(h)),
        );
    }
    let masked_by: Vec<&str> = masking.iter().map(|h| h.name.as_str()).collect();
    let help = if !masking.is_empty() {
        format!(
            "they can hold together in {}, but {} of higher salience may be activated there too, and no memory without them was found within the search budget; give one a higher salience if it should win",
            witness.describe(),
            masked_by.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(" or ")
        )
    } else if witness.widened {
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
    let mut data = json!({
        "rules": [ra.name, rb.name],
        "targets": [target(ra), target(rb)],
        "memory": witness.json,
        "exact": !witness.widened,
    });
    if !masked_by.is_empty() {
        data["may_be_masked_by"] = json!(masked_by);
    }
    Some(d.with_help(help).with_witness(data))
}
