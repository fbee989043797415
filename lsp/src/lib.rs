//! The situ language server (`situ lsp`): the protocol over standard input
//! and output, on the compiler's check pipeline.
//!
//! Documents live in memory ([`world`]); the compiler reads them through a
//! `Loader` that serves open buffers before the disk. Every answer is
//! computed from the compiler's `Checked` result and an index of the names
//! of the ASTs ([`index`]). The crate does the protocol; the compiler stays
//! pure.
//!
//! Three layers, each importing only the ones below it:
//! - [`server`] is the loop: it reads a frame ([`transport`]), hands it to
//!   [`protocol`], writes what comes back, and publishes diagnostics;
//! - [`protocol`] holds every piece of the protocol's JSON: params become
//!   typed inputs, the features' answers become results, failures become
//!   JSON-RPC errors;
//! - the features ([`nav`], [`complete`], [`actions`], [`tokens`],
//!   [`diagnostics`], [`verdicts`]) take an analysis and a place and return
//!   data in the protocol's terms ([`data`]), with no JSON; they import
//!   the documents ([`world`]), the data and [`diagnostics`] (a compiler
//!   finding placed), and nothing below them imports a feature.
//!
//! The verdicts of properties and tests ([`verdicts`]) run `situ test`'s
//! policy (`situ_verify::suite`) when a document is opened or saved, on a
//! worker thread and a budget of work suited to an editor; their state
//! ([`runs`]) is kept by the [`world`], which imports no feature.

pub mod actions;
pub mod complete;
pub mod data;
pub mod diagnostics;
pub mod index;
pub mod nav;
pub mod protocol;
pub mod runs;
pub mod server;
pub mod text;
pub mod tokens;
pub mod transport;
pub mod verdicts;
pub mod world;

pub use server::serve;
pub use tokens::{TOKEN_MODIFIERS, TOKEN_TYPES};

/// Serves on standard input and output; the process's exit code.
pub fn run_stdio() -> i32 {
    serve(std::io::stdin(), std::io::stdout().lock())
}
