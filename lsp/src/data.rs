//! What the features answer with, in the protocol's terms (places, edits,
//! findings, fixes), before [`crate::protocol`] writes it as JSON: the pieces
//! several features share. Each feature declares its own answers beside its
//! code.

use lsp_types::Range;
use std::collections::BTreeMap;

/// A place in a document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    pub uri: String,
    pub range: Range,
}

/// Replace `range` by `new_text`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TextEdit {
    pub range: Range,
    pub new_text: String,
}

/// Edits of several documents, by URI, each in the order of the text.
pub type WorkspaceEdit = BTreeMap<String, Vec<TextEdit>>;

/// Why a feature declines a well-formed request (no name to rename here, a
/// name already taken): the user's to read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Refusal(pub String);

/// One finding, placed in the editor's terms: the compiler's
/// ([`crate::diagnostics`]) or a verdict's ([`crate::verdicts`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Finding {
    pub range: Range,
    pub error: bool,
    pub code: &'static str,
    /// The message, with the help on a line of its own.
    pub message: String,
    /// The primary label, the secondary ones, the help and the witness, each
    /// with its place.
    pub related: Vec<(Location, String)>,
    pub help: Option<String>,
    /// The compiler's evidence, passed on as it gives it.
    pub witness: Option<serde_json::Value>,
    /// Shown faded: an event or a function nothing uses.
    pub unnecessary: bool,
}

/// A quick fix of one finding ([`crate::actions`], [`crate::verdicts`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CodeAction {
    pub title: String,
    /// The finding it fixes.
    pub finding: Finding,
    /// The first fix the compiler gives.
    pub preferred: bool,
    pub edit: WorkspaceEdit,
}
