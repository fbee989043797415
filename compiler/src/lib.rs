//! The situ compiler: from source files to a checked [`Model`] and a list of
//! diagnostics.
//!
//! The pipeline is one function, [`check`], of named hand-offs:
//! ```text
//! load (read, decode, parse every file, follow includes)   -> Loaded
//! resolve (names, types, tables, FSMs, tests, properties)   -> Model + diagnostics
//! checks (static checks, on a model without errors)         -> diagnostics
//! allow (attributes mark the warnings they silence)          -> diagnostics
//! ```
//! The crate does no I/O of its own: files come through a [`Loader`]
//! ([`loader::FsLoader`] for the file system, [`loader::MemLoader`] for tests).
//!
//! ```
//! use situ_compiler::{check_source, codes};
//!
//! let ok = check_source("ok.situ", "states { IT initial RD final }\n\
//!     agent Ready sensor { event RDY }\n\
//!     rule ready { when state == IT and RDY then RD }");
//! assert!(ok.diagnostics.is_empty());
//! assert_eq!(ok.model.rules[0].name, "ready");
//!
//! let bad = check_source("bad.situ", "states { IT initial }\nrule r { when RDY then RD }");
//! let found: Vec<&str> = bad.diagnostics.iter().map(|d| d.code).collect();
//! assert_eq!(found, [codes::UNDEFINED_EVENT, codes::UNDEFINED_STATE]);
//! ```

pub mod bundle;
pub mod checks;
pub mod codegen;
pub mod codes;
pub mod graph;
pub mod load;
pub mod loader;
pub mod model;
pub mod render;
mod resolve;
pub mod rete;
pub mod source;
pub mod spec;

/// "Did you mean …?" (`situ_bundle::suggest`, shared with the runtime).
pub use situ_bundle::suggest;

pub use load::RootError;
pub use loader::Loader;
pub use model::Model;
pub use situ_grammar::diag::{Diagnostic, FileId, Severity};
pub use source::SourceMap;

use std::path::Path;

/// The result of checking one root file and its includes.
#[derive(Debug, Clone)]
pub struct Checked {
    pub sources: SourceMap,
    /// Complete when there is no error; otherwise what could be resolved.
    pub model: Model,
    /// Every finding, sorted by file and place; allowed ones included.
    pub diagnostics: Vec<Diagnostic>,
}

impl Checked {
    /// The findings to show: all but the allowed ones.
    pub fn visible(&self) -> impl Iterator<Item = &Diagnostic> {
        self.diagnostics.iter().filter(|d| !d.allowed)
    }

    pub fn errors(&self) -> usize {
        self.visible().filter(|d| d.severity == Severity::Error).count()
    }

    pub fn warnings(&self) -> usize {
        self.visible().filter(|d| d.severity == Severity::Warning).count()
    }

    /// Whether the findings fail the check (errors, or with `deny_warnings` any warning).
    pub fn fails(&self, deny_warnings: bool) -> bool {
        self.errors() > 0 || (deny_warnings && self.warnings() > 0)
    }
}

/// Checks `root` and every file it includes.
pub fn check(root: &Path, loader: &dyn Loader) -> Result<Checked, RootError> {
    let loaded = load::load(root, loader)?;
    Ok(check_loaded(loaded))
}

/// Checks `root` with more files read after it (`situ run --script FILE`):
/// their items see the root's declarations.
pub fn check_with(root: &Path, extra: &[&Path], loader: &dyn Loader) -> Result<Checked, RootError> {
    let loaded = load::load_with(root, extra, loader)?;
    Ok(check_loaded(loaded))
}

/// Checks a source given as text; includes are not available.
pub fn check_source(name: &str, text: &str) -> Checked {
    check_loaded(load::load_text(name, text, &loader::MemLoader::new()))
}

/// The parsed files of a compilation, by [`FileId`].
pub type ParsedFiles = Vec<(FileId, situ_grammar::ast::File)>;

/// [`check`] without the static checks: loading, names, types and `allow`
/// only, for a tool that must answer at every keystroke (`situ lsp`) and
/// runs the whole check afterwards; with the parsed files, by [`FileId`]
/// order. When this finds an error, [`check`] finds the same (the static
/// checks run only without errors).
pub fn check_quick(root: &Path, loader: &dyn Loader) -> Result<(Checked, ParsedFiles), RootError> {
    let loaded = load::load(root, loader)?;
    Ok(check_phases(loaded, false))
}

/// [`check_quick`] with the files parsed through `cache`, which keeps each
/// item's parse from one call to the next: after an edit, only the items it
/// touched are parsed again. The result is [`check_quick`]'s.
pub fn check_quick_cached(
    root: &Path,
    loader: &dyn Loader,
    cache: &mut situ_grammar::ItemCache,
) -> Result<(Checked, ParsedFiles), RootError> {
    let loaded = load::load_cached(root, loader, Some(cache))?;
    Ok(check_phases(loaded, false))
}

/// Codes that only say a name is missing: after a syntax error the name may
/// well be declared in the item that failed to parse, so these are not shown.
const NAME_CODES: &[&str] = &[
    codes::UNDEFINED_STATE,
    codes::UNDEFINED_AGENT,
    codes::UNDEFINED_EVENT,
    codes::UNDEFINED_FUNCTION,
    codes::UNDEFINED_FIELD,
    codes::INITIAL_STATE,
    codes::NEVER_STALE,
];

fn check_loaded(loaded: load::Loaded) -> Checked {
    check_phases(loaded, true).0
}

fn check_phases(loaded: load::Loaded, static_checks: bool) -> (Checked, ParsedFiles) {
    let load::Loaded { sources, files, mut diagnostics, .. } = loaded;
    let syntax_failed = !diagnostics.is_empty();
    let (model, found) = resolve::resolve(&files);
    diagnostics.extend(found.into_iter().filter(|d| !(syntax_failed && NAME_CODES.contains(&d.code))));
    if static_checks && diagnostics.iter().all(|d| d.severity != Severity::Error) {
        diagnostics.extend(checks::run(&model));
    }
    resolve::allow::apply(&mut diagnostics, &files);
    diagnostics.sort_by(|a, b| {
        (a.primary.file, a.primary.span.start, a.code).cmp(&(b.primary.file, b.primary.span.start, b.code))
    });
    (Checked { sources, model, diagnostics }, files)
}
