//! `situ run FILE …`: one command, four programs, chosen by the flags and
//! the rules in [`run`] (the one place that decides):
//!
//! 1. `--transport zenoh`, or `--stack demo|none`: one process of a
//!    deployment, or the Fig. 5 demo, in real time ([`super::distributed`]);
//! 2. `--script NAME` or `--random SEED`: any rules file on a script or the
//!    guided random generator, every agent a stand-in ([`super::scripted`]);
//! 3. otherwise the rules' reference stack on a mission in simulated time
//!    ([`super::mission`]: `rules/outdoor.situ`, `rules/ugv.situ`,
//!    `rules/ugv-merge.situ`, `rules/dla.situ`, told by their agents; with
//!    `--compare` the UGV's two programs, with `--missions N` DLA's
//!    experience, [`super::experience`]);
//! 4. rules with no reference stack and no flag of a mission: their first
//!    script (the mission module hands them to [`super::scripted`]).

use std::path::PathBuf;

// The flags of `situ run` (its help is the doc comment of `Command::Run`).
#[derive(clap::Args, Debug)]
pub struct Args {
    /// A `.situ` source or a bundle (rules/outdoor.situ, rules/ugv.situ: the stack is told by the agents).
    pub file: PathBuf,
    /// A built-in scenario (outdoor-default, dafflon-4, dla-offices) or a TOML file; default: the stack's own.
    #[arg(long)]
    pub scenario: Option<String>,
    /// Record the run to this MCAP file (Foxglove reads it).
    #[arg(long)]
    pub record: Option<PathBuf>,
    /// Write trajectory.svg, timeline.svg, metrics.json and recording.mcap into this directory.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// The noise seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Stop after this many seconds of simulated time (default 600, the UGV 120, DLA 300).
    #[arg(long)]
    pub until: Option<f64>,
    /// Dafflon et al.'s comparison of the controllers (rules/ugv.situ): hard-switch,merge.
    #[arg(long, value_delimiter = ',')]
    pub compare: Option<Vec<String>>,
    /// DLA (rules/dla.situ): the reactive layer's case base, read before the run (a new one is
    /// trained when the file does not exist) and written after it with the cases learnt.
    #[arg(long, value_name = "FILE", conflicts_with = "compare")]
    pub cases: Option<PathBuf>,
    /// DLA: the reactive layer does not learn on line (the case base is used as it is).
    #[arg(long)]
    pub no_learning: bool,
    /// DLA: N successive missions (seeds --seed, --seed + 1, …), one case base learning
    /// through them: a line per mission, the curve in --out (experience.svg).
    #[arg(long, value_name = "N", conflicts_with_all = ["compare", "record", "foxglove", "serve"])]
    pub missions: Option<u64>,
    /// DLA, with --missions: held-out missions (learning off) per evaluation of the case base,
    /// before the first learning mission, after the last and about every N/6 between (0: none).
    #[arg(long, value_name = "M", default_value_t = 8, requires = "missions")]
    pub evaluate: u64,
    /// Serve the run live over Foxglove's WebSocket protocol at this address (the
    /// recording's channels and messages; waits for a client, then runs in real time).
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:8765",
          conflicts_with = "compare")]
    pub foxglove: Option<String>,
    /// Serve the Supervisor's page of the run live (`situ view`'s page, following the run) at
    /// this port or address (default: a free port on 127.0.0.1; the URL is the first line on
    /// standard output). A run in simulated time waits for the page, then runs in real time.
    #[arg(long, value_name = "ADDR", num_args = 0..=1, default_missing_value = "127.0.0.1:0",
          conflicts_with = "compare")]
    pub serve: Option<String>,
    /// Any rules file: play this `script` block (its name) or the first script of this
    /// `.situ` file, every agent a stand-in that follows its table or FSM.
    #[arg(long, conflicts_with_all = ["compare", "scenario", "random"])]
    pub script: Option<String>,
    /// Any rules file: the guided random generator drives every agent, with this seed.
    #[arg(long, conflicts_with_all = ["compare", "scenario"])]
    pub random: Option<u64>,
    /// The agents: the simulated vehicle (simulated time), the scripted
    /// Fig. 5 demo, or none here (real time).
    #[arg(long, value_enum, default_value_t = super::distributed::Stack::Sim)]
    pub stack: super::distributed::Stack,
    /// In this process, or one process of a deployment over Zenoh.
    #[arg(long, value_enum, default_value_t = super::distributed::Transport::Inproc)]
    pub transport: super::distributed::Transport,
    /// The deployment: process and host tables (with --transport zenoh).
    #[arg(long)]
    pub deploy: Option<PathBuf>,
    /// Which process of the deployment this is.
    #[arg(long)]
    pub process: Option<String>,
    /// Run only these agents (the process of the deployment that has them).
    #[arg(long, value_delimiter = ',')]
    pub only: Option<Vec<String>>,
    /// Real-time runs (demo, none): the Bulletinboard journals its log to this file and, started
    /// again with it, resumes the state and facts it holds (a deployment's board: `journal = …`).
    #[arg(long, value_name = "PATH", conflicts_with_all = ["script", "random", "compare", "missions"])]
    pub journal: Option<PathBuf>,
    /// Real-time runs (demo, none): how long, in seconds.
    #[arg(long, default_value_t = 10.0)]
    pub duration: f64,
    /// Real-time runs (demo, none): the agents' workers and the Bulletinboard's thread under
    /// SCHED_FIFO at this priority (1 to 99; needs CAP_SYS_NICE or an rtprio limit, else said and
    /// run under the normal scheduler).
    #[arg(long, value_name = "PRIORITY", value_parser = clap::value_parser!(i32).range(1..=99),
          conflicts_with_all = ["script", "random", "compare", "missions"])]
    pub rt_priority: Option<i32>,
    #[command(flatten)]
    pub trust: super::Trust,
}

/// Reads `--trust` and hands the run to the program its flags choose.
pub fn run(args: Args) -> super::Outcome {
    let trust = args.trust.policy()?;
    let Args {
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
        journal,
        rt_priority,
        ..
    } = args;
    let local = stack == super::distributed::Stack::Sim && transport == super::distributed::Transport::Inproc;
    Ok(if local && (script.is_some() || random.is_some()) {
        super::scripted::run(super::scripted::Args { file, script, random, until, out, record, foxglove, serve, trust })
    } else if local {
        let dla = super::mission::DlaArgs { cases, learn: !no_learning, missions, evaluate };
        let args =
            super::mission::Args { file, scenario, record, out, seed, until, compare, foxglove, serve, dla, trust };
        super::mission::run(args)
    } else {
        super::distributed::run(super::distributed::Args {
            file,
            stack,
            transport,
            deploy,
            process,
            only,
            duration,
            journal,
            rt_priority,
            record,
            foxglove,
            serve,
            trust,
        })
    })
}
