//! The `situ` command line: parses arguments and calls the crates. Every
//! subcommand is one module of `cmd/`; each returns the process exit code.

mod cmd;

use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// situ: write, check and run the situation rules of robot navigation stacks.
#[derive(Parser)]
#[command(name = "situ", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Parse, resolve and check rule files; exit 0 clean, 1 findings that fail, 2 usage or I/O.
    Check {
        /// The root files to check (each with its includes).
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// How to print findings.
        #[arg(long, value_enum, default_value_t = cmd::check::Format::Human)]
        format: cmd::check::Format,
        /// Fail (exit 1) on warnings too.
        #[arg(long)]
        deny_warnings: bool,
    },
    /// Format rule files in place; with --check, only report which would change.
    Fmt {
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Change nothing; exit 1 if a file is not formatted.
        #[arg(long)]
        check: bool,
    },
    /// Print the long text of a diagnostic code (all codes when none is given).
    Explain {
        /// A code such as E0101 or situ::E0101.
        code: Option<String>,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let code = match cli.command {
        Command::Check { files, format, deny_warnings } => cmd::check::run(&files, format, deny_warnings),
        Command::Fmt { files, check } => cmd::fmt::run(&files, check),
        Command::Explain { code } => cmd::explain::run(code.as_deref()),
    };
    ExitCode::from(code)
}

#[cfg(test)]
mod tests {
    #[test]
    fn cli_is_well_formed() {
        use clap::CommandFactory;
        super::Cli::command().debug_assert();
    }
}
