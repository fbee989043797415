//! `situ check FILE --ros2-map MAP`: the real binary checks the ROS 2 map of
//! a delivery robot (`tests/ros2/`) against its rules. The clean map has no
//! findings; each bad map exits 1 naming its codes at `MAP:LINE:COL`, in the
//! human, JSON and SARIF formats alike; a map that is not TOML is a finding
//! with a place; an unreadable map, or several roots with one map, exit 2.

mod common;
use common::*;

const RULES: &str = "tests/ros2/delivery.situ";

fn map(name: &str) -> String {
    format!("tests/ros2/{name}")
}

fn check(map_name: &str, extra: &[&str]) -> std::process::Output {
    let map = map(map_name);
    situ(&[&["check", RULES, "--ros2-map", &map], extra].concat())
}

#[test]
fn the_clean_map_has_no_findings() {
    let o = check("delivery.toml", &["--deny-warnings"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(stdout(&o).contains("delivery.situ: no findings"), "{}", text(&o));
}

#[test]
fn an_unknown_type_is_named_at_its_place() {
    let o = check("bad_type.toml", &[]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let out = stdout(&o);
    assert!(out.contains("situ::E0402"), "{out}");
    assert!(out.contains("bad_type.toml:5:8"), "{out}");
    assert!(out.contains("did you mean `sensor_msgs/msg/LaserScan`?"), "{out}");
    assert!(out.contains("delivery.situ: 1 error, 1 warning"), "{out}");
}

#[test]
fn a_field_not_in_the_message_is_named_at_its_place() {
    let o = check("bad_field.toml", &[]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let out = stdout(&o);
    assert!(out.contains("situ::E0403"), "{out}");
    assert!(out.contains("bad_field.toml:6:15"), "{out}");
    assert!(out.contains("`geometry_msgs/msg/TwistWithCovariance` has no field `linear`"), "{out}");
}

#[test]
fn every_finding_of_a_map_is_reported_at_once() {
    let o = check("bad_names.toml", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let found: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).expect("a JSON line")).collect();
    let at = |code: &str| -> Vec<(u64, u64)> {
        found
            .iter()
            .filter(|d| d["code"] == format!("situ::{code}"))
            .map(|d| (d["line"].as_u64().unwrap(), d["column"].as_u64().unwrap()))
            .collect()
    };
    for d in &found {
        assert!(d["file"].as_str().unwrap().ends_with("bad_names.toml"), "{d}");
    }
    assert_eq!(at("E0406"), [(2, 9)]);
    assert_eq!(at("E0409"), [(13, 12)]);
    assert_eq!(at("E0407"), [(14, 1)]);
    assert_eq!(at("E0405"), [(17, 9)]);
    assert_eq!(at("E0412"), [(25, 9)]);
    assert_eq!(at("W0411"), [(2, 9)]);
    assert_eq!(found.len(), 6, "{found:?}");
}

/// The JSON findings of a map, and the places of those of `code`.
fn json_findings(map_name: &str) -> Vec<serde_json::Value> {
    let o = check(map_name, &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    stdout(&o).lines().map(|l| serde_json::from_str(l).expect("a JSON line")).collect()
}

fn places(found: &[serde_json::Value], code: &str) -> Vec<(u64, u64)> {
    found
        .iter()
        .filter(|d| d["code"] == format!("situ::{code}"))
        .map(|d| (d["line"].as_u64().unwrap(), d["column"].as_u64().unwrap()))
        .collect()
}

#[test]
fn names_repeats_and_the_bridges_own_topics_are_findings() {
    let found = json_findings("bad_wiring.toml");
    assert_eq!(places(&found, "E0415"), [(7, 15)], "{found:?}");
    assert_eq!(places(&found, "W0417"), [(22, 9)], "{found:?}");
    assert_eq!(places(&found, "E0418"), [(30, 9)], "{found:?}");
    assert_eq!(places(&found, "W0421"), [(37, 9)], "{found:?}");
    assert_eq!(places(&found, "E0414"), [(47, 11)], "{found:?}");
    assert_eq!(places(&found, "E0416"), [(51, 8)], "{found:?}");
    assert_eq!(found.len(), 6, "{found:?}");

    // The human form: the corrected name and the duration's form in the helps.
    let o = check("bad_wiring.toml", &[]);
    let out = stdout(&o);
    for expected in [
        "`/scan-front` is not a ROS 2 topic name: `-` is not allowed in a name",
        "write `topic = \"/scan_front\"`",
        "every message on `/scan` posts `CLEAR` twice",
        "`/situ/state` is the bridge's own output",
        "the bridge ignores the messages of its own writers",
        "write `timeout = \"500ms\"`",
        "`/planner` plays `Planner` and `Orders`",
        "delivery.situ: 4 errors, 2 warnings",
    ] {
        assert!(out.contains(expected), "{expected:?} not in\n{out}");
    }
}

#[test]
fn a_map_that_reads_diagnostics_warns_and_passes() {
    let o = situ(&["check", "tests/ros2/heartbeat.situ", "--ros2-map", "tests/ros2/heartbeat.toml"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(stdout(&o).contains("situ::W0421") && stdout(&o).contains("heartbeat.toml:8:9"), "{}", text(&o));
    let o = situ(&["check", "tests/ros2/heartbeat.situ", "--ros2-map", "tests/ros2/heartbeat.toml", "--deny-warnings"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
}

#[test]
fn an_event_no_entry_produces_is_a_warning() {
    let o = check("unmapped.toml", &[]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let out = stdout(&o);
    assert!(out.contains("situ::W0411") && out.contains("unmapped.toml:3:9"), "{out}");
    assert!(out.contains("`Lidar` reports `CLEAR`, but no map entry produces it"), "{out}");
    let o = check("unmapped.toml", &["--deny-warnings"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
}

#[test]
fn sarif_names_the_map() {
    let o = check("bad_type.toml", &["--format", "sarif"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let log: serde_json::Value = serde_json::from_str(&stdout(&o)).expect("a SARIF log");
    let results = log["runs"][0]["results"].as_array().expect("results");
    let result = results.iter().find(|r| r["level"] == "error").expect("the error");
    assert_eq!(result["ruleId"], "situ::E0402", "{result}");
    let place = &result["locations"][0]["physicalLocation"];
    assert!(place["artifactLocation"]["uri"].as_str().unwrap().ends_with("bad_type.toml"), "{place}");
    assert_eq!(place["region"]["startLine"], 5, "{place}");
}

#[test]
fn a_map_that_is_not_toml_is_a_finding_with_a_place() {
    let o = check("not_toml.toml", &[]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let out = stdout(&o);
    assert!(out.contains("situ::E0401") && out.contains("not_toml.toml:3:"), "{out}");
}

#[test]
fn usage_errors_exit_2() {
    let o = check("no_such_map.toml", &[]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("no_such_map.toml"), "{}", text(&o));
    let clean = map("delivery.toml");
    let o = situ(&["check", RULES, RULES, "--ros2-map", &clean]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("--ros2-map applies to one root file"), "{}", text(&o));
}

#[test]
fn the_rules_are_checked_without_the_map_too() {
    let o = situ(&["check", RULES]);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn explain_prints_the_codes_of_the_map() {
    for code_name in ["E0401", "E0403", "W0411", "E0413", "E0415", "E0416", "W0417", "E0418", "W0421"] {
        let o = situ(&["explain", code_name]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        assert!(stdout(&o).contains(&format!("{code_name}: ")), "{}", text(&o));
        assert!(stdout(&o).contains("```toml") || stdout(&o).contains("[[event]]"), "{}", text(&o));
    }
}

#[test]
fn expressions_over_arrays_check_clean() {
    let o = check("arrays.toml", &["--deny-warnings"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

#[test]
fn mistakes_in_expressions_over_arrays_name_their_fix() {
    let o = check("bad_expressions.toml", &["--format", "json"]);
    assert_eq!(code(&o), 1, "{}", text(&o));
    let found: Vec<serde_json::Value> =
        stdout(&o).lines().map(|l| serde_json::from_str(l).expect("a JSON line")).collect();
    for (code, line, column, help) in [
        ("E0419", 10, 28, "divide by a number that is not zero"),
        ("E0420", 17, 16, "find(array, name == 'x')"),
        ("E0404", 27, 34, "the comparisons are `==`"),
        ("E0403", 34, 30, "write `it` for the element"),
    ] {
        let d =
            found.iter().find(|d| d["code"] == format!("situ::{code}")).unwrap_or_else(|| panic!("{code}: {found:?}"));
        assert_eq!((d["line"].as_u64(), d["column"].as_u64()), (Some(line), Some(column)), "{d}");
        assert!(d["help"].as_str().is_some_and(|h| h.contains(help)), "{d}");
    }
    for code_name in ["E0419", "E0420"] {
        let o = situ(&["explain", code_name]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        assert!(stdout(&o).contains("[[event]]"), "{}", text(&o));
    }
}
