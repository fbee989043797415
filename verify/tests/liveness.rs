//! Liveness proved for runs of any length: `always (P -> eventually Q)`
//! without a bound, by IC3 on the liveness-to-safety circuit
//! (`situ_verify::liveness`). A true property with durations is proved
//! (the exploration samples time, so it alone leaves it undecided); a false
//! one gets a lasso that the engine confirms; and the prover agrees with
//! the exploration wherever that one settles a liveness property.

use situ_compiler::loader::FsLoader;
use situ_compiler::spec::{self, PropertySpec};
use situ_compiler::{bundle, check_source};
use situ_verify::abstraction::Alphabet;
use situ_verify::explore::{Graph, Limits};
use situ_verify::ic3;
use situ_verify::liveness;
use situ_verify::model::Model;
use situ_verify::monitor::Monitor;
use situ_verify::property::{self, Checker, Conclusion, Engines, Options, Premise};
use situ_verify::random::Search;
use situ_verify::{RunStep, Verdict};
use std::path::Path;
use std::sync::Arc;

/// A job that a lapse of its sensor or any new report ends: once busy, it
/// is done at the next event, whatever its gap.
const ENDS: &str = r#"
states { Idle initial Busy Done }
agent Job sensor { stale after 100ms event PING event PONG }
rule start { when state == Idle and PING then Busy }
rule again { when state == Busy and PING x2 then Done }
rule pong { when state == Busy and PONG then Done }
rule lapse { when state == Busy and stale Job then Done }
property "a busy job ends" { always (state == Busy -> eventually state == Done) }
"#;

/// A job that ends only when its sensor falls silent: a sensor that keeps
/// ticking within 100ms keeps it busy for ever.
const TICKS: &str = r#"
states { Idle initial Busy Done }
agent Job sensor { stale after 100ms event START event TICK }
rule start { when state == Idle and START then Busy }
rule done { when state == Busy and stale Job then Done }
property "a busy job ends" { always (state == Busy -> eventually state == Done) }
"#;

/// Without durations: the exploration is exact and settles both.
const EXACT: &str = r#"
states { Idle initial Busy Done }
agent Job interface { event START event STOP }
rule start { when state == Idle and START then Busy }
rule stop { when state == Busy and STOP then Done }
rule retry { when state == Busy and START then Done }
property "a busy job ends" { always (state == Busy -> eventually state == Done) }
property "an idle job starts" { always (state == Idle -> eventually state == Busy) }
"#;

fn load(text: &str) -> (Arc<bundle::Content>, Vec<PropertySpec>) {
    let checked = check_source("t.situ", text);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    (Arc::new(bundle::build(&checked)), spec::lower(&checked).properties)
}

fn options() -> Options {
    Options {
        engines: Engines::Both,
        search: Search { seed: 1, cases: 16, length: 8 },
        limits: Limits { depth: 30, max_states: 20_000 },
        effort: property::DEFAULT_EFFORT,
        timeout: None,
    }
}

/// The liveness prover alone on property `i`.
fn prover(content: &Arc<bundle::Content>, props: &[&PropertySpec], i: usize) -> Option<Verdict> {
    let alphabet = Arc::new(Alphabet::new(content, props));
    let model = Model::build(content, &alphabet, props).expect("a circuit");
    liveness::check(content, &alphabet, &model, i, props[i], ic3::Limits::frames(60))
}

/// Q wherever P: the obligation never arises.
const AT_ONCE: &str = r#"
states { Idle initial Busy Done }
agent Job sensor { stale after 100ms event START event STOP }
rule start { when state == Idle and START then Busy }
rule stop { when state == Busy and STOP then Done }
property "a busy job is not idle" { always (state == Busy -> eventually state != Idle) }
"#;

#[test]
fn an_obligation_that_never_arises_is_proved() {
    let (content, props) = load(AT_ONCE);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let (_, reports) = property::check_all(&content, &refs, &options());
    match &reports[0].conclusion {
        Conclusion::Proved { by: Checker::Symbolic, .. } => {}
        other => panic!("came to {other:?}"),
    }
}

#[test]
fn a_true_liveness_property_with_durations_is_proved() {
    // Its obligation does arise (a busy job is not done): the proof is
    // the loop detector's, not the first look's.
    let (content, props) = load(ENDS);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let (_, reports) = property::check_all(&content, &refs, &options());
    let r = &reports[0];
    // The exploration samples the gaps: it cannot prove it.
    assert!(matches!(r.exhaustive, Some(Verdict::Exhausted { .. })), "{:?}", r.exhaustive);
    match &r.conclusion {
        Conclusion::Proved { by: Checker::Symbolic, what } => {
            assert!(what.contains("every infinite run"), "{what}")
        }
        other => panic!("came to {other:?}"),
    }
    // Of something: a busy job is reachable.
    assert!(matches!(r.premise, Some(Premise::Reachable(_))), "{:?}", r.premise);
}

/// The prefix and the cycle of a lasso, from its events' times and the
/// reason's "events A to B repeat forever".
fn split(c: &situ_verify::Counterexample) -> (Vec<RunStep>, Vec<RunStep>) {
    let mut last = 0;
    let run: Vec<RunStep> = c
        .steps
        .iter()
        .map(|s| {
            let gap = s.time - last;
            last = s.time;
            RunStep { event: s.event, payload: s.payload.clone(), gap }
        })
        .collect();
    let from = c.reason.split("events ").nth(1).and_then(|t| t.split(' ').next()).expect("a cycle");
    let from: usize = from.parse().expect("a number");
    let (prefix, cycle) = run.split_at(from - 1);
    (prefix.to_vec(), cycle.to_vec())
}

#[test]
fn a_false_liveness_property_gets_a_lasso_that_the_engine_confirms() {
    let (content, props) = load(TICKS);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let alphabet = Alphabet::new(&content, &refs);
    match prover(&content, &refs, 0) {
        Some(Verdict::Failed(c)) => {
            assert!(c.reason.contains("repeat forever"), "{}", c.reason);
            let (prefix, cycle) = split(&c);
            assert!(!cycle.is_empty());
            assert!(liveness::confirmed(&content, &alphabet, refs[0], &prefix, &cycle), "{c:?}");
            // The cycle never lets the sensor fall silent.
            assert!(cycle.iter().all(|s| s.gap <= 100_000_000), "{cycle:?}");
        }
        other => panic!("came to {other:?}"),
    }
    // Through the policy, with an exploration too shallow to close the
    // loop: IC3's lasso is the violation.
    let mut shallow = options();
    shallow.limits.depth = 1;
    let (_, reports) = property::check_all(&content, &refs, &shallow);
    assert!(matches!(reports[0].exhaustive, Some(Verdict::Bounded { .. })), "{:?}", reports[0].exhaustive);
    match &reports[0].conclusion {
        Conclusion::Violated { by: Checker::Symbolic, how, counterexample } => {
            assert!(counterexample.reason.contains("repeat forever"), "{}", counterexample.reason);
            assert!(how.contains("lasso"), "{how}");
        }
        other => panic!("came to {other:?}"),
    }
}

#[test]
fn a_run_that_leaves_the_obligation_is_not_confirmed_as_a_lasso() {
    let (content, props) = load(TICKS);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let alphabet = Alphabet::new(&content, &refs);
    let id = |name: &str| content.events.iter().position(|e| e.name == name).expect("an event") as u32;
    let (start, tick) = (id("START"), id("TICK"));
    let step = |event, gap| RunStep { event, payload: Vec::new(), gap };
    let busy = [step(start, 0), step(tick, 0)];
    // Ticks 50ms apart: busy for ever.
    assert!(liveness::confirmed(&content, &alphabet, refs[0], &busy, &[step(tick, 50_000_000)]));
    // Busy all along, but the sensor's fact after the cycle is not the one before it.
    assert!(!liveness::confirmed(&content, &alphabet, refs[0], &busy[..1], &[step(tick, 50_000_000)]));
    // A silence of 200ms: done, the obligation is discharged.
    assert!(!liveness::confirmed(&content, &alphabet, refs[0], &busy, &[step(tick, 200_000_000)]));
    // Not pending when the cycle begins.
    assert!(!liveness::confirmed(&content, &alphabet, refs[0], &[], &[step(tick, 0)]));
}

/// Every liveness property of a file: the prover's verdict and the
/// exploration's, where the exploration settled it.
fn cross_check(content: &Arc<bundle::Content>, props: &[PropertySpec]) -> usize {
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let graph = Graph::build(content, &refs, Limits { depth: 40, max_states: 20_000 });
    let mut compared = 0;
    for (i, p) in refs.iter().enumerate() {
        let m = Monitor::new(p);
        if !m.is_liveness() || m.never {
            continue;
        }
        let explored = graph.check(i, p);
        let settled = matches!(explored, Verdict::Proved { .. } | Verdict::Failed(_));
        if !settled {
            continue;
        }
        let proved = prover(content, &refs, i);
        match (&explored, &proved) {
            (Verdict::Proved { .. }, Some(Verdict::Inductive { .. })) => {}
            (Verdict::Failed(e), Some(Verdict::Failed(c))) => {
                // Both a lasso, or both a cascade.
                let lasso = c.reason.contains("repeat forever");
                assert_eq!(lasso, e.reason.contains("repeat forever"), "{}: {c:?} / {e:?}", p.name);
                if lasso {
                    let alphabet = Alphabet::new(content, &refs);
                    let (prefix, cycle) = split(c);
                    assert!(liveness::confirmed(content, &alphabet, p, &prefix, &cycle), "{}: {c:?}", p.name);
                }
            }
            _ => panic!("{}: the exploration says {explored:?}, the prover {proved:?}", p.name),
        }
        compared += 1;
    }
    compared
}

#[test]
fn the_prover_agrees_with_the_exploration_where_it_settles() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut compared = 0;
    let mut files = vec![root.join("tests/verify/liveness.situ")];
    for f in ["outdoor", "ugv", "ugv-merge", "dla"] {
        files.push(root.join(format!("rules/{f}.situ")));
    }
    for path in files {
        let checked = situ_compiler::check(&path, &FsLoader).expect("a file");
        assert_eq!(checked.errors(), 0, "{path:?}");
        let content = Arc::new(bundle::build(&checked));
        compared += cross_check(&content, &spec::lower(&checked).properties);
    }
    // A program without durations, where the exploration is exact.
    let (content, props) = load(EXACT);
    compared += cross_check(&content, &props);
    assert!(compared >= 4, "only {compared} liveness properties settled by the exploration");
}

#[test]
fn a_false_liveness_property_is_never_proved_at_any_budget() {
    let (content, props) = load(TICKS);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    for effort in [0, 1, 10, 100, 1_000, 10_000, 100_000] {
        let mut opts = options();
        opts.limits.depth = 1;
        opts.effort = effort;
        let (_, reports) = property::check_all(&content, &refs, &opts);
        match &reports[0].conclusion {
            Conclusion::Undecided { .. } | Conclusion::Violated { .. } => {}
            other => panic!("effort {effort}: came to {other:?}"),
        }
    }
}
