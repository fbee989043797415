//! The situ language front end: the pest grammar (`situ.pest`), the parser
//! with error recovery, the AST with a span on every node, and the formatter.
//!
//! This crate is pure: it reads strings and returns values; it does no I/O.
//!
//! ```
//! use situ_grammar::{parse, diag::FileId, ast::Item};
//!
//! let parsed = parse("states { IT initial RD }\nrule ready { when RDY then RD }", FileId(0));
//! assert!(parsed.errors.is_empty());
//! assert!(matches!(parsed.file.items[1], Item::Rule(_)));
//! ```

pub mod ast;
pub mod diag;
pub mod fmt;
pub mod lex;
pub mod parse;
mod script;
mod shift;

pub use fmt::format;
pub use parse::cache::ItemCache;
pub use parse::{parse, Parsed};
