//! `situ run FILE|BUNDLE [--scenario S] [--record F.mcap] [--out DIR]
//! [--seed N] [--until SECONDS] [--compare hard-switch,merge]
//! [--foxglove [ADDR]] [--serve [ADDR]] [--cases FILE] [--no-learning]`:
//! runs the rules' reference stack (`rules/outdoor.situ`, `rules/ugv.situ`,
//! `rules/ugv-merge.situ` or `rules/dla.situ`, told by the agents:
//! [`situ_dla::registry`]) in simulated time, in process, the compiled rules
//! deciding the state; shows what happened and how well. Exit 0 when the
//! mission is done (the goal, no collision), 1 when it failed (a collision, a
//! stop, the time ran out), 2 on usage, I/O, a bad scenario or a damaged
//! bundle.
//!
//! The same command dispatches, by its flags and the rules: `--compare`
//! (the UGV's two programs, [`situ_sim::stack::compare`]), `--missions N`
//! (DLA's experience, [`super::experience`]), and rules with no reference
//! stack run on their script ([`super::scripted`]).
//!
//! `--foxglove [ADDR]` (default 127.0.0.1:8765) serves the run live over
//! Foxglove's WebSocket protocol, `--serve [ADDR]` the Supervisor's page
//! (`situ view`'s, fed live): both are taps of the run's one recorder (see
//! [`super::watchers`]). The run waits for its watchers, then goes in real
//! time (a simulated second a second), so a person watches it.
//!
//! (The transport is in process; `--transport zenoh` runs a deployment,
//! [`super::distributed`].)

use super::view::data::Site;
use super::watchers::Watchers;
use super::{FAILED, OK, USAGE};
use situ_compiler::bundle::{self, Content, Encoding};
use situ_dla::missions::load_or_train;
use situ_dla::stack::{lock_plans, Dla, SharedCases};
use situ_runtime::record::mcap::McapRecorder;
use situ_sim::scenario::{self, Scenario};
use situ_sim::stack::{self, Recording, Stack, StackConfig, StackRun, UgvPrograms};
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
    /// Serve the Supervisor's page of the run live at this address.
    pub serve: Option<String>,
    pub dla: DlaArgs,
    /// The policy of `--trust`.
    pub trust: situ_compiler::bundle::Trust,
}

/// DLA's options (`rules/dla.situ`).
#[derive(Debug, Clone, Default)]
pub struct DlaArgs {
    /// The case base file: read before, written after the run.
    pub cases: Option<PathBuf>,
    /// Whether the reactive layer learns on line.
    pub learn: bool,
    /// Successive missions, one case base learning through them
    /// ([`super::experience`]).
    pub missions: Option<u64>,
    /// Held-out missions per evaluation of the experience.
    pub evaluate: u64,
}

/// The bundle's bytes, to attach to the recording: the file as it was read
/// and checked (its signature with it), or the source compiled to JSON.
fn bundle_bytes(bytes: Option<Vec<u8>>, content: &Content) -> Vec<u8> {
    bytes.unwrap_or_else(|| bundle::encode(content, Encoding::Json))
}

/// A DLA run's case base: the handle the stack learns into, how many cases
/// it started with, and whether they were read (else trained).
struct DlaCases {
    handle: SharedCases,
    before: usize,
    read: bool,
}

pub fn run(args: Args) -> u8 {
    let program = match super::program::load(&args.file, false, &args.trust) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let content = program.content.clone();
    let file_bytes = program.bytes.clone();
    let kind = match situ_dla::registry().of(&content) {
        Ok(k) => k,
        Err(_) if args.scenario.is_none() && args.compare.is_none() && args.dla.missions.is_none() => {
            // Any other robot: its first script, every agent a stand-in.
            let Args { file, until, out, record, foxglove, serve, trust, .. } = args;
            return super::scripted::run(super::scripted::Args {
                file,
                script: None,
                random: None,
                until,
                out,
                record,
                foxglove,
                serve,
                trust,
            });
        }
        Err(e) => {
            eprintln!("error: `{}`: {e}", args.file.display());
            return USAGE;
        }
    };
    let name = args.scenario.clone().unwrap_or_else(|| kind.default_scenario().to_string());
    let scenario = match scenario::named(&name) {
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
        return compare(&args, content, kind.as_ref(), &scenario, list);
    }
    if let Some(n) = args.dla.missions {
        let experience = super::experience::Args {
            file: &args.file,
            seed: args.seed,
            cases: args.dla.cases.as_deref(),
            learn: args.dla.learn,
            evaluate: args.dla.evaluate,
            out: args.out.as_deref(),
        };
        return super::experience::run(&experience, content, kind.as_ref(), &scenario, n, until);
    }

    // The recording: at --record, else in --out.
    let record_path = args.record.clone().or_else(|| args.out.as_ref().map(|d| d.join("recording.mcap")));
    let mcap = match &record_path {
        Some(path) => match McapRecorder::create(path, content.clone(), &bundle_bytes(file_bytes, &content)) {
            Ok(m) => Some(m),
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", path.display());
                return USAGE;
            }
        },
        None => None,
    };
    // Live: the same recorder, its channels and messages to the watchers too.
    let checked = program.checked;
    let watchers = match Watchers::start(args.foxglove.as_deref(), args.serve.as_deref(), || {
        Site::live(args.file.display().to_string(), content.clone(), checked.as_ref())
    }) {
        Ok(w) => w,
        Err(code) => return code,
    };
    let mcap = watchers.recorder(mcap, &content).map(|m| Arc::new(Mutex::new(m)));
    let cfg = StackConfig { seed: args.seed, until, ..StackConfig::default() };
    // DLA: the stack with the case base read or trained, learning or not.
    let mut dla = None;
    let stack: Arc<dyn Stack> = if kind.name() == situ_dla::stack::NAME {
        match load_or_train(args.dla.cases.as_deref(), args.seed) {
            Ok((cases, read)) => {
                let before = cases.len();
                let handle: SharedCases = Arc::new(Mutex::new(cases));
                let stack = Arc::new(Dla::new(Some(handle.clone()), args.dla.learn));
                dla = Some((stack.clone(), DlaCases { handle, before, read }));
                stack
            }
            Err(e) => {
                eprintln!("error: --cases {e}");
                return USAGE;
            }
        }
    } else {
        kind.clone()
    };
    let mut run = match StackRun::new(
        content.clone(),
        stack.clone(),
        &scenario.world,
        cfg,
        Recording { mcap, sinks: Vec::new() },
    ) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: `{}` cannot run on the {} stack: {e}", args.file.display(), kind.title());
            return USAGE;
        }
    };
    let mut line = super::LiveLine::new();
    if watchers.any() {
        watchers.wait();
        run.run_in_real_time(&mut |r| line.draw(|| r.progress().line()));
    } else {
        run.run(&mut |r| line.draw(|| r.progress().line()));
    }
    line.clear();
    let finished = run.finish();
    watchers.end();
    let report = match finished {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    println!("{} on {} (seed {})\n", content.source, scenario.name, args.seed);
    print!("{}", report.runtime.table());
    println!("\n{}", report.table());
    if let Some((stack, cases)) = &dla {
        if let Err(code) = dla_summary(stack, cases, args.dla.cases.as_deref()) {
            return code;
        }
    }
    if let Some(out) = &args.out {
        if let Err(e) = write_out(out, &scenario, &report, args.record.as_deref()) {
            eprintln!("error: {e}");
            return USAGE;
        }
        for (name, svg) in stack.pictures(&scenario, &report) {
            if let Err(e) = super::write_atomically(&out.join(name), svg.as_bytes()) {
                eprintln!("error: cannot write `{}`: {e}", out.join(name).display());
                return USAGE;
            }
        }
        println!("wrote {}", out.display());
    }
    if let Some(path) = &args.record {
        println!("recorded {}", path.display());
    }
    if report.outcome.success() {
        OK
    } else {
        FAILED
    }
}

/// DLA's lines after the report (routes, cases, no route) and the case base
/// written back to `--cases`.
fn dla_summary(stack: &Dla, cases: &DlaCases, path: Option<&Path>) -> Result<(), u8> {
    let p = lock_plans(stack.plans());
    let base = cases.handle.lock().unwrap_or_else(|e| e.into_inner());
    println!(
        "  DLA               {} route(s), {} after a blocked path; {} case(s) {}, {} learnt on line",
        p.routes,
        p.replans,
        cases.before,
        if cases.read { "read" } else { "trained" },
        p.learnt
    );
    if let Some(explored) = p.no_route {
        println!(
            "  no route          the goal cannot be reached from here, even through unexplored regions ({:.0} % of the map explored)",
            100.0 * explored
        );
    }
    if let Some(path) = path {
        if let Err(e) = base.write(path) {
            eprintln!("error: cannot write the case base `{}`: {e}", path.display());
            return Err(USAGE);
        }
        println!("  case base         {} cases written to {}", base.len(), path.display());
    }
    Ok(())
}

/// `trajectory.svg`, `timeline.svg`, `metrics.json` (and `recording.mcap`,
/// copied from `--record` when it was written there).
fn write_out(
    out: &Path,
    scenario: &Scenario,
    report: &stack::RunReport,
    recorded: Option<&Path>,
) -> Result<(), String> {
    let write = |name: &str, bytes: &[u8]| {
        super::write_atomically(&out.join(name), bytes)
            .map_err(|e| format!("cannot write `{}`: {e}", out.join(name).display()))
    };
    for (name, svg) in report.pictures(scenario).map_err(|e| e.to_string())? {
        write(name, svg.as_bytes())?;
    }
    write("metrics.json", report.to_json().as_bytes())?;
    if let Some(from) = recorded {
        let to = out.join("recording.mcap");
        std::fs::copy(from, &to).map_err(|e| format!("cannot write `{}`: {e}", to.display()))?;
    }
    Ok(())
}

/// `--compare`: Dafflon et al.'s table, both strategies situ programs run
/// through the stack (`ugv.situ` and `ugv-merge.situ`, side by side), each
/// with the sim's own closed loop for reference.
fn compare(args: &Args, content: Arc<Content>, kind: &dyn Stack, scenario: &Scenario, list: &[String]) -> u8 {
    let strategies = match stack::merge::strategies(list) {
        Ok(s) => s,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    if args.record.is_some() {
        eprintln!("warning: --record is not used with --compare");
    }
    let (mut programs, sibling) = match UgvPrograms::plan(&args.file, content, kind, &strategies) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    if let Some(sibling) = sibling {
        match super::program::load(&sibling.path, false, &args.trust) {
            Ok(p) => programs.set(sibling.strategy, p.content),
            Err(code) => return code,
        }
    }
    let (table, _) = match stack::compare(&programs, &situ_dla::registry(), &scenario.world, &strategies, args.seed) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    print!("{table}");
    println!(
        "\nBoth strategies are situ programs run through the stack: the hard switch (ugv.situ: the \
         Selector's events, the rules avoid_ccw/avoid_cw/way_free, only the selected controller linked \
         to the Vehicle) and the merge (ugv-merge.situ: both controllers command the Merger, which \
         blends them (eqs. 16-19) and alone commands the Vehicle); the sim-loop rows are the sim's own \
         closed loop (situ_sim::baseline::ugv::run), for reference. Steering rates are taken at 20 Hz in all."
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

/// `--compare --out DIR`: each row's path and time line
/// ([`situ_sim::baseline::ugv::Comparison::pictures`]).
fn write_comparison(
    out: &Path,
    scenario: &Scenario,
    table: &situ_sim::baseline::ugv::Comparison,
) -> Result<(), String> {
    for (name, svg) in table.pictures(scenario).map_err(|e| e.to_string())? {
        super::write_atomically(&out.join(&name), svg.as_bytes())
            .map_err(|e| format!("cannot write `{}`: {e}", out.join(&name).display()))?;
    }
    Ok(())
}
