//! `situ run FILE --script S | --random SEED [--until SECONDS] [--out DIR]
//! [--record F.mcap]`: any rules file on the real runtime, every agent a
//! stand-in that follows its table or FSM and reports what the script (or
//! the guided generator) gives it. `S` is the name of a `script` block of
//! FILE or its includes, or a `.situ` file of scripts read after FILE.
//! With `--foxglove [ADDR]` or `--serve [ADDR]` the run waits for its
//! watchers ([`super::watchers`]) and plays in real time.
//!
//! Exit 0 when the run played to its end (or to a final state) with every
//! event taken; 1 when the Bulletinboard refused an event or a cascade did
//! not settle, or the rules have errors; 2 on usage and I/O.

use super::view::data::Site;
use super::watchers::Watchers;
use super::{FAILED, OK, USAGE};
use situ_compiler::bundle::{self, Content, Encoding};
use situ_compiler::loader::FsLoader;
use situ_compiler::spec::{self, ScriptSpec};
use situ_runtime::record::mcap::McapRecorder;
use situ_runtime::record::Sink;
use situ_runtime::script::wiring::Snapshot;
use situ_runtime::script::{chart, Driver, PickError, ScriptRun};
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub struct Args {
    pub file: PathBuf,
    pub script: Option<String>,
    pub random: Option<u64>,
    pub until: Option<f64>,
    pub out: Option<PathBuf>,
    pub record: Option<PathBuf>,
    /// Serve the run live over Foxglove's WebSocket protocol at this address.
    pub foxglove: Option<String>,
    /// Serve the Supervisor's page of the run live at this address.
    pub serve: Option<String>,
    /// The policy of `--trust`.
    pub trust: situ_compiler::bundle::Trust,
}

/// The rules and the scripts they can be run with.
struct Loaded {
    content: Arc<Content>,
    scripts: Vec<ScriptSpec>,
    /// Whether the rules came as a bundle (no scripts then).
    bundle: bool,
    /// The bundle file's bytes, to attach to the recording as they are
    /// (signature included).
    bytes: Option<Vec<u8>>,
    /// The checked source (none for a bundle), for the live page's graph.
    checked: Option<situ_compiler::Checked>,
}

fn load(file: &Path, script_file: Option<&Path>, trust: &situ_compiler::bundle::Trust) -> Result<Loaded, u8> {
    if !super::program::is_source(file) {
        if script_file.is_some() {
            eprintln!("error: a script file is read with the rules' source: run the `.situ` file, not a bundle");
            return Err(USAGE);
        }
        let p = super::program::load(file, false, trust)?;
        return Ok(Loaded { content: p.content, scripts: Vec::new(), bundle: true, bytes: p.bytes, checked: None });
    }
    super::program::refuse_source(file, trust)?;
    let extra: Vec<&Path> = script_file.into_iter().collect();
    let checked = situ_compiler::check_with(file, &extra, &FsLoader).map_err(|e| {
        eprintln!("error: {e}");
        USAGE
    })?;
    if checked.fails(false) {
        print!("{}", situ_compiler::render::human_all(&checked, super::style()));
        eprintln!(
            "error: `{}` has {} error(s); fix them first (`situ check` explains each)",
            script_file.unwrap_or(file).display(),
            checked.errors()
        );
        return Err(FAILED);
    }
    let content = Arc::new(bundle::build(&checked));
    let scripts = spec::scripts(&checked);
    Ok(Loaded { content, scripts, bundle: false, bytes: None, checked: Some(checked) })
}

/// The script named `name` (the first without one), or why not, said with
/// the file's name and what the user can do instead.
fn pick(scripts: &[ScriptSpec], bundle: bool, file: &Path, name: Option<&str>) -> Result<ScriptSpec, String> {
    situ_runtime::script::pick(scripts, name).cloned().map_err(|e| match e {
        PickError::NoScripts => format!(
            "`{}` has no reference stack (those of rules/outdoor.situ and rules/ugv.situ) and no `script` \
             block: give `--script FILE` or `--random SEED`",
            file.display()
        ),
        PickError::NoSuchScript { name: n, known } if known.is_empty() && bundle => {
            format!("a bundle carries no scripts: run `{}`'s source to use script \"{n}\"", file.display())
        }
        PickError::NoSuchScript { name: n, known } if known.is_empty() => {
            format!("no script \"{n}\": `{}` has no `script` block, and no file `{n}` exists", file.display())
        }
        PickError::NoSuchScript { name: n, known } => {
            let names: Vec<String> = known.iter().map(|s| format!("\"{s}\"")).collect();
            format!("no script \"{n}\" (and no such file); the scripts are: {}", names.join(", "))
        }
    })
}

pub fn run(args: Args) -> u8 {
    let script_file = args.script.as_deref().map(Path::new).filter(|p| p.is_file());
    let loaded = match load(&args.file, script_file, &args.trust) {
        Ok(l) => l,
        Err(code) => return code,
    };
    // `--script` and `--random` exclude each other (clap says so).
    let driver = match args.random {
        Some(seed) => Driver::Random { seed },
        None => {
            let mut scripts = loaded.scripts.clone();
            // A script file's own scripts, the first of them unless named.
            if let Some(f) = script_file {
                scripts.retain(|s| Path::new(&s.place.file) == f);
                if scripts.is_empty() {
                    eprintln!("error: `{}` has no `script` block", f.display());
                    return USAGE;
                }
            }
            let name = if script_file.is_some() { None } else { args.script.as_deref() };
            match pick(&scripts, loaded.bundle, &args.file, name) {
                Ok(s) => Driver::Script(s),
                Err(e) => {
                    eprintln!("error: {e}");
                    return USAGE;
                }
            }
        }
    };
    let until = match args.until {
        None => None,
        Some(s) if s.is_finite() && s > 0.0 && s < 1e9 => Some((s * 1e9).round() as u64),
        Some(s) => {
            eprintln!("error: --until must be a positive number of seconds (below 1e9), not {s}");
            return USAGE;
        }
    };
    let content = loaded.content;
    if let Some(out) = &args.out {
        if let Err(e) = std::fs::create_dir_all(out) {
            eprintln!("error: cannot create `{}`: {e}", out.display());
            return USAGE;
        }
    }
    // The recording is written beside its place and renamed when whole.
    let record_to = args.record.clone().or_else(|| args.out.as_ref().map(|d| d.join("recording.mcap")));
    let partial = record_to.as_deref().map(situ_compiler::bundle::file::partial_path);
    let file = match &partial {
        Some(path) => {
            let bytes = loaded.bytes.clone().unwrap_or_else(|| bundle::encode(&content, Encoding::Json));
            match McapRecorder::create(path, content.clone(), &bytes) {
                Ok(m) => Some(m.flush_by_message_time()),
                Err(e) => {
                    eprintln!("error: cannot write `{}`: {e}", path.display());
                    return USAGE;
                }
            }
        }
        None => None,
    };
    let watchers = match Watchers::start(args.foxglove.as_deref(), args.serve.as_deref(), || {
        Site::live(args.file.display().to_string(), content.clone(), loaded.checked.as_ref())
    }) {
        Ok(w) => w,
        Err(code) => return code,
    };
    let sink = watchers.recorder(file, &content).map(|m| Box::new(m) as Box<dyn Sink>);
    let mut run = ScriptRun::new(content.clone(), driver.clone(), until, sink);
    let mut live = super::LiveLine::new();
    if watchers.any() {
        watchers.wait();
        in_real_time(&mut run, &mut live);
    } else {
        run.run(&mut |r| live.draw(|| r.progress().line()));
    }
    live.clear();
    let tracked = run.tracked();
    let snapshots = run.snapshots().to_vec();
    let end = run.now();
    let finished = run.finish();
    watchers.end();
    let report = match finished {
        Ok(r) => r,
        Err(e) => {
            if let Some(p) = &partial {
                let _ = std::fs::remove_file(p);
            }
            eprintln!("error: the recording failed: {e}");
            return USAGE;
        }
    };
    if let (Some(from), Some(to)) = (&partial, &record_to) {
        if let Err(e) = std::fs::rename(from, to) {
            eprintln!("error: cannot write `{}`: {e}", to.display());
            return USAGE;
        }
    }
    println!("{} on {} ({})\n", content.source, report.driver, report.ended);
    print!("{}", report.runtime.table());
    if let Some(x) = &report.exploration {
        println!("{}", x.line());
    }
    println!("\n{}", report.agents_table(&content));
    if !report.problems.is_empty() {
        println!("problems the Bulletinboard reported:");
        for p in report.problems.iter().take(10) {
            println!("  {p}");
        }
        if report.problems.len() > 10 {
            println!("  … {} more in metrics.json", report.problems.len() - 10);
        }
    }
    if let Some(out) = &args.out {
        let title = format!("{} — {}", content.source, report.driver);
        if let Err(e) = write_out(out, &content, &tracked, &snapshots, end, &title, &report) {
            eprintln!("error: {e}");
            return USAGE;
        }
        println!("wrote {}", out.display());
    }
    if let Some(path) = &args.record {
        println!("recorded {}", path.display());
    }
    if report.clean() {
        OK
    } else {
        FAILED
    }
}

/// Plays the run a simulated second a wall second (its watchers follow it),
/// in slices of [`SLICE`].
fn in_real_time(run: &mut ScriptRun, line: &mut super::LiveLine) {
    const SLICE: u64 = 5_000_000;
    let start = std::time::Instant::now();
    let mut t = 0u64;
    while !run.finished() && t < run.end() {
        t = t.saturating_add(SLICE).min(run.end());
        run.run_until(t);
        let ahead = std::time::Duration::from_nanos(t).saturating_sub(start.elapsed());
        if !ahead.is_zero() {
            std::thread::sleep(ahead);
        }
        line.draw(|| run.progress().line());
    }
}

/// `timeline.svg`, `wiring-STATE.svg` of every state visited (as the run
/// saw it), `metrics.json`.
fn write_out(
    out: &Path,
    content: &Content,
    tracked: &situ_runtime::script::report::Tracked,
    snapshots: &[Option<Snapshot>],
    end: u64,
    title: &str,
    report: &situ_runtime::script::report::ScriptReport,
) -> Result<(), String> {
    let write = |name: &str, bytes: &[u8]| {
        super::write_atomically(&out.join(name), bytes)
            .map_err(|e| format!("cannot write `{}`: {e}", out.join(name).display()))
    };
    write("timeline.svg", chart::timeline_svg(content, tracked, end, title).as_bytes())?;
    let mut visited = vec![content.initial];
    visited.extend(tracked.states.iter().map(|&(_, s)| s));
    visited.sort_unstable();
    visited.dedup();
    for s in visited {
        let svg = match snapshots.get(s as usize).and_then(Option::as_ref) {
            Some(snap) => super::graph::svg(&situ_compiler::graph::wiring_moment(content, &snap.moment())),
            // A state that was at rest only inside one step of the
            // scheduler: its static wiring.
            None => super::graph::svg(&situ_compiler::graph::wiring(content, Some(s))),
        }
        .map_err(|e| format!("cannot lay out the wiring of a state: {e}"))?;
        write(&format!("wiring-{}.svg", content.states[s as usize].name), svg.as_bytes())?;
    }
    write("metrics.json", report.to_json().as_bytes())?;
    Ok(())
}
