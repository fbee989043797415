//! The one diagnostic type of situ: pure data. Rendering (miette, JSON, SARIF)
//! lives in the compiler; this crate only produces diagnostics for syntax.

use crate::ast::Span;
use serde::Serialize;

/// Identifies a source file within one compilation (an index into its source map).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Default)]
pub struct FileId(pub u32);

/// How bad a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Warning,
    Error,
}

impl Severity {
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Warning => "warning",
            Severity::Error => "error",
        }
    }
}

/// A place in a file with a short text about it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Label {
    pub file: FileId,
    pub span: Span,
    pub text: String,
}

/// One replacement of source text: `span` of `file` becomes `text`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Edit {
    pub file: FileId,
    pub span: Span,
    pub text: String,
}

/// A mechanical fix a tool may apply (an editor's code action): what it does,
/// in a few words, and the edits that do it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fix {
    pub title: String,
    pub edits: Vec<Edit>,
}

/// One finding: a stable code, a message, a primary place with its label,
/// further places, and a help line where a fix is known.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Diagnostic {
    /// The stable code without its namespace, e.g. `E0101`.
    pub code: &'static str,
    pub severity: Severity,
    pub message: String,
    pub primary: Label,
    pub secondary: Vec<Label>,
    pub help: Option<String>,
    /// Structured evidence a person can replay (static checks fill it in).
    pub witness: Option<serde_json::Value>,
    /// Set when an `allow(...)` attribute silenced this finding.
    pub allowed: bool,
    /// Fixes that apply the help mechanically, best first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub fixes: Vec<Fix>,
}

impl Diagnostic {
    pub fn error(
        code: &'static str,
        message: impl Into<String>,
        file: FileId,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        Diagnostic {
            code,
            severity: Severity::Error,
            message: message.into(),
            primary: Label { file, span, text: label.into() },
            secondary: Vec::new(),
            help: None,
            witness: None,
            allowed: false,
            fixes: Vec::new(),
        }
    }

    pub fn warning(
        code: &'static str,
        message: impl Into<String>,
        file: FileId,
        span: Span,
        label: impl Into<String>,
    ) -> Self {
        Diagnostic { severity: Severity::Warning, ..Self::error(code, message, file, span, label) }
    }

    pub fn with_help(mut self, help: impl Into<String>) -> Self {
        self.help = Some(help.into());
        self
    }

    pub fn with_label(mut self, file: FileId, span: Span, text: impl Into<String>) -> Self {
        self.secondary.push(Label { file, span, text: text.into() });
        self
    }

    /// Adds a fix that replaces `span` of `file` by `text`.
    pub fn with_fix(mut self, title: impl Into<String>, file: FileId, span: Span, text: impl Into<String>) -> Self {
        self.fixes.push(Fix { title: title.into(), edits: vec![Edit { file, span, text: text.into() }] });
        self
    }

    pub fn with_witness(mut self, witness: serde_json::Value) -> Self {
        self.witness = Some(witness);
        self
    }
}
