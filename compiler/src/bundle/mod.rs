//! The bundle: the format, codec, signatures and key files are the
//! `situ-bundle` crate's, re-exported here so that `situ_compiler::bundle::…`
//! names what it always named; [`build`] (a checked program's content) is
//! the compiler's own.

pub mod build;

pub use build::build;
pub use situ_bundle::*;
