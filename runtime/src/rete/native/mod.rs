//! Native code: a bundle's rules as Rust, compiled with the program that
//! runs them (`situ build --native`, docs/performance.md).
//!
//! [`generate`] writes a Rust module for a bundle: its fast program
//! (`fast.rs`) unrolled, each table read as a constant: per event its
//! payload check, insert and search of the rules its new fact can
//! activate, per state the search after a firing, per rule its
//! conditions. The module calls the fast path's own pieces ([`rt`]), each
//! with constants instead of table entries, so that the code it runs is the
//! fast path's with its tables folded in: the same insert, the same
//! conditions and tests, the same conflict resolution, the same firing
//! and recording. Everything a step does not do (expiry, the rests of a
//! heartbeat, `force_*`, a reset) stays the fast path's, on the same
//! working memory.
//!
//! The bundle stays the unit of deployment and of signing:
//! [`Engine::with_native`] takes a bundle's content and a generated
//! module's [`Native`], generates the module's text again from the
//! content, and refuses the pair unless its digest is the one the module
//! was generated with ([`NativeError::Mismatch`]). Native code therefore
//! never runs on a bundle other than its own, and every index it holds was
//! checked against that bundle's tables (`Program::check`) when it was
//! generated: the invariant under which the fast path reads unchecked.
//!
//! Held to the interpreter by `runtime-tests/tests/native.rs`: the
//! modules of the repository's rules files and of random rule sets,
//! generated and committed, must be what [`generate`] writes today
//! (golden), and must answer every operation as the interpreter does.

mod gen;
#[doc(hidden)]
pub mod rt;

use super::{Engine, Step, StepError};
use situ_bundle::{Content, Value};
use std::sync::Arc;

pub use gen::{generate, MAX_NATIVE_ENTRIES};

/// A step of native code for one event of its bundle: the engine's
/// [`step`](Engine::step) of that event.
pub type StepFn = fn(&mut Engine, u64, &[Value]) -> Result<Step, StepError>;

/// A generated module's entry point (its `NATIVE` static).
#[derive(Debug)]
pub struct Native {
    /// The SHA-256 of the module's generated code (hex), which
    /// [`Engine::with_native`] compares with the code generated again
    /// from the bundle.
    pub digest: &'static str,
    /// Per event of the bundle, its step.
    pub steps: &'static [StepFn],
}

/// Why native code cannot be generated for a bundle, or cannot run it.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NativeError {
    /// The fast path declines the bundle; native code is the fast path's.
    #[error("the fast path declines this bundle ({0}): no native code for it")]
    Declined(&'static str),
    /// The rule searches would be too much code.
    #[error("the bundle's rule searches have {entries} entries, more than the {max} native code takes")]
    TooLarge { entries: usize, max: usize },
    /// The module was generated from another bundle (or by another situ).
    #[error(
        "the native code was generated from another bundle or by another version of situ \
         (its digest {found}, this bundle's {expected}): generate it again with `situ build --native`"
    )]
    Mismatch { expected: String, found: String },
}

impl Engine {
    /// The engine of a validated bundle running `native`, the module that
    /// `situ build --native` generated from it: as [`new`](Engine::new),
    /// with each step run by the module. Refused unless the module's code
    /// is what [`generate`] writes for this bundle.
    pub fn with_native(content: Arc<Content>, native: &'static Native) -> Result<Engine, NativeError> {
        let expected = gen::digest(&content)?;
        if expected != native.digest {
            return Err(NativeError::Mismatch { expected, found: native.digest.to_string() });
        }
        let mut engine = Engine::new(content);
        // `generate` succeeded: the fast path took the bundle.
        debug_assert!(engine.is_fast());
        engine.native = Some(native);
        Ok(engine)
    }

    /// Whether the engine's steps run native code ([`with_native`](Engine::with_native)).
    pub fn is_native(&self) -> bool {
        self.native.is_some()
    }
}
