//! What the features answer with, in the protocol's terms (places, edits),
//! before [`crate::protocol`] writes it as JSON: the pieces several features
//! share. Each feature declares its own answers beside its code.

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
