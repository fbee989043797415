//! Golden tests of `situ test`: they run the real binary on the repository's
//! rule files and on small files with planted bugs, and check exit codes,
//! the summary line, failure reports with places, counterexamples that
//! replay as tests, and the JSON form.

mod common;

use common::{code, situ, stdout, write};

/// A small stack with one failing test and one failing property.
const BUGGY: &str = r#"states { Ready initial Armed Fired final }
agent Btn interface { event ARM event FIRE event SAFE }
agent Lamp actuator { function glow table { Armed => run glow()  _ => sleep } }
rule arm { when state == Ready and ARM then Armed }
rule safe { when state == Armed and SAFE then Ready }
rule fire { when state in {Ready, Armed} and FIRE then Fired }
test "arming lights the lamp" {
    on ARM
    expect state Armed, Lamp running
}
test "a safe button does not fire" {
    on SAFE, FIRE
    expect state Ready, Lamp sleeping
}
property "firing needs arming" { always (state == Ready -> next state != Fired) }
property "the lamp glows when armed" { always (state == Armed -> Lamp running) }
"#;

/// The `test` block that `situ test` prints for a counterexample, as printed:
/// from its first line to the `}` that closes it.
fn replay_block(out: &str) -> String {
    let start = out.find("\ntest \"counterexample").expect("a test block at the start of a line") + 1;
    let mut block = String::new();
    for line in out[start..].lines() {
        block.push_str(line);
        block.push('\n');
        if line == "}" {
            return block;
        }
    }
    panic!("an unclosed test block: {block}");
}

fn the_papers_stacks_pass_their_tests_and_properties(file: &str, at_least: usize) {
    let o = situ(&["test", file]);
    let out = stdout(&o);
    assert_eq!(code(&o), 0, "{file}:\n{out}");
    let last = out.lines().last().unwrap_or_default();
    assert!(last.ends_with(" passed, 0 failed, 0 undecided"), "{last}");
    assert!(!out.contains("FAILED"), "{out}");
    // Every property is proved for runs of any length, not searched.
    let properties = out.matches("\nproperty \"").count();
    let proved = out.matches("symbolic: proved for runs of any length").count();
    assert!(properties >= at_least, "{out}");
    assert_eq!(proved, properties, "{out}");
}

// One test per file: they run side by side.
#[test]
fn the_outdoor_rules_pass_their_tests_and_properties() {
    the_papers_stacks_pass_their_tests_and_properties("rules/outdoor.situ", 7);
}

#[test]
fn the_ugv_rules_pass_their_tests_and_properties() {
    the_papers_stacks_pass_their_tests_and_properties("rules/ugv.situ", 7);
}

#[test]
fn the_merging_ugv_rules_pass_their_tests_and_properties() {
    the_papers_stacks_pass_their_tests_and_properties("rules/ugv-merge.situ", 7);
}

#[test]
fn the_dla_rules_pass_their_tests_and_properties() {
    the_papers_stacks_pass_their_tests_and_properties("rules/dla.situ", 2);
}

#[test]
fn failures_name_their_place_and_what_was_found() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "buggy.situ", BUGGY);
    let o = situ(&["test", &file, "--engine", "exhaustive"]);
    let out = stdout(&o);
    assert_eq!(code(&o), 1, "{out}");
    assert!(out.contains("test \"arming lights the lamp\" ... ok"), "{out}");
    assert!(out.contains("test \"a safe button does not fire\" ... FAILED"), "{out}");
    assert!(out.contains(&format!("{file}:13:12: expected state Ready, found Fired")), "{out}");
    assert!(!out.contains("expected Lamp sleeping"), "the lamp sleeps in Fired: {out}");
    assert!(out.contains("property \"firing needs arming\" ... FAILED"), "{out}");
    assert!(out.contains("counterexample (exhaustive exploration, shortest, 1 events)"), "{out}");
    assert!(out.contains("Ready -> Fired   fired `fire`"), "{out}");
    assert!(out.contains("property \"the lamp glows when armed\" ... ok (proved by exhaustive exploration)"), "{out}");
    assert_eq!(out.lines().last(), Some("2 passed, 2 failed, 0 undecided"), "{out}");
}

#[test]
fn a_counterexample_replays_as_a_test() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "buggy.situ", BUGGY);
    let o = situ(&["test", &file, "--filter", "firing", "--engine", "random", "--cases", "500"]);
    let out = stdout(&o);
    assert_eq!(code(&o), 1, "{out}");
    let block = replay_block(&out);
    assert!(block.trim_end().ends_with('}'), "{block}");
    let replay = write(dir.path(), "replay.situ", format!("{BUGGY}\n{block}"));
    let o = situ(&["test", &replay, "--filter", "counterexample"]);
    assert_eq!(code(&o), 0, "{}\n{block}", stdout(&o));
    assert_eq!(stdout(&o).lines().last(), Some("1 passed, 0 failed, 0 undecided"));
}

/// A property that only a NaN payload breaks (issue 18: the counterexample
/// printed `R(d: NaN)`, which did not parse).
const NAN_ONLY: &str = r#"states { Idle initial Odd Alarm final }
agent Rng sensor { event R { d: f64 } }
agent Btn interface { event GO }
rule nan_seen { when state == Idle and R and not R(d < 0.0) and not R(d >= 0.0) then Odd }
rule alarm { when state == Odd and GO then Alarm }
property "no alarm" { never state == Alarm }
"#;

/// A property that only NaN, then -inf, then inf break, in that order.
const NON_FINITE: &str = r#"states { Idle initial Odd Low Alarm final }
agent Rng sensor { event R { d: f64 } }
rule nan_seen { when state == Idle and R and not R(d < 0.0) and not R(d >= 0.0) then Odd }
rule lowest { when state == Odd and R(d <= -inf) then Low }
rule highest { when state == Low and R(d >= inf) then Alarm }
property "no alarm" { never state == Alarm }
"#;

/// Runs `situ test` on `rules`, expects a failure whose counterexample block
/// contains each of `values`, pastes the block back and expects it to pass.
fn counterexample_replays(rules: &str, values: &[&str]) {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "odd.situ", rules);
    let o = situ(&["test", &file, "--engine", "exhaustive"]);
    let out = stdout(&o);
    assert_eq!(code(&o), 1, "{out}");
    let block = replay_block(&out);
    for value in values {
        assert!(block.contains(value), "{value} in:\n{block}");
    }
    let replay = write(dir.path(), "replay.situ", format!("{rules}\n{block}"));
    let o = situ(&["test", &replay, "--filter", "counterexample"]);
    assert_eq!(code(&o), 0, "{}\n{block}", stdout(&o));
    assert_eq!(stdout(&o).lines().last(), Some("1 passed, 0 failed, 0 undecided"));
}

#[test]
fn a_counterexample_with_nan_replays_as_a_test() {
    counterexample_replays(NAN_ONLY, &["R(d: NaN)"]);
}

#[test]
fn a_counterexample_with_nan_and_infinities_replays_as_a_test() {
    counterexample_replays(NON_FINITE, &["R(d: NaN)", "R(d: -inf)", "R(d: inf)"]);
}

#[test]
fn nan_and_infinities_replay_in_a_test_block() {
    let dir = tempfile::tempdir().unwrap();
    // As `situ test` prints a counterexample.
    let block = "test \"counterexample: no alarm\" {\n    on R(d: NaN) at 0ms,\n       R(d: -inf) at 0ms,\n       R(d: inf) at 1ms\n    expect state Alarm\n}\n";
    let file = write(dir.path(), "odd.situ", format!("{NON_FINITE}\n{block}"));
    let o = situ(&["test", &file, "--filter", "counterexample"]);
    assert_eq!(code(&o), 0, "{}", stdout(&o));
    assert_eq!(stdout(&o).lines().last(), Some("1 passed, 0 failed, 0 undecided"));
}

#[test]
fn json_gives_one_object_per_result() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "buggy.situ", BUGGY);
    let o = situ(&["test", &file, "--format", "json", "--engine", "exhaustive"]);
    assert_eq!(code(&o), 1);
    let lines: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).expect("a JSON object per line")).collect();
    assert_eq!(lines.len(), 5);
    let kinds: Vec<&str> = lines.iter().map(|l| l["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["test", "test", "property", "property", "summary"]);
    assert_eq!(lines[2]["verdict"], "violated");
    assert_eq!(lines[3]["verdict"], "proved");
    assert_eq!(lines[3]["proved_by"], "exhaustive exploration");
    assert_eq!(
        (lines[4]["passed"].as_u64(), lines[4]["failed"].as_u64(), lines[4]["undecided"].as_u64()),
        (Some(2), Some(2), Some(0))
    );
    assert_eq!(lines[1]["passed"], false);
    assert_eq!(lines[1]["failures"][0]["place"], format!("{file}:13:12"));
    assert_eq!(lines[2]["exhaustive"]["verdict"], "failed");
    assert_eq!(lines[2]["counterexample"]["events"][0]["event"], "FIRE");
    assert_eq!(lines[2]["counterexample"]["events"][0]["state"], "Fired");
    assert_eq!(lines[3]["exhaustive"]["verdict"], "proved");
}

#[test]
fn filter_selects_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "buggy.situ", BUGGY);
    let o = situ(&["test", &file, "--filter", "lamp"]);
    assert_eq!(code(&o), 0, "{}", stdout(&o));
    assert_eq!(stdout(&o).lines().last(), Some("2 passed, 0 failed, 0 undecided"));
}

#[test]
fn a_file_with_errors_fails_with_its_diagnostics() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(
        dir.path(),
        "bad.situ",
        "states { IT initial RS }\nagent A sensor { event GO }\nrule go { when state == IT and GO then RS }\n\
         test \"late\" { on GO at 50ms, GO at 20ms expect state RS }\n\
         property \"unknown\" { always (state == RQ) }\n",
    );
    let o = situ(&["test", &file]);
    let out = stdout(&o);
    assert_eq!(code(&o), 1, "{out}");
    assert!(out.contains("situ::E0117") && out.contains("situ::E0101"), "{out}");
    assert_eq!(out.lines().last(), Some("0 passed, 1 failed, 0 undecided"));
}

#[test]
fn usage_and_io_errors_exit_2() {
    assert_eq!(code(&situ(&["test", "no/such/file.situ"])), 2);
    assert_eq!(code(&situ(&["test"])), 2);
    assert_eq!(code(&situ(&["test", "rules/outdoor.situ", "--engine", "magic"])), 2);
}

/// A ladder of `n` states, one event per rung: "never the top" is false,
/// with a counterexample of `n` events.
fn ladder(n: usize) -> String {
    let mut s = String::from("states { S0 initial");
    for i in 1..=n {
        s.push_str(&format!(" S{i}"));
    }
    s.push_str(" }\nagent Up sensor {");
    for i in 1..=n {
        s.push_str(&format!(" event U{i}"));
    }
    s.push_str(" }\n");
    for i in 1..=n {
        s.push_str(&format!("rule r{i} {{ when state == S{} and U{i} then S{i} }}\n", i - 1));
    }
    s.push_str(&format!("property \"the top is never reached\" {{ never state == S{n} }}\n"));
    s
}

#[test]
fn a_false_property_is_undecided_at_a_tiny_budget_never_ok() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "ladder.situ", ladder(16));
    let tiny = ["--depth", "2", "--length", "3", "--cases", "8", "--prove-effort", "50"];
    let o = situ(&[&["test", file.as_str()][..], &tiny].concat());
    let out = stdout(&o);
    assert_eq!(code(&o), 1, "{out}");
    assert!(out.contains("property \"the top is never reached\" ... UNDECIDED"), "{out}");
    assert!(out.contains("symbolic: gave up at its work budget (`--prove-effort`)"), "{out}");
    assert!(!out.contains("... ok"), "{out}");
    assert_eq!(out.lines().rev().find(|l| l.contains("passed")), Some("0 passed, 0 failed, 1 undecided"), "{out}");
    // Allowed, it passes the run but is still called undecided.
    let o = situ(&[&["test", file.as_str(), "--allow-undecided"][..], &tiny].concat());
    assert_eq!(code(&o), 0, "{}", stdout(&o));
    assert!(stdout(&o).contains("UNDECIDED"));
    // The wall-clock guard is said as such, and is never a pass.
    let o = situ(&[&["test", file.as_str(), "--prove-timeout", "0"][..], &tiny[..6]].concat());
    assert_eq!(code(&o), 1, "{}", stdout(&o));
    assert!(stdout(&o).contains("gave up at the wall-clock guard (`--prove-timeout`)"), "{}", stdout(&o));
    // JSON says the same.
    let o = situ(&[&["test", file.as_str(), "--format", "json"][..], &tiny].concat());
    assert_eq!(code(&o), 1);
    let lines: Vec<serde_json::Value> = stdout(&o).lines().map(|l| serde_json::from_str(l).expect("JSON")).collect();
    assert_eq!(lines[0]["verdict"], "undecided");
    assert_eq!(lines[0]["code"], "E0502");
    assert_eq!(lines[0]["passed"], false);
    assert_eq!(lines[1]["undecided"], 1);
    // With the default budget, the 16 events are found and replay.
    let o = situ(&["test", &file, "--depth", "2", "--length", "3", "--cases", "8"]);
    let out = stdout(&o);
    assert_eq!(code(&o), 1, "{out}");
    assert!(out.contains("counterexample (IC3, replayed on the engine, shrunk, 16 events)"), "{out}");
}

#[test]
fn a_printed_counterexample_parses_after_an_include() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "buggy.situ", BUGGY);
    let file = write(dir.path(), "main.situ", "include \"buggy.situ\"\n");
    let o = situ(&["test", &file, "--filter", "firing", "--engine", "exhaustive"]);
    let block = replay_block(&stdout(&o));
    let replay = write(dir.path(), "replay.situ", format!("include \"buggy.situ\"\n{block}"));
    let o = situ(&["test", &replay, "--filter", "counterexample"]);
    assert_eq!(code(&o), 0, "{}\n{block}", stdout(&o));
}

#[test]
fn a_vacuous_property_is_reported_with_its_code() {
    let dir = tempfile::tempdir().unwrap();
    let rules = r#"states { Idle initial Armed Fired final }
agent Btn interface { event ARM event FIRE }
agent Lamp actuator { function glow table { Armed => run glow()  Fired => run glow()  _ => sleep } }
rule arm { when state == Idle and ARM then Armed }
rule fire { when state == Armed and FIRE then Fired }
property "vacuous" { always (state == Fired and Lamp sleeping -> next state == Fired) }
property "real" { always (state == Fired -> next state == Fired) }
"#;
    let file = write(dir.path(), "lamp.situ", rules);
    let o = situ(&["test", &file]);
    let out = stdout(&o);
    assert_eq!(code(&o), 0, "{out}");
    let vacuous = &out[out.find("property \"vacuous\"").unwrap()..out.find("property \"real\"").unwrap()];
    assert!(vacuous.contains("warning[W0501]: vacuous"), "{out}");
    let real = &out[out.find("property \"real\"").unwrap()..];
    assert!(real.contains("premise: reached after 2 events: ARM at 0ms, FIRE at 0ms"), "{out}");
    let explain = situ(&["explain", "W0501"]);
    assert!(stdout(&explain).contains("premise never holds"), "{}", stdout(&explain));
}

#[test]
fn sarif_carries_every_verdict_with_its_code_and_place() {
    let dir = tempfile::tempdir().unwrap();
    // The buggy stack (a failed test, a violated property) and an undecided ladder.
    let buggy = write(dir.path(), "b.situ", BUGGY);
    let ladder = write(dir.path(), "l.situ", ladder(16));
    let o = situ(&[
        "test",
        &buggy,
        &ladder,
        "--format",
        "sarif",
        "--depth",
        "2",
        "--length",
        "3",
        "--cases",
        "8",
        "--prove-effort",
        "50",
    ]);
    assert_eq!(code(&o), 1, "{}", stdout(&o));
    let log: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("one SARIF document");
    assert_eq!(log["version"], "2.1.0");
    let results = log["runs"][0]["results"].as_array().expect("results");
    let ids: Vec<&str> = results.iter().map(|r| r["ruleId"].as_str().unwrap()).collect();
    assert!(ids.contains(&"situ::E0504"), "{ids:?}");
    assert!(ids.contains(&"situ::E0503"), "{ids:?}");
    assert!(ids.contains(&"situ::E0502"), "{ids:?}");
    let in_ladder = |r: &&serde_json::Value| {
        r["locations"][0]["physicalLocation"]["artifactLocation"]["uri"].as_str().is_some_and(|u| u.ends_with("l.situ"))
    };
    let undecided = results.iter().filter(in_ladder).find(|r| r["ruleId"] == "situ::E0502").unwrap();
    let region = &undecided["locations"][0]["physicalLocation"]["region"];
    assert_eq!(region["startLine"], 19, "{undecided}");
    let violated = results.iter().find(|r| r["ruleId"] == "situ::E0503").unwrap();
    assert_eq!(violated["properties"]["witness"]["events"][0]["event"], "FIRE", "{violated}");
}
