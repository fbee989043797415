//! The bundle: everything a runtime needs to run a checked program, and
//! nothing of its source but the text of its rules (so that a firing can be
//! explained in source terms). One serde document, versioned and hashed.
//!
//! A bundle file is an envelope around the [`Content`]:
//!
//! ```text
//! {"format":"situ-bundle","format_version":1,"compiler_version":"0.1.0",
//!  "sha256":"<hex of the content's bytes>","content":{ … }}
//! ```
//!
//! The hash covers the exact bytes of `content` as written, so any edit of
//! the content (or a truncation) is detected before anything is built from
//! it. [`codec`] writes and reads bundles, JSON or binary, and says precisely
//! why a file is refused ([`codec::LoadError`]); [`sign`] signs and verifies
//! them, [`key`] reads and writes key files, and [`load`] reads a bundle
//! under a [`Trust`] policy, a value the caller builds.
//!
//! This crate is what the runtime and the compiler share: the format
//! ([`content`]), the codec, signatures, the runtime's view of tests,
//! properties and scripts ([`spec`]), and small helpers both need
//! ([`suggest`], [`Moment`], [`file::read_bounded`]). It knows nothing of
//! the language's syntax: the compiler builds a [`Content`] from a checked
//! program (`situ_compiler::bundle::build`).
//!
//! Modules import one way only: `signature` ← `codec` ← `sign` ← `trust`,
//! and `key` reads files with `file`.

pub mod codec;
pub mod content;
pub mod file;
mod float;
pub mod key;
mod moment;
pub mod sign;
mod signature;
pub mod spec;
pub mod suggest;
mod trust;

pub use codec::{decode, encode, Encoding, LoadError};
pub use content::*;
pub use moment::Moment;
pub use trust::{load, Loaded, Trust};
