//! The CDR decoder against an independent implementation: Eclipse Cyclone
//! DDS (the `cyclonedds` Python package, one of ROS 2's middlewares)
//! serializes messages of the carried definitions and of a package of the
//! tests' own (`cdr_samples.py`), and every field decoded here must be the
//! value it was given. Then the clean map of `tests/ros2/delivery.toml`, and
//! a map with constants on the tests' own package, are evaluated on them.
//!
//! A missing `python3` or `cyclonedds` fails the test: install the test
//! requirements with `python3 -m pip install -r examples/python/requirements.txt`.

use serde_json::Value as Json;
use situ_compiler::bundle::Value;
use situ_grammar::diag::FileId;
use situ_ros2_map::cdr::{Decoder, Value as Msg};
use situ_ros2_map::eval::Produced;
use situ_ros2_map::msgs::{Registry, SearchPath};
use situ_ros2_map::Translator;
use std::path::Path;
use std::process::Command;

struct Sample {
    name: String,
    ty: String,
    cdr: Vec<u8>,
    expect: serde_json::Map<String, Json>,
    f32: Vec<String>,
}

fn samples() -> Vec<Sample> {
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/cdr_samples.py");
    let out = Command::new("python3").arg(&script).output().unwrap_or_else(|e| {
        panic!("cannot run python3 ({e}): the test needs python3 with cyclonedds (examples/python/requirements.txt)")
    });
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        out.status.success(),
        "{} failed ({}): {stderr}\nthe test needs the Python package cyclonedds: \
         python3 -m pip install -r examples/python/requirements.txt",
        script.display(),
        out.status
    );
    let text = String::from_utf8(out.stdout).expect("the script prints UTF-8");
    let samples: Vec<Sample> = text
        .lines()
        .map(|line| {
            let j: Json = serde_json::from_str(line).expect("one JSON object a line");
            let hex = j["cdr_hex"].as_str().expect("cdr_hex");
            Sample {
                name: j["name"].as_str().expect("name").to_string(),
                ty: j["type"].as_str().expect("type").to_string(),
                cdr: (0..hex.len()).step_by(2).map(|i| u8::from_str_radix(&hex[i..i + 2], 16).expect("hex")).collect(),
                expect: j["expect"].as_object().expect("expect").clone(),
                f32: j["f32"].as_array().expect("f32").iter().map(|p| p.as_str().expect("path").to_string()).collect(),
            }
        })
        .collect();
    assert!(samples.len() >= 40, "too few samples: {}", samples.len());
    samples
}

/// The carried definitions and the tests' own package `arm_msgs`
/// (`tests/ros2/msgs`, a folder of packages).
fn registry() -> Registry {
    let msgs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/ros2/msgs");
    Registry::load(&SearchPath::with_ament(&[msgs], None))
}

/// The leaves of a decoded value.
fn leaves(v: &Msg) -> usize {
    match v {
        Msg::Array(items) => items.iter().map(leaves).sum(),
        Msg::Msg(fields) => fields.iter().map(|(_, v)| leaves(v)).sum(),
        _ => 1,
    }
}

fn float_of(j: &Json) -> Option<f64> {
    match j.as_str() {
        Some("nan") => Some(f64::NAN),
        Some("inf") => Some(f64::INFINITY),
        Some("-inf") => Some(f64::NEG_INFINITY),
        _ => j.as_f64(),
    }
}

/// Whether the decoded `got` is the value `want` cyclonedds was given.
fn same(got: &Msg, want: &Json, f32: bool) -> bool {
    match got {
        Msg::Bool(b) => want.as_bool() == Some(*b),
        Msg::Int(i) => want.as_i64() == Some(*i),
        Msg::Str(s) => want.as_str() == Some(s),
        Msg::Float(f) => match float_of(want) {
            Some(w) if w.is_nan() => f.is_nan(),
            // A float32 field holds the value rounded to float32.
            Some(w) if f32 => (*f as f32).to_bits() == (w as f32).to_bits() && f64::from(*f as f32) == *f,
            Some(w) => w == *f,
            None => false,
        },
        Msg::Array(_) | Msg::Msg(_) => false,
    }
}

#[test]
fn decodes_what_cyclonedds_serializes() {
    let samples = samples();
    let reg = registry();
    let mut types = std::collections::BTreeSet::new();
    let mut checked = 0;
    for s in &samples {
        let decoder = Decoder::new(&reg, &s.ty).unwrap_or_else(|| panic!("{}: {} is not defined", s.name, s.ty));
        let v = decoder.decode(&s.cdr).unwrap_or_else(|e| panic!("{}: {e}", s.name));
        let mut leaf_count = 0;
        for (path, want) in &s.expect {
            if let Some(inner) = path.strip_prefix("len(").and_then(|p| p.strip_suffix(')')) {
                let Some(Msg::Array(items)) = v.at(inner) else { panic!("{}: `{inner}` is not an array", s.name) };
                assert_eq!(Some(items.len() as u64), want.as_u64(), "{}: len({inner})", s.name);
                continue;
            }
            leaf_count += 1;
            let got = v.at(path).unwrap_or_else(|| panic!("{}: no `{path}` in {v:?}", s.name));
            let f32 = s.f32.contains(path);
            assert!(same(got, want, f32), "{}: `{path}` decoded {got:?}, cyclonedds wrote {want}", s.name);
            checked += 1;
        }
        assert_eq!(leaves(&v), leaf_count, "{}: the decoded message has other fields than cyclonedds wrote", s.name);
        // Every shorter prefix is refused, never read past its end.
        for cut in 0..s.cdr.len().saturating_sub(3).min(64) {
            let _ = decoder.decode(&s.cdr[..cut]);
        }
        types.insert(s.ty.clone());
    }
    for ty in [
        "sensor_msgs/msg/LaserScan",
        "nav_msgs/msg/Odometry",
        "sensor_msgs/msg/BatteryState",
        "geometry_msgs/msg/Twist",
        "diagnostic_msgs/msg/DiagnosticArray",
        "std_msgs/msg/Float64",
        "std_msgs/msg/String",
        "std_msgs/msg/Bool",
        "sensor_msgs/msg/NavSatFix",
        "sensor_msgs/msg/Imu",
        "sensor_msgs/msg/JointState",
        "action_msgs/msg/GoalStatusArray",
        "arm_msgs/msg/ArmStatus",
    ] {
        assert!(types.contains(ty), "no sample of {ty}");
    }
    assert!(checked > 1000, "only {checked} fields compared");
}

const RULES: &str = include_str!("../../tests/ros2/delivery.situ");
const MAP: &str = include_str!("../../tests/ros2/delivery.toml");

#[test]
fn delivery_map_on_cyclonedds_messages() {
    let checked = situ_compiler::check_source("tests/ros2/delivery.situ", RULES);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    let model = &checked.model;
    let mut t = Translator::new(model, MAP, &Registry::carried(), FileId(1)).unwrap_or_else(|d| panic!("{d:?}"));
    let ev = |agent: &str, event: &str, payload: Vec<Value>| Produced {
        agent: model.agent_id(agent).expect("agent").0,
        event: model.event_id(event).expect("event").0,
        payload,
    };
    let f = |x: f32| f64::from(x);
    let samples = samples();
    let mut seen = 0;
    for s in &samples {
        let base = s.name.strip_suffix("_be").unwrap_or(&s.name);
        let topic = match base.split('_').next() {
            Some("scan") => "/scan",
            Some("odom") => "/odom",
            Some("battery") => "/battery",
            Some("diag") => "/diagnostics",
            _ => continue,
        };
        let (want, problems): (Vec<Produced>, usize) = match base {
            "scan_obstacle" => (vec![ev("Lidar", "OBSTACLE", vec![Value::F64(f(0.31))])], 0),
            "scan_clear" => (vec![ev("Lidar", "CLEAR", vec![])], 0),
            // `min` of no ranges: both entries refuse the message.
            "scan_empty" => (vec![], 2),
            "scan_long" => (vec![ev("Lidar", "OBSTACLE", vec![Value::F64(f(0.1))])], 0),
            "odom_moving" => (vec![ev("Base", "MOVING", vec![Value::F64(1.5 * 3.6)])], 0),
            "odom_stopped" => (vec![ev("Base", "STOPPED", vec![])], 0),
            "odom_reverse" => (vec![ev("Base", "MOVING", vec![Value::F64(-0.3 * 3.6)])], 0),
            "battery_low" => (vec![ev("Battery", "BATTERY_LOW", vec![Value::F64(f(0.15) * 100.0), Value::I64(3)])], 0),
            "battery_full" | "battery_absent" => (vec![], 0),
            // level `error` (1 of {warn, error}), component `base` (0 of {base, lidar, other}).
            "diag_error" => (vec![ev("Diagnostics", "HW_ERROR", vec![Value::Symbol(1), Value::Symbol(0)])], 0),
            "diag_ok" | "diag_empty" => (vec![], 0),
            other => panic!("no expectation for {other}"),
        };
        let out = t.on_message(topic, &s.cdr);
        assert_eq!(out.produced, want, "{}: {:?}", s.name, out.problems);
        assert_eq!(out.problems.len(), problems, "{}: {:?}", s.name, out.problems);
        seen += 1;
    }
    assert_eq!(seen, 2 * 13, "every delivery sample in both byte orders");
    // A message cut short is refused as a whole and counted.
    let scan = samples.iter().find(|s| s.name == "scan_obstacle").expect("scan_obstacle");
    let out = t.on_message("/scan", &scan.cdr[..40]);
    assert!(out.produced.is_empty());
    assert!(out.problems[0].message.starts_with("LaserScan: "), "{:?}", out.problems);
    let stats = t.stats();
    // `scan_empty` in both byte orders, two entries each.
    assert_eq!((stats.messages, stats.refused, stats.failed), (27, 1, 4));
}

const ARM_RULES: &str = "
states { IDLE initial MOVING FAULT final }
agent Arm sensor { event ARM_MOVING { speed: f64, tool: {suction, none} } event ARM_FAULT { forces: i64 } }
agent Nav processing { event NAV_ABORTED }
rule go { when state == IDLE and ARM_MOVING then MOVING }
rule fault salience 5 { when state != FAULT and ARM_FAULT then FAULT }
rule abort salience 5 { when state != FAULT and NAV_ABORTED then FAULT }
";

/// Constants by name in conditions and payloads: of the message
/// (`MODE_MOVING`), of the message by its type (`ArmStatus.MODE_FAULT`),
/// of a field's type (`GoalStatus.STATUS_ABORTED`).
const ARM_MAP: &str = r#"
[[event]]
agent = "Arm"
event = "ARM_MOVING"
topic = "/arm"
type = "arm_msgs/ArmStatus"
when = "mode == MODE_MOVING and not gripper.closed"
[event.payload]
speed = "MAX_SPEED * 2"
tool = "tool"

[[event]]
agent = "Arm"
event = "ARM_FAULT"
topic = "/arm"
type = "arm_msgs/msg/ArmStatus"
when = "mode == ArmStatus.MODE_FAULT and gripper.closed"
[event.payload]
forces = "len(gripper.forces) + Gripper.LIMIT"

[[event]]
agent = "Nav"
event = "NAV_ABORTED"
topic = "/navigate_to_pose/_action/status"
type = "action_msgs/msg/GoalStatusArray"
when = "len(status_list) > 1 and status_list[1].status == GoalStatus.STATUS_ABORTED"
"#;

#[test]
fn constants_and_a_package_of_its_own_on_cyclonedds_messages() {
    let checked = situ_compiler::check_source("arm.situ", ARM_RULES);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    let model = &checked.model;
    let reg = registry();
    // `Gripper.LIMIT` is not a constant: the map is refused, the help says what there is.
    let errors = Translator::new(model, ARM_MAP, &reg, FileId(1)).unwrap_err();
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert_eq!(errors[0].message, "`arm_msgs/msg/Gripper` has no constant `LIMIT`");
    assert_eq!(errors[0].help.as_deref(), Some("`arm_msgs/msg/Gripper` has no constants"));
    let map = ARM_MAP.replace(" + Gripper.LIMIT", " + 10 * ArmStatus.MODE_FAULT");
    let mut t = Translator::new(model, &map, &reg, FileId(1)).unwrap_or_else(|d| panic!("{d:?}"));
    let ev = |agent: &str, event: &str, payload: Vec<Value>| Produced {
        agent: model.agent_id(agent).expect("agent").0,
        event: model.event_id(event).expect("event").0,
        payload,
    };
    let mut seen = 0;
    for s in samples() {
        let base = s.name.strip_suffix("_be").unwrap_or(&s.name);
        let (topic, want) = match base {
            "arm_moving" => ("/arm", vec![ev("Arm", "ARM_MOVING", vec![Value::F64(3.0), Value::Symbol(0)])]),
            "arm_fault" => ("/arm", vec![ev("Arm", "ARM_FAULT", vec![Value::I64(20)])]),
            "goal_status" => ("/navigate_to_pose/_action/status", vec![ev("Nav", "NAV_ABORTED", vec![])]),
            "goal_status_empty" => ("/navigate_to_pose/_action/status", vec![]),
            _ => continue,
        };
        let out = t.on_message(topic, &s.cdr);
        assert_eq!(out.produced, want, "{}: {:?}", s.name, out.problems);
        assert!(out.problems.is_empty(), "{}: {:?}", s.name, out.problems);
        seen += 1;
    }
    assert_eq!(seen, 8);
}
