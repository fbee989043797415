//! Search that reaches depth: the exploration's bound made deeper by
//! bounded model checking of the circuit (`situ_verify::bmc`).
//!
//! - On the two drones of `tests/explore/`, with `situ test`'s default
//!   budgets, every property is searched to at least 8 events (or broken),
//!   where the exploration alone stops after 2.
//! - The bounded search is honest: on programs the exploration covers whole
//!   up to K events, both find a counterexample of the same length, or
//!   both none up to K (exactly so without durations, where the
//!   exploration's gaps are every gap; with durations the circuit's gaps
//!   are any, so it finds every run the exploration does, no later), on the
//!   planted bugs of `tests/verify/` and on random small rule sets.
//! - A counterexample found deeper than the exploration replays on the
//!   engine and is shrunk.

use proptest::prelude::*;
use situ_compiler::loader::FsLoader;
use situ_compiler::spec::{self, PropertySpec};
use situ_compiler::{bundle, check_source};
use situ_verify::abstraction::Alphabet;
use situ_verify::bmc::{self, Outcome};
use situ_verify::explore::{Graph, Limits};
use situ_verify::ic3;
use situ_verify::model::Model;
use situ_verify::monitor::Monitor;
use situ_verify::property::{self, Checker, Conclusion, Engines, Options};
use situ_verify::random::{self, Search};
use situ_verify::{RunStep, Verdict};
use std::cell::Cell;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn load_file(path: &Path) -> (Arc<bundle::Content>, Vec<PropertySpec>) {
    let checked = situ_compiler::check(path, &FsLoader).expect("a file");
    assert_eq!(checked.errors(), 0, "{path:?}: {:?}", checked.diagnostics);
    (Arc::new(bundle::build(&checked)), spec::lower(&checked).properties)
}

fn load(text: &str) -> Option<(Arc<bundle::Content>, Vec<PropertySpec>)> {
    let checked = check_source("t.situ", text);
    (checked.errors() == 0).then(|| (Arc::new(bundle::build(&checked)), spec::lower(&checked).properties))
}

/// `situ test`'s default budgets (without the random search, which does
/// not change the exhaustive verdict): the exhaustive verdict of each
/// property as `situ test` reports it.
fn exhaustive_verdicts(path: &Path) -> Vec<(String, Verdict)> {
    let (content, props) = load_file(path);
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let opts = Options { engines: Engines::Exhaustive, ..property::DEFAULT_OPTIONS };
    let (_, reports) = property::check_all(&content, &refs, &opts);
    refs.iter().zip(reports).map(|(p, r)| (p.name.clone(), r.exhaustive.expect("explored"))).collect()
}

#[test]
fn the_drones_are_searched_to_at_least_eight_events() {
    for file in ["tests/explore/inspection-drone.situ", "tests/explore/survey-drone.situ"] {
        let verdicts = exhaustive_verdicts(&root().join(file));
        assert!(verdicts.len() >= 5, "{file}: {} properties", verdicts.len());
        for (name, v) in &verdicts {
            match v {
                Verdict::Bounded { depth, .. } => assert!(*depth >= 8, "{file}, {name}: {}", v.summary()),
                Verdict::Failed(c) => {
                    let run: Vec<RunStep> = steps(c);
                    let (content, props) = load_file(&root().join(file));
                    let p = props.iter().find(|p| &p.name == name).expect("the property");
                    assert!(random::check_run(&content, p, &run, &Cell::new(0)).is_err(), "{file}, {name}: {c:?}");
                }
                Verdict::Proved { .. } | Verdict::Exhausted { .. } => {}
                other => panic!("{file}, {name}: {other:?}"),
            }
        }
    }
}

/// A counterexample's run, gaps from its times.
fn steps(c: &situ_verify::Counterexample) -> Vec<RunStep> {
    let mut prev = 0;
    c.steps
        .iter()
        .map(|s| {
            let gap = s.time - prev;
            prev = s.time;
            RunStep { event: s.event, payload: s.payload.clone(), gap }
        })
        .collect()
}

/// The exploration, complete to `k` events, and the bounded search to `k`
/// agree on every safety property; returns how many were compared. With
/// `exact_time` (no durations) the lengths are equal; otherwise the
/// circuit's run is no longer than the exploration's.
fn cross_check(content: &Arc<bundle::Content>, props: &[PropertySpec], k: usize) -> usize {
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let graph = Graph::build(content, &refs, Limits { depth: k, max_states: 200_000 });
    assert!(graph.complete_depth >= k || graph.closed, "the exploration covers {k} events");
    let alphabet = Alphabet::new(content, &refs);
    let Ok(model) = Model::build(content, &alphabet, &refs) else { return 0 };
    let untimed = alphabet.gaps.len() == 1;
    let mut compared = 0;
    for (i, p) in refs.iter().enumerate() {
        let Some(bad) = model.bad[i] else { continue };
        if Monitor::new(p).is_liveness() && !p.never {
            continue;
        }
        let explored = graph.check(i, p);
        let searched = bmc::search(&model.aig, bad, ic3::Limits::frames(k));
        match (&explored, &searched) {
            (Verdict::Failed(c), Outcome::Counterexample(run)) => {
                if untimed {
                    assert_eq!(run.len(), c.steps.len(), "{}: {c:?}", p.name);
                } else {
                    assert!(run.len() <= c.steps.len(), "{}: {run:?} / {c:?}", p.name);
                }
                let run = model.run_of(&alphabet, run);
                assert!(random::check_run(content, p, &run, &Cell::new(0)).is_err(), "{}: {run:?}", p.name);
            }
            // A closed exploration may break it beyond `k` events (a shortest
            // run longer than the search's bound): the circuit, searched to
            // that length, must break it too.
            (Verdict::Failed(c), Outcome::Clear { depth, .. }) if c.steps.len() > *depth => {
                match bmc::search(&model.aig, bad, ic3::Limits::frames(c.steps.len())) {
                    Outcome::Counterexample(run) => {
                        assert!(run.len() > *depth && run.len() <= c.steps.len(), "{}: {run:?} / {c:?}", p.name);
                        if untimed {
                            assert_eq!(run.len(), c.steps.len(), "{}: {c:?}", p.name);
                        }
                        let run = model.run_of(&alphabet, &run);
                        assert!(random::check_run(content, p, &run, &Cell::new(0)).is_err(), "{}: {run:?}", p.name);
                    }
                    other => panic!(
                        "{}: the exploration breaks it in {} events, the circuit searched that deep not: {other:?}",
                        p.name,
                        c.steps.len()
                    ),
                }
            }
            (Verdict::Failed(c), Outcome::Clear { .. }) => {
                panic!("{}: the exploration breaks it in {} events, the circuit not", p.name, c.steps.len())
            }
            (_, Outcome::Clear { depth, .. }) => assert_eq!(*depth, k, "{}", p.name),
            (_, Outcome::Counterexample(run)) => {
                assert!(!untimed, "{}: the circuit breaks it in {} events, the exploration not", p.name, run.len());
                let run = model.run_of(&alphabet, run);
                assert!(random::check_run(content, p, &run, &Cell::new(0)).is_err(), "{}: {run:?}", p.name);
            }
        }
        compared += 1;
    }
    compared
}

#[test]
fn the_bounded_search_agrees_with_the_exploration_on_the_planted_bugs() {
    let mut compared = 0;
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("tests/verify"))
        .expect("tests/verify")
        .map(|e| e.expect("an entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "situ"))
        .collect();
    files.sort();
    files.push(root().join("examples/mower/mower.situ"));
    for path in files {
        let (content, props) = load_file(&path);
        compared += cross_check(&content, &props, 4);
    }
    assert!(compared >= 10, "only {compared} properties compared");
}

/// A small random rule base: `n` states, agents of one or two events (some
/// with a number), rules of distinct saliences, an optional duration, and
/// properties of every safety shape.
fn program(
    n: usize,
    events: &[(usize, bool)],
    rules: &[(usize, usize, usize, u8, usize)],
    timed: bool,
    props: &[(u8, usize, usize)],
) -> String {
    let mut s = String::from("states { S0 initial");
    for i in 1..n {
        s.push_str(&format!(" S{i}"));
    }
    s.push_str(" }\n");
    let agents = events.iter().map(|e| e.0).max().unwrap_or(0) + 1;
    for a in 0..agents {
        s.push_str(&format!("agent A{a} sensor {{"));
        if timed && a == 0 {
            s.push_str(" stale after 100ms");
        }
        for (e, &(owner, field)) in events.iter().enumerate() {
            if owner == a {
                s.push_str(&format!(" event E{e}{}", if field { " { x: f64 }" } else { "" }));
            }
        }
        s.push_str(" }\n");
    }
    for (r, &(from, ev, to, test, run)) in rules.iter().enumerate() {
        let (from, ev, to) = (from % n, ev % events.len(), to % n);
        let pattern = match (events[ev].1, test % 3) {
            (true, 0) => format!("E{ev}(x < 5.0)"),
            (true, 1) => format!("E{ev}(x >= 2.0)"),
            _ => format!("E{ev}"),
        };
        let run = if run > 1 { format!(" x{run}") } else { String::new() };
        s.push_str(&format!("rule r{r} salience {r} {{ when state == S{from} and {pattern}{run} then S{to} }}\n"));
    }
    if timed {
        s.push_str(&format!("rule quiet salience {} {{ when state == S1 and stale A0 then S0 }}\n", rules.len()));
    }
    for (k, &(shape, a, b)) in props.iter().enumerate() {
        let (a, b) = (a % n, b % n);
        let body = match shape % 4 {
            0 => format!("never state == S{a}"),
            1 => format!("always (state == S{a} -> next state in {{S{a}, S{b}}})"),
            2 => format!("always (state == S{a} -> eventually state == S{b} within 2 events)"),
            _ => format!("always (E{} -> state != S{a})", b % events.len()),
        };
        s.push_str(&format!("property \"p{k}\" {{ {body} }}\n"));
    }
    s
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn the_bounded_search_agrees_with_the_exploration_on_random_rule_sets(
        n in 2usize..5,
        events in prop::collection::vec((0usize..3, any::<bool>()), 1..5),
        rules in prop::collection::vec((0usize..5, 0usize..5, 0usize..5, 0u8..3, 1usize..3), 1..7),
        timed in any::<bool>(),
        props in prop::collection::vec((0u8..4, 0usize..5, 0usize..5), 1..4),
    ) {
        // Agents are numbered densely: an agent without events is none.
        let mut events = events;
        let mut owners: Vec<usize> = events.iter().map(|e| e.0).collect();
        owners.sort_unstable();
        owners.dedup();
        for e in &mut events {
            e.0 = owners.iter().position(|&o| o == e.0).unwrap_or(0);
        }
        let text = program(n, &events, &rules, timed, &props);
        if let Some((content, props)) = load(&text) {
            cross_check(&content, &props, 4);
        }
    }
}

/// Found by the random rule sets in CI: the exploration of this program is
/// closed, and its shortest run breaking the property is 5 events long,
/// beyond the search's 4; the circuit searched 5 deep breaks it the same.
#[test]
fn a_shortest_run_beyond_the_bound_is_found_when_searched_that_deep() {
    let events = [(0, false), (0, false), (0, false)];
    let text = program(3, &events, &[(1, 2, 2, 0, 2), (0, 3, 1, 0, 1)], false, &[(2, 2, 0)]);
    let (content, props) = load(&text).expect("the program checks");
    assert_eq!(cross_check(&content, &props, 4), 1);
}

/// Twelve steps, each on its own event, among noise: "never S12" is broken
/// by a run of 12 events, beyond the exploration at `--depth 12` with a
/// small state budget.
fn ladder(noise: usize) -> String {
    let mut s = String::from("states { S0 initial");
    for i in 1..=12 {
        s.push_str(&format!(" S{i}"));
    }
    s.push_str(" }\nagent Up sensor {");
    for i in 1..=12 {
        s.push_str(&format!(" event U{i}"));
    }
    s.push_str(" }\n");
    for k in 0..noise {
        s.push_str(&format!("agent N{k} sensor {{ event HUM{k} {{ level: f64 }} }}\n"));
        s.push_str(&format!("rule loud{k} salience 1 {{ when state == S12 and HUM{k}(level > 3.0) then S0 }}\n"));
    }
    for i in 1..=12 {
        s.push_str(&format!("rule r{i} {{ when state == S{} and U{i} then S{i} }}\n", i - 1));
    }
    s.push_str("property \"the top is never reached\" { never state == S12 }\n");
    s
}

#[test]
fn a_counterexample_deeper_than_the_exploration_replays_and_is_shrunk() {
    let (content, props) = load(&ladder(3)).expect("the ladder");
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let opts = Options {
        engines: Engines::Exhaustive,
        search: Search { seed: 1, cases: 1, length: 3 },
        limits: Limits { depth: 12, max_states: 2_000 },
        effort: property::DEFAULT_EFFORT,
        timeout: None,
    };
    let (session, reports) = property::check_all(&content, &refs, &opts);
    assert!(session.graph.as_ref().is_some_and(|g| g.complete_depth < 12), "the exploration alone stops short");
    match &reports[0].conclusion {
        Conclusion::Violated { by: Checker::Exhaustive, counterexample: c, .. } => {
            assert_eq!(c.steps.len(), 12, "{c:?}");
            assert_eq!(c.point, 12);
            assert!(c.steps.iter().all(|s| s.time % 1_000_000 == 0), "round times: {c:?}");
            let run = steps(c);
            for i in 0..run.len() {
                let mut shorter = run.clone();
                shorter.remove(i);
                let ok = random::check_run(&content, &props[0], &shorter, &Cell::new(0)).is_ok();
                assert!(ok, "event {i} is not needed");
            }
        }
        other => panic!("{other:?}"),
    }
    assert!(reports[0].symbolic.is_none(), "IC3 is not needed once the search broke it");
}

/// Ten agents of two events each, every one read by a rule: the exploration
/// alone runs out of states after 2 or 3 events.
fn wide() -> String {
    let mut s = String::from("states { Idle initial Busy Rest final Done final }\n");
    for k in 0..10 {
        s.push_str(&format!("agent A{k} sensor {{ event P{k} {{ v: f64 }} event Q{k} }}\n"));
        s.push_str(&format!("rule up{k} salience {} {{ when state == Idle and P{k}(v > 1.0) then Busy }}\n", 2 * k));
        s.push_str(&format!("rule down{k} salience {} {{ when state == Busy and Q{k} then Rest }}\n", 2 * k + 1));
    }
    s.push_str("rule end salience 30 { when state == Busy and P0(v > 1.0) and Q9 and P5(v > 1.0) then Done }\n");
    s.push_str(
        "property \"busy ends at rest or done\" { always (state == Busy -> next state in {Busy, Rest, Done}) }\n",
    );
    s.push_str("property \"done stays done\" { always (state == Done -> next state == Done) }\n");
    s
}

#[test]
fn a_wide_file_is_reported_to_the_depth_asked_for() {
    let (content, props) = load(&wide()).expect("the wide file");
    let refs: Vec<&PropertySpec> = props.iter().collect();
    let opts = Options { engines: Engines::Exhaustive, ..property::DEFAULT_OPTIONS };
    let (session, reports) = property::check_all(&content, &refs, &opts);
    let explored = session.graph.as_ref().map_or(0, |g| g.complete_depth);
    assert!(explored < 8, "the exploration alone reaches {explored} events");
    for r in &reports {
        match &r.exhaustive {
            Some(Verdict::Bounded { depth, note, .. }) => {
                assert_eq!(*depth, opts.limits.depth, "{note}");
                assert!(note.contains("with any gaps"), "{note}");
            }
            other => panic!("{other:?}"),
        }
        // Deeper is still not a proof: IC3 proves these, and says so.
        assert!(matches!(r.conclusion, Conclusion::Proved { by: Checker::Symbolic, .. }), "{:?}", r.conclusion);
    }
}
