//! The compiler's findings as the editor shows them: the code, the primary
//! place, every further label as related information, the help and the
//! witness.

pub use crate::data::Finding;
use crate::world::{Analysis, World};
use situ_compiler::codes;
use situ_grammar::diag::{Diagnostic, FileId, Severity};
use std::collections::BTreeMap;

/// One finding of the analysis.
pub fn finding(a: &Analysis, d: &Diagnostic) -> Finding {
    let file = d.primary.file;
    let mut related = Vec::new();
    if !d.primary.text.is_empty() {
        related.push((a.location(file, d.primary.span), d.primary.text.clone()));
    }
    for l in &d.secondary {
        if (l.file.0 as usize) < a.paths.len() {
            related.push((a.location(l.file, l.span), l.text.clone()));
        }
    }
    if let Some(help) = &d.help {
        related.push((a.location(file, d.primary.span), format!("help: {help}")));
    }
    if let Some(w) = &d.witness {
        related.push((a.location(file, d.primary.span), format!("witness: {w}")));
    }
    let mut message = d.message.clone();
    if let Some(help) = &d.help {
        message.push_str("\nhelp: ");
        message.push_str(help);
    }
    Finding {
        range: a.range(file, d.primary.span),
        error: d.severity == Severity::Error,
        code: d.code,
        message,
        related,
        help: d.help.clone(),
        witness: d.witness.clone(),
        unnecessary: [codes::UNUSED_EVENT, codes::UNUSED_FUNCTION].contains(&d.code),
    }
}

/// The findings of every covered file (the compiler's, then the verdicts'
/// of [`crate::verdicts`]), by URI, with the version of the open document
/// they were computed on; `None` for a file whose analysis waits
/// for its static checks (what was published stays until they end).
pub type Published = BTreeMap<String, Option<(Option<i32>, Vec<Finding>)>>;

pub fn all(world: &World) -> Published {
    let mut out = BTreeMap::new();
    for path in world.covered() {
        let Some((a, file)) = world.primary(&path) else { continue };
        if !a.complete {
            out.insert(a.uri(file), None);
            continue;
        }
        let uri = a.uri(file);
        let mut found: Vec<Finding> = of_file(a, file).map(|d| finding(a, d)).collect();
        // The verdicts of the properties and tests, while they are of these documents.
        found.extend(world.verdicts.found(&a.root, world.generation(&a.root), &uri).iter().cloned());
        let version = world.docs.get(&path).map(|d| d.version);
        out.insert(uri, Some((version, found)));
    }
    out
}

/// The findings of `a` whose primary place is in `file`.
pub fn of_file(a: &Analysis, file: FileId) -> impl Iterator<Item = &Diagnostic> {
    a.checked.visible().filter(move |d| d.primary.file == file)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn findings_of_a_file_with_their_places() {
        let (w, path) = crate::world::world_of("diagnostics", crate::world::SMALL);
        let published = all(&w);
        let (version, found) = published.values().next().unwrap().clone().unwrap();
        assert_eq!(version, Some(1));
        let unused = found.iter().find(|f| f.code == codes::UNUSED_EVENT).expect("F is never read");
        assert!(!unused.error && unused.unnecessary);
        assert_eq!((unused.range.start.line, unused.range.start.character), (5, 10));
        let row = found.iter().find(|f| f.code == codes::NO_TABLE_ENTRY).expect("RD has no row");
        assert!(!row.unnecessary);
        assert!(row.witness.is_some());
        assert!(row.related.iter().any(|(_, m)| m.starts_with("witness: ")));
        assert!(published.contains_key(&crate::text::path_to_uri(&path)));
    }
}
