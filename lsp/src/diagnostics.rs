//! The compiler's findings as LSP diagnostics: the code, the primary place,
//! every further label as related information, the help and the witness.

use crate::world::{Analysis, World};
use serde_json::{json, Value};
use situ_compiler::codes;
use situ_grammar::diag::{Diagnostic, FileId, Severity};
use std::collections::BTreeMap;

/// One finding for the file `file` of the analysis.
pub fn to_lsp(a: &Analysis, d: &Diagnostic) -> Value {
    let file = d.primary.file;
    let mut related = Vec::new();
    if !d.primary.text.is_empty() {
        related.push(json!({ "location": a.location(file, d.primary.span), "message": d.primary.text }));
    }
    for l in &d.secondary {
        if (l.file.0 as usize) < a.paths.len() {
            related.push(json!({ "location": a.location(l.file, l.span), "message": l.text }));
        }
    }
    if let Some(help) = &d.help {
        related.push(json!({ "location": a.location(file, d.primary.span), "message": format!("help: {help}") }));
    }
    if let Some(w) = &d.witness {
        related.push(json!({ "location": a.location(file, d.primary.span), "message": format!("witness: {w}") }));
    }
    let mut message = d.message.clone();
    if let Some(help) = &d.help {
        message.push_str("\nhelp: ");
        message.push_str(help);
    }
    let mut out = json!({
        "range": a.range(file, d.primary.span),
        "severity": if d.severity == Severity::Error { 1 } else { 2 },
        "code": d.code,
        "source": "situ",
        "message": message,
        "relatedInformation": related,
        "data": { "help": d.help, "witness": d.witness },
    });
    if [codes::UNUSED_EVENT, codes::UNUSED_FUNCTION].contains(&d.code) {
        out["tags"] = json!([1]); // unnecessary: shown faded
    }
    out
}

/// The diagnostics of every covered file, by URI, with the version of the
/// open document they were computed on; `None` for a file whose analysis
/// waits for its static checks (what was published stays until they end).
pub type Published = BTreeMap<String, Option<(Option<i32>, Vec<Value>)>>;

pub fn all(world: &World) -> Published {
    let mut out = BTreeMap::new();
    for path in world.covered() {
        let Some((a, file)) = world.primary(&path) else { continue };
        if !a.complete {
            out.insert(a.uri(file), None);
            continue;
        }
        let diags: Vec<Value> = a.checked.visible().filter(|d| d.primary.file == file).map(|d| to_lsp(a, d)).collect();
        let version = world.docs.get(&path).map(|d| d.version);
        out.insert(a.uri(file), Some((version, diags)));
    }
    out
}

/// The findings of `a` whose primary place is in `file`.
pub fn of_file(a: &Analysis, file: FileId) -> impl Iterator<Item = &Diagnostic> {
    a.checked.visible().filter(move |d| d.primary.file == file)
}
