//! E0304: a rule whose conditions can never hold together.

use super::transitions::Transitions;
use crate::codes;
use crate::model::Model;
use situ_grammar::diag::Diagnostic;

pub fn check(model: &Model, tr: &Transitions) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for (rule, sit) in model.rules.iter().zip(&tr.situations) {
        let Err(unsat) = sit else { continue };
        let mut d = Diagnostic::error(
            codes::UNSATISFIABLE_RULE,
            format!("rule `{}` can never fire: {}", rule.name, unsat.reason),
            rule.origin.file,
            rule.origin.span,
            "never fires",
        );
        for o in &unsat.origins {
            d = d.with_label(o.file, o.span, "this condition");
        }
        out.push(
            d.with_help("remove the rule, or fix the conditions that exclude each other")
                .with_witness(serde_json::json!({ "rule": rule.name, "reason": unsat.reason })),
        );
    }
    out
}
