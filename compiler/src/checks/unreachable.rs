//! E0301: a state that no sequence of events leads to from the initial state.

use super::transitions::Transitions;
use crate::codes;
use crate::model::{Model, StateId};
use serde_json::json;
use situ_grammar::diag::Diagnostic;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    let Some(initial) = model.initial else { return Vec::new() };
    let pred = tr.shortest_paths(model, initial);
    let reachable: Vec<StateId> = model.state_ids().filter(|s| pred[s.index()].is_some()).collect();
    let paths: serde_json::Map<String, serde_json::Value> = reachable
        .iter()
        .map(|&s| {
            let steps: Vec<_> = tr.path(&pred, s).unwrap_or_default().iter().map(|e| step(model, e)).collect();
            (model.state(s).name.clone(), json!(steps))
        })
        .collect();
    let mut out = Vec::new();
    for state in model.state_ids().filter(|s| pred[s.index()].is_none()) {
        let st = model.state(state);
        let mut why = Vec::new();
        let mut d = Diagnostic::error(
            codes::UNREACHABLE_STATE,
            format!("state `{}` is unreachable from `{}`", st.name, model.state(initial).name),
            st.origin.file,
            st.origin.span,
            "never entered",
        );
        for (rule, sit) in model.rules.iter().zip(&tr.situations).filter(|(r, _)| r.target == state) {
            let reason = match sit {
                Err(unsat) => format!("its conditions never hold: {}", unsat.reason),
                Ok(s) => {
                    let from: Vec<&str> =
                        s.states.iter().filter(|&&x| x != state).map(|x| model.state(*x).name.as_str()).collect();
                    format!(
                        "it fires only in {}, which {} unreachable",
                        from.join(", "),
                        if from.len() == 1 { "is" } else { "are" }
                    )
                }
            };
            d = d.with_label(rule.origin.file, rule.origin.span, format!("leads there, but {reason}"));
            why.push(json!({ "rule": rule.name, "why": reason }));
        }
        let help = if why.is_empty() {
            format!("no rule has `then {}`; add one, or remove the state", st.name)
        } else {
            "make one of these rules able to fire from a reachable state".to_string()
        };
        out.push(d.with_help(help).with_witness(json!({ "state": st.name, "rules": why, "reachable": paths })));
    }
    out
}

/// One step of a path, for witnesses.
pub fn step(model: &Model, e: &super::transitions::Edge) -> serde_json::Value {
    json!({
        "from": model.state(e.from).name,
        "to": model.state(e.to).name,
        "rule": model.rules[e.rule.index()].name,
        "memory": e.witness.json,
        "events": e.witness.describe(),
    })
}
