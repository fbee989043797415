//! A property is proved, violated or undecided — never "ok" when no checker
//! knows. These tests hold the policy of `situ_verify::property` to that:
//! a false property at any budget, the same verdict under load, vacuous
//! premises, IC3's counterexamples shrunk, and the examples of the verdicts'
//! codes (W0501, E0502) that `situ explain` prints.

use situ_compiler::spec::{self, PropertySpec};
use situ_compiler::{bundle, check_source, codes};
use situ_verify::explore::Limits;
use situ_verify::property::{self, Checker, Conclusion, Engines, Options, Premise, Report};
use situ_verify::random::{self, Search};
use situ_verify::{scenario, Verdict};
use std::cell::Cell;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Fourteen steps from `S0` to `S14`, each on its own event, with noise
/// that the rules ignore: the counterexample to "never S14" is 14 events
/// long, beyond a shallow exploration and a short random search.
fn ladder() -> String {
    let mut s = String::from("states { S0 initial");
    for i in 1..=14 {
        s.push_str(&format!(" S{i}"));
    }
    s.push_str(" }\nagent Up sensor {");
    for i in 1..=14 {
        s.push_str(&format!(" event U{i}"));
    }
    s.push_str(" }\nagent Noise sensor { event HUM event BUZZ }\n");
    for i in 1..=14 {
        s.push_str(&format!("rule r{i} {{ when state == S{} and U{i} then S{i} }}\n", i - 1));
    }
    s.push_str("property \"the top is never reached\" { never state == S14 }\n");
    s
}

fn load(text: &str) -> (Arc<bundle::Content>, Vec<PropertySpec>) {
    let checked = check_source("t.situ", text);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    (Arc::new(bundle::build(&checked)), spec::lower(&checked).properties)
}

/// The checkers' budgets; the random search's runs are `length` events long.
fn options(depth: usize, effort: u64, cases: u32, length: usize) -> Options {
    Options {
        engines: Engines::Both,
        search: Search { seed: 1, cases, length },
        limits: Limits { depth, max_states: 20_000 },
        effort,
        timeout: None,
    }
}

fn check(text: &str, opts: &Options) -> Vec<Report> {
    let (content, props) = load(text);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    property::check_all(&content, &refs, opts).1
}

#[test]
fn a_false_property_is_never_proved_at_any_budget() {
    let text = ladder();
    let mut undecided = 0;
    for effort in [0, 1, 10, 100, 1_000, 10_000, 100_000, 1_000_000] {
        let r = &check(&text, &options(2, effort, 4, 3))[0];
        match &r.conclusion {
            Conclusion::Undecided { reasons } => {
                undecided += 1;
                assert!(reasons.iter().any(|l| l.contains("work budget")), "{effort}: {reasons:?}");
            }
            Conclusion::Violated { counterexample, .. } => assert_eq!(counterexample.steps.len(), 14),
            other => panic!("effort {effort}: a false property came to {other:?}"),
        }
    }
    assert!(undecided >= 2, "the smallest budgets cannot decide it");
    // Enough work: IC3 finds the 14 events, shrunk to the ones needed.
    let r = &check(&text, &options(2, property::DEFAULT_EFFORT, 4, 3))[0];
    match &r.conclusion {
        Conclusion::Violated { by: Checker::Symbolic, counterexample, .. } => {
            assert_eq!(counterexample.steps.len(), 14, "{counterexample:?}")
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_verdict_does_not_depend_on_the_machines_load() {
    let text = ladder();
    let opts = options(2, 3_000, 4, 3);
    let quiet: Vec<String> = check(&text, &opts).iter().map(|r| format!("{:?}", r.conclusion)).collect();
    // Both cores busy while the same check runs again.
    let stop = Arc::new(AtomicBool::new(false));
    let load: Vec<_> = (0..2)
        .map(|_| {
            let stop = stop.clone();
            std::thread::spawn(move || {
                let mut x = 0u64;
                while !stop.load(Ordering::Relaxed) {
                    x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
                }
                x
            })
        })
        .collect();
    let busy: Vec<String> = check(&text, &opts).iter().map(|r| format!("{:?}", r.conclusion)).collect();
    stop.store(true, Ordering::Relaxed);
    for t in load {
        t.join().expect("a load thread");
    }
    assert_eq!(quiet, busy);
    assert!(quiet[0].starts_with("Undecided"), "{}", quiet[0]);
}

#[test]
fn a_vacuous_property_is_flagged_and_a_proof_shows_its_premise_reached() {
    let text = r#"states { Idle initial Armed Fired final }
agent Btn interface { event ARM event FIRE }
agent Lamp actuator { function glow table { Armed => run glow()  Fired => run glow()  _ => sleep } }
rule arm { when state == Idle and ARM then Armed }
rule fire { when state == Armed and FIRE then Fired }
property "vacuous" { always (state == Fired and Lamp sleeping -> state == Armed) }
property "real" { always (state == Fired -> next state == Fired) }
property "no premise" { never state == Idle and FIRE }
"#;
    let reports = check(text, &options(12, property::DEFAULT_EFFORT, 64, 30));
    assert!(matches!(reports[0].conclusion, Conclusion::Proved { .. }), "{:?}", reports[0].conclusion);
    assert!(matches!(reports[0].premise, Some(Premise::Vacuous { .. })), "{:?}", reports[0].premise);
    assert!(matches!(reports[1].conclusion, Conclusion::Proved { .. }), "{:?}", reports[1].conclusion);
    match &reports[1].premise {
        Some(Premise::Reachable(run)) => assert_eq!(run.steps.len(), 2, "ARM, FIRE: {run:?}"),
        other => panic!("{other:?}"),
    }
    assert!(reports[2].premise.is_none());
}

#[test]
fn ic3s_counterexamples_are_shrunk_to_the_events_needed() {
    // The exploration stops at depth 0, so IC3 finds the run; the noise
    // events that IC3 may put in it are gone, and each event is needed.
    let text = ladder();
    let (content, props) = load(&text);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let mut opts = options(0, property::DEFAULT_EFFORT, 1, 3);
    opts.engines = Engines::Exhaustive;
    let (session, reports) = property::check_all(&content, &refs, &opts);
    let Conclusion::Violated { by: Checker::Symbolic, counterexample: c, .. } = &reports[0].conclusion else {
        panic!("{:?}", reports[0].conclusion)
    };
    assert_eq!(c.steps.len(), 14);
    let run: Vec<situ_verify::RunStep> = {
        let mut prev = 0;
        c.steps
            .iter()
            .map(|s| {
                let gap = s.time - prev;
                prev = s.time;
                situ_verify::RunStep { event: s.event, payload: s.payload.clone(), gap }
            })
            .collect()
    };
    for i in 0..run.len() {
        let mut shorter = run.clone();
        shorter.remove(i);
        assert!(random::check_run(&content, &props[0], &shorter, &Cell::new(0)).is_ok(), "event {i} is not needed");
    }
    assert!(c.steps.iter().all(|s| s.time % 1_000_000 == 0), "round times: {c:?}");
    assert!(session.model.is_some());
}

#[test]
fn an_unbounded_eventually_is_not_proved_by_a_bounded_search() {
    // Liveness on a timed program: the exploration's abstraction samples
    // the gaps, IC3 does not prove liveness: undecided, with the reason.
    let text = r#"states { Idle initial Busy Done final }
agent Job sensor { stale after 1s event START event END }
rule start { when state == Idle and START then Busy }
rule done { when state == Busy and END then Done }
rule quiet { when state == Busy and stale Job then Done }
property "a job ends" { always (state == Busy -> eventually state == Done) }
"#;
    let r = &check(text, &options(12, property::DEFAULT_EFFORT, 16, 30))[0];
    match &r.conclusion {
        Conclusion::Violated { .. } => {}
        Conclusion::Undecided { reasons } => {
            assert!(reasons.iter().any(|l| l.contains("unbounded `eventually`")), "{reasons:?}")
        }
        other => panic!("liveness on a sampled abstraction came to {other:?}"),
    }
}

/// The ```situ blocks after a heading of a code's text.
fn blocks_after<'a>(doc: &'a str, heading: &str) -> Vec<&'a str> {
    let Some(start) = doc.find(heading) else { return Vec::new() };
    let section = &doc[start + heading.len()..];
    let section = &section[..section.find("\n## ").unwrap_or(section.len())];
    section.split("```situ\n").skip(1).filter_map(|b| b.split("```").next()).collect()
}

#[test]
fn the_examples_of_the_verdict_codes_are_real() {
    let opts = options(12, property::DEFAULT_EFFORT, 64, 30);
    let verdict_codes: Vec<_> = codes::ALL.iter().filter(|c| codes::is_verdict(c.code)).collect();
    assert_eq!(verdict_codes.len(), 4);
    for c in verdict_codes {
        let raises = |text: &str| -> bool {
            if c.code == codes::FAILED_TEST {
                let checked = check_source("t.situ", text);
                let content = Arc::new(bundle::build(&checked));
                return spec::lower(&checked).tests.iter().any(|t| !scenario::run(&content, t).passed());
            }
            let reports = check(text, &opts);
            reports.iter().any(|r| match c.code {
                codes::VACUOUS_PROPERTY => matches!(r.premise, Some(Premise::Vacuous { .. })),
                codes::UNDECIDED_PROPERTY => matches!(r.conclusion, Conclusion::Undecided { .. }),
                codes::VIOLATED_PROPERTY => matches!(r.conclusion, Conclusion::Violated { .. }),
                other => panic!("{other}: no rule for this code"),
            })
        };
        for ex in blocks_after(c.explain, "## Example") {
            assert!(raises(ex), "{}: the Example does not raise it", c.code);
        }
        for fix in blocks_after(c.explain, "## Use instead") {
            assert!(!raises(fix), "{}: Use instead still raises it", c.code);
        }
    }
}

#[test]
fn a_verdict_never_reads_proved_when_it_is_not() {
    // The words the CLI prints come from the conclusion: a sampled
    // abstraction's "no counterexample" is undecided.
    let text = blocks_after(codes::lookup("E0502").expect("E0502").explain, "## Example")[0];
    let r = &check(text, &options(12, property::DEFAULT_EFFORT, 16, 30))[0];
    assert_eq!(r.conclusion.word(), "undecided");
    assert!(matches!(r.symbolic, Some(Verdict::Inductive { sampled: Some(_), .. })), "{:?}", r.symbolic);
}

#[test]
fn a_variable_is_linked_only_to_the_event_its_rule_joined() {
    // `?n` compares PATH_BLOCKED's route with ROUTE's number: the route
    // planner's other event (NO_ROUTE, its field 0) never meets it there,
    // so two fields are linked and the abstraction is exact (DLA's rules).
    let text = r#"states { Planning initial Following Replanning Unreachable final }
agent Planner processing { event ROUTE { number: i64 } event NO_ROUTE { explored: f64 } }
agent Path processing { event PATH_BLOCKED { route: i64 } }
rule routed { when state in {Planning, Replanning} and ROUTE(number: ?n) and not PATH_BLOCKED(route: ?n) then Following }
rule blocked { when state == Following and ROUTE(number: ?n) and PATH_BLOCKED(route: ?n) then Replanning }
rule none { when state in {Planning, Replanning} and NO_ROUTE then Unreachable }
property "replanning follows a blocked path" { always (state == Replanning -> PATH_BLOCKED) }
"#;
    let (content, props) = load(text);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let alphabet = situ_verify::abstraction::Alphabet::new(&content, &refs);
    assert!(alphabet.exact(), "{:?}", alphabet.samples);
    let r = &check(text, &options(12, property::DEFAULT_EFFORT, 16, 30))[0];
    assert!(matches!(r.conclusion, Conclusion::Proved { .. }), "{:?}", r.conclusion);
}
