//! The `situ` command line: parses arguments and calls the crates. Every
//! subcommand is one module of `cmd/`, with its arguments (one
//! `#[derive(Args)]` struct, shared groups such as [`cmd::Trust`] flattened
//! into it); each returns its exit code or a [`cmd::CliError`], and
//! [`cmd::exit_code`] prints the error and maps it to the exit code, here
//! and nowhere else.

mod cmd;

use clap::{CommandFactory, Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

/// situ: write, check and run the situation rules of robot navigation stacks.
#[derive(Parser)]
#[command(name = "situ", version, about, long_about = None, propagate_version = true)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per process: the size of the largest subcommand's arguments
// costs nothing worth boxing them for.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
enum Command {
    /// Parse, resolve and check rule files; exit 0 clean, 1 findings that fail, 2 usage or I/O.
    Check(cmd::check::Args),
    /// Format rule files in place; with --check, only report which would change.
    Fmt(cmd::fmt::Args),
    /// Print the long text of a diagnostic code (all codes when none is given).
    Explain(cmd::explain::Args),
    /// Compile a checked source to a bundle (versioned, hashed); exit 1 on findings, 2 on I/O.
    Build(cmd::build::Args),
    /// Signing keys: `situ key new NAME` writes NAME.key (secret) and NAME.pub (public).
    Key {
        #[command(subcommand)]
        what: cmd::key::What,
    },
    /// Throughput and latency of the Bulletinboard on a seeded random event stream, as JSON.
    Bench(cmd::bench::Args),
    /// Run rules: the reference stack on a mission, or any rules file on a script; exit 0 done, 1 failed, 2 usage.
    Run(cmd::run::Args),
    /// Step through the rules by hand: post events, let time pass, ask why (commands from stdin when not a terminal).
    Repl(cmd::repl::Args),
    /// Feed a recording's events to a bundle and say where the states differ from the recorded ones; exit 0 same, 1 differ, 2 unreadable (not a regular file, over 1 GiB, not MCAP, damaged, nothing of situ's); a recording cut short (a killed run) replays up to the cut and says so.
    Replay(cmd::replay::Args),
    /// The ROS 2 bridge: topics to events, the situation to topics, lifecycle nodes driven by the tables (docs/ros2.md; `--features ros2`).
    Ros2(cmd::ros2::Args),
    /// Start every local process of a deployment (Zenoh) and stop them cleanly on Ctrl-C.
    Up(cmd::distributed::UpArgs),
    /// Pictures: the wiring of a state, the Rete network, the state transitions.
    Graph(cmd::graph::Args),
    /// Serve the Supervisor's console on 127.0.0.1 until Ctrl-C: the state graph, the wiring of a state, the rules, and for a recording a timeline; exit 2 on a damaged recording, other rules, or a port in use.
    View(cmd::view::Args),
    /// Run the tests and check the properties of rule files; exit 0 all hold, 1 a failure, 2 usage or I/O.
    Test(cmd::test::Args),
    /// Generate code from the rules: `situ gen agent AGENT FILE --lang python|rust`.
    Gen {
        #[command(subcommand)]
        what: cmd::gen::What,
    },
    /// Export the abstraction and the properties of a rule file to another tool.
    Export(cmd::export::Args),
    /// Print the completion script of a shell for situ.
    #[command(long_about = "Print the completion script of a shell for situ to standard output.\n\n\
        Install it where the shell looks for completions, for example:\n\
        \x20 situ completions bash > ~/.local/share/bash-completion/completions/situ\n\
        \x20 situ completions zsh > ~/.zfunc/_situ   (with `fpath+=~/.zfunc` before `compinit`)\n\
        \x20 situ completions fish > ~/.config/fish/completions/situ.fish\n\
        \x20 situ completions powershell >> $PROFILE\n\
        \x20 situ completions elvish > ~/.config/elvish/lib/situ.elv   (then `use situ`)")]
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
    /// The language server (LSP over standard input and output), for editors: see docs/editors.md.
    Lsp,
    /// Print situ's man page, or write one page per subcommand into a directory.
    #[command(long_about = "Print the man page of situ (roff) to standard output: `situ man | man -l -`.\n\n\
        With -o DIR, write situ.1 and a page per subcommand (situ-check.1, situ-gen-agent.1, ...) \
        into DIR, each atomically; for example `situ man -o ~/.local/share/man/man1`.")]
    Man {
        /// Write situ.1 and a page per subcommand into this directory instead.
        #[arg(short, long, value_name = "DIR")]
        output: Option<PathBuf>,
    },
}

fn main() -> ExitCode {
    // Output piped into a program that stops reading (`situ run … | head`)
    // ends this one quietly, as it does any Unix tool, instead of a panic
    // on the next write.
    #[cfg(unix)]
    // SAFETY: restoring the default action of one signal before any thread starts.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    ExitCode::from(cmd::exit_code(dispatch(cli.command)))
}

/// Runs a subcommand: its exit code, or why it stopped short.
fn dispatch(command: Command) -> cmd::Outcome {
    match command {
        Command::Check(args) => cmd::check::run(&args),
        Command::Completions { shell } => cmd::manners::completions(shell, Cli::command()),
        Command::Man { output } => cmd::manners::man(Cli::command(), output.as_deref()),
        Command::Fmt(args) => Ok(cmd::fmt::run(&args)),
        Command::Explain(args) => cmd::explain::run(&args),
        Command::Build(args) => cmd::build::run(&args),
        Command::Key { what } => Ok(cmd::key::run(what)),
        Command::Bench(args) => cmd::bench::run(&args),
        Command::Test(args) => cmd::test::run(&args),
        Command::Gen { what } => cmd::gen::run(what),
        Command::Export(args) => cmd::export::run(&args),
        Command::Run(args) => cmd::run::run(args),
        Command::Repl(args) => cmd::repl::run(&args.file),
        Command::Lsp => Ok(cmd::lsp::run()),
        Command::Replay(args) => cmd::replay::run(&args),
        Command::Up(args) => Ok(cmd::distributed::up(&args)),
        Command::Graph(args) => cmd::graph::run(&args),
        Command::Ros2(args) => cmd::ros2::run(args),
        Command::View(args) => cmd::view::run(&args),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn cli_is_well_formed() {
        use clap::CommandFactory;
        super::Cli::command().debug_assert();
    }
}
