//! `situ test FILE… [--filter NAME] [--format human|json] [--engine …]
//! [--seed S] [--cases N] [--length L] [--depth K] [--max-states N] [--stats]`:
//! runs every `test` block and checks every `property` block. Exit 0 when all
//! hold, 1 when one fails (or a file has errors), 2 on usage or I/O errors.

use super::{FAILED, OK, USAGE};
use serde_json::json;
use situ_compiler::bundle::{self, Content};
use situ_compiler::loader::FsLoader;
use situ_compiler::render;
use situ_compiler::spec::{self, PropertySpec, TestSpec};
use situ_verify::abstraction::Alphabet;
use situ_verify::explore::{Graph, Limits};
use situ_verify::model::Model;
use situ_verify::monitor::Monitor;
use situ_verify::prove;
use situ_verify::random::{self, Search};
use situ_verify::{scenario, show_event, Counterexample, Verdict};
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Format {
    /// A line per test and property, the failures, a summary.
    Human,
    /// One JSON object per test or property, one per line.
    Json,
}

/// Which checkers look at the properties.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Engine {
    /// Exhaustive exploration, then random search.
    Both,
    Exhaustive,
    Random,
}

pub struct Args {
    pub files: Vec<PathBuf>,
    pub filter: Option<String>,
    pub format: Format,
    pub engine: Engine,
    pub seed: u64,
    pub cases: u32,
    pub length: usize,
    pub depth: usize,
    pub max_states: usize,
    /// Seconds of IC3 per property.
    pub prove_timeout: f64,
    pub stats: bool,
}

/// What one property came to.
struct PropertyResult {
    exhaustive: Option<Verdict>,
    /// IC3 on the circuit of the abstraction (runs of any length).
    symbolic: Option<Verdict>,
    /// Why IC3 gave no verdict, when it gave none.
    symbolic_note: Option<String>,
    random: Option<Verdict>,
}

impl PropertyResult {
    fn failed(&self) -> bool {
        let bad = |v: &Option<Verdict>| v.as_ref().is_some_and(|v| v.failed() || matches!(v, Verdict::Disagree { .. }));
        bad(&self.exhaustive) || bad(&self.symbolic) || bad(&self.random)
    }

    /// The counterexample to show: the exhaustive one (shortest) first.
    fn counterexample(&self) -> Option<(&'static str, &Counterexample)> {
        fn of(v: &Option<Verdict>) -> Option<&Counterexample> {
            match v {
                Some(Verdict::Failed(c)) => Some(c),
                _ => None,
            }
        }
        let how = |c: &Counterexample| {
            if c.reason.contains("repeat forever") {
                "exhaustive, a lasso"
            } else {
                "exhaustive, shortest"
            }
        };
        of(&self.exhaustive)
            .map(|c| (how(c), c))
            .or_else(|| of(&self.symbolic).map(|c| ("IC3, replayed on the engine", c)))
            .or_else(|| of(&self.random).map(|c| ("random, shrunk", c)))
    }
}

pub fn run(args: Args) -> u8 {
    let (mut passed, mut failed) = (0usize, 0usize);
    let mut io_failed = false;
    let human = matches!(args.format, Format::Human);
    for path in &args.files {
        let checked = match situ_compiler::check(path, &FsLoader) {
            Ok(c) => c,
            Err(e) => {
                eprintln!("error: {e}");
                io_failed = true;
                continue;
            }
        };
        if checked.errors() > 0 {
            if human {
                print!("{}", render::human_all(&checked, super::style()));
                println!("{}: {} error(s): no test or property was run", path.display(), checked.errors());
            } else {
                print!("{}", render::json_lines(&checked));
            }
            failed += 1;
            continue;
        }
        let content = Arc::new(bundle::build(&checked));
        let spec = spec::lower(&checked);
        let wanted = |name: &str| args.filter.as_deref().is_none_or(|f| name.contains(f));
        let tests: Vec<&TestSpec> = spec.tests.iter().filter(|t| wanted(&t.name)).collect();
        let props: Vec<&PropertySpec> = spec.properties.iter().filter(|p| wanted(&p.name)).collect();
        if human {
            println!(
                "\nrunning {} and {} from {}",
                count(tests.len(), "test"),
                count(props.len(), "property"),
                path.display()
            );
        }
        let mut failures = Vec::new();
        for t in &tests {
            let outcome = scenario::run(&content, t);
            if human {
                println!("test \"{}\" ... {}", t.name, if outcome.passed() { "ok" } else { "FAILED" });
            } else {
                let list: Vec<_> = outcome
                    .failures
                    .iter()
                    .map(|f| json!({"place": f.place.to_string(), "message": f.message}))
                    .collect();
                println!(
                    "{}",
                    json!({"kind": "test", "file": path.display().to_string(), "name": t.name,
                           "place": t.place.to_string(), "passed": outcome.passed(), "events": outcome.events,
                           "failures": list})
                );
            }
            if outcome.passed() {
                passed += 1;
            } else {
                failed += 1;
                let mut text = format!("---- test \"{}\" ({}) ----\n", t.name, t.place);
                for f in &outcome.failures {
                    text.push_str(&format!("  {}: {}\n", f.place, f.message));
                }
                failures.push(text);
            }
        }
        if !props.is_empty() {
            let results = check_properties(&args, &content, &props, human);
            for (p, r) in props.iter().zip(&results) {
                let mut lines: Vec<String> =
                    [("exhaustive", &r.exhaustive), ("symbolic", &r.symbolic), ("random", &r.random)]
                        .iter()
                        .filter_map(|(name, v)| v.as_ref().map(|v| format!("{name}: {}", v.summary())))
                        .collect();
                if let Some(note) = &r.symbolic_note {
                    lines.insert(lines.len().min(1), format!("symbolic: {note}"));
                }
                let lines = match (&r.random, args.engine) {
                    (None, Engine::Both | Engine::Random) => {
                        let mut l = lines;
                        l.push("random: not run (an unbounded `eventually` is decided on infinite runs)".into());
                        l
                    }
                    _ => lines,
                };
                if human {
                    println!("property \"{}\" ... {}", p.name, if r.failed() { "FAILED" } else { "ok" });
                    for l in &lines {
                        println!("    {l}");
                    }
                } else {
                    println!("{}", property_json(&content, path, p, r));
                }
                if r.failed() {
                    failed += 1;
                    let mut text = format!("---- property \"{}\" ({}) ----\n", p.name, p.place);
                    if let Some((how, cex)) = r.counterexample() {
                        text.push_str(&format!("counterexample ({how}, {} events):\n", cex.steps.len()));
                        text.push_str(&cex.describe(&content));
                        text.push_str("replay it as a test (paste it into the file):\n");
                        for line in cex.as_test(&content, &p.name).lines() {
                            text.push_str(&format!("    {line}\n"));
                        }
                    }
                    failures.push(text);
                } else {
                    passed += 1;
                }
            }
        }
        if human && !failures.is_empty() {
            println!("\nfailures:\n");
            for f in &failures {
                println!("{f}");
            }
        }
    }
    if human {
        println!("\n{passed} passed, {failed} failed");
    }
    if io_failed {
        USAGE
    } else if failed > 0 {
        FAILED
    } else {
        OK
    }
}

fn check_properties(args: &Args, content: &Arc<Content>, props: &[&PropertySpec], human: bool) -> Vec<PropertyResult> {
    let graph = (args.engine != Engine::Random).then(|| {
        let start = Instant::now();
        let g = Graph::build(content, props, Limits { depth: args.depth, max_states: args.max_states });
        if args.stats && human {
            println!(
                "exploration: {} abstract states, {} edges, {} letters, {} gaps, complete to {} events{}, {:.3} s",
                g.states(),
                g.edges(),
                g.alphabet.letters.len(),
                g.alphabet.gaps.len(),
                g.complete_depth,
                if g.closed { " (closed)" } else { "" },
                start.elapsed().as_secs_f64()
            );
        }
        g
    });
    let alphabet = Arc::new(Alphabet::new(content, props));
    let budget = std::time::Duration::from_secs_f64(args.prove_timeout.clamp(0.0, 86_400.0));
    // The circuit of the abstraction, for proofs over runs of any length.
    let model = (args.engine != Engine::Random).then(|| {
        let start = Instant::now();
        let m = Model::build(content, &alphabet, props);
        if args.stats && human {
            match &m {
                Ok(m) => println!(
                    "circuit: {} latches, {} inputs, {} and-gates, {:.3} s",
                    m.aig.latches().len(),
                    m.aig.inputs().len(),
                    m.aig.len() - 1 - m.aig.latches().len() - m.aig.inputs().len(),
                    start.elapsed().as_secs_f64()
                ),
                Err(why) => println!("circuit: not built ({})", why.0),
            }
        }
        m
    });
    props
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let exhaustive = graph.as_ref().map(|g| g.check(i, p));
            let settled = exhaustive.as_ref().is_some_and(|v| v.failed() || matches!(v, Verdict::Proved { .. }));
            let liveness = Monitor::new(p).is_liveness();
            let (symbolic, symbolic_note) = match &model {
                Some(Ok(_)) if liveness => {
                    (None, Some("not run (an unbounded `eventually` is a liveness property: searched only)".into()))
                }
                Some(Ok(m)) if !settled => {
                    let start = Instant::now();
                    let v = prove::prove(content, &alphabet, m, i, p, Some(budget));
                    if args.stats && human {
                        println!("ic3 \"{}\": {:.3} s", p.name, start.elapsed().as_secs_f64());
                    }
                    let note = v.is_none().then(|| {
                        format!("gave up after {} s (`--prove-timeout`): the other verdicts stand", args.prove_timeout)
                    });
                    (v, note)
                }
                Some(Err(why)) if !settled => (None, Some(format!("not run (no circuit: {})", why.0))),
                _ => (None, None),
            };
            // Unbounded `eventually` is decided on infinite runs: not by random runs.
            let m = Monitor::new(p);
            let decided = !m.is_liveness() || m.never;
            let random = (args.engine != Engine::Exhaustive && decided).then(|| {
                let start = Instant::now();
                let v = random::search(
                    content,
                    &alphabet,
                    p,
                    Search { seed: args.seed, cases: args.cases, length: args.length },
                );
                if args.stats && human {
                    if let Verdict::NotFound { steps, .. } = v {
                        let s = start.elapsed().as_secs_f64();
                        println!("random \"{}\": {steps} steps in {s:.3} s ({:.0} steps/s)", p.name, steps as f64 / s);
                    }
                }
                v
            });
            PropertyResult { exhaustive, symbolic, symbolic_note, random }
        })
        .collect()
}

fn property_json(content: &Content, path: &std::path::Path, p: &PropertySpec, r: &PropertyResult) -> serde_json::Value {
    let verdict = |v: &Option<Verdict>| {
        v.as_ref().map(|v| {
            let kind = match v {
                Verdict::Proved { .. } | Verdict::Inductive { sampled: None, .. } => "proved",
                Verdict::Inductive { .. } => "exhausted",
                Verdict::Disagree { .. } => "disagree",
                Verdict::Exhausted { .. } => "exhausted",
                Verdict::Bounded { .. } => "bounded",
                Verdict::NotFound { .. } => "not_found",
                Verdict::Failed(_) => "failed",
            };
            json!({"verdict": kind, "summary": v.summary()})
        })
    };
    let cex = r.counterexample().map(|(how, c)| {
        let steps: Vec<_> = c
            .steps
            .iter()
            .map(|s| {
                json!({"event": show_event(content, s.event, &s.payload), "time_ns": s.time,
                       "state": content.states[s.state as usize].name, "fired": s.fired})
            })
            .collect();
        json!({"found_by": how, "events": steps, "point": c.point, "reason": c.reason,
               "test": c.as_test(content, &p.name)})
    });
    json!({"kind": "property", "file": path.display().to_string(), "name": p.name, "place": p.place.to_string(),
           "passed": !r.failed(), "exhaustive": verdict(&r.exhaustive), "symbolic": verdict(&r.symbolic), "random": verdict(&r.random),
           "counterexample": cex})
}

fn count(n: usize, what: &str) -> String {
    match (n, what) {
        (1, _) => format!("1 {what}"),
        (_, "property") => format!("{n} properties"),
        _ => format!("{n} {what}s"),
    }
}
