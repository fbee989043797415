//! Golden tests of `situ run`: the real binary on the papers' stacks, its
//! exit codes, the files it writes, the recording read back, determinism,
//! and its refusals (a bad scenario, a damaged bundle, rules with no stack).

mod common;

use common::{code, situ, text};
use situ_runtime::record::mcap::read_messages;
use std::collections::BTreeMap;
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 temp path")
}

#[test]
fn the_default_mission_is_done_and_leaves_its_four_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("run");
    let o = situ(&["run", "rules/outdoor.situ", "--out", s(&out)]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    for want in ["final state GL", "mission done: goal reached", "closest distance", "steering rate", "RO "] {
        assert!(stdout.contains(want), "`{want}` in:\n{stdout}");
    }
    for f in ["trajectory.svg", "timeline.svg", "metrics.json", "recording.mcap"] {
        assert!(out.join(f).is_file(), "{f} written");
    }
    let metrics: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("metrics.json")).unwrap()).unwrap();
    assert_eq!(metrics["outcome"]["kind"], "goal_reached");
    assert!(metrics["runtime"]["states"].as_array().is_some_and(|s| !s.is_empty()));
    assert!(metrics["metrics"]["architecture"]["messages_per_stream"]["Fusion->LPL"].as_u64() > Some(0));
    assert!(metrics["metrics"]["architecture"]["agents_running"]["RO"]
        .as_array()
        .is_some_and(|a| a.iter().any(|x| x == "Fusion")));
    assert!(std::fs::read_to_string(out.join("trajectory.svg")).unwrap().starts_with("<svg"));

    let (messages, cut) = read_messages(&std::fs::read(out.join("recording.mcap")).unwrap()).unwrap();
    assert!(!cut, "a whole recording");
    let mut counts: BTreeMap<&str, usize> = BTreeMap::new();
    for (topic, _, _) in &messages {
        *counts.entry(topic.as_str()).or_default() += 1;
    }
    for topic in ["/state", "/events", "/pose", "/obstacles", "/situ/events", "/situ/data", "/situ/modes"] {
        assert!(counts.get(topic).is_some_and(|n| *n > 0), "{topic}: {counts:?}");
    }
    let states: Vec<&str> =
        messages.iter().filter(|(t, _, _)| t == "/state").filter_map(|(_, _, m)| m["state"].as_str()).collect();
    assert_eq!(states.first(), Some(&"RD"));
    assert_eq!(states.last(), Some(&"GL"));
    let pose = messages.iter().find(|(t, _, _)| t == "/pose").map(|(_, _, m)| m).unwrap();
    assert_eq!(pose["frame_id"], "map");
    assert!(pose["pose"]["position"]["x"].is_number());
}

#[test]
fn the_same_seed_gives_the_same_metrics_json_to_the_byte() {
    let dir = tempfile::tempdir().unwrap();
    let run = |name: &str| {
        let out = dir.path().join(name);
        // 40 s: past the obstacle on the road, then the time runs out (exit 1).
        let o = situ(&["run", "rules/outdoor.situ", "--seed", "3", "--until", "40", "--out", s(&out)]);
        assert_eq!(code(&o), 1, "a timeout is a failed mission:\n{}", text(&o));
        assert!(text(&o).contains("no final state after 40.0 s"), "{}", text(&o));
        std::fs::read(out.join("metrics.json")).unwrap()
    };
    let (a, b) = (run("a"), run("b"));
    assert!(a == b, "metrics.json differs between two runs of one seed");
}

#[test]
fn the_ugv_compares_the_hard_switch_of_the_rules_with_the_merge() {
    let dir = tempfile::tempdir().unwrap();
    let o = situ(&["run", "rules/ugv.situ", "--compare", "hard-switch,merge", "--out", s(dir.path())]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    // --out writes the pictures its help promises, one pair per row.
    for name in ["comparison.json", "trajectory-merge-sim-loop.svg", "timeline-merge-sim-loop.svg"] {
        assert!(dir.path().join(name).is_file(), "{name}");
    }
    let stack = std::fs::read_to_string(dir.path().join("trajectory-hard-switch-rules-ugv-situ-stack.svg")).unwrap();
    assert!(stack.starts_with("<svg") && stack.contains("<polyline"), "a drawn trajectory");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("scenario dafflon-4"), "{out}");
    assert!(out.contains("hard-switch (rules/ugv.situ, stack)") && out.contains("merge (sim loop)"), "{out}");
    // The merge is a situ program too, run through the stack.
    assert!(out.contains("merge (rules/ugv-merge.situ, stack)"), "{out}");
    let merge = std::fs::read_to_string(dir.path().join("trajectory-merge-rules-ugv-merge-situ-stack.svg")).unwrap();
    assert!(merge.starts_with("<svg") && merge.contains("<polyline"), "a drawn trajectory");
    let o = situ(&["run", "rules/ugv.situ", "--compare", "hard-switch,teleport"]);
    assert_eq!(code(&o), 2);
    assert!(text(&o).contains("teleport"), "{}", text(&o));
}

#[test]
fn the_merge_program_runs_alone_and_compares_from_either_side() {
    let o = situ(&["run", "rules/ugv-merge.situ"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(text(&o).contains("scenario          dafflon-4"), "{}", text(&o));
    assert!(text(&o).contains("mission done: goal reached"), "{}", text(&o));
    assert!(text(&o).contains("Docking"), "{}", text(&o));
    // From the merge's side: the hard switch is ugv.situ beside it.
    let o = situ(&["run", "rules/ugv-merge.situ", "--compare", "merge,hard-switch"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(out.contains("merge (rules/ugv-merge.situ, stack)") && out.contains("hard-switch (rules/ugv.situ, stack)"));
    // A copy of ugv.situ with no ugv-merge.situ beside it: a usage error that says so.
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy("rules/ugv.situ", dir.path().join("ugv.situ")).unwrap();
    let o = situ(&["run", s(&dir.path().join("ugv.situ")), "--compare", "hard-switch,merge"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(text(&o).contains("ugv-merge.situ"), "{}", text(&o));
    // Only the hard switch asked: nothing else is read.
    let o = situ(&["run", s(&dir.path().join("ugv.situ")), "--compare", "hard-switch"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn a_bad_scenario_is_a_usage_error_that_names_the_problem() {
    let o = situ(&["run", "rules/outdoor.situ", "--scenario", "sim/tests/scenarios-bad/missing-field.toml"]);
    assert_eq!(code(&o), 2);
    assert!(text(&o).contains("missing field `y`"), "{}", text(&o));
    let o = situ(&["run", "rules/outdoor.situ", "--scenario", "sim/tests/scenarios-bad/goal-off-map.toml"]);
    assert_eq!(code(&o), 2);
    assert!(text(&o).contains("goal (95, 60) is off the map"), "{}", text(&o));
    let o = situ(&["run", "rules/outdoor.situ", "--scenario", "no-such-place"]);
    assert_eq!(code(&o), 2);
    assert!(text(&o).contains("no-such-place"), "{}", text(&o));
    let o = situ(&["run", "rules/outdoor.situ", "--until", "-3"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
}

#[test]
fn a_damaged_bundle_is_refused_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let bundle = dir.path().join("outdoor.bundle");
    assert_eq!(code(&situ(&["build", "rules/outdoor.situ", "-o", s(&bundle)])), 0);
    let mut bytes = std::fs::read(&bundle).unwrap();
    let i = bytes.len() / 2;
    bytes[i] ^= 0x20;
    std::fs::write(&bundle, &bytes).unwrap();
    let o = situ(&["run", s(&bundle), "--until", "1"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(text(&o).contains("outdoor.bundle"), "{}", text(&o));
}

#[test]
fn rules_without_a_reference_stack_or_a_script_say_what_to_give() {
    let dir = tempfile::tempdir().unwrap();
    let f = dir.path().join("tiny.situ");
    std::fs::write(&f, "states { IT initial RD final }\nagent Ready sensor { event RDY }\nrule ready { when state == IT and RDY then RD }\n").unwrap();
    let o = situ(&["run", s(&f)]);
    assert_eq!(code(&o), 2);
    assert!(text(&o).contains("no reference stack") && text(&o).contains("--random SEED"), "{}", text(&o));
}

#[test]
fn dla_reads_and_writes_its_case_base_and_refuses_a_bad_one_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let cases = dir.path().join("cases.txt");
    let out = dir.path().join("out");
    // No file yet: a case base is trained, then written with what was learnt.
    let o = situ(&["run", "rules/dla.situ", "--until", "8", "--cases", s(&cases), "--out", s(&out)]);
    assert_eq!(code(&o), 1, "8 s is not enough to arrive: {}", text(&o));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("case(s) trained"), "{stdout}");
    let first = std::fs::read_to_string(&cases).unwrap();
    assert!(first.starts_with("situ-casebase 1\nsectors 8\n"), "{}", &first[..40.min(first.len())]);
    for f in ["dla.svg", "dla-route.svg", "metrics.json"] {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        assert!(!text.is_empty(), "{f}");
    }
    assert!(std::fs::read_to_string(out.join("dla.svg")).unwrap().contains("<polyline class=\"trajectory\""));
    // Read back on the next run.
    let o = situ(&["run", "rules/dla.situ", "--until", "4", "--cases", s(&cases)]);
    assert!(String::from_utf8_lossy(&o.stdout).contains("case(s) read"), "{}", text(&o));
    // Damaged, or of another robot: exit 2, the file as it was.
    let damaged = first.replacen("c ", "c x", 1);
    let other = first.replacen("sectors 8", "sectors 6", 1);
    for bad in [damaged, other] {
        std::fs::write(&cases, &bad).unwrap();
        let o = situ(&["run", "rules/dla.situ", "--until", "4", "--cases", s(&cases)]);
        assert_eq!(code(&o), 2, "{}", text(&o));
        assert!(String::from_utf8_lossy(&o.stderr).contains("--cases"), "{}", text(&o));
        assert_eq!(std::fs::read_to_string(&cases).unwrap(), bad, "left as it was");
    }
}

#[test]
fn dla_missions_print_the_experience_and_draw_its_curve() {
    let dir = tempfile::tempdir().unwrap();
    let cases = dir.path().join("cases.txt");
    let out = dir.path().join("out");
    let o =
        situ(&["run", "rules/dla.situ", "--missions", "2", "--evaluate", "1", "--cases", s(&cases), "--out", s(&out)]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(stdout.contains("2 learning mission(s), seeds 1–2"), "{stdout}");
    // A line per learning mission, and evaluations after 0, 1 and 2.
    assert!(stdout.contains("        1     1  goal at ") && stdout.contains("        2     2  goal at "), "{stdout}");
    assert!(stdout.contains("held-out mission(s) (seeds 1000000–1000000), learning off"), "{stdout}");
    let evaluations = stdout.lines().filter(|l| l.contains("1/1 100 %") || l.contains("0/1   0 %")).count();
    assert_eq!(evaluations, 3, "{stdout}");
    assert!(stdout.contains("× real time"), "{stdout}");
    let svg = std::fs::read_to_string(out.join("experience.svg")).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("held-out missions done"), "{}", &svg[..100.min(svg.len())]);
    let json: serde_json::Value = serde_json::from_slice(&std::fs::read(out.join("experience.json")).unwrap()).unwrap();
    assert_eq!(json["missions"].as_array().unwrap().len(), 2);
    assert_eq!(json["evaluations"].as_array().unwrap().len(), 3);
    // The base grew, and was written.
    let written = std::fs::read_to_string(&cases).unwrap();
    let n: usize = written.lines().nth(4).and_then(|l| l.strip_prefix("cases ")).unwrap().parse().unwrap();
    assert!(n > 343, "{n} cases");
    // Not a DLA stack, or no mission: usage.
    for args in
        [&["run", "rules/outdoor.situ", "--missions", "2"][..], &["run", "rules/dla.situ", "--missions", "0"][..]]
    {
        let o = situ(args);
        assert_eq!(code(&o), 2, "{args:?}: {}", text(&o));
        assert!(String::from_utf8_lossy(&o.stderr).contains("--missions"), "{}", text(&o));
    }
}
