//! One module per subcommand.

pub mod check;
pub mod explain;
pub mod fmt;

use std::io::IsTerminal;

/// Exit codes of the command line contract.
pub const OK: u8 = 0;
/// Findings that fail, or files that are not formatted.
pub const FAILED: u8 = 1;
/// A usage or I/O error.
pub const USAGE: u8 = 2;

/// The style of human reports on this terminal.
pub fn style() -> situ_compiler::render::Style {
    let colour = std::io::stdout().is_terminal() && std::env::var_os("NO_COLOR").is_none();
    let width = std::env::var("COLUMNS").ok().and_then(|c| c.parse().ok()).unwrap_or(100);
    situ_compiler::render::Style { colour, width }
}
