//! Expressions on decoded messages, and the translator on hand-written CDR.

use super::*;
use crate::cdr::Value as M;
use crate::expr;

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
    let mut t = Translator::new(&checked.model, MAP, &Registry::carried(), FileId(1)).unwrap();
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
    let errors = Translator::new(&checked.model, &bad, &Registry::carried(), FileId(1)).unwrap_err();
    assert!(errors.iter().any(|d| d.code == codes::ROS2_UNKNOWN_FIELD));
}

/// A value out of the message's borrow, for comparisons.
#[derive(Debug, PartialEq)]
enum Out {
    Int(i64),
    Float(f64),
    Bool(bool),
    Str(String),
    Node,
}

/// A robot's messages in one: `/diagnostics`' `status`, a `JointState`'s
/// parallel arrays, a `GoalStatusArray`'s `status_list`, a quaternion and a
/// vector.
fn robot() -> M {
    let kv = |k: &str, v: &str| M::Msg(vec![("key", M::Str(k.into())), ("value", M::Str(v.into()))]);
    let status = |level: i64, name: &str, values: Vec<M>| {
        M::Msg(vec![("level", M::Int(level)), ("name", M::Str(name.into())), ("values", M::Array(values))])
    };
    let goal = |status: i64, id: i64| {
        M::Msg(vec![("goal_info", M::Msg(vec![("id", M::Int(id))])), ("status", M::Int(status))])
    };
    let floats = |xs: &[f64]| M::Array(xs.iter().map(|x| M::Float(*x)).collect());
    let strings = |xs: &[&str]| M::Array(xs.iter().map(|x| M::Str(x.to_string())).collect());
    let half = std::f64::consts::FRAC_1_SQRT_2;
    M::Msg(vec![
        (
            "status",
            M::Array(vec![
                status(0, "lidar", vec![kv("rate", "10")]),
                status(2, "motor", vec![kv("temp", "90"), kv("fault", "overheat")]),
                status(1, "battery", vec![]),
            ]),
        ),
        ("quiet", M::Array(vec![])),
        ("name", strings(&["shoulder", "elbow", "wrist"])),
        ("position", floats(&[0.5, -1.25, 2.0])),
        ("velocity", floats(&[0.0, f64::NAN, 1.0])),
        ("status_list", M::Array(vec![goal(4, 7), goal(2, 8)])),
        ("levels", M::Array(vec![M::Int(3), M::Int(-7), M::Int(5)])),
        // A yaw of 90°: (0, 0, sin 45°, cos 45°).
        ("q", M::Msg(vec![("x", M::Float(0.0)), ("y", M::Float(0.0)), ("z", M::Float(half)), ("w", M::Float(half))])),
        ("zero", M::Msg(vec![("x", M::Float(0.0)), ("y", M::Float(0.0)), ("z", M::Float(0.0)), ("w", M::Float(0.0))])),
        ("v", M::Msg(vec![("x", M::Float(3.0)), ("y", M::Float(0.0)), ("z", M::Float(-4.0))])),
        ("min_int", M::Int(i64::MIN)),
    ])
}

fn on(text: &str) -> Result<Out, String> {
    let m = robot();
    let src = Source { expr: expr::parse(text).unwrap_or_else(|e| panic!("{text}: {e:?}")), text: text.to_string() };
    src.eval(&m).map(|v| match v {
        Val::Int(i) => Out::Int(i),
        Val::Float(f) => Out::Float(f),
        Val::Bool(b) => Out::Bool(b),
        Val::Str(s) => Out::Str(s.to_string()),
        Val::Node(_) => Out::Node,
    })
}

fn near(text: &str, want: f64) {
    match on(text) {
        Ok(Out::Float(x)) => assert!((x - want).abs() < 1e-12, "{text}: {x} is not {want}"),
        other => panic!("{text}: {other:?}"),
    }
}

#[test]
fn functions_over_elements() {
    assert_eq!(on("any(status, level >= 2)"), Ok(Out::Bool(true)));
    assert_eq!(on("any(status, level > 2)"), Ok(Out::Bool(false)));
    assert_eq!(on("all(status, level <= 2)"), Ok(Out::Bool(true)));
    assert_eq!(on("all(status, level == 0)"), Ok(Out::Bool(false)));
    assert_eq!(on("count(status, level >= 1)"), Ok(Out::Int(2)));
    assert_eq!(on("max(status, level)"), Ok(Out::Int(2)));
    assert_eq!(on("min(status, level)"), Ok(Out::Int(0)));
    assert_eq!(on("min(status, level - 0.5)"), Ok(Out::Float(-0.5)));
    assert_eq!(on("mean(status, level)"), Ok(Out::Float(1.0)));
    assert_eq!(on("find(status, name == 'motor').level"), Ok(Out::Int(2)));
    assert_eq!(on("find(status, level == 1).name"), Ok(Out::Str("battery".into())));
    assert_eq!(on("find(status, level == 1)"), Ok(Out::Node));
    assert_eq!(on("find(position, it < 0)"), Ok(Out::Float(-1.25)));
    assert_eq!(on("count(position, it > 0)"), Ok(Out::Int(2)));
    // A NaN element (an invalid reading) is skipped, as `min(ranges)` does.
    assert_eq!(on("count(velocity, it >= 0)"), Ok(Out::Int(2)));
    assert_eq!(on("all(velocity, it >= 0)"), Ok(Out::Bool(true)));
    assert_eq!(on("any(velocity, it < 0)"), Ok(Out::Bool(false)));
    assert_eq!(on("max(velocity, it * 2)"), Ok(Out::Float(2.0)));
    assert_eq!(on("find(velocity, it > 0.5)"), Ok(Out::Float(1.0)));
    assert_eq!(on("any(status, it.name == 'lidar')"), Ok(Out::Bool(true)));
    // Empty arrays: any is false, all is true, count is 0.
    assert_eq!(on("any(quiet, level > 0)"), Ok(Out::Bool(false)));
    assert_eq!(on("all(quiet, level > 0)"), Ok(Out::Bool(true)));
    assert_eq!(on("count(quiet, level > 0)"), Ok(Out::Int(0)));
}

#[test]
fn nested_scopes() {
    assert_eq!(on("any(status, any(values, key == 'fault'))"), Ok(Out::Bool(true)));
    assert_eq!(on("count(status, any(values, key == 'fault' or key == 'rate'))"), Ok(Out::Int(2)));
    assert_eq!(on("all(status, all(values, value != ''))"), Ok(Out::Bool(true)));
    assert_eq!(on("find(status, len(values) == 2).values[-1].value"), Ok(Out::Str("overheat".into())));
    assert_eq!(on("max(status, count(values, it.key != ''))"), Ok(Out::Int(2)));
}

#[test]
fn any_and_all_stop_at_the_first_answer() {
    // The second element's `values[5]` is missing, but the first decides.
    assert_eq!(on("any(status, level == 0 or values[5].key == 'x')"), Ok(Out::Bool(true)));
    assert_eq!(on("all(status, level == 1 and values[5].key == 'x')"), Ok(Out::Bool(false)));
}

#[test]
fn indexes_by_value_and_from_the_end() {
    assert_eq!(on("position[index(name, 'elbow')]"), Ok(Out::Float(-1.25)));
    assert_eq!(on("index(name, 'wrist')"), Ok(Out::Int(2)));
    assert_eq!(on("index(levels, 5)"), Ok(Out::Int(2)));
    assert_eq!(on("index(levels, 5.0)"), Ok(Out::Int(2)));
    assert_eq!(on("index(position, 2)"), Ok(Out::Int(2)));
    assert_eq!(on("status_list[-1].status"), Ok(Out::Int(2)));
    assert_eq!(on("status_list[-2].goal_info.id"), Ok(Out::Int(7)));
    assert_eq!(on("status_list[len(status_list) - 1].goal_info.id"), Ok(Out::Int(8)));
    assert_eq!(on("name[-3]"), Ok(Out::Str("shoulder".into())));
    assert_eq!(on("levels[1 + 1]"), Ok(Out::Int(5)));
}

#[test]
fn functions_of_numbers_and_vectors() {
    assert_eq!(on("abs(levels[1])"), Ok(Out::Int(7)));
    assert_eq!(on("abs(position[1])"), Ok(Out::Float(1.25)));
    assert_eq!(on("sqrt(levels[0] + 1)"), Ok(Out::Float(2.0)));
    assert_eq!(on("hypot(3, 4)"), Ok(Out::Float(5.0)));
    assert_eq!(on("norm(v)"), Ok(Out::Float(5.0)));
    near("norm(q)", 1.0);
    near("norm(position)", (0.25f64 + 1.5625 + 4.0).sqrt());
    near("yaw(q)", std::f64::consts::FRAC_PI_2);
    near("pitch(q)", 0.0);
    near("roll(q)", 0.0);
}

#[test]
fn euler_angles_match_a_rotation() {
    // Roll 0.3, pitch -0.2, yaw 1.1 (Z-Y-X), as a quaternion, then back.
    let (r, p, y) = (0.3f64, -0.2f64, 1.1f64);
    let (cr, sr, cp, sp, cy, sy) =
        ((r / 2.0).cos(), (r / 2.0).sin(), (p / 2.0).cos(), (p / 2.0).sin(), (y / 2.0).cos(), (y / 2.0).sin());
    let q = [
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    ];
    // A quaternion of any length gives the same angles.
    let m = M::Msg(vec![(
        "q",
        M::Msg(vec![
            ("x", M::Float(2.0 * q[0])),
            ("y", M::Float(2.0 * q[1])),
            ("z", M::Float(2.0 * q[2])),
            ("w", M::Float(2.0 * q[3])),
        ]),
    )]);
    for (f, want) in [("roll", r), ("pitch", p), ("yaw", y)] {
        let e = expr::parse(&format!("{f}(q)")).unwrap();
        match eval(&e, &m) {
            Ok(Val::Float(x)) => assert!((x - want).abs() < 1e-12, "{f}: {x} is not {want}"),
            other => panic!("{f}: {other:?}"),
        }
    }
}

#[test]
fn missing_values_are_said_alike() {
    let err = |t: &str| on(t).unwrap_err();
    assert_eq!(
        err("find(status, name == 'gps').level"),
        "`find(status, name == 'gps')` is missing: no element of the 3 matches"
    );
    assert_eq!(
        err("position[index(name, 'knee')]"),
        "`index(name, 'knee')` is missing: no element of the 3 equals 'knee'"
    );
    assert_eq!(err("max(quiet, level)"), "`max(quiet, level)` is missing: `max` of an array that is empty");
    assert_eq!(
        err("status_list[-3].status"),
        "`status_list[-3]` is missing: index -3 is before the start of an array of 2"
    );
    assert_eq!(err("status_list[2].status"), "`status_list[2]` is missing: index 2 is past the end of an array of 2");
    assert_eq!(
        err("status_list[1 + 1].status"),
        "`status_list[1 + 1]` is missing: index 2 is past the end of an array of 2"
    );
    assert_eq!(
        err("levels[100000000000000000000]"),
        "`levels[100000000000000000000]` is missing: index 100000000000000000000 is past the end of an array of 3"
    );
    assert_eq!(err("quiet[-1]"), "`quiet[-1]` is missing: index -1 is before the start of an array of 0");
    // A missing value inside an element makes the whole function missing.
    assert!(err("count(status, values[0].key == 'rate')").contains("is missing: index 0 is past the end"));
    // What is wrong, not missing, says so.
    assert_eq!(err("velocity[1] > 0"), "`velocity[1]` is NaN");
    assert_eq!(err("abs(min_int)"), "`abs(min_int)` overflows an integer");
    assert_eq!(err("sqrt(position[1])"), "`sqrt(position[1])` `sqrt` of a negative number (-1.25)");
    assert_eq!(err("yaw(zero)"), "`yaw(zero)` is of a zero quaternion, which has no angles");
    assert_eq!(
        err("levels[min_int]"),
        "`levels[min_int]` is missing: index -9223372036854775808 is before the start of an array of 3"
    );
}

/// A hand-made rules and map on `/diagnostics` with the new forms: each
/// missing value is one problem of its entry, and no event.
#[test]
fn a_missing_value_is_a_problem_of_the_entry() {
    let rules = "states { RUN initial HOT final }\nagent Diag sensor { event HOT_MOTOR { level: i64 } }\n\
                 rule hot { when state == RUN and HOT_MOTOR then HOT }\n";
    let map = "[[event]]\nagent = \"Diag\"\nevent = \"HOT_MOTOR\"\ntopic = \"/diagnostics\"\n\
               type = \"diagnostic_msgs/msg/DiagnosticArray\"\n\
               when = \"any(status, name == 'motor' and any(values, key == 'fault'))\"\n\
               [event.payload]\nlevel = \"find(status, level >= 2).level\"\n";
    let checked = situ_compiler::check_source("diag.situ", rules);
    let mut t =
        Translator::new(&checked.model, map, &Registry::carried(), FileId(1)).unwrap_or_else(|e| panic!("{e:?}"));
    let array = diagnostic_array;
    let hot = array(&[(0, "lidar", &[]), (2, "motor", &[("fault", "overheat")])]);
    let out = t.on_message("/diagnostics", &hot);
    assert!(out.problems.is_empty(), "{:?}", out.problems);
    assert_eq!(out.produced[0].payload, vec![Value::I64(2)]);
    // No fault: the condition is false, no problem.
    let out = t.on_message("/diagnostics", &array(&[(1, "motor", &[])]));
    assert_eq!((out.produced.len(), out.problems.len()), (0, 0));
    assert_eq!(t.stats().failed, 0);
    // A fault at level 1: the condition holds, the payload is missing.
    let out = t.on_message("/diagnostics", &array(&[(1, "motor", &[("fault", "x")])]));
    assert!(out.produced.is_empty());
    assert_eq!(out.problems[0].event.as_deref(), Some("HOT_MOTOR"));
    assert_eq!(out.problems[0].message, "level: `find(status, level >= 2)` is missing: no element of the 1 matches");
    assert_eq!(t.stats().failed, 1);
}

/// The CDR of a DiagnosticArray (header with an empty frame id, then
/// `status`), each status its level, name and key-value pairs.
/// A status of [`diagnostic_array`]: level, name, key-value pairs.
type Status<'a> = (u8, &'a str, &'a [(&'a str, &'a str)]);

fn diagnostic_array(statuses: &[Status<'_>]) -> Vec<u8> {
    let mut b = vec![0u8, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0];
    let string = |b: &mut Vec<u8>, s: &str| {
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        b.extend((s.len() as u32 + 1).to_le_bytes());
        b.extend(s.as_bytes());
        b.push(0);
    };
    b.extend((statuses.len() as u32).to_le_bytes());
    for (level, name, values) in statuses {
        b.push(*level);
        string(&mut b, name);
        string(&mut b, "");
        string(&mut b, "");
        while !b.len().is_multiple_of(4) {
            b.push(0);
        }
        b.extend((values.len() as u32).to_le_bytes());
        for (k, v) in *values {
            string(&mut b, k);
            string(&mut b, v);
        }
    }
    b
}

mod props {
    use super::*;
    use crate::types::{type_of, Ty};
    use proptest::prelude::*;
    use situ_grammar::ast::Span;

    const TOKENS: &[&str] = &[
        "any(", "all(", "count(", "find(", "index(", "min(", "max(", "mean(", "len(", "abs(", "norm(", "yaw(", "sqrt(",
        "hypot(", "status", "values", "level", "name", "key", "value", "it", "header", "frame_id", "stamp", "sec", ",",
        ",", ")", ")", "[", "]", "-1", "0", "1", "2", ".", "+", "-", "*", "/", "==", "!=", "<", ">=", "and", "or",
        "not", "'motor'", "'fault'", "0.5", "true", "(", "=", "&&", "0.0",
    ];

    /// Whether a value is of the type typing gave.
    fn fits(v: &Val<'_>, ty: &Ty) -> bool {
        matches!(
            (ty, v),
            (Ty::Int, Val::Int(_))
                | (Ty::Bool, Val::Bool(_))
                | (Ty::Str, Val::Str(_))
                | (Ty::Float, Val::Float(_))
                | (Ty::Msg(_), Val::Node(cdr::Value::Msg(_)))
                | (Ty::Array(..), Val::Node(cdr::Value::Array(_)))
        )
    }

    /// What may go wrong on a message with an expression that checks clean.
    const AT_RUN_TIME: &[&str] =
        &["is missing: ", "is NaN", "overflows", "division by zero", "of a negative number", "zero quaternion"];

    /// Where a generated expression is read: a DiagnosticArray, one of its
    /// `status` or one of a status' `values`.
    #[derive(Clone, Copy, PartialEq)]
    enum At {
        Top,
        Status,
        Value,
    }

    /// Builds well-typed expressions of a DiagnosticArray from random choices.
    struct Gen {
        choices: Vec<u8>,
        next: usize,
    }

    impl Gen {
        fn pick(&mut self, n: usize) -> usize {
            let c = self.choices.get(self.next).copied().unwrap_or(0);
            self.next += 1;
            c as usize % n
        }

        /// An array of statuses (at the top) or of key-values (in a status).
        fn array(&mut self, at: At, d: usize) -> Option<(String, At)> {
            Some(match (at, self.pick(if d == 0 { 1 } else { 3 })) {
                (At::Top, 0) => ("status".into(), At::Status),
                (At::Top, 1) => (format!("find(status, {}).values", self.cond(At::Status, d - 1)), At::Value),
                (At::Top, _) => (format!("status[{}].values", self.int(At::Top, d - 1)), At::Value),
                (At::Status, _) => ("values".into(), At::Value),
                (At::Value, _) => return None,
            })
        }

        fn cond(&mut self, at: At, d: usize) -> String {
            match self.pick(if d == 0 { 1 } else { 7 }) {
                0 => "true".into(),
                1 => {
                    format!("{} {} {}", self.num(at, d - 1), ["<", ">=", "==", "!="][self.pick(4)], self.num(at, d - 1))
                }
                2 => format!("{} {} {}", self.string(at, d - 1), ["==", "!="][self.pick(2)], self.string(at, d - 1)),
                3 => format!("({} {} {})", self.cond(at, d - 1), ["and", "or"][self.pick(2)], self.cond(at, d - 1)),
                4 => format!("not {}", self.cond(at, d - 1)),
                _ => match self.array(at, d - 1) {
                    Some((arr, el)) => format!("{}({arr}, {})", ["any", "all"][self.pick(2)], self.cond(el, d - 1)),
                    None => "false".into(),
                },
            }
        }

        fn int(&mut self, at: At, d: usize) -> String {
            match (self.pick(if d == 0 { 1 } else { 5 }), at) {
                (0, _) => ["0", "1", "-1", "2"][self.pick(4)].into(),
                (1, At::Status) => "level".into(),
                (1, _) => "header.stamp.sec".into(),
                (2, _) => match self.array(at, d - 1) {
                    Some((arr, el)) => format!("count({arr}, {})", self.cond(el, d - 1)),
                    None => "3".into(),
                },
                (3, _) => match self.array(at, d - 1) {
                    Some((arr, _)) => format!("len({arr}) - {}", self.int(at, d - 1)),
                    None => "0".into(),
                },
                _ => format!("abs({})", self.int(at, d - 1)),
            }
        }

        fn num(&mut self, at: At, d: usize) -> String {
            match self.pick(if d == 0 { 1 } else { 6 }) {
                0 => ["0.5", "2.5", "-1.5"][self.pick(3)].into(),
                1 => self.int(at, d - 1),
                2 => {
                    format!("({} {} {})", self.num(at, d - 1), ["+", "-", "*", "/"][self.pick(4)], self.num(at, d - 1))
                }
                3 => format!("{}({})", ["abs", "sqrt"][self.pick(2)], self.num(at, d - 1)),
                4 => format!("hypot({}, {})", self.num(at, d - 1), self.num(at, d - 1)),
                _ => match self.array(at, d - 1) {
                    Some((arr, At::Status)) => {
                        format!("{}({arr}, {})", ["min", "max", "mean"][self.pick(3)], self.num(At::Status, d - 1))
                    }
                    _ => "1".into(),
                },
            }
        }

        fn string(&mut self, at: At, d: usize) -> String {
            match (self.pick(if d == 0 { 1 } else { 4 }), at) {
                (0, _) => ["'motor'", "'fault'", "'hot'"][self.pick(3)].into(),
                (1, At::Status) => "name".into(),
                (1, At::Value) => ["key", "value", "it.key"][self.pick(3)].into(),
                (1, At::Top) => "header.frame_id".into(),
                (2, At::Top) => format!("find(status, {}).name", self.cond(At::Status, d - 1)),
                (2, At::Status) => format!("values[{}].key", self.int(At::Status, d - 1)),
                _ => match self.array(at, d - 1) {
                    Some((arr, At::Value)) => format!("find({arr}, {}).value", self.cond(At::Value, d - 1)),
                    Some((arr, _)) => format!("{arr}[{}].name", self.int(at, d - 1)),
                    None => "'x'".into(),
                },
            }
        }
    }

    /// Well-typed expressions of a DiagnosticArray, to the depth of 4.
    fn expression() -> impl Strategy<Value = String> {
        proptest::collection::vec(any::<u8>(), 64).prop_map(|choices| {
            let mut g = Gen { choices, next: 0 };
            match g.pick(3) {
                0 => g.cond(At::Top, 4),
                1 => g.num(At::Top, 4),
                _ => g.string(At::Top, 4),
            }
        })
    }

    fn agree(text: &str) -> Result<(), TestCaseError> {
        let s = map::Str { value: text.to_string(), span: Span::new(0, text.len()), inner: Some(0) };
        let typed = type_of(&s, "diagnostic_msgs/msg/DiagnosticArray", &Registry::carried(), FileId(1));
        let findings = || {
            typed
                .syntax
                .iter()
                .chain(&typed.paths)
                .chain(&typed.mismatches)
                .chain(&typed.zero_divisions)
                .chain(&typed.indexes)
        };
        for d in findings() {
            prop_assert!(d.primary.span.end <= text.len() && d.help.is_some(), "{text}: {d:?}");
        }
        let (Some(e), Some(ty), 0) = (&typed.expr, &typed.ty, findings().count()) else { return Ok(()) };
        let decoder = cdr::Decoder::new(&Registry::carried(), "diagnostic_msgs/msg/DiagnosticArray").unwrap();
        for msg in [
            diagnostic_array(&[(0, "lidar", &[("rate", "10")]), (2, "motor", &[("fault", "hot")])]),
            diagnostic_array(&[(1, "motor", &[])]),
            diagnostic_array(&[]),
        ] {
            let m = decoder.decode(&msg).unwrap();
            match eval(e, &m) {
                Ok(v) => prop_assert!(fits(&v, ty), "{text}: {v:?} is not {ty:?}"),
                Err(err) => prop_assert!(
                    AT_RUN_TIME.iter().any(|w| err.message.contains(w)),
                    "{text}: a clean expression failed: {err:?}"
                ),
            }
        }
        Ok(())
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(1000))]

        /// Any sequence of the expressions' tokens parses or fails without a
        /// panic, and its findings have places and helps.
        #[test]
        fn token_soup(toks in proptest::collection::vec(proptest::sample::select(TOKENS), 1..16)) {
            agree(&toks.join(" "))?;
        }

        /// An expression that checks clean evaluates to a value of its type,
        /// or fails only for what the message holds (a missing value, NaN…).
        #[test]
        fn typing_and_evaluation_agree(text in expression()) {
            agree(&text)?;
        }
    }
}

/// The expression `text` on messages of type `msg`, its constants replaced
/// as the translator replaces them (typing resolves them, scopes included).
fn with_constants(msg: &'static str, text: &str) -> Expr {
    let s = map::Str { value: text.into(), span: situ_grammar::ast::Span::new(0, 0), inner: None };
    let typed = crate::types::type_of(&s, msg, &Registry::carried(), FileId(1));
    assert!(typed.paths.is_empty() && typed.mismatches.is_empty(), "{text}: {typed:?}");
    let mut e = typed.expr.expect("parsed");
    constants(&mut e, &typed.constants);
    e
}

#[test]
fn constants_evaluate_to_their_values() {
    let m = M::Msg(vec![("power_supply_status", M::Int(1)), ("present", M::Bool(true))]);
    let run = |msg: &'static str, text: &str| {
        eval(&with_constants(msg, text), &m).map(|v| format!("{v:?}")).map_err(|e| e.message)
    };
    let battery = "sensor_msgs/msg/BatteryState";
    assert_eq!(run(battery, "power_supply_status == POWER_SUPPLY_STATUS_CHARGING"), Ok("Bool(true)".into()));
    assert_eq!(run(battery, "present and POWER_SUPPLY_STATUS_FULL - 1 > 2"), Ok("Bool(true)".into()));
    assert_eq!(run("diagnostic_msgs/msg/DiagnosticArray", "DiagnosticStatus.STALE"), Ok("Int(3)".into()));
    assert_eq!(run("action_msgs/msg/GoalStatusArray", "GoalStatus.STATUS_ABORTED"), Ok("Int(6)".into()));
    // A field of the name is the field, not a constant.
    assert_eq!(run(battery, "power_supply_status"), Ok("Int(1)".into()));
}

#[test]
fn constants_in_an_elements_scope_are_the_elements() {
    let goal = |status: i64| M::Msg(vec![("status", M::Int(status))]);
    let m = M::Msg(vec![("status_list", M::Array(vec![goal(4), goal(6), goal(2)]))]);
    let run = |text: &str| {
        eval(&with_constants("action_msgs/msg/GoalStatusArray", text), &m)
            .map(|v| format!("{v:?}"))
            .map_err(|e| e.message)
    };
    assert_eq!(run("any(status_list, status == STATUS_ABORTED)"), Ok("Bool(true)".into()));
    assert_eq!(run("count(status_list, status == GoalStatus.STATUS_SUCCEEDED)"), Ok("Int(1)".into()));
    assert_eq!(run("status_list[-1].status == GoalStatus.STATUS_EXECUTING"), Ok("Bool(true)".into()));
    assert_eq!(run("all(status_list, status != STATUS_CANCELED)"), Ok("Bool(true)".into()));
}
