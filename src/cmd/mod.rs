//! One module per subcommand.

pub mod bench;
pub mod build;
pub mod check;
pub mod distributed;
pub mod experience;
pub mod explain;
pub mod export;
pub mod fmt;
pub mod gen;
pub mod graph;
pub mod key;
pub mod lsp;
pub mod manners;
pub mod mission;
pub mod program;
pub mod recheck;
pub mod repl;
pub mod replay;
pub mod ros2;
pub mod run;
pub mod scripted;
pub mod test;
pub mod view;
pub mod watchers;

use std::io::IsTerminal;
use std::path::{Path, PathBuf};

/// Exit codes of the command line contract.
pub const OK: u8 = 0;
/// Findings that fail, or files that are not formatted.
pub const FAILED: u8 = 1;
/// A usage or I/O error.
pub const USAGE: u8 = 2;

/// Why a command stopped short. [`exit_code`] prints it and maps it to the
/// exit code, once, for every command.
#[derive(Debug, thiserror::Error)]
pub enum CliError {
    /// A usage or I/O error: `error: MESSAGE` on standard error, exit 2.
    #[error("{0}")]
    Usage(String),
    /// What was asked for fails (no circuit, nothing to export):
    /// `error: MESSAGE` on standard error, exit 1.
    #[error("{0}")]
    Failed(String),
    /// Said already where it was found (findings printed with their report,
    /// a loader's own message): exit with this code and print nothing more.
    #[error("exit {0}")]
    Reported(u8),
}

/// What a command comes to: its exit code ([`OK`], or [`FAILED`] when what
/// it checked fails), or why it stopped short.
pub type Outcome = Result<u8, CliError>;

/// The exit code of an outcome; an error's message is printed here.
pub fn exit_code(outcome: Outcome) -> u8 {
    match outcome {
        Ok(code) => code,
        Err(CliError::Usage(message)) => {
            eprintln!("error: {message}");
            USAGE
        }
        Err(CliError::Failed(message)) => {
            eprintln!("error: {message}");
            FAILED
        }
        Err(CliError::Reported(code)) => code,
    }
}

/// `--trust PUBKEY…`, shared by every command that loads bundles. The help
/// says "Run"; a command whose verb differs says its own (`mut_arg`).
#[derive(clap::Args, Debug, Clone, Default)]
pub struct Trust {
    /// Run only bundles signed by one of these public keys (`situ key new`); refuse others (exit 2).
    #[arg(long, value_name = "PUBKEY")]
    pub trust: Vec<PathBuf>,
}

impl Trust {
    /// The policy of these keys, which the command passes to every load:
    /// each bundle must be signed by one of them (none: every valid bundle
    /// loads).
    pub fn policy(&self) -> Result<situ_compiler::bundle::Trust, CliError> {
        program::trust_of(&self.trust).map_err(CliError::Reported)
    }
}

/// The progress line of a run on standard error, redrawn at most every
/// 200 ms of wall time and only on a terminal; wiped when the run ends.
pub struct LiveLine {
    live: bool,
    last: Option<std::time::Instant>,
    drawn: bool,
}

impl LiveLine {
    const REDRAW: std::time::Duration = std::time::Duration::from_millis(200);

    pub fn new() -> LiveLine {
        LiveLine { live: std::io::stderr().is_terminal(), last: None, drawn: false }
    }

    /// Draws the line `line` makes, if it is time to.
    pub fn draw(&mut self, line: impl FnOnce() -> String) {
        if self.live && self.last.is_none_or(|t| t.elapsed() >= Self::REDRAW) {
            self.last = Some(std::time::Instant::now());
            self.drawn = true;
            eprint!("\r{}\x1b[K", line());
        }
    }

    /// Wipes the line, if one was drawn.
    pub fn clear(&mut self) {
        if self.drawn {
            eprint!("\r\x1b[K");
        }
    }
}

/// The style of human reports on this terminal.
pub fn style() -> situ_compiler::render::Style {
    let colour = std::io::stdout().is_terminal() && std::env::var_os("NO_COLOR").is_none();
    let width = std::env::var("COLUMNS").ok().and_then(|c| c.parse().ok()).unwrap_or(100);
    situ_compiler::render::Style { colour, width }
}

/// The host and port of a listening address given as `PORT` (on
/// 127.0.0.1) or `HOST:PORT` (an IPv6 host in brackets); `None` when it is
/// neither (`--foxglove`, `--serve`).
pub fn host_port(addr: &str) -> Option<(&str, u16)> {
    let (host, port) = match addr.rsplit_once(':') {
        Some((h, p)) => (h.trim_start_matches('[').trim_end_matches(']'), p),
        None => ("127.0.0.1", addr),
    };
    (!host.is_empty()).then_some(())?;
    Some((host, port.parse().ok()?))
}

/// Writes a file so that it is never half written (a temporary file next
/// to it, then a rename, keeping the permissions of a file it replaces).
pub fn write_atomically(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    situ_compiler::bundle::file::write_atomically(path, bytes, false)
}

#[cfg(test)]
mod tests {
    use super::host_port;

    #[test]
    fn an_address_is_a_port_or_a_host_and_a_port() {
        assert_eq!(host_port("8080"), Some(("127.0.0.1", 8080)));
        assert_eq!(host_port("0.0.0.0:8765"), Some(("0.0.0.0", 8765)));
        assert_eq!(host_port("[::1]:9"), Some(("::1", 9)));
        assert_eq!(host_port("localhost:http"), None);
        assert_eq!(host_port(":8080"), None);
        assert_eq!(host_port("nowhere"), None);
        assert_eq!(host_port("1:70000"), None);
    }
}
