//! `situ run FILE --stack demo [--transport zenoh --deploy D (--process P |
//! --only A,B)] [--duration S] [--record F.mcap]`: a stack of agents in
//! real time, in this process or as one process of a deployment over Zenoh;
//! and `situ up D FILE …`: every local process of a deployment, started
//! together and stopped cleanly (Ctrl-C or SIGTERM stops them all).
//!
//! The agents come from `--stack`: `demo` is the scripted stack of
//! `examples/fig5` (runtime::demo); `none` runs no agent here, only the
//! Bulletinboard (the agents are in other processes or other languages:
//! `examples/python/ladar.py`). The simulated vehicle of `situ run`'s
//! default stack needs all its agents and its physics in one process, in
//! simulated time: it does not run over Zenoh.
//!
//! A process of the deployment that only routes (`mode = "router"`, no
//! agents, no Bulletinboard) runs a Zenoh router and nothing else, until
//! Ctrl-C, SIGTERM or `--duration`; `situ up` stops it once every other
//! process has ended.

use super::view::data::Site;
use super::watchers::Watchers;
use super::{FAILED, OK, USAGE};
use situ_compiler::bundle::{self, Content, Encoding};
use situ_runtime::agent::{self, Agent};
use situ_runtime::demo;
use situ_runtime::journal;
use situ_runtime::realtime::{self, RealtimeConfig};
use situ_runtime::record::mcap::McapRecorder;
use situ_runtime::record::Sink;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Transport {
    /// Every agent in this process.
    Inproc,
    /// One process of a deployment, over Zenoh (build with `--features zenoh`).
    Zenoh,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Stack {
    /// The simulated vehicle of the rules (outdoor.situ, ugv.situ), simulated time.
    Sim,
    /// The scripted agents of examples/fig5, real time.
    Demo,
    /// No agent in this process: the Bulletinboard only.
    None,
}

pub struct Args {
    pub file: PathBuf,
    pub stack: Stack,
    pub transport: Transport,
    pub deploy: Option<PathBuf>,
    pub process: Option<String>,
    pub only: Option<Vec<String>>,
    pub duration: f64,
    /// The board's journal (over a deployment's `journal`).
    pub journal: Option<PathBuf>,
    /// The threads under SCHED_FIFO at this priority.
    pub rt_priority: Option<i32>,
    pub record: Option<PathBuf>,
    /// Serve the run live over Foxglove's WebSocket protocol at this address.
    pub foxglove: Option<String>,
    /// Serve the Supervisor's page of the run live at this address (the
    /// process of the Bulletinboard).
    pub serve: Option<String>,
    /// The policy of `--trust`.
    pub trust: situ_compiler::bundle::Trust,
}

/// The flag Ctrl-C and SIGTERM raise: one per process, its handler
/// installed by the first call. Commands call it first thing, before
/// their set-up (loading, Zenoh's session, the recording): a signal that
/// comes while a process starts is then a clean stop as soon as it runs,
/// not the default action's death with a recording half written.
pub fn stop_flag() -> Arc<AtomicBool> {
    static STOP: std::sync::OnceLock<Arc<AtomicBool>> = std::sync::OnceLock::new();
    STOP.get_or_init(|| {
        let stop = Arc::new(AtomicBool::new(false));
        let s = stop.clone();
        // An error here (another handler was installed) only means no
        // clean stop on signals.
        let _ = ctrlc::set_handler(move || s.store(true, Ordering::Release));
        stop
    })
    .clone()
}

fn agents_of(stack: Stack, names: &[String]) -> Result<Vec<Box<dyn Agent>>, String> {
    match stack {
        Stack::None => Ok(Vec::new()),
        Stack::Demo => demo::agents(names, Arc::new(Mutex::new(Vec::new()))).map_err(|e| e.to_string()),
        Stack::Sim => {
            Err("the simulated vehicle runs in one process, in simulated time: use `--stack demo` or `--stack none`"
                .into())
        }
    }
}

/// The recording, with the bundle attached: the file's bytes as they were
/// read and checked (its signature with them), or the source compiled; the
/// watchers asked for tapped to it. `None`: no file, no watcher.
fn recorder(
    args: &Args,
    content: &Arc<Content>,
    file: Option<&[u8]>,
    checked: Option<&situ_compiler::Checked>,
) -> Result<(Option<Box<dyn Sink>>, Watchers), u8> {
    let recording = match &args.record {
        None => None,
        Some(path) => {
            let compiled;
            let bytes = match file {
                Some(b) => b,
                None => {
                    compiled = bundle::encode(content, Encoding::Json);
                    &compiled
                }
            };
            match McapRecorder::create(path, content.clone(), bytes) {
                Ok(r) => Some(r),
                Err(e) => {
                    eprintln!("error: cannot write `{}`: {e}", path.display());
                    return Err(USAGE);
                }
            }
        }
    };
    let watchers = Watchers::start(args.foxglove.as_deref(), args.serve.as_deref(), || {
        Site::live(args.file.display().to_string(), content.clone(), checked)
    })?;
    let sink = watchers.recorder(recording, content).map(|r| Box::new(r) as Box<dyn Sink>);
    Ok((sink, watchers))
}

pub fn run(args: Args) -> u8 {
    if !(args.duration.is_finite() && args.duration > 0.0) {
        eprintln!("error: --duration must be a positive number of seconds");
        return USAGE;
    }
    stop_flag();
    if let Some(p) = args.rt_priority {
        // Asked of the kernel on a thread of its own, to say a refusal
        // before the run (which says it in the recording too).
        let probe = std::thread::spawn(move || situ_runtime::priority::enter(p).map(|_| ()));
        if let Ok(Err(e)) = probe.join() {
            eprintln!("warning: {}", situ_runtime::priority::refused(p, "this process's threads", &e));
        }
    }
    let program = match super::program::load(&args.file, false, &args.trust) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let file = program.bytes.as_deref();
    let checked = program.checked.as_ref();
    match args.transport {
        Transport::Inproc => inproc(&args, program.content.clone(), file, checked),
        Transport::Zenoh => zenoh(&args, program.content.clone(), file, checked),
    }
}

/// The agents of `stack` among `names`, bound to the functions `content`
/// names; the error printed and a usage exit code otherwise.
fn bound_agents(stack: Stack, content: &Content, names: &[String]) -> Result<agent::Bound, u8> {
    let bound =
        agents_of(stack, names).and_then(|agents| agent::bind(content, agents, false).map_err(|e| e.to_string()));
    bound.map_err(|e| {
        eprintln!("error: {e}");
        USAGE
    })
}

/// The board's journal at `path`, if any, opened for `content`: what it
/// recovers is said on standard error as `NAME: recovered …`.
fn open_journal(path: Option<&Path>, content: &Content, name: &str) -> Result<Option<journal::Opened>, u8> {
    let Some(path) = path else { return Ok(None) };
    let name = name.to_string();
    match journal::Opened::open(path, content) {
        Ok(j) => Ok(Some(j.telling(move |text| eprintln!("{name}: {text}")))),
        Err(e) => {
            eprintln!("error: {e}");
            Err(USAGE)
        }
    }
}

fn finish(summary: situ_runtime::summary::Summary) -> u8 {
    print!("{}", summary.table());
    if summary.board.cascade_errors > 0 {
        FAILED
    } else {
        OK
    }
}

fn inproc(args: &Args, content: Arc<Content>, file: Option<&[u8]>, checked: Option<&situ_compiler::Checked>) -> u8 {
    let names: Vec<String> = content.agents.iter().map(|a| a.name.clone()).collect();
    let bound = match bound_agents(args.stack, &content, &names) {
        Ok(b) => b,
        Err(code) => return code,
    };
    let (sink, watchers) = match recorder(args, &content, file, checked) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let journal = match open_journal(args.journal.as_deref(), &content, "board") {
        Ok(j) => j,
        Err(code) => return code,
    };
    let config =
        RealtimeConfig { stop: Some(stop_flag()), journal, priority: args.rt_priority, ..RealtimeConfig::default() };
    let summary = realtime::run(content, bound, sink, config, Duration::from_secs_f64(args.duration), &mut |c| {
        eprintln!("state {}", c.to)
    });
    watchers.end();
    finish(summary)
}

#[cfg(not(feature = "zenoh"))]
fn zenoh(args: &Args, _content: Arc<Content>, _file: Option<&[u8]>, _: Option<&situ_compiler::Checked>) -> u8 {
    let _ = (&args.deploy, &args.process, &args.only, &args.serve, &args.foxglove);
    eprintln!("error: {NO_ZENOH}");
    USAGE
}

#[cfg(feature = "zenoh")]
fn zenoh(args: &Args, content: Arc<Content>, file: Option<&[u8]>, checked: Option<&situ_compiler::Checked>) -> u8 {
    use situ_bus_zenoh::deploy::Deployment;
    use situ_bus_zenoh::{Placement, ZenohBus};
    use situ_runtime::bus::Bus;
    let Some(deploy) = &args.deploy else {
        eprintln!("error: --transport zenoh needs --deploy DEPLOY.toml (the process and host tables)");
        return USAGE;
    };
    let names: Vec<String> = content.agents.iter().map(|a| a.name.clone()).collect();
    let d = match Deployment::load(deploy, &names) {
        Ok(d) => d,
        Err(e) => {
            eprintln!("error[{}]: {e}", e.code());
            return USAGE;
        }
    };
    if d.tls.is_none() {
        eprintln!("{}", open_deployment_warning(deploy, &d.robot));
    }
    let process = match (&args.process, &args.only) {
        (Some(p), None) => d.process(p).ok_or_else(|| format!("no process `{p}` in `{}`", deploy.display())),
        (None, Some(only)) => d
            .process_of(only)
            .ok_or_else(|| format!("no process of `{}` runs all of {}", deploy.display(), only.join(", "))),
        _ => Err("say which process of the deployment this is: --process NAME or --only AGENT,…".into()),
    };
    let process = match process {
        Ok(p) => p.clone(),
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    if process.routes_only() {
        return route(args, &d, &process);
    }
    let here: Vec<String> = args.only.clone().unwrap_or_else(|| process.agents.clone());
    let bound = match bound_agents(args.stack, &content, &here) {
        Ok(b) => b,
        Err(code) => return code,
    };
    let local: Vec<bool> = content.agents.iter().map(|a| here.contains(&a.name)).collect();
    let placement = Placement { robot: d.robot.clone(), local, board: process.board };
    // A board of a standby group: its log, shared with the bus that answers
    // the other boards' catch-up requests.
    let standby = d
        .standby_config(&process.name, STATUS_EVERY)
        .map(|config| (config, situ_runtime::standby::SharedLog::default()));
    let beats = match d.beats(&process) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("error[{}]: {e}", e.code());
            return USAGE;
        }
    };
    let group = standby.as_ref().map(|(config, log)| situ_bus_zenoh::standby::BoardGroup {
        name: config.name.clone(),
        lease: config.lease,
        log: log.clone(),
        beats,
    });
    let bus =
        match ZenohBus::open_in_group(content.clone(), placement, &d.zenoh_config(&process), Default::default(), group)
        {
            Ok(b) => b,
            Err(e) => {
                eprintln!("error: process `{}`: {e}", process.name);
                return USAGE;
            }
        };
    let board_peers = bus.peers();
    if let Some(addr) = board_peers.as_ref().and_then(|p| p.beats_addr()) {
        eprintln!("{}: hears the boards' beats on udp/{addr}", process.name);
    }
    let standby = match (standby, board_peers.clone()) {
        (Some((config, log)), Some(peers)) => {
            let name = process.name.clone();
            let tell: situ_runtime::standby::Tell = std::sync::Arc::new(move |what: &str| eprintln!("{name}: {what}"));
            Some(situ_runtime::standby::Standby { config, peers, log, tell: Some(tell) })
        }
        _ => None,
    };
    if !process.board && (args.serve.is_some() || args.foxglove.is_some()) {
        eprintln!(
            "error: process `{}` has no Bulletinboard: the process that has it (`board = true` in `{}`) serves \
             --serve and --foxglove",
            process.name,
            deploy.display()
        );
        return USAGE;
    }
    let (sink, watchers) = match recorder(args, &content, file, checked) {
        Ok(s) => s,
        Err(code) => return code,
    };
    let bus: Arc<dyn Bus> = Arc::new(bus);
    let journal = match (process.board, args.journal.clone().or_else(|| d.journal(&process))) {
        (true, Some(_)) if standby.is_some() => {
            eprintln!(
                "error: --journal: process `{}` is a board of a standby group: a journal is for a single board",
                process.name
            );
            Err(USAGE)
        }
        (true, path) => open_journal(path.as_deref(), &content, &process.name),
        (false, Some(_)) => {
            eprintln!("error: --journal: process `{}` has no Bulletinboard", process.name);
            Err(USAGE)
        }
        (false, None) => Ok(None),
    };
    let journal = match journal {
        Ok(j) => j,
        Err(code) => return code,
    };
    let config = RealtimeConfig {
        journal,
        board: process.board,
        max_skew: d.max_skew(),
        stop_on_final: true,
        stop: Some(stop_flag()),
        status_every: STATUS_EVERY,
        standby,
        priority: args.rt_priority,
        ..RealtimeConfig::default()
    };
    let name = process.name.clone();
    let states: Vec<String> = content.states.iter().map(|s| s.name.clone()).collect();
    eprintln!("{name}: {} agent(s) here{}", here.len(), if process.board { ", and the Bulletinboard" } else { "" });
    let summary =
        realtime::run_on(content, bound, sink, config, Duration::from_secs_f64(args.duration), bus, &mut |c| {
            eprintln!("{name}: state {}", states[c.to as usize])
        });
    watchers.end();
    if let Some((heard, renewed)) = board_peers.as_ref().and_then(|p| p.beats_heard()) {
        eprintln!("{name}: {heard} beat(s) heard over UDP, {renewed} of them from the leader heard over Zenoh");
    }
    finish(summary)
}

/// A process that only routes (`mode = "router"`, no agent, no
/// Bulletinboard): its Zenoh session carries the others' messages until
/// Ctrl-C, SIGTERM or `--duration`.
#[cfg(feature = "zenoh")]
fn route(args: &Args, d: &situ_bus_zenoh::deploy::Deployment, process: &situ_bus_zenoh::deploy::Process) -> u8 {
    let name = &process.name;
    if args.serve.is_some() || args.foxglove.is_some() || args.record.is_some() {
        eprintln!(
            "error: process `{name}` only routes: --serve, --foxglove and --record belong to the process of the \
             Bulletinboard"
        );
        return USAGE;
    }
    let router = match situ_bus_zenoh::Router::open(&d.zenoh_config(process)) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: process `{name}`: {e}");
            return USAGE;
        }
    };
    let stop = stop_flag();
    let endpoints: Vec<&str> = process.listen.iter().chain(&process.connect).map(String::as_str).collect();
    eprintln!("{name}: routes situ/{}/… (Zenoh router on {}; no agents here)", d.robot, endpoints.join(", "));
    let end = std::time::Instant::now() + Duration::from_secs_f64(args.duration);
    while !stop.load(Ordering::Acquire) && std::time::Instant::now() < end {
        std::thread::sleep(Duration::from_millis(50));
    }
    drop(router);
    eprintln!("{name}: stopped routing");
    OK
}

/// How often a Bulletinboard of a deployment repeats its status.
#[cfg(feature = "zenoh")]
const STATUS_EVERY: Duration = Duration::from_millis(200);

#[cfg(not(feature = "zenoh"))]
const NO_ZENOH: &str =
    "this situ was built without the Zenoh transport; build it with `cargo build --release --features zenoh`";

/// What a deployment without `[tls]` allows, said on standard error by
/// every process of it (`docs/protocol.md`, "What an open deployment allows").
#[cfg(feature = "zenoh")]
fn open_deployment_warning(deploy: &Path, robot: &str) -> String {
    format!(
        "warning: `{}` has no [tls] section: no TLS and no access control. Anyone who reaches its endpoints can \
         put on situ/{robot}/…: forged events, forged data, and forged status messages that the agents' processes \
         follow (they can drive the stack to a final state, such as a stop). Add [tls] with certificates \
         (docs/protocol.md, \"What an open deployment allows\").",
        deploy.display()
    )
}

/// What `situ up` starts (each process's name, and whether it only routes)
/// and what it leaves to others (the external processes, as said).
type Started = (Vec<(String, bool)>, Vec<String>);

/// The processes of the deployment that `situ up` starts on this host (not
/// `external`), each with whether it only routes; and what the external
/// ones are, to say that they are expected to join. An error is the line
/// to print (`error[CODE]: …` or `error: …`).
#[cfg(feature = "zenoh")]
fn local_processes(deploy: &Path, agents: &[String]) -> Result<Started, String> {
    let d =
        situ_bus_zenoh::deploy::Deployment::load(deploy, agents).map_err(|e| format!("error[{}]: {e}", e.code()))?;
    let started = d.processes.iter().filter(|p| p.is_local() && !p.external);
    let external = d.processes.iter().filter(|p| p.external).map(|p| {
        let what = if p.board { "the Bulletinboard".to_string() } else { p.agents.join(", ") };
        format!("`{}` ({what})", p.name)
    });
    Ok((started.map(|p| (p.name.clone(), p.routes_only())).collect(), external.collect()))
}

#[cfg(not(feature = "zenoh"))]
fn local_processes(_deploy: &Path, _agents: &[String]) -> Result<Started, String> {
    Err(format!("error: {NO_ZENOH}"))
}

/// `situ up DEPLOY FILE [--stack …] [--duration S] [--trust PUBKEY]…`: the
/// processes get the same `--trust` keys (each checks the bundle itself)
/// and each warns when the deployment is open (no `[tls]`).
// The arguments of `situ up` (its help is the doc comment of `Command::Up`).
#[derive(clap::Args, Debug)]
pub struct UpArgs {
    /// The deployment file.
    pub deploy: PathBuf,
    /// The rules (a `.situ` source or a bundle).
    pub file: PathBuf,
    #[arg(long, value_enum, default_value_t = Stack::Demo)]
    pub stack: Stack,
    /// How long each process runs, in seconds.
    #[arg(long, default_value_t = 10.0)]
    pub duration: f64,
    #[command(flatten)]
    pub trust: super::Trust,
}

pub fn up(args: &UpArgs) -> u8 {
    let (deploy, file, stack, duration, trust) =
        (args.deploy.as_path(), args.file.as_path(), args.stack, args.duration, args.trust.trust.as_slice());
    let policy = match super::program::trust_of(trust) {
        Ok(t) => t,
        Err(code) => return code,
    };
    let program = match super::program::load(file, false, &policy) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let names: Vec<String> = program.content.agents.iter().map(|a| a.name.clone()).collect();
    let (processes, external) = match local_processes(deploy, &names) {
        Ok(p) => p,
        Err(line) => {
            eprintln!("{line}");
            return USAGE;
        }
    };
    if !external.is_empty() {
        eprintln!("up: not started here (external), expected to join: {}", external.join(", "));
    }
    let stop = stop_flag();
    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: cannot find this program: {e}");
            return USAGE;
        }
    };
    let stack = match stack {
        Stack::Sim => "sim",
        Stack::Demo => "demo",
        Stack::None => "none",
    };
    // Each process checks the bundle against the same keys.
    let trust_args: Vec<&std::ffi::OsStr> = trust.iter().flat_map(|k| ["--trust".as_ref(), k.as_os_str()]).collect();
    let mut children = Vec::new();
    // The processes that only route: stopped once every other has ended.
    let routers: Vec<&str> = processes.iter().filter(|p| p.1).map(|p| p.0.as_str()).collect();
    let processes: Vec<String> = processes.iter().map(|p| p.0.clone()).collect();
    for p in &processes {
        // A router outlives the others (it is stopped when they have ended).
        let duration = if routers.contains(&p.as_str()) { duration + 60.0 } else { duration };
        let child = std::process::Command::new(&exe)
            .arg("run")
            .arg(file)
            .args(["--transport", "zenoh", "--deploy"])
            .arg(deploy)
            .args(["--process", p, "--stack", stack, "--duration", &duration.to_string()])
            .args(trust_args.iter())
            .spawn();
        match child {
            Ok(c) => children.push((p.clone(), c)),
            Err(e) => {
                eprintln!("error: cannot start process `{p}`: {e}");
                stop.store(true, Ordering::Release);
            }
        }
    }
    eprintln!("up: {} process(es): {}", children.len(), processes.join(", "));
    let mut status = OK;
    let mut running: Vec<(String, std::process::Child)> = children;
    let mut routers_asked = routers.is_empty() || routers.len() == processes.len();
    while !running.is_empty() {
        if stop.load(Ordering::Acquire) {
            // Ask each to stop as it would on Ctrl-C (SIGTERM), then wait.
            for (_, c) in &running {
                let _ = std::process::Command::new("kill").args(["-TERM", &c.id().to_string()]).status();
            }
            stop.store(false, Ordering::Release);
        }
        if !routers_asked && running.iter().all(|(name, _)| routers.contains(&name.as_str())) {
            // Every other process has ended: nothing left to carry.
            routers_asked = true;
            stop.store(true, Ordering::Release);
        }
        let mut still = Vec::new();
        for (name, mut c) in running {
            match c.try_wait() {
                Ok(Some(code)) => {
                    eprintln!("up: `{name}` ended ({code})");
                    if !code.success() {
                        status = FAILED;
                    }
                }
                Ok(None) => still.push((name, c)),
                Err(e) => {
                    eprintln!("up: `{name}`: {e}");
                    status = FAILED;
                }
            }
        }
        running = still;
        std::thread::sleep(Duration::from_millis(50));
    }
    status
}
