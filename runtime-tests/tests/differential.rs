//! Differential test of the Rete interpreter against the naive evaluator of
//! `naive/mod.rs`: on the same event streams they must fire the same rules
//! in the same order and reach the same states, event after event; and of
//! the engine's fast path (`Engine::new`) against the interpreter
//! (`Engine::interpreted`, `twin/mod.rs`): same answers to every operation
//! (steps, refusals, cascade errors, recorded firings with their facts,
//! heartbeats, settling, forced facts and states, resets) and the same
//! working memory after each.
//!
//! - `rules/outdoor.situ` and `rules/ugv.situ` on the benchmark's seeded
//!   streams (missions reset on final states, as `situ bench` does);
//! - random event sequences (proptest, shrinking) on both files;
//! - random rule sets with every condition kind (guards, payload tests,
//!   ranges, run lengths, windows, staleness, negations, variables) on random
//!   event sequences, and (fast path only) on random operations;
//! - (fast path only) every `.situ` file of the repository that builds, on
//!   seeded streams: each must go the fast way.
//!
//! Shrunk counterexamples are kept in `differential.proptest-regressions`.

mod naive;
mod twin;

use naive::Naive;
use proptest::prelude::*;
use situ_compiler::bundle::{Content, Value};
use situ_compiler::Checked;
use situ_runtime::rete::{Engine, PostError};
use situ_runtime::stream::Generator;
use std::sync::Arc;
use twin::{ops, pool, posts, twins};

fn compile(checked: &Checked) -> Arc<Content> {
    let front: Vec<_> = checked.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front.is_empty(), "{front:?}");
    let content = situ_compiler::bundle::build(checked);
    situ_compiler::bundle::codec::validate(&content).expect("valid");
    Arc::new(content)
}

fn rules_file(name: &str) -> Checked {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules").join(name);
    situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("readable")
}

/// Runs both on `events`; `reset_on_final` resets both when a mission ends.
fn agree(
    checked: &Checked,
    content: &Arc<Content>,
    events: &[(u32, u64, Vec<Value>)],
    reset_on_final: bool,
) -> Result<(), String> {
    let mut engine = Engine::interpreted(content.clone());
    let mut naive = Naive::new(&checked.model);
    for (i, (event, time, payload)) in events.iter().enumerate() {
        // `None`: refused (out of order, §10.4).
        let got: Option<Result<Vec<usize>, Vec<usize>>> = match engine.post(*event, *time, payload) {
            Ok(None) => Some(Ok(vec![])),
            Ok(Some(change)) => Some(Ok(change.firings.iter().map(|f| f.rule as usize).collect())),
            Err(PostError::Cascade { firings, .. }) => Some(Err(firings.iter().map(|f| f.rule as usize).collect())),
            Err(PostError::OutOfOrder { .. }) => None,
            Err(other) => return Err(format!("event {i} refused: {other:?}")),
        };
        let want = naive.post(*event as usize, *time, payload);
        let name = |fired: &Result<Vec<usize>, Vec<usize>>| -> Result<Vec<String>, Vec<String>> {
            let names = |rules: &Vec<usize>| rules.iter().map(|&r| content.rules[r].name.clone()).collect();
            fired.as_ref().map(names).map_err(names)
        };
        if got.as_ref().map(name) != want.as_ref().map(name) || engine.state() != naive.state.0 {
            return Err(format!(
                "event {i} ({} at {time}): rete fired {:?} and is in {}, naive fired {:?} and is in {}",
                content.events[*event as usize].name,
                got.as_ref().map(name),
                content.states[engine.state() as usize].name,
                want.as_ref().map(name),
                content.states[naive.state.index()].name,
            ));
        }
        if matches!(got, Some(Err(_))) {
            return Ok(()); // a cascade error ends the run, for both
        }
        if reset_on_final && content.states[engine.state() as usize].is_final {
            engine.reset();
            naive.reset();
        }
    }
    Ok(())
}

#[test]
fn the_papers_stacks_on_seeded_streams() {
    for file in ["outdoor.situ", "ugv.situ"] {
        let checked = rules_file(file);
        let content = compile(&checked);
        let mut fired = 0;
        for seed in 0..12u64 {
            let mut g = Generator::new(content.clone(), seed);
            let events: Vec<(u32, u64, Vec<Value>)> =
                (0..4000).filter_map(|_| g.next_event()).map(|e| (e.event, e.time, e.payload)).collect();
            agree(&checked, &content, &events, true).unwrap_or_else(|e| panic!("{file}, seed {seed}: {e}"));
            twins(&content, &posts(&events, true)).unwrap_or_else(|e| panic!("{file}, seed {seed}, fast path: {e}"));
            let mut engine = Engine::new(content.clone());
            assert!(engine.is_fast(), "{file}: {:?}", engine.fast_declined());
            for (ev, t, p) in &events {
                if let Ok(Some(c)) = engine.post(*ev, *t, p) {
                    fired += c.firings.len();
                }
                if content.states[engine.state() as usize].is_final {
                    engine.reset();
                }
            }
        }
        assert!(fired > 100, "{file}: the streams fired only {fired} rules: they test little");
    }
}

// ─── Random events over a given bundle ─────────────────────────────────────

/// Values for a field: NaN, the rules' thresholds and their neighbours.
/// Millisecond gaps that cross the stale times (200 to 1000 ms) and the
/// windows (500 ms) of the files, and land on them exactly.
const GAPS_MS: [u64; 8] = [0, 1, 10, 10, 50, 100, 250, 600];
/// The same for the random rule sets: windows of 30 ms, `stale after 50ms`;
/// a negative gap is an event that arrives late (its time is before now).
const GEN_GAPS_MS: [i64; 9] = [0, 1, 10, 20, 30, 31, 50, 51, -30];

fn events(content: Arc<Content>, max: usize) -> impl Strategy<Value = Vec<(u32, u64, Vec<Value>)>> {
    let n_events = content.events.len();
    prop::collection::vec((0..n_events, 0..GAPS_MS.len(), prop::collection::vec(any::<u16>(), 4)), 1..max).prop_map(
        move |raw| {
            let mut t = 0;
            raw.into_iter()
                .map(|(e, gap, seeds)| {
                    t += GAPS_MS[gap] * 1_000_000;
                    let payload = (0..content.events[e].fields.len())
                        .map(|f| {
                            let p = pool(&content, e, f);
                            p[seeds[f % seeds.len()] as usize % p.len()]
                        })
                        .collect();
                    (e as u32, t, payload)
                })
                .collect()
        },
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn outdoor_on_random_events(evs in events(compile(&rules_file("outdoor.situ")), 120)) {
        let checked = rules_file("outdoor.situ");
        let content = compile(&checked);
        prop_assert_eq!(agree(&checked, &content, &evs, false), Ok(()));
        prop_assert!(twins(&content, &posts(&evs, false)).is_ok(), "{:?}", twins(&content, &posts(&evs, false)));
    }

    #[test]
    fn ugv_on_random_events(evs in events(compile(&rules_file("ugv.situ")), 120)) {
        let checked = rules_file("ugv.situ");
        let content = compile(&checked);
        prop_assert_eq!(agree(&checked, &content, &evs, false), Ok(()));
        prop_assert!(twins(&content, &posts(&evs, false)).is_ok(), "{:?}", twins(&content, &posts(&evs, false)));
    }
}

// ─── Random rule sets ──────────────────────────────────────────────────────

const STACK: &str = "states { IT initial S1 S2 S3 S4 final }
agent A sensor { stale after 50ms event AX { d: f64, k: i64 } event AY }
agent B sensor { event BX { d: f64, s: {l, r} } event BY }
agent C processing { event CX { b: bool } event CY }
";
const STATES: [&str; 5] = ["IT", "S1", "S2", "S3", "S4"];

#[derive(Debug, Clone)]
enum Cond {
    Guard(Vec<usize>),
    NotGuard(Vec<usize>),
    /// event (0..6), constraint (0..8), run length, window
    Pattern {
        event: usize,
        test: usize,
        run: u64,
        within: bool,
    },
    Not {
        event: usize,
        test: usize,
        within: bool,
    },
    Stale(bool),
}

fn pattern_text(event: usize, test: usize, run: u64, within: bool, bound: bool) -> String {
    let names = ["AX", "AY", "BX", "BY", "CX", "CY"];
    let mut s = names[event].to_string();
    let tests = match event {
        0 => ["d < 10.0", "d >= 10.0", "d in 5.0..=20.0", "k != 3", "d: ?v", "d <= ?v", "k > 2", ""],
        2 => ["d < 10.0", "d > 10.0", "s == l", "s != r", "d: ?v", "d >= ?v", "d in 0.0..10.0", ""],
        4 => ["b == true", "b != true", "", "", "", "", "", ""],
        _ => [""; 8],
    };
    let mut t = tests[test].to_string();
    // A variable is compared only where it is bound (the rule's first pattern binds it).
    if t.contains("?v") && !bound && !t.contains(": ?v") {
        t.clear();
    }
    if !t.is_empty() {
        s.push_str(&format!("({t})"));
    }
    if run > 1 {
        s.push_str(&format!(" x{run}"));
    }
    if within {
        s.push_str(" within 30ms");
    }
    s
}

fn cond() -> impl Strategy<Value = Cond> {
    prop_oneof![
        prop::collection::vec(0..5usize, 1..3).prop_map(Cond::Guard),
        prop::collection::vec(0..5usize, 1..2).prop_map(Cond::NotGuard),
        (0..6usize, prop::sample::select(vec![0, 1, 2, 3, 4, 4, 4, 5, 5, 5, 6, 7]), 1..3u64, prop::bool::weighted(0.3))
            .prop_map(|(event, test, run, within)| Cond::Pattern { event, test, run, within }),
        (0..6usize, 0..8usize, prop::bool::weighted(0.2)).prop_map(|(event, test, within)| Cond::Not {
            event,
            test,
            within
        }),
        any::<bool>().prop_map(Cond::Stale),
    ]
}

fn rule_text(i: usize, conds: &[Cond], salience: i64, target: usize) -> String {
    // `?v` is bound by the first AX or BX pattern that binds it, if any.
    let binder = conds.iter().position(|c| matches!(c, Cond::Pattern { event: 0 | 2, test: 4, .. }));
    let mut parts = Vec::new();
    for (k, c) in conds.iter().enumerate() {
        let bound = binder.is_some_and(|b| b != k);
        parts.push(match c {
            Cond::Guard(s) => format!("state in {{{}}}", s.iter().map(|&x| STATES[x]).collect::<Vec<_>>().join(", ")),
            Cond::NotGuard(s) => format!("state != {}", STATES[s[0]]),
            Cond::Pattern { event, test, run, within } => {
                let test = if *test == 4 && binder != Some(k) { 7 } else { *test };
                pattern_text(*event, test, *run, *within, bound || binder == Some(k))
            }
            Cond::Not { event, test, within } => {
                let test = if *test == 4 { 7 } else { *test };
                format!("not {}", pattern_text(*event, test, 1, *within, binder.is_some()))
            }
            Cond::Stale(neg) => format!("{}stale A", if *neg { "not " } else { "" }),
        });
    }
    format!("rule r{i} salience {salience} {{ when {} then {} }}\n", parts.join(" and "), STATES[target])
}

fn rule_set() -> impl Strategy<Value = String> {
    prop::collection::vec((prop::collection::vec(cond(), 1..4), 0..2i64, 0..5usize), 1..7).prop_map(|rules| {
        let mut s = STACK.to_string();
        for (i, (conds, salience, target)) in rules.iter().enumerate() {
            s.push_str(&rule_text(i, conds, *salience, *target));
        }
        s
    })
}

fn raw_events() -> impl Strategy<Value = Vec<(usize, usize, u16, u16)>> {
    prop::collection::vec((0..6usize, 0..GEN_GAPS_MS.len(), any::<u16>(), any::<u16>()), 1..40)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1024, ..ProptestConfig::default() })]

    #[test]
    fn random_rule_sets_on_random_events(src in rule_set(), raw in raw_events()) {
        let checked = situ_compiler::check_source("gen.situ", &src);
        let front: Vec<_> = checked.diagnostics.iter().filter(|d| d.code < "E0300").collect();
        // The generator writes valid rules; a front-end error is a bug of the test.
        prop_assert!(front.is_empty(), "{}\n{:?}", src, front);
        let content = compile(&checked);
        let mut t = 0;
        let evs: Vec<(u32, u64, Vec<Value>)> = raw
            .into_iter()
            .map(|(e, gap, a, b)| {
                t = (t as i64 + GEN_GAPS_MS[gap] * 1_000_000).max(0) as u64;
                let payload = (0..content.events[e].fields.len())
                    .map(|f| {
                        let p = pool(&content, e, f);
                        p[[a, b][f % 2] as usize % p.len()]
                    })
                    .collect();
                (e as u32, t, payload)
            })
            .collect();
        prop_assert_eq!(agree(&checked, &content, &evs, false), Ok(()), "{}", src);
        let fast = twins(&content, &posts(&evs, false));
        prop_assert!(fast.is_ok(), "{}\n{:?}", src, fast);
    }
}

// ─── The fast path against the interpreter ─────────────────────────────────

/// The time steps of the random operations (ms): as `GEN_GAPS_MS`, and the
/// files' stale times and windows.
const OP_GAPS_MS: [i64; 12] = [0, 1, 10, 20, 30, 31, 50, 51, -30, 250, 501, 1001];

fn rule_set_and_ops() -> impl Strategy<Value = (String, Arc<Content>, Vec<twin::Op>)> {
    rule_set().prop_flat_map(|src| {
        let content = compile(&situ_compiler::check_source("gen.situ", &src));
        (Just(src), Just(content.clone()), ops(content, &OP_GAPS_MS, pool, 60))
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    /// Every entry point of the engine, on random rule sets: the fast path
    /// answers as the interpreter.
    #[test]
    fn fast_path_on_random_rule_sets_and_operations((src, content, ops) in rule_set_and_ops()) {
        let result = twins(&content, &ops);
        prop_assert!(result.is_ok(), "{}\n{:?}", src, result);
    }

    #[test]
    fn fast_path_on_outdoor_operations(ops in ops(compile(&rules_file("outdoor.situ")), &OP_GAPS_MS, pool, 150)) {
        let content = compile(&rules_file("outdoor.situ"));
        let result = twins(&content, &ops);
        prop_assert!(result.is_ok(), "{:?}", result);
    }
}

/// The `.situ` files under `dir`, recursively (no build output).
fn situ_files(dir: &std::path::Path, out: &mut Vec<std::path::PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if !matches!(path.file_name().and_then(|n| n.to_str()), Some("target" | ".git" | "node_modules")) {
                situ_files(&path, out);
            }
        } else if path.extension().is_some_and(|e| e == "situ") {
            out.push(path);
        }
    }
}

/// Every rules file of the repository that builds (no front-end error)
/// goes the fast way, and the fast path agrees with the interpreter on
/// seeded streams over it (the benchmark's generator, missions reset on
/// final states).
#[test]
fn every_rules_file_of_the_repository_on_the_fast_path() {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut files = Vec::new();
    for dir in ["rules", "examples", "tests", "api", "compiler", "lsp", "editors", "grammar"] {
        situ_files(&root.join(dir), &mut files);
    }
    files.sort();
    let (mut built, mut fired) = (0, 0);
    for path in &files {
        let Ok(checked) = situ_compiler::check(path, &situ_compiler::loader::FsLoader) else { continue };
        if checked.diagnostics.iter().any(|d| d.code < "E0300") || checked.model.initial.is_none() {
            continue;
        }
        let content = Arc::new(situ_compiler::bundle::build(&checked));
        if situ_compiler::bundle::codec::validate(&content).is_err() {
            continue;
        }
        built += 1;
        for seed in 0..2u64 {
            let mut g = Generator::new(content.clone(), seed);
            let events: Vec<(u32, u64, Vec<Value>)> =
                (0..1500).filter_map(|_| g.next_event()).map(|e| (e.event, e.time, e.payload)).collect();
            fired += twins(&content, &posts(&events, true))
                .unwrap_or_else(|e| panic!("{}, seed {seed}: {e}", path.display()));
        }
    }
    assert!(built >= 100, "only {built} of {} files built: the walk tests little", files.len());
    assert!(fired > 1000, "the streams fired only {fired} rules");
}
