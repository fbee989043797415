//! The situ language server (`situ lsp`): the protocol over standard input
//! and output, on the compiler's check pipeline.
//!
//! Documents live in memory ([`world`]); the compiler reads them through a
//! `Loader` that serves open buffers before the disk. Every answer is
//! computed from the compiler's `Checked` result and an index of the names
//! of the ASTs ([`index`]). The crate does the protocol; the compiler stays
//! pure.

pub mod actions;
pub mod complete;
pub mod diagnostics;
pub mod index;
pub mod nav;
pub mod server;
pub mod text;
pub mod tokens;
pub mod transport;
pub mod world;

pub use server::serve;

/// Serves on standard input and output; the process's exit code.
pub fn run_stdio() -> i32 {
    serve(std::io::stdin(), std::io::stdout().lock())
}
