//! W0306 trap state: a reachable, non-final state with no rule that can lead
//! out of it. W0307 dead end: a reachable state with a way out, but from
//! which no final state can be reached (the mission cannot end).

use super::transitions::Transitions;
use crate::codes;
use crate::model::*;
use serde_json::json;
use situ_grammar::diag::Diagnostic;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    let Some(initial) = model.initial else { return Vec::new() };
    let reachable = tr.shortest_paths(model, initial);
    let finals: Vec<StateId> = model.state_ids().filter(|s| model.state(*s).is_final).collect();
    // Backward reachability from the final states.
    let mut ends = vec![false; model.states.len()];
    let mut stack = finals.clone();
    for f in &finals {
        ends[f.index()] = true;
    }
    while let Some(s) = stack.pop() {
        for e in tr.edges.iter().filter(|e| e.to == s) {
            if !ends[e.from.index()] {
                ends[e.from.index()] = true;
                stack.push(e.from);
            }
        }
    }
    let mut out = Vec::new();
    for s in model.state_ids().filter(|s| reachable[s.index()].is_some()) {
        let st = model.state(s);
        if st.is_final {
            continue;
        }
        let exits: Vec<&str> =
            tr.edges.iter().filter(|e| e.from == s).map(|e| model.rules[e.rule.index()].name.as_str()).collect();
        if exits.is_empty() {
            out.push(
                Diagnostic::warning(
                    codes::TRAP_STATE,
                    format!("state `{}` has no way out", st.name),
                    st.origin.file,
                    st.origin.span,
                    "no rule leaves it",
                )
                .with_help("add a rule that leads out of it, or mark it `final` if the mission may end here")
                .with_witness(json!({ "state": st.name })),
            );
        } else if !finals.is_empty() && !ends[s.index()] {
            let final_names: Vec<&str> = finals.iter().map(|f| model.state(*f).name.as_str()).collect();
            out.push(
                Diagnostic::warning(
                    codes::DEAD_END,
                    format!("no final state can be reached from `{}`", st.name),
                    st.origin.file,
                    st.origin.span,
                    "the mission cannot end from here",
                )
                .with_help(format!("add a rule that leads, directly or not, to {}", final_names.join(" or ")))
                .with_witness(json!({ "state": st.name, "leaves_by": exits, "finals": final_names })),
            );
        }
    }
    out
}
