//! The one error type of the facade: each variant says what failed and
//! where, and keeps what a client needs to show it (the findings of a
//! source that does not check, the bundle's own error).

use situ_compiler::bundle::sign::TrustError;
use situ_compiler::bundle::LoadError;
use situ_compiler::{Checked, RootError};
use std::path::PathBuf;

/// Why an operation of the facade did not complete.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// A file could not be read (missing, not a regular file, too large).
    #[error("cannot read `{}`: {source}", path.display())]
    Read { path: PathBuf, source: std::io::Error },
    /// The root file of a check could not be loaded at all.
    #[error(transparent)]
    Root(#[from] RootError),
    /// The source has errors (or warnings, when they are denied): the
    /// findings are in `checked`.
    #[error("`{name}` has {errors} error(s) and {warnings} warning(s)")]
    Findings { name: String, errors: usize, warnings: usize, checked: Box<Checked> },
    /// Formatting refused a source with syntax errors.
    #[error("the source has {} syntax error(s): it is not formatted", .0.len())]
    Syntax(Vec<situ_compiler::Diagnostic>),
    /// A source was given where only signed bundles are trusted.
    #[error("`{}` is a source, which carries no signature: with --trust only bundles signed by a trusted key run", path.display())]
    UnsignedSource { path: PathBuf },
    /// A bundle is damaged, of another format version, or was changed.
    #[error(transparent)]
    Bundle(#[from] LoadError),
    /// A recording is not one situ can read (not MCAP, damaged, too large).
    #[error(transparent)]
    Recording(#[from] situ_runtime::record::mcap::read::ReadError),
    /// A recording carries no bundle and none was given.
    #[error("the recording has no bundle attached: give one")]
    NoAttachedBundle,
    /// The bundle attached to a recording does not load (damaged, or not
    /// signed by a trusted key).
    #[error("the bundle attached to the recording: {0}")]
    Attached(Box<Error>),
    /// A recording holds nothing of situ's, or not of these rules.
    #[error(transparent)]
    Replay(#[from] situ_runtime::replay::ReplayError),
    /// No script to play (none in the rules, or none of that name).
    #[error(transparent)]
    Script(#[from] situ_runtime::script::PickError),
    /// An output could not be written.
    #[error("cannot write {what}: {source}")]
    Write { what: &'static str, source: std::io::Error },
    /// A bundle is not signed by a trusted key (a damaged one is
    /// [`Error::Bundle`], under any policy).
    #[error(transparent)]
    Trust(TrustError),
}

impl From<TrustError> for Error {
    fn from(e: TrustError) -> Self {
        match e {
            TrustError::Load(e) => Error::Bundle(e),
            e => Error::Trust(e),
        }
    }
}
