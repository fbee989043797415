//! `situ test FILE… [--filter NAME] [--format human|json] [--engine …]
//! [--seed S] [--cases N] [--length L] [--depth K] [--max-states N]
//! [--prove-effort N] [--prove-timeout S] [--allow-undecided] [--stats]`:
//! runs every `test` block and checks every `property` block
//! (`situ_verify::property` decides each: proved, violated or undecided).
//! Exit 0 when every test passes and every property is proved, 1 when one
//! fails or is undecided (undecided is allowed with `--allow-undecided`), or
//! a file has errors, 2 on usage or I/O errors.

use super::{FAILED, OK, USAGE};
use situ_compiler::bundle::Content;
use situ_compiler::loader::FsLoader;
use situ_compiler::render;
use situ_compiler::spec::PropertySpec;
use situ_verify::explore::Limits;
use situ_verify::property::{
    self, Checker, Conclusion, Engines, Premise, Report, Session, DEFAULT_OPTIONS as DEFAULTS,
};
use situ_verify::random::Search;
use situ_verify::suite::{self, FileOutcome, SuiteReport};
use situ_verify::{show_event, Counterexample, Verdict};
use std::path::PathBuf;
use std::time::Duration;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Format {
    /// A line per test and property, the failures, a summary.
    Human,
    /// One JSON object per test or property, one per line.
    Json,
    /// One SARIF 2.1.0 log: failed tests (E0504), violated (E0503),
    /// undecided (E0502) and vacuous (W0501) properties, with the files' findings.
    Sarif,
}

/// Which checkers look at the properties.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Engine {
    /// Exhaustive exploration, then random search.
    Both,
    Exhaustive,
    Random,
}

// The arguments of `situ test`.
#[derive(clap::Args)]
pub struct Args {
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Only the tests and properties whose name contains this.
    #[arg(long)]
    pub filter: Option<String>,
    #[arg(long, value_enum, default_value_t = Format::Human)]
    pub format: Format,
    /// Which checkers look at the properties.
    #[arg(long, value_enum, default_value_t = Engine::Both)]
    pub engine: Engine,
    /// The seed of the random search.
    #[arg(long, default_value_t = DEFAULTS.search.seed)]
    pub seed: u64,
    /// Random runs per property.
    #[arg(long, default_value_t = DEFAULTS.search.cases)]
    pub cases: u32,
    /// Events per random run.
    #[arg(long, default_value_t = DEFAULTS.search.length)]
    pub length: usize,
    /// The most events the exhaustive exploration goes from the start.
    #[arg(long, default_value_t = DEFAULTS.limits.depth)]
    pub depth: usize,
    /// The most abstract states the exhaustive exploration makes.
    #[arg(long, default_value_t = DEFAULTS.limits.max_states)]
    pub max_states: usize,
    /// IC3's work budget per property, in SAT propagations: the same
    /// budget gives the same verdict on any machine under any load.
    #[arg(long, default_value_t = situ_verify::property::DEFAULT_EFFORT)]
    pub prove_effort: u64,
    /// A wall-clock guard on IC3, in seconds per property; a property it
    /// stops is undecided, and the output says it was the clock.
    #[arg(long, default_value_t = 600.0)]
    pub prove_timeout: f64,
    /// Exit 0 when no property is violated, even if some are undecided.
    #[arg(long)]
    pub allow_undecided: bool,
    /// Print the size and time of the exploration and the random search.
    #[arg(long)]
    pub stats: bool,
}

impl Engine {
    fn engines(self) -> Engines {
        match self {
            Engine::Both => Engines::Both,
            Engine::Exhaustive => Engines::Exhaustive,
            Engine::Random => Engines::Random,
        }
    }
}

impl Args {
    /// The suite's options (`situ_verify::suite` holds the policy).
    fn options(&self) -> suite::Options {
        suite::Options {
            filter: self.filter.clone(),
            properties: property::Options {
                engines: self.engine.engines(),
                search: Search { seed: self.seed, cases: self.cases, length: self.length },
                limits: Limits { depth: self.depth, max_states: self.max_states },
                effort: self.prove_effort,
                timeout: Some(Duration::from_secs_f64(self.prove_timeout.clamp(0.0, 86_400.0))),
            },
            allow_undecided: self.allow_undecided,
        }
    }
}

pub fn run(args: &Args) -> super::Outcome {
    let report = suite::run(&args.files, &FsLoader, &args.options());
    let verdict = report.verdict();
    match args.format {
        Format::Human => human(args, &report),
        Format::Json => json_lines(&report),
        Format::Sarif => sarif(report),
    }
    Ok(match verdict {
        suite::Verdict::Pass => OK,
        suite::Verdict::Fail => FAILED,
        suite::Verdict::Unreadable => USAGE,
    })
}

/// A line per test and property, the failures of each file, a summary.
fn human(args: &Args, report: &SuiteReport) {
    for file in &report.files {
        let path = file.path.display();
        let r = match &file.outcome {
            FileOutcome::Unreadable(e) => {
                eprintln!("error: {e}");
                continue;
            }
            FileOutcome::Errors(checked) => {
                print!("{}", render::human_all(checked, super::style()));
                println!("{path}: {} error(s): no test or property was run", checked.errors());
                continue;
            }
            FileOutcome::Ran(_, r) => r,
        };
        println!(
            "\nrunning {} and {} from {path}",
            count(r.tests.len(), "test"),
            count(r.properties.len(), "property"),
        );
        let mut failures = Vec::new();
        for t in &r.tests {
            println!("test \"{}\" ... {}", t.spec.name, if t.outcome.passed() { "ok" } else { "FAILED" });
            if !t.outcome.passed() {
                let mut text = format!("---- test \"{}\" ({}) ----\n", t.spec.name, t.spec.place);
                for f in &t.outcome.failures {
                    text.push_str(&format!("  {}: {}\n", f.place, f.message));
                }
                failures.push(text);
            }
        }
        if args.stats {
            if let Some(session) = &r.session {
                print_stats(session, &r.properties);
            }
        }
        for p in &r.properties {
            print_property(&r.content, &p.spec, &p.report);
            if let Some(text) = property_failure(&r.content, &p.spec, &p.report) {
                failures.push(text);
            }
        }
        if !failures.is_empty() {
            println!("\nfailures:\n");
            for f in &failures {
                println!("{f}");
            }
        }
    }
    let s = report.summary;
    println!("\n{} passed, {} failed, {} undecided", s.passed, s.failed, s.undecided);
    if s.undecided > 0 && !report.allow_undecided {
        println!("undecided properties fail the run (E0502: `situ explain E0502`); `--allow-undecided` lets them pass");
    }
}

/// A failed property's text in the failures, if it failed.
fn property_failure(content: &Content, p: &PropertySpec, r: &Report) -> Option<String> {
    match &r.conclusion {
        Conclusion::Violated { by, how, counterexample } => {
            let mut text = format!("---- property \"{}\" ({}) ----\n", p.name, p.place);
            text.push_str(&format!(
                "counterexample ({}, {how}, {} events):\n",
                by.name(),
                counterexample.steps.len()
            ));
            text.push_str(&counterexample.describe(content));
            text.push_str("replay it as a test (paste it into the file):\n");
            text.push_str(&counterexample.as_test(content, &p.name));
            Some(text)
        }
        Conclusion::Disagree { .. } => Some(format!(
            "---- property \"{}\" ({}) ----\nIC3's counterexample does not replay on the engine: an error of situ, please report it\n",
            p.name, p.place
        )),
        Conclusion::Proved { .. } | Conclusion::Undecided { .. } => None,
    }
}

/// One JSON object per test or property, one per line, and the summary
/// (the records are the library's: `situ_api::test_records`).
fn json_lines(report: &SuiteReport) {
    for file in &report.files {
        if let FileOutcome::Unreadable(e) = &file.outcome {
            eprintln!("error: {e}");
        }
    }
    for record in situ_api::test_records(report) {
        println!("{record}");
    }
}

/// One SARIF 2.1.0 log: each file's findings with its verdicts as findings.
fn sarif(report: SuiteReport) {
    let (mut checks, mut unreadable) = (Vec::new(), Vec::new());
    for file in report.files {
        match file.outcome {
            FileOutcome::Unreadable(e) => {
                eprintln!("error: {e}");
                unreadable.push(e);
            }
            FileOutcome::Errors(checked) => checks.push(checked),
            FileOutcome::Ran(mut checked, r) => {
                checked.diagnostics.extend(r.findings());
                checks.push(checked);
            }
        }
    }
    let checks: Vec<&situ_compiler::Checked> = checks.iter().collect();
    let failures: Vec<_> = unreadable.iter().collect();
    println!("{}", render::sarif_with_failures(&checks, &failures));
}

/// `--stats`: the size and time of the exploration, the circuit, IC3 and
/// the random search.
fn print_stats(session: &Session, props: &[suite::PropertyResult]) {
    if let Some(g) = &session.graph {
        println!(
            "exploration: {} abstract states, {} edges, {} letters, {} gaps, complete to {} events{}, {:.3} s",
            g.states(),
            g.edges(),
            g.alphabet.letters.len(),
            g.alphabet.gaps.len(),
            g.complete_depth,
            if g.closed { " (closed)" } else { "" },
            session.graph_time.as_secs_f64()
        );
    }
    match &session.model {
        Some(Ok(m)) => println!(
            "circuit: {} latches, {} inputs, {} and-gates, {:.3} s",
            m.aig.latches().len(),
            m.aig.inputs().len(),
            m.aig.len() - 1 - m.aig.latches().len() - m.aig.inputs().len(),
            session.model_time.as_secs_f64()
        ),
        Some(Err(why)) => println!("circuit: not built ({why})"),
        None => {}
    }
    for p in props {
        let (name, r) = (&p.spec.name, &p.report);
        if let Some(t) = r.ic3_time {
            println!("ic3 \"{name}\": {:.3} s", t.as_secs_f64());
        }
        if let (Some(t), Some(Verdict::NotFound { steps, .. })) = (r.random_time, &r.random) {
            let s = t.as_secs_f64();
            println!("random \"{name}\": {steps} steps in {s:.3} s ({:.0} steps/s)", *steps as f64 / s);
        }
    }
}

/// A property's line, each checker's answer, its premise.
fn print_property(content: &Content, p: &PropertySpec, r: &Report) {
    let head = match &r.conclusion {
        Conclusion::Proved { by, .. } => format!("ok (proved by {})", by.name()),
        Conclusion::Violated { .. } => "FAILED".to_string(),
        Conclusion::Undecided { .. } => "UNDECIDED".to_string(),
        Conclusion::Disagree { .. } => "ERROR".to_string(),
    };
    println!("property \"{}\" ... {head}", p.name);
    for (name, v) in [("exhaustive", &r.exhaustive), ("symbolic", &r.symbolic), ("random", &r.random)] {
        match (&r.conclusion, v) {
            // A liveness proof says what it covers (every infinite run).
            (Conclusion::Proved { by: Checker::Symbolic, what }, Some(_)) if name == "symbolic" => {
                println!("    {name}: {what}")
            }
            (_, Some(v)) => println!("    {name}: {}", v.summary()),
            (_, None) => {}
        }
    }
    if let Some(n) = &r.symbolic_note {
        println!("    symbolic: {n}");
    }
    if let Some(n) = &r.random_note {
        println!("    random: {n}");
    }
    if let Conclusion::Undecided { .. } = r.conclusion {
        println!("    undecided: no checker proved or broke it within its budget (`situ explain E0502`)");
    }
    match &r.premise {
        Some(Premise::Reachable(run)) => println!("    premise: reached after {}", brief_run(content, run)),
        Some(Premise::Vacuous { by }) => println!(
            "    warning[W0501]: vacuous: the premise never holds ({} proved it), so the property says nothing (`situ explain W0501`)",
            by.name()
        ),
        Some(Premise::Unknown) => println!("    premise: not shown reachable within the budgets"),
        None => {}
    }
}

/// A run in one line: `ARM at 0ms, FIRE at 10ms`, or `the start`.
fn brief_run(content: &Content, run: &Counterexample) -> String {
    if run.steps.is_empty() {
        return "no event (it holds at the start)".to_string();
    }
    let show = |s: &situ_verify::CexStep| {
        format!("{} at {}", show_event(content, s.event, &s.payload), situ_verify::show_duration(s.time))
    };
    let n = run.steps.len();
    // A long run: its first two events and its last three (JSON has them all).
    let events: Vec<String> = if n <= 6 {
        run.steps.iter().map(show).collect()
    } else {
        let mut v: Vec<String> = run.steps[..2].iter().map(show).collect();
        v.push(format!("… {} more …", n - 5));
        v.extend(run.steps[n - 3..].iter().map(show));
        v
    };
    format!("{n} event{}: {}", if n == 1 { "" } else { "s" }, events.join(", "))
}

fn count(n: usize, what: &str) -> String {
    match (n, what) {
        (1, _) => format!("1 {what}"),
        (_, "property") => format!("{n} properties"),
        _ => format!("{n} {what}s"),
    }
}
