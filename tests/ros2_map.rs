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

/// `situ check --format json` of `rules` with `map` and `extra` arguments,
/// without the `AMENT_PREFIX_PATH` of the machine (or with `ament`): the
/// exit code and the findings.
fn check_env(rules: &str, map: &str, extra: &[&str], ament: Option<&std::path::Path>) -> (i32, Vec<serde_json::Value>) {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_situ"));
    c.args([&["check", rules, "--ros2-map", map, "--format", "json"], extra].concat());
    c.env("NO_COLOR", "1").env_remove("AMENT_PREFIX_PATH");
    if let Some(a) = ament {
        c.env("AMENT_PREFIX_PATH", a);
    }
    let o = c.output().expect("the binary runs");
    let found =
        stdout(&o).lines().map(|l| serde_json::from_str(l).unwrap_or_else(|_| panic!("{}", text(&o)))).collect();
    (code(&o), found)
}

/// The findings of `code`: (line, column, message, help).
fn of(found: &[serde_json::Value], code: &str) -> Vec<(u64, u64, String, String)> {
    found
        .iter()
        .filter(|d| d["code"] == format!("situ::{code}"))
        .map(|d| {
            let s = |k: &str| d[k].as_str().unwrap_or("").to_string();
            (d["line"].as_u64().unwrap_or(0), d["column"].as_u64().unwrap_or(0), s("message"), s("help"))
        })
        .collect()
}

const ARM: &str = "tests/ros2/arm.situ";

#[test]
fn a_package_of_the_robot_with_msg_path() {
    let (c, found) = check_env(ARM, "tests/ros2/arm.toml", &["--msg-path", "tests/ros2/msgs", "--deny-warnings"], None);
    assert_eq!((c, found.len()), (0, 0), "{found:?}");
    // A package folder itself, as well as a folder of packages.
    let (c, found) = check_env(ARM, "tests/ros2/arm.toml", &["--msg-path", "tests/ros2/msgs/arm_msgs"], None);
    assert_eq!((c, found.len()), (0, 0), "{found:?}");
    // Without it: the package is unknown, and the help says where situ looked.
    let (c, found) = check_env(ARM, "tests/ros2/arm.toml", &[], None);
    assert_eq!(c, 1);
    let e = of(&found, "E0402");
    assert_eq!(e.iter().map(|d| (d.0, d.1)).collect::<Vec<_>>(), [(7, 8), (16, 8)], "{found:?}");
    assert_eq!(
        e[0].3,
        "no package `arm_msgs` in: the definitions situ carries; give its folder with `--msg-path DIR` or `msg_path = [\"DIR\"]`"
    );
    assert_eq!(found.len(), 2, "nothing after an unknown type: {found:?}");
}

#[test]
fn a_package_of_the_robot_with_msg_path_in_the_map() {
    let (c, found) = check_env(ARM, "tests/ros2/arm_msg_path.toml", &["--deny-warnings"], None);
    assert_eq!((c, found.len()), (0, 0), "{found:?}");
    let (c, found) = check_env(ARM, "tests/ros2/bad_msg_path.toml", &[], None);
    assert_eq!(c, 1);
    let e = of(&found, "E0423");
    assert_eq!((e[0].0, e[0].1), (1, 21), "{found:?}");
    assert_eq!(e[0].2, "`msg_path` entry `no_such_folder` is not a folder");
    let errors = found.iter().filter(|d| d["severity"] == "error").count();
    assert_eq!(errors, 1, "the other folder is read: {found:?}");
}

/// A temporary folder of its own for one test.
fn temp(name: &str) -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("situ-ros2-map-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("a temp folder");
    dir
}

fn copy_package(to: &std::path::Path) {
    std::fs::create_dir_all(to.join("msg")).expect("a folder");
    for f in ["ArmStatus.msg", "Gripper.msg"] {
        std::fs::copy(format!("tests/ros2/msgs/arm_msgs/msg/{f}"), to.join("msg").join(f)).expect("a copy");
    }
}

#[test]
fn a_package_of_the_robot_from_ament_prefix_path() {
    let root = temp("ament");
    copy_package(&root.join("install/share/arm_msgs"));
    let other = root.join("other");
    std::fs::create_dir_all(&other).expect("a folder");
    let ament = std::env::join_paths([other, root.join("install")]).expect("a path list");
    let (c, found) = check_env(ARM, "tests/ros2/arm.toml", &["--deny-warnings"], Some(std::path::Path::new(&ament)));
    assert_eq!((c, found.len()), (0, 0), "{found:?}");
    // A prefix given with --msg-path reads the same.
    let prefix = root.join("install");
    let (c, found) = check_env(ARM, "tests/ros2/arm.toml", &["--msg-path", prefix.to_str().expect("UTF-8")], None);
    assert_eq!((c, found.len()), (0, 0), "{found:?}");
    let _ = std::fs::remove_dir_all(root);
}

#[test]
fn a_definition_that_does_not_parse_is_a_finding() {
    let root = temp("broken");
    copy_package(&root.join("arm_msgs"));
    let gripper = root.join("arm_msgs/msg/Gripper.msg");
    std::fs::write(&gripper, "float32 gap\nbool closed\nint16[<=0] forces\n").expect("write");
    let (c, found) = check_env(ARM, "tests/ros2/arm.toml", &["--msg-path", root.to_str().expect("UTF-8")], None);
    assert_eq!(c, 1);
    let e = of(&found, "E0422");
    assert_eq!(e.iter().map(|d| (d.0, d.1)).collect::<Vec<_>>(), [(7, 8), (16, 8)], "{found:?}");
    assert_eq!(e[0].2, "the definition of `arm_msgs/msg/ArmStatus` does not load");
    let at = format!("{}:3: `int16[<=0]`: the size of an array is a whole number above 0", gripper.display());
    assert!(e[0].3.starts_with(&at), "{}", e[0].3);
    assert_eq!(found.len(), 2, "no follow-on findings: {found:?}");
    // A field of a type no place defines.
    std::fs::write(&gripper, "float32 gap\nFinger[] fingers\n").expect("write");
    let (_, found) = check_env(ARM, "tests/ros2/arm.toml", &["--msg-path", root.to_str().expect("UTF-8")], None);
    let e = of(&found, "E0422");
    assert!(
        e[0].3.contains(
            ":2: field `fingers` of `arm_msgs/msg/Gripper` is of type `arm_msgs/msg/Finger`, which is not found"
        ),
        "{}",
        e[0].3
    );
    let _ = std::fs::remove_dir_all(root);
}

#[test]
fn msg_path_must_be_a_folder_and_needs_a_map() {
    let o = situ(&["check", ARM, "--ros2-map", "tests/ros2/arm.toml", "--msg-path", "tests/ros2/nowhere"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("--msg-path tests/ros2/nowhere: not a folder"), "{}", text(&o));
    let o = situ(&["check", ARM, "--msg-path", "tests/ros2/msgs"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
}

#[test]
fn an_unknown_type_lists_its_package_and_raises_nothing_after_it() {
    let (c, found) = check_env(RULES, "tests/ros2/unknown_type_on_a_topic.toml", &[], None);
    assert_eq!(c, 1);
    let e = of(&found, "E0402");
    assert_eq!((e[0].0, e[0].1), (16, 8), "{found:?}");
    let help = &e[0].3;
    assert!(
        help.starts_with("did you mean `sensor_msgs/msg/LaserScan`? `sensor_msgs` has: BatteryState, CameraInfo, "),
        "{help}"
    );
    assert!(help.contains(", JointState, "), "{help}");
    assert!(of(&found, "E0413").is_empty(), "{found:?}");
}

#[test]
fn a_name_that_is_neither_field_nor_constant_lists_both() {
    let root = temp("constants");
    let map = root.join("arm.toml");
    let original = std::fs::read_to_string("tests/ros2/arm_msg_path.toml").expect("the map");
    let msgs = std::fs::canonicalize("tests/ros2/msgs").expect("the folder");
    let folder = format!("[{:?}]", msgs.to_str().expect("UTF-8"));
    std::fs::write(&map, original.replace("[\"msgs\"]", &folder).replace("MODE_MOVING", "MODE_MOVNG")).expect("write");
    let (c, found) = check_env(ARM, map.to_str().expect("UTF-8"), &[], None);
    assert_eq!(c, 1);
    let e = of(&found, "E0403");
    assert_eq!(e.len(), 1, "{found:?}");
    assert_eq!(e[0].2, "`arm_msgs/msg/ArmStatus` has no field `MODE_MOVNG`");
    assert_eq!(
        e[0].3,
        "did you mean `MODE_MOVING`? `arm_msgs/msg/ArmStatus` has: header, mode, joints, gripper, tool; \
         its constants: MODE_IDLE, MODE_MOVING, MODE_FAULT, MAX_SPEED"
    );
    let _ = std::fs::remove_dir_all(root);
}

#[test]
fn explain_prints_the_codes_of_definitions() {
    for code_name in ["E0422", "E0423"] {
        let o = situ(&["explain", code_name]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        assert!(stdout(&o).contains(&format!("{code_name}: ")), "{}", text(&o));
    }
}
