//! The tests of `situ_runtime::script::explore` that compile a situ source (moved
//! here so that the runtime does not depend on the compiler).

use situ_bundle::Content;
use situ_runtime::script::explore::*;
use situ_runtime::script::{Driver, ScriptRun};
use std::sync::Arc;

const MOWER: &str = include_str!("../../examples/mower/mower.situ");
const DRONE: &str = include_str!("../../tests/explore/inspection-drone.situ");

fn content(name: &str, src: &str) -> Arc<Content> {
    let checked = situ_compiler::check_source(name, src);
    let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.severity == situ_compiler::Severity::Error).collect();
    assert!(errors.is_empty(), "{errors:?}");
    Arc::new(situ_compiler::bundle::build(&checked))
}

/// The coverage and summary of a `--random` run of `seconds`.
fn explore(c: &Arc<Content>, seed: u64, seconds: u64) -> (Coverage, String) {
    let mut run = ScriptRun::new(c.clone(), Driver::Random { seed }, Some(seconds * 1_000_000_000), None);
    run.run(&mut |_| {});
    let report = run.finish().unwrap();
    let summary = format!("{}\n{}", report.runtime.table(), report.to_json());
    (report.exploration.expect("a random run reports what it explored"), summary)
}

fn share(c: &Coverage) -> f64 {
    c.visited.len() as f64 / c.reachable.len() as f64
}

#[test]
fn the_map_reaches_what_the_rules_lead_to_and_a_final_state_leads_back() {
    // D is unreachable: an error for `situ check`, built all the same.
    let checked = situ_compiler::check_source(
        "t.situ",
        "states { A initial B C final D }\n\
         agent S sensor { event GO event STOP event BACK }\n\
         rule go { when state == A and GO then B }\n\
         rule stop { when state == B and STOP then C }\n\
         rule back { when state == D and BACK then A }\n",
    );
    let c = situ_compiler::bundle::build(&checked);
    let map = Map::new(&c);
    let names: Vec<&str> = (0..4).filter(|&s| map.reachable[s]).map(|s| c.states[s].name.as_str()).collect();
    assert_eq!(names, ["A", "B", "C"], "D has no way in");
    let c_id = c.state_id("C").unwrap() as usize;
    assert_eq!(map.edges[c_id], [c.initial], "a final state leads to the next episode");
    // Two steps from A to the final state, one from B.
    let mut target = vec![false; 4];
    target[c_id] = true;
    let d = map.distances(&target);
    assert_eq!((d[c.initial as usize], d[c.state_id("B").unwrap() as usize]), (2, 1));
}

#[test]
fn a_run_goes_on_after_a_final_state_with_a_new_episode() {
    // The first episode ends at the first GO.
    let c = content(
        "t.situ",
        "states { A initial B final }\nagent S sensor { event GO }\nrule go { when state == A and GO then B }\n",
    );
    let (cov, summary) = explore(&c, 3, 10);
    assert!(cov.episodes > 10, "{cov:?}");
    assert_eq!(cov.visited, ["A", "B"]);
    assert!(summary.contains("\"episodes\""), "{summary}");
}

#[test]
fn the_mower_is_explored_in_five_minutes() {
    let c = content("mower.situ", MOWER);
    for seed in [1, 2] {
        let (cov, _) = explore(&c, seed, 300);
        assert!(share(&cov) >= 0.8, "seed {seed}: {}", cov.line());
        assert!(cov.episodes > 1, "seed {seed}: {}", cov.line());
    }
}

#[test]
fn the_inspection_drone_is_explored_in_five_minutes() {
    let c = content("inspection-drone.situ", DRONE);
    assert_eq!(Map::new(&c).reachable.iter().filter(|&&r| r).count(), 10);
    for seed in [1, 2] {
        let (cov, _) = explore(&c, seed, 300);
        assert!(share(&cov) >= 0.8, "seed {seed}: {}", cov.line());
        assert!(cov.episodes > 1, "seed {seed}: {}", cov.line());
    }
}

#[test]
fn a_recording_of_many_episodes_replays_the_same() {
    let c = content("inspection-drone.situ", DRONE);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.mcap");
    let bytes = situ_bundle::encode(&c, situ_bundle::Encoding::Json);
    let rec = situ_runtime::record::mcap::McapRecorder::create(&path, c.clone(), &bytes).unwrap();
    let mut run = ScriptRun::new(c.clone(), Driver::Random { seed: 1 }, Some(3_000_000_000), Some(Box::new(rec)));
    run.run(&mut |_| {});
    let report = run.finish().unwrap();
    assert!(report.exploration.unwrap().episodes > 2);
    let replayed = situ_runtime::replay::replay(&std::fs::read(&path).unwrap(), c).unwrap();
    assert!(replayed.same(), "{}", replayed.describe());
}

#[test]
fn one_seed_gives_one_run() {
    let c = content("inspection-drone.situ", DRONE);
    let (a, sa) = explore(&c, 7, 30);
    let (b, sb) = explore(&c, 7, 30);
    assert_eq!((&a, &sa), (&b, &sb));
    let (_, other) = explore(&c, 8, 30);
    assert_ne!(sb, other, "another seed, another run");
}
