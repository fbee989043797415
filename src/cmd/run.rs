//! `situ run FILE|BUNDLE [--scenario S] [--record F.mcap] [--out DIR]
//! [--seed N] [--until SECONDS] [--compare hard-switch,merge]
//! [--foxglove [ADDR]] [--serve [ADDR]]`: runs the rules' reference stack
//! (`rules/outdoor.situ`, `rules/ugv.situ` or `rules/ugv-merge.situ`, told
//! by the agents) in simulated time, in process, the compiled rules deciding
//! the state; shows what happened and how well. Exit 0 when the mission is
//! done (the goal, no collision), 1 when it failed (a collision, a stop, the
//! time ran out), 2 on usage, I/O, a bad scenario or a damaged bundle.
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
use situ_runtime::record::mcap::McapRecorder;
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
    /// Serve the Supervisor's page of the run live at this address.
    pub serve: Option<String>,
    pub dla: DlaArgs,
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

/// The case base of a DLA run: the file's, or a new one trained by the
/// scripted driver when the file does not exist (or none was given). A file
/// that cannot be used is an error (exit 2), and it is left as it was.
pub(super) fn dla_cases(args: &DlaArgs, seed: u64) -> Result<(stack::dla::Cases, bool), String> {
    match &args.cases {
        Some(path) if path.exists() => stack::dla::Cases::read(path)
            .map(|c| (c, true))
            .map_err(|e| format!("--cases `{}`: {e} (the file is left as it was)", path.display())),
        _ => Ok((stack::dla::train(seed, stack::dla::TRAINING_SECONDS, stack::dla::NOVELTY), false)),
    }
}

/// A built-in scenario by name, or a TOML file; the error names the field
/// or the place.
fn load_scenario(name: &str) -> Result<Scenario, String> {
    if let Some(s) = scenario::builtin(name) {
        return Ok(s);
    }
    let path = Path::new(name);
    if !path.exists() && !name.ends_with(".toml") {
        return Err(format!(
            "no built-in scenario `{name}` (outdoor-default, dafflon-4, dla-offices, dla-field) and no such file"
        ));
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
    let content = program.content.clone();
    let file_bytes = program.bytes.clone();
    let kind = match StackKind::of(&content) {
        Ok(k) => k,
        Err(_) if args.scenario.is_none() && args.compare.is_none() && args.dla.missions.is_none() => {
            // Any other robot: its first script, every agent a stand-in.
            let Args { file, until, out, record, foxglove, serve, .. } = args;
            return super::scripted::run(super::scripted::Args {
                file,
                script: None,
                random: None,
                until,
                out,
                record,
                foxglove,
                serve,
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
        return compare(&args, content, kind, &scenario, list);
    }
    if let Some(n) = args.dla.missions {
        return super::experience::run(&args, content, kind, &scenario, n, until);
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
    let mut cfg = StackConfig { seed: args.seed, until, learn: args.dla.learn, ..StackConfig::default() };
    let mut cases_read = None;
    if kind == StackKind::Dla {
        match dla_cases(&args.dla, args.seed) {
            Ok((cases, read)) => {
                let n = cases.len();
                let handle = stack::dla::CasesHandle(Arc::new(Mutex::new(cases)));
                cases_read = Some((handle.clone(), n, read));
                cfg.cases = Some(handle);
            }
            Err(e) => {
                eprintln!("error: {e}");
                return USAGE;
            }
        }
    }
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
    match watchers.any() {
        true => {
            watchers.wait();
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
        false => run.run(&mut |r| line.draw(|| r.progress().line())),
    }
    line.clear();
    let run_plans = run.plans().cloned();
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
    if let (Some((handle, before, read)), Some(plans)) = (&cases_read, run_plans.as_ref()) {
        let p = plans.lock().unwrap_or_else(|e| e.into_inner());
        let cases = handle.0.lock().unwrap_or_else(|e| e.into_inner());
        println!(
            "  DLA               {} route(s), {} after a blocked path; {} case(s) {}, {} learnt on line",
            p.routes,
            p.replans,
            before,
            if *read { "read" } else { "trained" },
            p.learnt
        );
        if let Some(explored) = p.no_route {
            println!(
                "  no route          the goal cannot be reached from here, even through unexplored regions ({:.0} % of the map explored)",
                100.0 * explored
            );
        }
        if let Some(path) = &args.dla.cases {
            if let Err(e) = cases.write(path) {
                eprintln!("error: cannot write the case base `{}`: {e}", path.display());
                return USAGE;
            }
            println!("  case base         {} cases written to {}", cases.len(), path.display());
        }
    }
    if let Some(out) = &args.out {
        if let Err(e) = write_out(out, &scenario, &report, args.record.as_deref()) {
            eprintln!("error: {e}");
            return USAGE;
        }
        for (name, svg) in run_plans.iter().flat_map(|p| dla_pictures(p, &scenario, &report)) {
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

/// DLA's pictures: `dla.svg`, the last occupancy grid and the regions of
/// its pyramid, with the last path and the trajectory; `dla-route.svg`, the
/// map the last route was planned on, its regions numbered along the route.
fn dla_pictures(
    plans: &stack::dla::SharedPlans,
    scenario: &Scenario,
    report: &stack::RunReport,
) -> Vec<(&'static str, String)> {
    let p = plans.lock().unwrap_or_else(|e| e.into_inner());
    let world = &scenario.world;
    let trajectory: Vec<(f64, f64)> = report.metrics.samples.iter().map(|s| (s.x, s.y)).collect();
    let start = (world.start.x, world.start.y);
    let goal = (world.goal.position.x, world.goal.position.y);
    let mut out = Vec::new();
    if let Some(map) = &p.map {
        let title = format!("{} — {}: the last map, its regions, the last path", scenario.name, report.rules);
        let svg =
            situ_sim::dla::draw::draw(&map.grid, Some(map.pyramid()), &[], &p.path, &trajectory, start, goal, &title);
        out.push(("dla.svg", svg));
    }
    if let Some(route) = &p.route {
        let title =
            format!("{} — {}: route {} on the map it was planned on", scenario.name, report.rules, route.number);
        let svg = situ_sim::dla::draw::draw(
            &route.map.grid,
            Some(route.map.pyramid()),
            &route.regions,
            &p.path,
            &trajectory,
            start,
            goal,
            &title,
        );
        out.push(("dla-route.svg", svg));
    }
    out
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

/// The other program of the comparison, beside the rules file: the merge
/// (`ugv-merge.situ`) beside the hard switch (`ugv.situ`), or the other way
/// round. Read from the file, not built in, so that the table compares the
/// programs as they are on disk, edits included.
fn sibling(file: &Path, name: &str, strategy: Strategy) -> Result<Arc<Content>, u8> {
    let path = file.parent().unwrap_or(Path::new("")).join(name);
    if !path.is_file() {
        eprintln!(
            "error: --compare: the {} strategy runs `{name}` through the stack, and there is no `{}` beside `{}`",
            strategy.name(),
            path.display(),
            file.display()
        );
        return Err(USAGE);
    }
    super::program::load(&path, false).map(|p| p.content)
}

/// `--compare`: Dafflon et al.'s table, both strategies situ programs run
/// through the stack (`ugv.situ` and `ugv-merge.situ`, side by side), each
/// with the sim's own closed loop for reference.
fn compare(args: &Args, content: Arc<Content>, kind: StackKind, scenario: &Scenario, list: &[String]) -> u8 {
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
    let wants = |s: Strategy| strategies.contains(&s);
    let mut programs = stack::UgvPrograms::default();
    let other = match kind {
        StackKind::Ugv => {
            programs.hard_switch = Some(content);
            wants(Strategy::Merge).then_some((&mut programs.merge, "ugv-merge.situ", Strategy::Merge))
        }
        StackKind::UgvMerge => {
            programs.merge = Some(content);
            wants(Strategy::HardSwitch).then_some((&mut programs.hard_switch, "ugv.situ", Strategy::HardSwitch))
        }
        StackKind::Outdoor | StackKind::Dla => {
            eprintln!(
                "error: --compare needs the UGV's rules (rules/ugv.situ or rules/ugv-merge.situ): hard-switch and merge are its controllers"
            );
            return USAGE;
        }
    };
    if let Some((slot, name, strategy)) = other {
        match sibling(&args.file, name, strategy) {
            Ok(c) => *slot = Some(c),
            Err(code) => return code,
        }
    }
    let (table, _) = match stack::compare(&programs, &scenario.world, &strategies, args.seed) {
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
         closed loop (situ_sim::ugv::run), for reference. Steering rates are taken at 20 Hz in all."
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
