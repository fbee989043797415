//! Phase 5: `#[allow(CODE, ...)]` on an item marks the warnings with these
//! codes whose primary place lies in the item as allowed. Only warnings can
//! be allowed; an unknown code or an error code is itself an error.

use crate::codes;
use situ_grammar::ast::{self, Attribute, Span};
use situ_grammar::diag::{Diagnostic, FileId, Severity};

/// Checks every attribute and marks the findings it silences. Call it after
/// every other check has run.
pub fn apply(diags: &mut Vec<Diagnostic>, files: &[(FileId, ast::File)]) {
    let mut scopes: Vec<(FileId, Span, &'static str)> = Vec::new();
    let mut bad = Vec::new();
    for (file, f) in files {
        for item in &f.items {
            let attributes: &[Attribute] = match item {
                ast::Item::Agent(a) => &a.attributes,
                ast::Item::Rule(r) => &r.attributes,
                _ => &[],
            };
            for code in attributes.iter().flat_map(|a| &a.allow) {
                match codes::lookup(&code.name) {
                    Some(c) if c.severity == Severity::Warning => scopes.push((*file, item.span(), c.code)),
                    Some(c) => bad.push(
                        Diagnostic::error(
                            codes::BAD_ALLOW,
                            format!("`{}` is an error and cannot be allowed", c.code),
                            *file,
                            code.span,
                            "an error code",
                        )
                        .with_help("only warnings can be allowed; fix the error instead"),
                    ),
                    None => bad.push(
                        Diagnostic::error(
                            codes::BAD_ALLOW,
                            format!("unknown code `{}`", code.name),
                            *file,
                            code.span,
                            "no such code",
                        )
                        .with_help("`situ explain CODE` lists the codes; they look like `W0301`"),
                    ),
                }
            }
        }
    }
    for d in diags.iter_mut() {
        let p = &d.primary;
        if d.severity == Severity::Warning
            && scopes
                .iter()
                .any(|(f, s, c)| *f == p.file && s.start <= p.span.start && p.span.end <= s.end && *c == d.code)
        {
            d.allowed = true;
        }
    }
    diags.extend(bad);
}
