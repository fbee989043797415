//! `situ run FILE|BUNDLE [--scenario S] [--record F.mcap] [--out DIR]
//! [--seed N] [--until SECONDS] [--compare hard-switch,merge]
//! [--foxglove [ADDR]]`: runs the
//! rules' reference stack (`rules/outdoor.situ` or `rules/ugv.situ`, told by
//! the agents) in simulated time, in process, the compiled rules deciding
//! the state; shows what happened and how well. Exit 0 when the mission is
//! done (the goal, no collision), 1 when it failed (a collision, a stop, the
//! time ran out), 2 on usage, I/O, a bad scenario or a damaged bundle.
//!
//! `--foxglove [ADDR]` (default 127.0.0.1:8765) serves the run live over
//! Foxglove's WebSocket protocol: the recording's own channels, schemas and
//! messages (one [`McapRecorder`], its [`Tap`] the server), with or without
//! a file. The run waits for a client's first subscription, then goes in
//! real time (a simulated second a second), so a person watches it.
//!
//! (The transport is in process; `--transport zenoh` is for later.)

use super::{FAILED, OK, USAGE};
use situ_compiler::bundle::{self, Content, Encoding};
use situ_runtime::record::mcap::{McapRecorder, Tap};
use situ_sim::scenario::{self, Scenario};
use situ_sim::stack::{self, Recording, StackConfig, StackKind, StackRun};
use situ_sim::ugv::Strategy;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

pub struct Args {
    pub file: PathBuf,
    pub scenario: Option<String>,
    pub record: Option<PathBuf>,
    pub out: Option<PathBuf>,
    pub seed: u64,
    pub until: Option<f64>,
    pub compare: Option<Vec<String>>,
    /// Serve the run live over Foxglove's WebSocket protocol at this address.
    pub foxglove: Option<String>,
}

/// A built-in scenario by name, or a TOML file; the error names the field
/// or the place.
fn load_scenario(name: &str) -> Result<Scenario, String> {
    if let Some(s) = scenario::builtin(name) {
        return Ok(s);
    }
    let path = Path::new(name);
    if !path.exists() && !name.ends_with(".toml") {
        return Err(format!("no built-in scenario `{name}` (outdoor-default, dafflon-4) and no such file"));
    }
    scenario::load(path).map_err(|e| format!("scenario `{name}`: {e}"))
}

/// The bundle's bytes, to attach to the recording: the file as it was read
/// and checked (its signature with it), or the source compiled to JSON.
fn bundle_bytes(bytes: Option<Vec<u8>>, content: &Content) -> Vec<u8> {
    bytes.unwrap_or_else(|| bundle::encode(content, Encoding::Json))
}

pub fn run(args: Args) -> u8 {
    let program = match super::program::load(&args.file, false) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let content = program.content;
    let file_bytes = program.bytes;
    let kind = match StackKind::of(&content) {
        Ok(k) => k,
        Err(_) if args.scenario.is_none() && args.compare.is_none() && args.foxglove.is_some() => {
            eprintln!(
                "error: --foxglove serves the runs of the reference stacks (rules/outdoor.situ, rules/ugv.situ) only, for now"
            );
            return USAGE;
        }
        Err(_) if args.scenario.is_none() && args.compare.is_none() => {
            // Any other robot: its first script, every agent a stand-in.
            let Args { file, until, out, record, .. } = args;
            return super::scripted::run(super::scripted::Args {
                file,
                script: None,
                random: None,
                until,
                out,
                record,
            });
        }
        Err(e) => {
            eprintln!("error: `{}`: {e}", args.file.display());
            return USAGE;
        }
    };
    let name = args.scenario.clone().unwrap_or_else(|| kind.default_scenario().to_string());
    let scenario = match load_scenario(&name) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    let until = args.until.unwrap_or(kind.default_until());
    if !(until.is_finite() && until > 0.0) {
        eprintln!("error: --until must be a positive number of seconds, not {until}");
        return USAGE;
    }
    if let Some(out) = &args.out {
        if let Err(e) = std::fs::create_dir_all(out) {
            eprintln!("error: cannot create `{}`: {e}", out.display());
            return USAGE;
        }
    }
    if let Some(list) = &args.compare {
        return compare(&args, content, &scenario, list);
    }

    // The recording: at --record, else in --out.
    let record_path = args.record.clone().or_else(|| args.out.as_ref().map(|d| d.join("recording.mcap")));
    let mut mcap = match &record_path {
        Some(path) => match McapRecorder::create(path, content.clone(), &bundle_bytes(file_bytes, &content)) {
            Ok(m) => Some(m),
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", path.display());
                return USAGE;
            }
        },
        None => None,
    };
    // Live: the same recorder, its channels and messages to the server too.
    let live = match &args.foxglove {
        Some(addr) => match LiveServer::start(addr) {
            Ok(server) => {
                let m = mcap.get_or_insert_with(|| McapRecorder::live(content.clone()));
                m.tap(Box::new(server.tap()));
                Some(server)
            }
            Err(e) => {
                eprintln!("error: --foxglove: {e}");
                return USAGE;
            }
        },
        None => None,
    };
    let mcap = mcap.map(|m| Arc::new(Mutex::new(m)));
    let cfg = StackConfig { seed: args.seed, until, ..StackConfig::default() };
    let physics_step = cfg.physics_step;
    let mut run =
        match StackRun::new(content.clone(), kind, &scenario.world, cfg, Recording { mcap, sinks: Vec::new() }) {
            Ok(r) => r,
            Err(e) => {
                eprintln!("error: `{}` cannot run on the {kind:?} stack: {e}", args.file.display());
                return USAGE;
            }
        };
    let mut line = super::LiveLine::new();
    match &live {
        Some(server) => {
            server.wait_for_a_client();
            // Real time: a simulated second a wall second.
            let start = std::time::Instant::now();
            let per_second = (1_000_000_000 / physics_step).max(1);
            let mut k = 0u64;
            while run.step() {
                k += 1;
                let t = run.physics.lock().unwrap_or_else(|e| e.into_inner()).t;
                let ahead = std::time::Duration::from_secs_f64(t.max(0.0)).saturating_sub(start.elapsed());
                if !ahead.is_zero() {
                    std::thread::sleep(ahead);
                }
                if k.is_multiple_of(per_second) {
                    line.draw(|| run.progress().line());
                }
            }
        }
        None => run.run(&mut |r| line.draw(|| r.progress().line())),
    }
    line.clear();
    let report = match run.finish() {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    println!("{} on {} (seed {})\n", content.source, scenario.name, args.seed);
    print!("{}", report.runtime.table());
    println!("\n{}", report.table());
    if let Some(out) = &args.out {
        if let Err(e) = write_out(out, &scenario, &report, args.record.as_deref()) {
            eprintln!("error: {e}");
            return USAGE;
        }
        println!("wrote {}", out.display());
    }
    if let Some(path) = &args.record {
        println!("recorded {}", path.display());
    }
    if let Some(server) = live {
        server.stop();
    }
    if report.outcome.success() {
        OK
    } else {
        FAILED
    }
}

/// `trajectory.svg`, `timeline.svg`, `metrics.json` (and `recording.mcap`,
/// copied from `--record` when it was written there).
fn write_out(
    out: &Path,
    scenario: &Scenario,
    report: &stack::RunReport,
    recorded: Option<&Path>,
) -> Result<(), String> {
    let title = format!("{} — {}", scenario.name, report.rules);
    let samples = &report.metrics.samples;
    let write = |name: &str, bytes: &[u8]| {
        super::write_atomically(&out.join(name), bytes)
            .map_err(|e| format!("cannot write `{}`: {e}", out.join(name).display()))
    };
    let trajectory = situ_sim::plot::trajectory_svg(&scenario.world, samples, &title).map_err(|e| e.to_string())?;
    write("trajectory.svg", trajectory.as_bytes())?;
    let timeline = situ_sim::plot::timeline_svg(samples, &title).map_err(|e| e.to_string())?;
    write("timeline.svg", timeline.as_bytes())?;
    write("metrics.json", report.to_json().as_bytes())?;
    if let Some(from) = recorded {
        let to = out.join("recording.mcap");
        std::fs::copy(from, &to).map_err(|e| format!("cannot write `{}`: {e}", to.display()))?;
    }
    Ok(())
}

/// `--compare`: Dafflon et al.'s table.
fn compare(args: &Args, content: Arc<Content>, scenario: &Scenario, list: &[String]) -> u8 {
    let mut strategies = Vec::new();
    for s in list {
        match Strategy::parse(s.trim()) {
            Some(x) => strategies.push(x),
            None => {
                eprintln!("error: --compare: unknown strategy `{s}` (hard-switch, merge)");
                return USAGE;
            }
        }
    }
    if args.record.is_some() {
        eprintln!("warning: --record is not used with --compare");
    }
    let (table, _) = match stack::compare(content, &scenario.world, &strategies, args.seed) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    print!("{table}");
    println!(
        "\nThe hard switch runs on the rules through the stack (the Selector's events, the rules \
         avoid_ccw/avoid_cw/way_free, the tables' links) and, for reference, in the sim's own closed \
         loop; the merge blends both controllers at once, which no table of the rules links to the \
         Vehicle: it runs in the sim's closed loop (situ_sim::ugv::run). Steering rates are taken at \
         20 Hz in both."
    );
    if let Some(out) = &args.out {
        let json = serde_json::to_string_pretty(&table).expect("the table serializes");
        if let Err(e) = super::write_atomically(&out.join("comparison.json"), json.as_bytes()) {
            eprintln!("error: cannot write `{}`: {e}", out.join("comparison.json").display());
            return USAGE;
        }
        if let Err(e) = write_comparison(out, scenario, &table) {
            eprintln!("error: {e}");
            return USAGE;
        }
        println!("wrote {}", out.display());
    }
    if table.rows.iter().all(|r| r.collisions == 0 && r.time_to_goal.is_some()) {
        OK
    } else {
        FAILED
    }
}

/// `--compare --out DIR`: each row's path and time line, as `trajectory-ROW.svg`
/// and `timeline-ROW.svg` (ROW: the row's name in lower case, words joined by `-`).
fn write_comparison(out: &Path, scenario: &Scenario, table: &situ_sim::ugv::Comparison) -> Result<(), String> {
    for (row, metrics) in table.rows.iter().zip(&table.runs) {
        let slug: String = row
            .strategy
            .to_lowercase()
            .split(|c: char| !c.is_ascii_alphanumeric())
            .filter(|w| !w.is_empty())
            .collect::<Vec<_>>()
            .join("-");
        let title = format!("{} — {}", scenario.name, row.strategy);
        let write = |name: String, text: String| {
            super::write_atomically(&out.join(&name), text.as_bytes())
                .map_err(|e| format!("cannot write `{}`: {e}", out.join(&name).display()))
        };
        let trajectory =
            situ_sim::plot::trajectory_svg(&scenario.world, &metrics.samples, &title).map_err(|e| e.to_string())?;
        write(format!("trajectory-{slug}.svg"), trajectory)?;
        let timeline = situ_sim::plot::timeline_svg(&metrics.samples, &title).map_err(|e| e.to_string())?;
        write(format!("timeline-{slug}.svg"), timeline)?;
    }
    Ok(())
}

/// `--foxglove`: a Foxglove WebSocket server of its own (its own context,
/// so only this run's channels are on it).
struct LiveServer {
    context: Arc<foxglove::Context>,
    handle: foxglove::WebSocketServerHandle,
    addr: String,
    subscribed: Arc<(Mutex<bool>, std::sync::Condvar)>,
}

/// Tells the run that a client subscribed.
struct Subscriptions(Arc<(Mutex<bool>, std::sync::Condvar)>);

impl foxglove::websocket::ServerListener for Subscriptions {
    fn on_subscribe(&self, _client: foxglove::websocket::Client, _channel: foxglove::websocket::ChannelView) {
        let (lock, cvar) = &*self.0;
        *lock.lock().unwrap_or_else(|e| e.into_inner()) = true;
        cvar.notify_all();
    }
}

impl LiveServer {
    /// Listens on `addr` (HOST:PORT); the error names the address.
    fn start(addr: &str) -> Result<LiveServer, String> {
        let (host, port) = addr
            .rsplit_once(':')
            .and_then(|(h, p)| Some((h.trim_start_matches('[').trim_end_matches(']'), p.parse::<u16>().ok()?)))
            .filter(|(h, _)| !h.is_empty())
            .ok_or_else(|| format!("`{addr}` is not an address (HOST:PORT, say 127.0.0.1:8765)"))?;
        // The port must be free: the error names it (the server's own error
        // does not always).
        if let Err(e) = std::net::TcpListener::bind((host, port)) {
            return Err(if e.kind() == std::io::ErrorKind::AddrInUse {
                format!("cannot listen on {addr}: the port {port} is in use")
            } else {
                format!("cannot listen on {addr}: {e}")
            });
        }
        let context = foxglove::Context::new();
        let subscribed = Arc::new((Mutex::new(false), std::sync::Condvar::new()));
        let handle = foxglove::WebSocketServer::new()
            .name(format!("situ {}", env!("CARGO_PKG_VERSION")))
            .bind(host, port)
            .context(&context)
            .listener(Arc::new(Subscriptions(subscribed.clone())))
            .start_blocking()
            .map_err(|e| format!("cannot listen on {addr}: {e}"))?;
        let addr = format!("{host}:{}", handle.port());
        Ok(LiveServer { context, handle, addr, subscribed })
    }

    fn tap(&self) -> FoxgloveTap {
        FoxgloveTap { context: self.context.clone(), channels: std::collections::HashMap::new() }
    }

    /// Waits for a client's first subscription (and a moment for its
    /// others), so that the run is watched from its start.
    fn wait_for_a_client(&self) {
        eprintln!(
            "foxglove: serving ws://{} (Foxglove: Open connection, Foxglove WebSocket); waiting for a client",
            self.addr
        );
        let (lock, cvar) = &*self.subscribed;
        let mut done = lock.lock().unwrap_or_else(|e| e.into_inner());
        while !*done {
            done = cvar.wait(done).unwrap_or_else(|e| e.into_inner());
        }
        drop(done);
        std::thread::sleep(std::time::Duration::from_millis(500));
        eprintln!("foxglove: a client subscribed; running in real time");
    }

    fn stop(self) {
        // A moment for the last messages to leave.
        std::thread::sleep(std::time::Duration::from_millis(500));
        self.handle.stop().wait_blocking();
        eprintln!("foxglove: the run is over; server stopped");
    }
}

/// The recorder's [`Tap`] to the server: a raw JSON channel per channel.
struct FoxgloveTap {
    context: Arc<foxglove::Context>,
    channels: std::collections::HashMap<u16, Arc<foxglove::RawChannel>>,
}

impl Tap for FoxgloveTap {
    fn channel(&mut self, id: u16, topic: &str, schema_name: &str, schema: &str) {
        let built = foxglove::ChannelBuilder::new(topic)
            .message_encoding("json")
            .schema(foxglove::Schema::new(schema_name, "jsonschema", schema.as_bytes().to_vec()))
            .context(&self.context)
            .build_raw();
        match built {
            Ok(c) => {
                self.channels.insert(id, c);
            }
            Err(e) => eprintln!("foxglove: channel {topic}: {e}"),
        }
    }

    fn message(&mut self, id: u16, time: u64, bytes: &[u8]) {
        if let Some(c) = self.channels.get(&id) {
            c.log_with_meta(bytes, foxglove::PartialMetadata { log_time: Some(time) });
        }
    }
}
