//! The `situ` command line: parses arguments and calls the crates. Every
//! subcommand is one module of `cmd/`; each returns the process exit code.

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
        /// Check again on every save of a file or of any file it includes, until Ctrl-C
        /// (exit 0); each round ends with a line of the time and the summary.
        #[arg(long)]
        watch: bool,
        /// Also check this ROS 2 map (TOML, docs/ros2.md) against the rules; one root file only.
        #[arg(long, value_name = "MAP")]
        ros2_map: Option<PathBuf>,
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
    /// Compile a checked source to a bundle (versioned, hashed); exit 1 on findings, 2 on I/O.
    Build {
        file: PathBuf,
        /// The bundle file to write.
        #[arg(short, long)]
        output: PathBuf,
        /// Write the compact binary form instead of JSON.
        #[arg(long)]
        binary: bool,
        /// Print the network's node counts and what sharing saved.
        #[arg(long)]
        stats: bool,
        /// Refuse to build on warnings too.
        #[arg(long)]
        deny_warnings: bool,
        /// Sign the bundle with this secret key (`situ key new NAME` writes NAME.key).
        #[arg(long, value_name = "KEY")]
        sign: Option<PathBuf>,
    },
    /// Signing keys: `situ key new NAME` writes NAME.key (secret) and NAME.pub (public).
    Key {
        #[command(subcommand)]
        what: cmd::key::What,
    },
    /// Throughput and latency of the Bulletinboard on a seeded random event stream, as JSON.
    Bench {
        /// A `.situ` source or a bundle.
        file: PathBuf,
        /// How many events.
        #[arg(long, default_value_t = 1_000_000)]
        events: u64,
        /// The stream's seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Read the events from this stream file instead (bench/README.md).
        #[arg(long)]
        stream_in: Option<PathBuf>,
        /// Write the generated stream here.
        #[arg(long)]
        stream_out: Option<PathBuf>,
        /// Write the `INDEX STATE` lines of the state changes here.
        #[arg(long)]
        states_out: Option<PathBuf>,
        /// Do not reset to the initial state after a final state.
        #[arg(long)]
        no_reset: bool,
        /// Bench only bundles signed by one of these public keys (`situ key new`); refuse others (exit 2).
        #[arg(long, value_name = "PUBKEY")]
        trust: Vec<PathBuf>,
    },
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
        /// Run only bundles signed by one of these public keys (`situ key new`); refuse others (exit 2).
        #[arg(long, value_name = "PUBKEY")]
        trust: Vec<PathBuf>,
    },
    /// Step through the rules by hand: post events, let time pass, ask why (commands from stdin when not a terminal).
    Repl {
        /// A `.situ` source or a bundle.
        file: PathBuf,
    },
    /// Feed a recording's events to a bundle and say where the states differ from the recorded ones; exit 0 same, 1 differ, 2 unreadable (not a regular file, over 1 GiB, not MCAP, damaged, nothing of situ's); a recording cut short (a killed run) replays up to the cut and says so.
    Replay {
        /// An MCAP recording of `situ run --record`.
        recording: PathBuf,
        /// The rules to replay on (a bundle or a `.situ` source); default: the recording's own.
        #[arg(long)]
        bundle: Option<PathBuf>,
        #[arg(long, value_enum, default_value_t = cmd::replay::Format::Human)]
        format: cmd::replay::Format,
        /// Replay only on bundles (the attached one or --bundle) signed by one of these public keys (`situ key new`); refuse others (exit 2).
        #[arg(long, value_name = "PUBKEY")]
        trust: Vec<PathBuf>,
    },
    /// The ROS 2 bridge: topics to events, the situation to topics, lifecycle nodes driven by the tables (docs/ros2.md; `--features ros2`).
    Ros2 {
        /// The rules (a `.situ` source or a bundle).
        file: PathBuf,
        /// The ROS 2 map (TOML): which topic each event comes from, which agents are lifecycle nodes.
        #[arg(long)]
        map: PathBuf,
        /// The DDS domain (default: ROS_DOMAIN_ID, else 0).
        #[arg(long)]
        domain: Option<u16>,
        /// The RMW of the robot's nodes: how their lifecycle services are carried.
        #[arg(long, value_enum, default_value_t = cmd::ros2::Rmw::Fastrtps)]
        rmw: cmd::ros2::Rmw,
        /// Stop after this many seconds (default: until Ctrl-C or SIGTERM).
        #[arg(long)]
        duration: Option<f64>,
        /// Record what came and went as a ROS 2 bag (a new directory; MCAP storage).
        #[arg(long, value_name = "DIR")]
        record: Option<PathBuf>,
        /// Run only bundles signed by one of these public keys (`situ key new`); refuse others (exit 2).
        #[arg(long, value_name = "PUBKEY")]
        trust: Vec<PathBuf>,
    },
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
        /// Run only bundles signed by one of these public keys (`situ key new`); refuse others (exit 2).
        #[arg(long, value_name = "PUBKEY")]
        trust: Vec<PathBuf>,
    },
    /// Pictures: the wiring of a state, the Rete network, the state transitions.
    Graph {
        /// A `.situ` source or a bundle (the states view needs the source).
        file: PathBuf,
        #[arg(long, value_enum)]
        view: cmd::graph::View,
        /// The state whose wiring to draw (default: all, as clusters).
        #[arg(long)]
        state: Option<String>,
        #[arg(long, value_enum, default_value_t = cmd::graph::Format::Dot)]
        format: cmd::graph::Format,
        /// Write here instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
    /// Serve the Supervisor's console on 127.0.0.1 until Ctrl-C: the state graph, the wiring of a state, the rules, and for a recording a timeline; exit 2 on a damaged recording, other rules, or a port in use.
    View {
        /// A `.situ` source, a bundle, or an MCAP recording of `situ run --record`.
        file: PathBuf,
        /// The rules of a recording (a `.situ` source or a bundle); default: the bundle attached to it. Refused (exit 2) when the recording was made on other rules.
        #[arg(long, value_name = "FILE")]
        rules: Option<PathBuf>,
        /// The port to listen on (default: a free one); the URL is the first line on standard output.
        #[arg(long)]
        port: Option<u16>,
    },
    /// Run the tests and check the properties of rule files; exit 0 all hold, 1 a failure, 2 usage or I/O.
    Test {
        #[arg(required = true)]
        files: Vec<PathBuf>,
        /// Only the tests and properties whose name contains this.
        #[arg(long)]
        filter: Option<String>,
        #[arg(long, value_enum, default_value_t = cmd::test::Format::Human)]
        format: cmd::test::Format,
        /// Which checkers look at the properties.
        #[arg(long, value_enum, default_value_t = cmd::test::Engine::Both)]
        engine: cmd::test::Engine,
        /// The seed of the random search.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Random runs per property.
        #[arg(long, default_value_t = 256)]
        cases: u32,
        /// Events per random run.
        #[arg(long, default_value_t = 120)]
        length: usize,
        /// The most events the exhaustive exploration goes from the start.
        #[arg(long, default_value_t = 12)]
        depth: usize,
        /// The most abstract states the exhaustive exploration makes.
        #[arg(long, default_value_t = 20_000)]
        max_states: usize,
        /// IC3's work budget per property, in SAT propagations: the same
        /// budget gives the same verdict on any machine under any load.
        #[arg(long, default_value_t = situ_verify::property::DEFAULT_EFFORT)]
        prove_effort: u64,
        /// A wall-clock guard on IC3, in seconds per property; a property it
        /// stops is undecided, and the output says it was the clock.
        #[arg(long, default_value_t = 600.0)]
        prove_timeout: f64,
        /// Exit 0 when no property is violated, even if some are undecided.
        #[arg(long)]
        allow_undecided: bool,
        /// Print the size and time of the exploration and the random search.
        #[arg(long)]
        stats: bool,
    },
    /// Generate code from the rules: `situ gen agent AGENT FILE --lang python|rust`.
    Gen {
        #[command(subcommand)]
        what: cmd::gen::What,
    },
    /// Export the abstraction and the properties of a rule file to another tool.
    Export {
        /// A Promela model for spin (one property per `-DPROP=k`).
        #[arg(long, required_unless_present = "aiger", conflicts_with = "aiger")]
        promela: bool,
        /// A binary AIGER 1.9 circuit for hardware model checkers such as ABC:
        /// the abstraction for runs of any length, one bad-state output per
        /// property (unbounded `eventually` has none).
        #[arg(long)]
        aiger: bool,
        /// Only this property (by name), as the circuit's single bad-state output.
        #[arg(long, requires = "aiger")]
        property: Option<String>,
        file: PathBuf,
        /// Write here instead of standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
        /// The most events the exploration goes from the start.
        #[arg(long, default_value_t = 12)]
        depth: usize,
        /// The most abstract states.
        #[arg(long, default_value_t = 20_000)]
        max_states: usize,
    },
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
    let code = match cli.command {
        Command::Check { files, format, deny_warnings, watch, ros2_map } => {
            cmd::check::run(&files, format, deny_warnings, watch, ros2_map.as_deref())
        }
        Command::Completions { shell } => cmd::manners::completions(shell, Cli::command()),
        Command::Man { output } => cmd::manners::man(Cli::command(), output.as_deref()),
        Command::Fmt { files, check } => cmd::fmt::run(&files, check),
        Command::Explain { code } => cmd::explain::run(code.as_deref()),
        Command::Build { file, output, binary, stats, deny_warnings, sign } => {
            cmd::build::run(&file, &output, binary, stats, deny_warnings, sign.as_deref())
        }
        Command::Key { what } => cmd::key::run(what),
        Command::Bench { file, events, seed, stream_in, stream_out, states_out, no_reset, trust } => {
            match cmd::program::trust(&trust) {
                Ok(()) => cmd::bench::run(cmd::bench::Args {
                    file,
                    events,
                    seed,
                    stream_in,
                    stream_out,
                    states_out,
                    no_reset,
                }),
                Err(code) => code,
            }
        }
        Command::Test {
            files,
            filter,
            format,
            engine,
            seed,
            cases,
            length,
            depth,
            max_states,
            prove_effort,
            prove_timeout,
            allow_undecided,
            stats,
        } => cmd::test::run(cmd::test::Args {
            files,
            filter,
            format,
            engine,
            seed,
            cases,
            length,
            depth,
            max_states,
            prove_effort,
            prove_timeout,
            allow_undecided,
            stats,
        }),
        Command::Gen { what } => cmd::gen::run(what),
        Command::Export { promela: _, aiger: true, property, file, output, .. } => {
            cmd::export::aiger(&file, output.as_ref(), property.as_deref())
        }
        Command::Export { file, output, depth, max_states, .. } => {
            cmd::export::run(&file, output.as_ref(), depth, max_states)
        }
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
            if let Err(code) = cmd::program::trust(&trust) {
                return ExitCode::from(code);
            }
            let local = stack == cmd::distributed::Stack::Sim && transport == cmd::distributed::Transport::Inproc;
            if local && (script.is_some() || random.is_some()) {
                cmd::scripted::run(cmd::scripted::Args { file, script, random, until, out, record, foxglove, serve })
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
                })
            }
        }
        Command::Repl { file } => cmd::repl::run(&file),
        Command::Lsp => cmd::lsp::run(),
        Command::Replay { recording, bundle, format, trust } => match cmd::program::trust(&trust) {
            Ok(()) => cmd::replay::run(&recording, bundle.as_ref(), format),
            Err(code) => code,
        },
        Command::Up { deploy, file, stack, duration, trust } => match cmd::program::trust(&trust) {
            Ok(()) => cmd::distributed::up(&deploy, &file, stack, duration, &trust),
            Err(code) => code,
        },
        Command::Graph { file, view, state, format, output } => {
            cmd::graph::run(&file, view, state.as_deref(), format, output.as_ref())
        }
        Command::Ros2 { file, map, domain, rmw, duration, record, trust } => {
            cmd::ros2::run(cmd::ros2::Args { file, map, domain, rmw, duration, record, trust })
        }
        Command::View { file, rules, port } => cmd::view::run(&file, rules.as_deref(), port),
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
