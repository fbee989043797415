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
    Run {
        /// A `.situ` source or a bundle (rules/outdoor.situ, rules/ugv.situ: the stack is told by the agents).
        file: PathBuf,
        /// A built-in scenario (outdoor-default, dafflon-4, dla-offices) or a TOML file; default: the stack's own.
        #[arg(long)]
        scenario: Option<String>,
        /// Record the run to this MCAP file (Foxglove reads it).
        #[arg(long)]
        record: Option<PathBuf>,
        /// Write trajectory.svg, timeline.svg, metrics.json and recording.mcap into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
        /// The noise seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Stop after this many seconds of simulated time (default 600, the UGV 120, DLA 300).
        #[arg(long)]
        until: Option<f64>,
        /// Dafflon et al.'s comparison of the controllers (rules/ugv.situ): hard-switch,merge.
        #[arg(long, value_delimiter = ',')]
        compare: Option<Vec<String>>,
        /// DLA (rules/dla.situ): the reactive layer's case base, read before the run (a new one is
        /// trained when the file does not exist) and written after it with the cases learnt.
        #[arg(long, value_name = "FILE", conflicts_with = "compare")]
        cases: Option<PathBuf>,
        /// DLA: the reactive layer does not learn on line (the case base is used as it is).
        #[arg(long)]
        no_learning: bool,
        /// DLA: N successive missions (seeds --seed, --seed + 1, …), one case base learning
        /// through them: a line per mission, the curve in --out (experience.svg).
        #[arg(long, value_name = "N", conflicts_with_all = ["compare", "record", "foxglove", "serve"])]
        missions: Option<u64>,
        /// DLA, with --missions: held-out missions (learning off) per evaluation of the case base,
        /// before the first learning mission, after the last and about every N/6 between (0: none).
        #[arg(long, value_name = "M", default_value_t = 8, requires = "missions")]
        evaluate: u64,
        /// Serve the run live over Foxglove's WebSocket protocol at this address (the
        /// recording's channels and messages; waits for a client, then runs in real time).
        #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8765",
              conflicts_with = "compare")]
        foxglove: Option<String>,
        /// Serve the Supervisor's page of the run live (`situ view`'s page, following the run) at
        /// this port or address (default: a free port on 127.0.0.1; the URL is the first line on
        /// standard output). A run in simulated time waits for the page, then runs in real time.
        #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:0",
              conflicts_with = "compare")]
        serve: Option<String>,
        /// Any rules file: play this `script` block (its name) or the first script of this
        /// `.situ` file, every agent a stand-in that follows its table or FSM.
        #[arg(long, conflicts_with_all = ["compare", "scenario", "random"])]
        script: Option<String>,
        /// Any rules file: the guided random generator drives every agent, with this seed.
        #[arg(long, conflicts_with_all = ["compare", "scenario"])]
        random: Option<u64>,
        /// The agents: the simulated vehicle (simulated time), the scripted
        /// Fig. 5 demo, or none here (real time).
        #[arg(long, value_enum, default_value_t = cmd::distributed::Stack::Sim)]
        stack: cmd::distributed::Stack,
        /// In this process, or one process of a deployment over Zenoh.
        #[arg(long, value_enum, default_value_t = cmd::distributed::Transport::Inproc)]
        transport: cmd::distributed::Transport,
        /// The deployment: process and host tables (with --transport zenoh).
        #[arg(long)]
        deploy: Option<PathBuf>,
        /// Which process of the deployment this is.
        #[arg(long)]
        process: Option<String>,
        /// Run only these agents (the process of the deployment that has them).
        #[arg(long, value_delimiter = ',')]
        only: Option<Vec<String>>,
        /// Real-time runs (demo, none): how long, in seconds.
        #[arg(long, default_value_t = 10.0)]
        duration: f64,
        #[command(flatten)]
        trust: cmd::Trust,
    },
    /// Step through the rules by hand: post events, let time pass, ask why (commands from stdin when not a terminal).
    Repl(cmd::repl::Args),
    /// Feed a recording's events to a bundle and say where the states differ from the recorded ones; exit 0 same, 1 differ, 2 unreadable (not a regular file, over 1 GiB, not MCAP, damaged, nothing of situ's); a recording cut short (a killed run) replays up to the cut and says so.
    Replay(cmd::replay::Args),
    /// The ROS 2 bridge: topics to events, the situation to topics, lifecycle nodes driven by the tables (docs/ros2.md; `--features ros2`).
    Ros2(cmd::ros2::Args),
    /// Start every local process of a deployment (Zenoh) and stop them cleanly on Ctrl-C.
    Up {
        /// The deployment file.
        deploy: PathBuf,
        /// The rules (a `.situ` source or a bundle).
        file: PathBuf,
        #[arg(long, value_enum, default_value_t = cmd::distributed::Stack::Demo)]
        stack: cmd::distributed::Stack,
        /// How long each process runs, in seconds.
        #[arg(long, default_value_t = 10.0)]
        duration: f64,
        #[command(flatten)]
        trust: cmd::Trust,
    },
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
        Command::Run {
            file,
            scenario,
            record,
            out,
            seed,
            until,
            compare,
            cases,
            no_learning,
            missions,
            evaluate,
            foxglove,
            serve,
            script,
            random,
            stack,
            transport,
            deploy,
            process,
            only,
            duration,
            trust,
        } => {
            let trust = trust.policy()?;
            let local = stack == cmd::distributed::Stack::Sim && transport == cmd::distributed::Transport::Inproc;
            Ok(if local && (script.is_some() || random.is_some()) {
                cmd::scripted::run(cmd::scripted::Args {
                    file,
                    script,
                    random,
                    until,
                    out,
                    record,
                    foxglove,
                    serve,
                    trust,
                })
            } else if local {
                let dla = cmd::run::DlaArgs { cases, learn: !no_learning, missions, evaluate };
                cmd::run::run(cmd::run::Args {
                    file,
                    scenario,
                    record,
                    out,
                    seed,
                    until,
                    compare,
                    foxglove,
                    serve,
                    dla,
                    trust,
                })
            } else {
                cmd::distributed::run(cmd::distributed::Args {
                    file,
                    stack,
                    transport,
                    deploy,
                    process,
                    only,
                    duration,
                    record,
                    foxglove,
                    serve,
                    trust,
                })
            })
        }
        Command::Repl(args) => cmd::repl::run(&args.file),
        Command::Lsp => Ok(cmd::lsp::run()),
        Command::Replay(args) => cmd::replay::run(&args),
        Command::Up { deploy, file, stack, duration, trust } => {
            Ok(cmd::distributed::up(&deploy, &file, stack, duration, &trust.trust))
        }
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
