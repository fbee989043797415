//! W0321: a static check that stopped at its work budget. A check whose
//! exact answer can need exponential work counts its work (cycles or
//! branches tried, never time) and stops at a fixed budget; it then says
//! so, where it stopped, and which code it could not decide, so that the
//! absence of a finding is never taken for a proof.

use crate::codes;
use crate::model::Origin;
use situ_grammar::diag::Diagnostic;

/// The note that the check of `code` stopped: `message` says where, the
/// primary label sits at `at`.
pub fn stopped(
    code: &str,
    message: String,
    at: Origin,
    label: &str,
    help: String,
    mut witness: serde_json::Value,
) -> Diagnostic {
    witness["check"] = serde_json::json!(code);
    Diagnostic::warning(codes::INCOMPLETE_CHECK, message, at.file, at.span, label)
        .with_help(format!("{help}; the check is incomplete there: no finding of {code} does not mean there is none"))
        .with_witness(witness)
}
