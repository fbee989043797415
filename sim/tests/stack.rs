//! The reference stacks on the real rules (`rules/outdoor.situ`,
//! `rules/ugv.situ`), through the runtime: the papers' results, asserted
//! on what the runtime recorded, and determinism.

use situ_compiler::bundle::{Content, Mode};
use situ_compiler::loader::FsLoader;
use situ_runtime::record::{Fate, Memory, SharedMemory};
use situ_sim::scenario;
use situ_sim::stack::{self, Outcome, Recording, Registry, RunReport, StackConfig, StackRun};
use situ_sim::ugv::Strategy;
use std::path::Path;
use std::sync::{Arc, OnceLock};

fn rules(name: &str) -> Arc<Content> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules").join(name);
    let checked = situ_compiler::check(&path, &FsLoader).expect("the rules file reads");
    assert!(!checked.fails(false), "{name} checks clean");
    Arc::new(situ_compiler::bundle::build(&checked))
}

fn run(rules_file: &str, seed: u64, memory: Option<SharedMemory>) -> RunReport {
    let content = rules(rules_file);
    let kind = Registry::sim().of(&content).expect("a reference stack");
    let world = scenario::builtin(kind.default_scenario()).expect("built in").world;
    let cfg = StackConfig { seed, until: kind.default_until(), ..StackConfig::default() };
    let recording = Recording { mcap: None, sinks: memory.into_iter().map(|m| Box::new(m) as _).collect() };
    let mut run = StackRun::new(content, kind, &world, cfg, recording).expect("every agent bound");
    run.run(&mut |_| {});
    run.finish().expect("finished")
}

/// The default mission once, with everything the runtime recorded.
fn outdoor() -> &'static (RunReport, Memory, Arc<Content>) {
    static RUN: OnceLock<(RunReport, Memory, Arc<Content>)> = OnceLock::new();
    RUN.get_or_init(|| {
        let memory = SharedMemory::default();
        let report = run("outdoor.situ", 1, Some(memory.clone()));
        (report, memory.snapshot(), rules("outdoor.situ"))
    })
}

#[test]
fn every_event_the_agents_report_is_one_of_the_rules_file() {
    let c = rules("outdoor.situ");
    for e in stack::outdoor::sample_events() {
        assert!(situ_sim::agent::payload(&c, e.as_ref()).is_some(), "{} maps onto outdoor.situ", e.name());
    }
    let name = |c: &situ_compiler::bundle::Content| Registry::sim().of(c).map(|s| s.name());
    assert_eq!(name(&c), Ok("outdoor"));
    assert_eq!(name(&rules("ugv.situ")), Ok("ugv"));
    assert_eq!(name(&rules("ugv-merge.situ")), Ok("ugv_merge"));
}

#[test]
fn zhang_zhu_the_default_mission_on_the_real_rules_reaches_the_goal_through_every_state() {
    let (report, _, _) = outdoor();
    println!("{}\n{}", report.runtime.table(), report.table());
    assert!(matches!(report.outcome, Outcome::GoalReached { .. }), "{:?}", report.outcome);
    let s = &report.metrics.summary;
    assert!(s.collisions.is_empty(), "{:?}", s.collisions);
    assert!(s.closest_distance.is_some_and(|d| d > 0.5), "kept clear: {:?}", s.closest_distance);
    // Every state of outdoor.situ the mission is meant to visit (not EM, SP).
    for st in ["IT", "RD", "RS", "RT", "RB", "RO", "CN", "CO", "GL"] {
        assert!(report.runtime.path.iter().any(|p| p == st), "{st} visited: {:?}", report.runtime.path);
    }
    assert!(!report.runtime.path.iter().any(|p| p == "EM" || p == "SP"));
    // Faster in the simple states than with an obstacle.
    let mean = |st: &str| report.per_state[st].mean_speed;
    assert!(mean("RS") > mean("RO") + 2.0, "RS {:.2} vs RO {:.2} m/s", mean("RS"), mean("RO"));
    assert!(mean("CN") > mean("CO") + 1.0, "CN {:.2} vs CO {:.2} m/s", mean("CN"), mean("CO"));
    assert!(mean("RS") > mean("CN"));
}

#[test]
fn zhang_zhu_fig_5_fusion_sleeps_on_the_straight_road_and_wakes_at_the_obstacle() {
    let (_, rec, c) = outdoor();
    let id = |n: &str| c.agent_id(n).unwrap();
    let (rfccd, ladar, fusion, lpl) = (id("RFCCD"), id("LADAR"), id("Fusion"), id("LPL"));
    let ro = c.state_id("RO").unwrap();
    let rs = c.state_id("RS").unwrap();
    // The obstacle: RS -> RO, and back.
    let into = rec.changes.iter().find(|ch| ch.changed() && ch.to == ro).expect("RS -> RO");
    let back = rec.changes.iter().find(|ch| ch.changed() && ch.from == ro).expect("RO -> RS");
    assert_eq!((into.from, back.to), (rs, rs));
    let (t_ro, t_rs) = (into.time, back.time);
    // Fusion's modes, as recorded: asleep from the start, awake exactly in RO.
    let modes: Vec<(u64, Mode)> = rec.modes.iter().filter(|m| m.agent == fusion).map(|m| (m.time, m.mode)).collect();
    assert_eq!(modes[0], (0, Mode::Sleeping));
    assert!(modes.contains(&(t_ro, Mode::Running)), "{modes:?}");
    assert!(modes.contains(&(t_rs, Mode::Sleeping)), "{modes:?}");
    assert_eq!(modes.iter().filter(|m| m.1 == Mode::Running).count(), 2, "woken for RO and CO only: {modes:?}");
    let delivered = |from: u32, to: u32, lo: u64, hi: u64| {
        rec.data
            .iter()
            .filter(|d| d.from == from && d.to == to && d.fate == Fate::Delivered && d.time > lo && d.time < hi)
            .count()
    };
    // Fig. 5a, in RS before the obstacle: RFCCD -> LPL; nothing to or from Fusion.
    assert!(delivered(rfccd, lpl, 0, t_ro) > 100);
    assert!(!rec.data.iter().any(|d| d.time < t_ro && (d.from == fusion || d.to == fusion)));
    // LADAR waits in RS: its scans are suppressed, its events count.
    assert!(rec.data.iter().any(|d| d.from == ladar && d.time < t_ro && d.fate == Fate::Suppressed));
    // Fig. 5b, in RO: RFCCD, LADAR -> Fusion -> LPL; RFCCD no longer to LPL.
    assert!(delivered(rfccd, fusion, t_ro, t_rs) > 10);
    assert!(delivered(ladar, fusion, t_ro, t_rs) > 10);
    assert!(delivered(fusion, lpl, t_ro, t_rs) > 10);
    assert_eq!(delivered(rfccd, lpl, t_ro, t_rs), 0);
    // And what Fusion reported came only while it was awake.
    let fusion_events: Vec<u64> = rec.events.iter().filter(|e| e.agent == fusion).map(|e| e.time).collect();
    assert!(!fusion_events.is_empty());
    assert!(fusion_events.iter().all(|&t| t >= t_ro), "no Fusion event before the obstacle");
}

fn ugv_programs() -> stack::UgvPrograms {
    stack::UgvPrograms { hard_switch: Some(rules("ugv.situ")), merge: Some(rules("ugv-merge.situ")) }
}

/// Both strategies through the stack (and the sim loop for reference), once.
fn dafflon() -> &'static (situ_sim::baseline::ugv::Comparison, Vec<RunReport>) {
    static RUN: OnceLock<(situ_sim::baseline::ugv::Comparison, Vec<RunReport>)> = OnceLock::new();
    RUN.get_or_init(|| {
        let world = scenario::dafflon_4().world;
        stack::compare(&ugv_programs(), &Registry::sim(), &world, &[Strategy::HardSwitch, Strategy::Merge], 1)
            .expect("compared")
    })
}

#[test]
fn dafflon_the_merge_is_smoother_than_the_hard_switch_of_the_rules() {
    let (table, reports) = dafflon();
    println!("{table}");
    let report = &reports[0];
    assert!(matches!(report.outcome, Outcome::GoalReached { .. }), "{:?}", report.outcome);
    assert!(report.runtime.path.iter().any(|s| s == "AvoidCW") && report.runtime.path.iter().any(|s| s == "AvoidCCW"));
    let hard = &table.rows[0];
    let merge = table.rows.iter().find(|r| r.strategy == "merge (sim loop)").expect("merge row");
    assert!(hard.strategy.contains("stack"));
    for r in [hard, merge] {
        assert_eq!(r.collisions, 0, "{}", r.strategy);
        assert!(r.closest_distance > 0.3, "{}: a safe closest distance, {:.2} m", r.strategy, r.closest_distance);
        // Both are capped by vmax = 2 m/s on the free stretch: the top
        // speed does not tell them apart.
        assert!((r.max_speed - 2.0).abs() < 0.05, "{}: top speed {:.2}", r.strategy, r.max_speed);
    }
    assert!(
        merge.max_steer_rate * 5.0 < hard.max_steer_rate,
        "peaks {} vs {}",
        merge.max_steer_rate,
        hard.max_steer_rate
    );
    assert!(merge.rms_steer_rate < hard.rms_steer_rate);
}

#[test]
fn dafflon_the_merge_of_the_rules_is_smoother_and_faster_than_the_hard_switch_of_the_rules() {
    let (table, reports) = dafflon();
    println!("{table}");
    let stack_row = |strategy: &str| {
        let prefix = format!("{strategy} (");
        table
            .rows
            .iter()
            .find(|r| r.strategy.starts_with(&prefix) && r.strategy.ends_with(", stack)"))
            .unwrap_or_else(|| panic!("{strategy} through the stack: {table}"))
    };
    let hard = stack_row("hard-switch");
    let merge = stack_row("merge");
    assert!(hard.strategy.contains("ugv.situ") && merge.strategy.contains("ugv-merge.situ"));
    let report = &reports[1];
    assert_eq!(report.stack, "ugv_merge");
    assert!(matches!(report.outcome, Outcome::GoalReached { .. }), "{:?}", report.outcome);
    // The Merger blended both limit cycles, then handed the last metres over.
    for st in ["Reaching", "AvoidCW", "AvoidCCW", "Docking", "Reached"] {
        assert!(report.runtime.path.iter().any(|s| s == st), "{st}: {:?}", report.runtime.path);
    }
    for r in [hard, merge] {
        assert_eq!(r.collisions, 0, "{}", r.strategy);
        assert!(r.closest_distance > 0.3, "{}: a safe closest distance, {:.2} m", r.strategy, r.closest_distance);
        assert!(r.time_to_goal.is_some(), "{}: reaches the target", r.strategy);
    }
    // Smaller steering-rate peaks (the paper's Fig. 5: no discontinuity).
    // While the Merger blends, by the sim loop's factor of 5; over the run,
    // with the Docking state's target reaching alone, by half.
    let samples = &report.metrics.samples;
    let blending = samples
        .windows(2)
        .filter(|w| ["Reaching", "AvoidCW", "AvoidCCW"].contains(&w[1].label.as_str()))
        .map(|w| ((w[1].steer_cmd - w[0].steer_cmd) / (w[1].t - w[0].t)).abs())
        .fold(0.0, f64::max);
    assert!(
        blending > 0.0 && blending * 5.0 < hard.max_steer_rate,
        "peaks merging {blending} vs {}",
        hard.max_steer_rate
    );
    assert!(
        merge.max_steer_rate * 2.0 < hard.max_steer_rate,
        "steering-rate peaks: {} vs {}",
        merge.max_steer_rate,
        hard.max_steer_rate
    );
    assert!(merge.rms_steer_rate < hard.rms_steer_rate, "{} vs {}", merge.rms_steer_rate, hard.rms_steer_rate);
    // Speed, as in the sim loop's test: both reach vmax on the free stretch
    // (the top speed is capped there); the merge keeps its speed among the
    // obstacles, so its mean speed is higher and it arrives sooner.
    assert!(merge.max_speed >= hard.max_speed - 0.05, "top speed {} vs {}", merge.max_speed, hard.max_speed);
    assert!(merge.mean_speed > hard.mean_speed + 0.1, "mean speed {} vs {}", merge.mean_speed, hard.mean_speed);
    assert!(merge.time_to_goal < hard.time_to_goal);
    // A larger margin in time: the smallest time to collision is longer.
    assert!(merge.min_ttc.unwrap_or(f64::INFINITY) > hard.min_ttc.unwrap_or(f64::INFINITY));
}

#[test]
fn the_same_scenario_and_seed_give_the_same_metrics_to_the_byte() {
    let a = outdoor().0.to_json();
    let b = run("outdoor.situ", 1, None).to_json();
    assert!(a.as_bytes() == b.as_bytes(), "metrics.json differs between two runs");
}

#[test]
fn a_lost_position_is_an_emergency_that_ends_in_a_stop_once_the_vehicle_stands() {
    let content = rules("outdoor.situ");
    let mut world = scenario::outdoor_default().world;
    world.gps_outages.push(situ_sim::geom::rect_polygon(situ_sim::geom::v2(150.0, 0.0), 20.0, 20.0, 0.0));
    let memory = SharedMemory::default();
    let cfg = StackConfig { seed: 1, until: 120.0, ..StackConfig::default() };
    let recording = Recording { mcap: None, sinks: vec![Box::new(memory.clone())] };
    let mut run = StackRun::new(content.clone(), Arc::new(stack::outdoor::Outdoor), &world, cfg, recording).unwrap();
    run.run(&mut |_| {});
    let report = run.finish().unwrap();
    assert!(matches!(&report.outcome, Outcome::Stopped { state, .. } if state == "SP"), "{:?}", report.outcome);
    assert_eq!(report.runtime.path, ["IT", "RD", "RS", "EM", "SP"]);
    let rec = memory.snapshot();
    let at = |s: &str| rec.changes.iter().find(|c| c.changed() && c.to == content.state_id(s).unwrap()).unwrap().time;
    // From 10 m/s at 4 m/s²: 2.5 s of braking. The DRSTOP Drive reported
    // standing at the start does not end the emergency (`within 100ms`).
    let braking = (at("SP") - at("EM")) as f64 * 1e-9;
    assert!((2.3..3.0).contains(&braking), "EM for {braking:.2} s");
    assert!(report.metrics.summary.collisions.is_empty());
}

fn source(name: &str, text: &str) -> Arc<Content> {
    let checked = situ_compiler::check_source(name, text);
    assert_eq!(checked.errors(), 0, "{name}: {:?}", checked.diagnostics);
    Arc::new(situ_compiler::bundle::build(&checked))
}

#[test]
fn a_program_of_no_stack_is_told_which_agents_each_stack_has() {
    let minimal = source(
        "minimal.situ",
        "states { IT initial RD final }\nagent Supervisor interface { event SVRDY }\nrule ready { when state == IT and SVRDY then RD }\n",
    );
    let e = Registry::sim().of(&minimal).err().expect("no stack");
    assert_eq!(
        e.to_string(),
        format!(
            "no simulated stack for these agents (Supervisor): `situ run` knows the agents of rules/outdoor.situ ({}), \
             of rules/ugv.situ ({}) and of rules/ugv-merge.situ (those and Merger)",
            stack::outdoor::AGENTS.join(", "),
            stack::ugv::AGENTS.join(", ")
        )
    );
}

#[test]
fn the_merge_is_told_from_the_hard_switch_in_any_order_of_the_registry() {
    use stack::{merge::UgvMerge, ugv::Ugv};
    let (hard, merge) = (rules("ugv.situ"), rules("ugv-merge.situ"));
    for registry in
        [Registry::new(vec![Arc::new(Ugv), Arc::new(UgvMerge)]), Registry::new(vec![Arc::new(UgvMerge), Arc::new(Ugv)])]
    {
        assert_eq!(registry.of(&merge).map(|s| s.name()), Ok("ugv_merge"));
        assert_eq!(registry.of(&hard).map(|s| s.name()), Ok("ugv"));
    }
}

#[test]
fn the_comparison_reads_its_other_program_beside_the_rules_or_says_where_it_looked() {
    use stack::merge::{strategies, CompareError};
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules");
    let all = strategies(&["hard-switch".into(), " merge".into()]).expect("both strategies");
    let registry = Registry::sim();
    let hard = rules("ugv.situ");
    let stack = registry.of(&hard).unwrap();
    let (programs, sibling) =
        stack::UgvPrograms::plan(&dir.join("ugv.situ"), hard.clone(), stack.as_ref(), &all).unwrap();
    assert!(programs.hard_switch.is_some() && programs.merge.is_none());
    let sibling = sibling.expect("the merge is wanted");
    assert_eq!((sibling.strategy, sibling.path), (Strategy::Merge, dir.join("ugv-merge.situ")));
    // Only the hard switch: no other program.
    let (_, none) =
        stack::UgvPrograms::plan(&dir.join("ugv.situ"), hard.clone(), stack.as_ref(), &[Strategy::HardSwitch]).unwrap();
    assert_eq!(none, None);
    // Alone in its directory.
    let lonely = tempfile::tempdir().unwrap();
    let file = lonely.path().join("ugv.situ");
    std::fs::write(&file, "").unwrap();
    let e = stack::UgvPrograms::plan(&file, hard, stack.as_ref(), &all).err().expect("no sibling");
    assert_eq!(
        e.to_string(),
        format!(
            "--compare: the merge strategy runs `ugv-merge.situ` through the stack, and there is no `{}` beside `{}`",
            lonely.path().join("ugv-merge.situ").display(),
            file.display()
        )
    );
    let outdoor = rules("outdoor.situ");
    let not = stack::UgvPrograms::plan(
        &dir.join("outdoor.situ"),
        outdoor.clone(),
        registry.of(&outdoor).unwrap().as_ref(),
        &all,
    );
    assert!(matches!(not, Err(CompareError::NotUgv)));
    let bad = strategies(&["merge".into(), "blend".into()]).expect_err("unknown");
    assert_eq!(bad.to_string(), "--compare: unknown strategy `blend` (hard-switch, merge)");
}

#[test]
fn a_run_in_real_time_is_the_same_run_and_reports_each_simulated_second() {
    let content = rules("outdoor.situ");
    let world = scenario::outdoor_default().world;
    let report = |paced: bool| {
        let cfg = StackConfig { seed: 1, until: 2.0, ..StackConfig::default() };
        let mut run =
            StackRun::new(content.clone(), Arc::new(stack::outdoor::Outdoor), &world, cfg, Recording::default())
                .unwrap();
        let mut seconds = Vec::new();
        let mut each = |r: &StackRun| seconds.push(r.t());
        if paced {
            run.run_in_real_time(&mut each);
        } else {
            run.run(&mut each);
        }
        (run.finish().unwrap().to_json(), seconds)
    };
    let (paced, at) = report(true);
    let (free, free_at) = report(false);
    assert!(paced.as_bytes() == free.as_bytes(), "metrics.json differs when paced");
    assert_eq!(at, [1.0, 2.0]);
    assert_eq!(at, free_at);
}
