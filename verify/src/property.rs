//! A property's verdict: **proved**, **violated** or **undecided**, never a
//! fourth. This module is the policy of `situ test` for properties: which
//! checkers run, on what budget, and how their answers combine.
//!
//! - **Violated**: some checker found a run that breaks the property on the
//!   real engine (the exploration's shortest first, then IC3's, then the
//!   random search's; IC3's and the random search's are shrunk, IC3's
//!   lassos confirmed on the engine).
//! - **Proved**: the exploration closed an exact abstraction (every run,
//!   liveness included), or IC3 closed an inductive invariant of an exact
//!   abstraction (every run of any length, with any gaps; for an unbounded
//!   `eventually`, of its liveness-to-safety circuit, [`liveness`]).
//! - **Undecided**: everything else, with what each checker reached. A
//!   bounded search, a sampled abstraction or a budget run out are not proofs.
//!
//! Budgets are deterministic: the exploration counts states and events,
//! IC3 frames and SAT propagations, the random search runs and events. The
//! same file and options give the same verdict on any machine under any
//! load; a wall-clock guard may stop IC3 earlier, and the verdict then says
//! that it was the clock.
//!
//! **Premises.** For a property `P -> …` the checkers also look at `never
//! P`: a run that reaches P is shown with a proof, and a premise that no run
//! reaches makes the property **vacuous** (W0501): true, but of nothing.

use super::abstraction::Alphabet;
use super::bmc;
use super::explore::{Graph, Limits};
use super::ic3;
use super::liveness;
use super::model::Model;
use super::monitor::Monitor;
use super::prove;
use super::random::{self, Search};
use super::{Counterexample, Verdict};
use situ_compiler::bundle::Content;
use situ_compiler::spec::{Consequent, Pred, PropertySpec};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Which checkers look at the properties.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Engines {
    /// Exhaustive exploration and IC3, then random search.
    Both,
    /// Exhaustive exploration and IC3.
    Exhaustive,
    /// Random search only.
    Random,
}

/// The default work budget of IC3 per property, in SAT propagations.
pub const DEFAULT_EFFORT: u64 = 200_000_000;

/// How much each checker may do.
#[derive(Debug, Clone, Copy)]
pub struct Options {
    pub engines: Engines,
    pub search: Search,
    pub limits: Limits,
    /// IC3's work budget per property, in SAT propagations.
    pub effort: u64,
    /// A wall-clock guard on each IC3 call (reaching it is said as such).
    pub timeout: Option<Duration>,
}

/// The budgets `situ test` uses when it is not told otherwise (its flags'
/// defaults are these): both checkers, 256 random runs of 120 events from
/// seed 1, exploration to 12 events or 20,000 states, IC3 on
/// [`DEFAULT_EFFORT`] propagations under a 600 s guard.
pub const DEFAULT_OPTIONS: Options = Options {
    engines: Engines::Both,
    search: Search { seed: 1, cases: 256, length: 120 },
    limits: Limits { depth: 12, max_states: 20_000 },
    effort: DEFAULT_EFFORT,
    timeout: Some(Duration::from_secs(600)),
};

impl Default for Options {
    fn default() -> Self {
        DEFAULT_OPTIONS
    }
}

/// The checker that decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Checker {
    Exhaustive,
    Symbolic,
    Random,
}

impl Checker {
    pub fn name(self) -> &'static str {
        match self {
            Checker::Exhaustive => "exhaustive exploration",
            Checker::Symbolic => "IC3",
            Checker::Random => "random search",
        }
    }
}

/// What a property came to.
#[derive(Debug, Clone, PartialEq)]
pub enum Conclusion {
    /// Holds on every run: `by` says which checker, `what` what it showed.
    Proved { by: Checker, what: String },
    /// A run that breaks it, replayed on the engine.
    Violated { by: Checker, how: &'static str, counterexample: Counterexample },
    /// Neither: what each checker reached, one line each.
    Undecided { reasons: Vec<String> },
    /// IC3's run does not break the property on the engine: an error of situ.
    Disagree { events: usize },
}

impl Conclusion {
    /// `proved`, `violated`, `undecided` or `error`.
    pub fn word(&self) -> &'static str {
        match self {
            Conclusion::Proved { .. } => "proved",
            Conclusion::Violated { .. } => "violated",
            Conclusion::Undecided { .. } => "undecided",
            Conclusion::Disagree { .. } => "error",
        }
    }
}

/// Whether a property's premise can hold.
#[derive(Debug, Clone, PartialEq)]
pub enum Premise {
    /// A run after which the premise holds (its last point).
    Reachable(Counterexample),
    /// No run reaches it: the property is vacuous (W0501). `by` proved it.
    Vacuous { by: Checker },
    /// Not decided within the budgets.
    Unknown,
}

/// One property's answers.
#[derive(Debug, Clone)]
pub struct Report {
    pub exhaustive: Option<Verdict>,
    /// IC3 on the circuit (runs of any length).
    pub symbolic: Option<Verdict>,
    /// Why IC3 did not run, when it did not.
    pub symbolic_note: Option<String>,
    pub random: Option<Verdict>,
    /// Why the random search did not run, when it did not.
    pub random_note: Option<String>,
    pub conclusion: Conclusion,
    /// For a property with a premise (`P -> …`), unless it is violated.
    pub premise: Option<Premise>,
    /// Wall-clock time of IC3 and of the random search (for `--stats`).
    pub ic3_time: Option<Duration>,
    pub random_time: Option<Duration>,
}

/// What was built once for every property of a file (for `--stats`).
pub struct Session {
    pub graph: Option<Graph>,
    pub graph_time: Duration,
    pub alphabet: Arc<Alphabet>,
    pub model: Option<Result<Model, String>>,
    pub model_time: Duration,
    /// The properties given, then one `never P` per premise.
    premises: Vec<Option<usize>>,
}

/// The property `never P` of a property's premise P, if it has one that is
/// not trivially true.
fn premise_property(p: &PropertySpec) -> Option<PropertySpec> {
    let premise = p.premise.as_ref()?;
    if *premise == Pred::Bool(true) {
        return None;
    }
    Some(PropertySpec {
        name: format!("the premise of {}", p.name),
        place: p.place.clone(),
        origin: p.origin,
        never: true,
        premise: None,
        consequent: Consequent::Now(premise.clone()),
    })
}

/// Checks every property of a program: one [`Report`] per property, in order.
pub fn check_all(content: &Arc<Content>, props: &[&PropertySpec], opts: &Options) -> (Session, Vec<Report>) {
    // The premises' `never P` ride along in the graph and the circuit.
    let derived: Vec<Option<PropertySpec>> = props.iter().map(|p| premise_property(p)).collect();
    let mut all: Vec<&PropertySpec> = props.to_vec();
    let mut premises = Vec::new();
    for d in &derived {
        premises.push(d.as_ref().map(|d| {
            all.push(d);
            all.len() - 1
        }));
    }
    let explore = opts.engines != Engines::Random;
    let start = Instant::now();
    let graph = explore.then(|| Graph::build(content, &all, opts.limits));
    let graph_time = start.elapsed();
    let alphabet = Arc::new(Alphabet::new(content, &all));
    let start = Instant::now();
    let model = explore.then(|| Model::build(content, &alphabet, &all).map_err(|e| e.0));
    let model_time = start.elapsed();
    let session = Session { graph, graph_time, alphabet, model, model_time, premises };
    let reports = props
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let mut r = check_one(content, &session, i, p, opts);
            if !matches!(r.conclusion, Conclusion::Violated { .. }) {
                if let (Some(j), Some(d)) = (session.premises[i], &derived[i]) {
                    r.premise = Some(premise(content, &session, j, d, opts));
                }
            }
            r
        })
        .collect();
    (session, reports)
}

/// The exploration's verdict, deepened on the circuit ([`bmc::deepen`]) to
/// `--depth` events on a share of IC3's budget ([`bmc::SHARE`]).
fn deeper(content: &Arc<Content>, s: &Session, i: usize, p: &PropertySpec, v: Verdict, opts: &Options) -> Verdict {
    let model = s.model.as_ref().and_then(|m| m.as_ref().ok());
    let budget = ic3::Limits { frames: opts.limits.depth, work: opts.effort / bmc::SHARE, ..limits(opts) };
    bmc::deepen(content, &s.alphabet, model, i, p, v, budget)
}

fn limits(opts: &Options) -> ic3::Limits {
    ic3::Limits { frames: prove::MAX_FRAMES, work: opts.effort, deadline: opts.timeout.map(|t| Instant::now() + t) }
}

/// The checkers on property `i` of the session, and their conclusion.
fn check_one(content: &Arc<Content>, s: &Session, i: usize, p: &PropertySpec, opts: &Options) -> Report {
    let monitor = Monitor::new(p);
    let liveness = monitor.is_liveness() && !monitor.never;
    let exhaustive = s.graph.as_ref().map(|g| deeper(content, s, i, p, g.check(i, p), opts));
    let settled = exhaustive.as_ref().is_some_and(|v| v.failed() || matches!(v, Verdict::Proved { .. }));
    let mut ic3_time = None;
    let (symbolic, symbolic_note) = match &s.model {
        None => (None, None),
        Some(_) if settled => (None, None),
        Some(Err(why)) => (None, Some(format!("not run (no circuit: {why})"))),
        Some(Ok(m)) if liveness => {
            let start = Instant::now();
            let v = liveness::check(content, &s.alphabet, m, i, p, limits(opts));
            ic3_time = Some(start.elapsed());
            let note = v.is_none().then(|| "not run: the circuit cannot say this property's predicates".to_string());
            (v, note)
        }
        Some(Ok(m)) => {
            let start = Instant::now();
            let v = prove::prove(content, &s.alphabet, m, i, p, limits(opts));
            ic3_time = Some(start.elapsed());
            (v, None)
        }
    };
    let mut random_time = None;
    let (random, random_note) = if opts.engines == Engines::Exhaustive {
        (None, None)
    } else if liveness {
        (None, Some("not run: an unbounded `eventually` is decided on infinite runs".to_string()))
    } else {
        let start = Instant::now();
        let v = random::search(content, &s.alphabet, p, opts.search);
        random_time = Some(start.elapsed());
        (Some(v), None)
    };
    let mut r = Report {
        exhaustive,
        symbolic,
        symbolic_note,
        random,
        random_note,
        conclusion: Conclusion::Undecided { reasons: Vec::new() },
        premise: None,
        ic3_time,
        random_time,
    };
    r.conclusion = conclude(&r, liveness);
    r
}

/// How the checkers' answers combine.
fn conclude(r: &Report, liveness: bool) -> Conclusion {
    let failed = |v: &Option<Verdict>| match v {
        Some(Verdict::Failed(c)) => Some(c.clone()),
        _ => None,
    };
    if let Some(c) = failed(&r.exhaustive) {
        let how = if c.reason.contains("repeat forever") { "a lasso" } else { "shortest" };
        return Conclusion::Violated { by: Checker::Exhaustive, how, counterexample: c };
    }
    if let Some(c) = failed(&r.symbolic) {
        let how = if c.reason.contains("repeat forever") {
            "a lasso, confirmed on the engine"
        } else {
            "replayed on the engine, shrunk"
        };
        return Conclusion::Violated { by: Checker::Symbolic, how, counterexample: c };
    }
    if let Some(c) = failed(&r.random) {
        return Conclusion::Violated { by: Checker::Random, how: "shrunk", counterexample: c };
    }
    // The circuit's run does not replay (IC3's, or the deepened exploration's).
    if let Some(Verdict::Disagree { events }) =
        [&r.symbolic, &r.exhaustive].into_iter().flatten().find(|v| matches!(v, Verdict::Disagree { .. }))
    {
        return Conclusion::Disagree { events: *events };
    }
    if let Some(v @ Verdict::Proved { .. }) = &r.exhaustive {
        return Conclusion::Proved { by: Checker::Exhaustive, what: v.summary() };
    }
    if let Some(v @ Verdict::Inductive { sampled: None, frames, clauses }) = &r.symbolic {
        let what = if liveness {
            format!(
                "proved on every infinite run (IC3 on the liveness-to-safety circuit: an inductive invariant of {clauses} clauses at frame {frames})"
            )
        } else {
            v.summary()
        };
        return Conclusion::Proved { by: Checker::Symbolic, what };
    }
    let mut reasons = Vec::new();
    for (name, v) in [("exhaustive", &r.exhaustive), ("symbolic", &r.symbolic), ("random", &r.random)] {
        if let Some(v) = v {
            reasons.push(format!("{name}: {}", v.summary()));
        }
    }
    if let Some(n) = &r.symbolic_note {
        reasons.push(format!("symbolic: {n}"));
    }
    if liveness {
        reasons.push(
            "an unbounded `eventually` is proved by an exploration that closes an exact abstraction, or by IC3 on the liveness-to-safety circuit of an exact abstraction".into(),
        );
    }
    Conclusion::Undecided { reasons }
}

/// Whether the premise of a property can hold: `never P` checked by the
/// exploration, then by the random search, then by IC3.
fn premise(content: &Arc<Content>, s: &Session, j: usize, never_p: &PropertySpec, opts: &Options) -> Premise {
    let exhaustive = s.graph.as_ref().map(|g| deeper(content, s, j, never_p, g.check(j, never_p), opts));
    match &exhaustive {
        Some(Verdict::Failed(c)) => return Premise::Reachable(c.clone()),
        Some(Verdict::Proved { .. }) => return Premise::Vacuous { by: Checker::Exhaustive },
        _ => {}
    }
    // A run that reaches the premise is usually found at random at once;
    // IC3 finds deep ones slowly, and alone proves that none exists.
    if opts.engines != Engines::Exhaustive {
        if let Verdict::Failed(c) = random::search(content, &s.alphabet, never_p, opts.search) {
            return Premise::Reachable(c);
        }
    }
    if let Some(Ok(m)) = &s.model {
        match prove::prove(content, &s.alphabet, m, j, never_p, limits(opts)) {
            Some(Verdict::Failed(c)) => return Premise::Reachable(c),
            Some(Verdict::Inductive { sampled: None, .. }) => return Premise::Vacuous { by: Checker::Symbolic },
            _ => {}
        }
    }
    Premise::Unknown
}
