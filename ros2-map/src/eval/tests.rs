//! Expressions on decoded messages, and the translator on hand-written CDR.

use super::*;
use crate::cdr::Value as M;

fn msg() -> M {
    let status = |level: i64, hw: &str| {
        M::Msg(vec![("level", M::Int(level)), ("hardware_id", M::Str(hw.into())), ("values", M::Array(vec![]))])
    };
    M::Msg(vec![
        ("ranges", M::Array(vec![M::Float(f64::NAN), M::Float(0.25), M::Float(f64::INFINITY)])),
        ("empty", M::Array(vec![])),
        ("nans", M::Array(vec![M::Float(f64::NAN)])),
        ("ints", M::Array(vec![M::Int(3), M::Int(-2)])),
        ("x", M::Float(2.0)),
        ("n", M::Int(i64::MAX)),
        ("nan", M::Float(f64::NAN)),
        ("ok", M::Bool(true)),
        ("status", M::Array(vec![status(2, "base")])),
        ("none", M::Array(vec![])),
    ])
}

fn run(text: &str) -> Result<Val<'static>, String> {
    let e = expr::parse(text).unwrap();
    let m = msg();
    let src = Source { expr: e, text: text.to_string() };
    src.eval(&m).map(|v| match v {
        Val::Int(i) => Val::Int(i),
        Val::Float(f) => Val::Float(f),
        Val::Bool(b) => Val::Bool(b),
        Val::Str(s) => Val::Str(if s == "base" { "base" } else { "?" }),
        Val::Node(_) => Val::Str("node"),
    })
}

#[test]
fn values() {
    assert_eq!(run("min(ranges)"), Ok(Val::Float(0.25)));
    assert_eq!(run("max(ranges)"), Ok(Val::Float(f64::INFINITY)));
    assert_eq!(run("min(ints) * 2"), Ok(Val::Int(-4)));
    assert_eq!(run("max(ints)"), Ok(Val::Int(3)));
    assert_eq!(run("mean(ints)"), Ok(Val::Float(0.5)));
    assert_eq!(run("len(ranges) + len(empty)"), Ok(Val::Int(3)));
    assert_eq!(run("x * 3.6 - 1"), Ok(Val::Float(6.2)));
    assert_eq!(run("x / 4"), Ok(Val::Float(0.5)));
    assert_eq!(run("-x < 0 and not (ok == false)"), Ok(Val::Bool(true)));
    assert_eq!(run("status[0].hardware_id == 'base' and status[0].level >= 1"), Ok(Val::Bool(true)));
    assert_eq!(run("status[0].hardware_id"), Ok(Val::Str("base")));
    assert_eq!(run("len(status) > 1 or x > 1"), Ok(Val::Bool(true)));
}

#[test]
fn short_circuit_guards_an_index() {
    assert_eq!(run("len(none) > 0 and none[0].level > 1"), Ok(Val::Bool(false)));
    assert_eq!(run("len(none) == 0 or none[0].level > 1"), Ok(Val::Bool(true)));
}

#[test]
fn errors_are_values() {
    let err = |t: &str| run(t).unwrap_err();
    assert_eq!(err("min(empty)"), "`min(empty)` is missing: `min` of an array that is empty");
    assert_eq!(err("mean(nans) > 1"), "`mean(nans)` is missing: `mean` of an array that is all 1 NaN");
    assert_eq!(err("x / (x - 2)"), "`x / (x - 2)` division by zero");
    assert_eq!(err("nan + 1"), "`nan` is NaN");
    assert_eq!(err("n + 1"), "`n + 1` overflows an integer");
    assert_eq!(err("-n - 2"), "`-n - 2` overflows an integer");
    assert_eq!(err("none[0].level"), "`none[0]` is missing: index 0 is past the end of an array of 0");
    assert_eq!(err("max(ranges) - max(ranges) > 0"), "`max(ranges) - max(ranges)` is NaN");
    assert!(err("missing > 1").contains("no field `missing`"));
    assert!(err("ok + 1").contains("`+` of a boolean and an integer"));
}

#[test]
fn payload_values() {
    let sym = Type::Symbols(vec!["warn".into(), "error".into()]);
    assert_eq!(to_payload(Val::Str("error"), &sym), Ok(Value::Symbol(1)));
    assert_eq!(to_payload(Val::Str("fatal"), &sym).unwrap_err().to_string(), "`fatal` is not one of warn, error");
    assert_eq!(to_payload(Val::Int(3), &Type::F64), Ok(Value::F64(3.0)));
    assert_eq!(to_payload(Val::Int(3), &Type::I64), Ok(Value::I64(3)));
    assert_eq!(to_payload(Val::Bool(true), &Type::Bool), Ok(Value::Bool(true)));
    assert!(to_payload(Val::Float(f64::INFINITY), &Type::F64).unwrap_err().to_string().contains("inf"));
    assert!(to_payload(Val::Float(0.5), &Type::I64).is_err());
}

const RULES: &str = include_str!("../../../tests/ros2/delivery.situ");
const MAP: &str = include_str!("../../../tests/ros2/delivery.toml");

/// A LaserScan of `ranges`, written by hand (little-endian).
fn scan(ranges: &[f32]) -> Vec<u8> {
    let mut b = vec![0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0];
    b.extend([0u8; 28]);
    b.extend((ranges.len() as u32).to_le_bytes());
    ranges.iter().for_each(|r| b.extend(r.to_le_bytes()));
    b.extend([0u8; 4]);
    b
}

#[test]
fn delivery_scan_by_hand() {
    let checked = situ_compiler::check_source("delivery.situ", RULES);
    let mut t = Translator::new(&checked.model, MAP, FileId(1)).unwrap();
    let topics: Vec<_> = t.topics().collect();
    assert_eq!(topics[0], ("/scan", "sensor_msgs/msg/LaserScan"));
    let (lidar, obstacle, clear) = (
        checked.model.agent_id("Lidar").unwrap().0,
        checked.model.event_id("OBSTACLE").unwrap().0,
        checked.model.event_id("CLEAR").unwrap().0,
    );
    let out = t.on_message("/scan", &scan(&[1.0, 0.25, f32::NAN]));
    assert_eq!(out.produced, vec![Produced { agent: lidar, event: obstacle, payload: vec![Value::F64(0.25)] }]);
    let out = t.on_message("/scan", &scan(&[1.0, f32::INFINITY]));
    assert_eq!(out.produced, vec![Produced { agent: lidar, event: clear, payload: vec![] }]);
    let out = t.on_message("/scan", &scan(&[]));
    assert!(out.produced.is_empty());
    assert_eq!(out.problems.len(), 2, "{:?}", out.problems);
    assert_eq!(out.problems[0].event.as_deref(), Some("OBSTACLE"));
    assert_eq!(out.problems[0].message, "when: `min(ranges)` is missing: `min` of an array that is empty");
    let out = t.on_message("/scan", &scan(&[1.0])[..20]);
    assert_eq!(out.problems[0].event, None);
    assert!(out.problems[0].message.starts_with("LaserScan: "), "{:?}", out.problems);
    assert_eq!(t.on_message("/nowhere", &[]).problems[0].message, "the map reads no topic `/nowhere`");
    assert_eq!(t.stats(), Stats { messages: 5, refused: 2, failed: 2, produced: 2 });
}

#[test]
fn a_map_with_errors_is_refused() {
    let checked = situ_compiler::check_source("delivery.situ", RULES);
    let bad = MAP.replace("min(ranges) < 0.5", "min(rangez) < 0.5");
    let errors = Translator::new(&checked.model, &bad, FileId(1)).unwrap_err();
    assert!(errors.iter().any(|d| d.code == codes::ROS2_UNKNOWN_FIELD));
}
