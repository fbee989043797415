//! The types of the functions over elements, of indexes and of the
//! functions of numbers and vectors, and each mismatch at its place.

use super::*;
use situ_grammar::ast::Span;

const DIAG: &str = "diagnostic_msgs/msg/DiagnosticArray";
const SCAN: &str = "sensor_msgs/msg/LaserScan";
const IMU: &str = "sensor_msgs/msg/Imu";

fn typed(text: &str, msg: &'static str) -> Typed {
    let s = Str { value: text.to_string(), span: Span::new(0, text.len()), inner: Some(0) };
    type_of(&s, msg, &crate::msgs::Registry::carried(), FileId(1))
}

fn ty(text: &str, msg: &'static str) -> Ty {
    let t = typed(text, msg);
    let all: Vec<_> =
        [&t.syntax, &t.paths, &t.mismatches, &t.zero_divisions, &t.indexes].into_iter().flatten().collect();
    assert!(all.is_empty(), "{text}: {all:?}");
    t.ty.unwrap_or_else(|| panic!("{text}: no type"))
}

/// The one finding of `text`, its code and the text at its place.
fn finding(text: &str, msg: &'static str) -> (&'static str, String, Diagnostic) {
    let t = typed(text, msg);
    let mut all: Vec<_> =
        [t.syntax, t.paths, t.mismatches, t.zero_divisions, t.indexes].into_iter().flatten().collect();
    assert_eq!(all.len(), 1, "{text}: {all:?}");
    let d = all.remove(0);
    assert!(d.help.is_some(), "{text}: no help: {d:?}");
    let at = text[d.primary.span.start..d.primary.span.end].to_string();
    (d.code, at, d)
}

#[test]
fn functions_over_elements_have_types() {
    assert_eq!(ty("any(status, level >= 2)", DIAG), Ty::Bool);
    assert_eq!(ty("all(status, level == 0 and len(values) > 0)", DIAG), Ty::Bool);
    assert_eq!(ty("count(status, level >= 1)", DIAG), Ty::Int);
    assert_eq!(ty("max(status, level)", DIAG), Ty::Int);
    assert_eq!(ty("min(status, level * 0.5)", DIAG), Ty::Float);
    assert_eq!(ty("mean(status, level)", DIAG), Ty::Float);
    assert_eq!(ty("find(status, name == 'motor')", DIAG), Ty::Msg("diagnostic_msgs/msg/DiagnosticStatus"));
    assert_eq!(ty("find(status, name == 'motor').level", DIAG), Ty::Int);
    assert_eq!(ty("find(status, name == 'motor').values[-1].key", DIAG), Ty::Str);
    assert_eq!(ty("any(status, any(values, key == 'fault' and value != 'ok'))", DIAG), Ty::Bool);
    assert_eq!(ty("count(ranges, it < 0.5)", SCAN), Ty::Int);
    assert_eq!(ty("min(ranges, it * 2)", SCAN), Ty::Float);
    assert_eq!(ty("find(ranges, it > 1)", SCAN), Ty::Float);
    assert_eq!(ty("any(status, it.level > 1)", DIAG), Ty::Bool);
    // An element's own arrays index as at the top.
    assert_eq!(ty("any(status, values[0].key == 'a')", DIAG), Ty::Bool);
}

#[test]
fn indexes_and_index_of() {
    assert_eq!(ty("index(ranges, 0.5)", SCAN), Ty::Int);
    assert_eq!(ty("ranges[index(ranges, 0.5)]", SCAN), Ty::Float);
    assert_eq!(ty("status[-1].level", DIAG), Ty::Int);
    assert_eq!(ty("status[len(status) - 1].name", DIAG), Ty::Str);
    assert_eq!(ty("orientation_covariance[-9]", IMU), Ty::Float);
    assert_eq!(ty("orientation_covariance[2 * 4]", IMU), Ty::Float);
    let (code, at, _) = finding("orientation_covariance[-10]", IMU);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "-10"));
    let (code, at, _) = finding("orientation_covariance[3 * 3]", IMU);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "3 * 3"));
    let (code, at, d) = finding("status[-1].levle", DIAG);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "levle"));
    assert!(d.help.as_deref().unwrap_or("").starts_with("did you mean `level`?"));
    let (code, at, d) = finding("find(status, true).values.key", DIAG);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "key"));
    assert!(d.help.as_deref().unwrap_or("").starts_with("pick an element first"));
    let (code, at, _) = finding("header[-1]", IMU);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "-1"));
}

#[test]
fn functions_of_numbers_and_vectors() {
    assert_eq!(ty("abs(angle_min)", SCAN), Ty::Float);
    assert_eq!(ty("abs(len(ranges) - 3)", SCAN), Ty::Int);
    assert_eq!(ty("sqrt(range_max)", SCAN), Ty::Float);
    assert_eq!(ty("hypot(angle_min, 1)", SCAN), Ty::Float);
    assert_eq!(ty("norm(angular_velocity)", IMU), Ty::Float);
    assert_eq!(ty("norm(orientation)", IMU), Ty::Float);
    assert_eq!(ty("norm(orientation_covariance)", IMU), Ty::Float);
    for f in ["yaw", "pitch", "roll"] {
        assert_eq!(ty(&format!("{f}(orientation)"), IMU), Ty::Float);
    }
}

#[test]
fn mismatches_of_the_new_forms() {
    for (text, msg, at, needs) in [
        ("any(status, level)", DIAG, "level", "`any` needs a condition on the element, found an integer"),
        ("all(status, name)", DIAG, "name", "`all` needs a condition on the element, found a string"),
        ("count(ranges, it)", SCAN, "it", "`count` needs a condition on the element, found a number"),
        ("find(status, 1)", DIAG, "1", "`find` needs a condition on the element, found an integer"),
        ("max(status, name)", DIAG, "name", "`max` needs a number of the element, found a string"),
        ("any(header, true)", DIAG, "header", "`any` needs an array, found a `std_msgs/msg/Header` message"),
        ("index(status, 1)", DIAG, "status", "`index` needs an array of numbers, strings or booleans, found an array of `diagnostic_msgs/msg/DiagnosticStatus` messages"),
        ("index(ranges, 'a')", SCAN, "'a'", "`index` needs a number, found a string"),
        ("abs(header.frame_id)", SCAN, "header.frame_id", "`abs` needs a number, found a string"),
        ("sqrt(ranges)", SCAN, "ranges", "`sqrt` needs a number, found an array of numbers"),
        ("hypot(1, header)", SCAN, "header", "`hypot` needs a number, found a `std_msgs/msg/Header` message"),
        ("yaw(angular_velocity)", IMU, "angular_velocity", "`yaw` needs a quaternion (numeric `x y z w`), found a `geometry_msgs/msg/Vector3` message"),
        ("norm(header)", IMU, "header", "`norm` needs a vector (numeric `x y z`, or an array of numbers), found a `std_msgs/msg/Header` message"),
    ] {
        let (code, found, d) = finding(text, msg);
        assert_eq!((code, found.as_str(), d.message.as_str()), (codes::ROS2_TYPE_MISMATCH, at, needs), "{text}");
    }
}

#[test]
fn the_element_scope_has_only_the_element() {
    // `header` is a field of the message, not of an element of `status`.
    let (code, at, d) = finding("any(status, header.frame_id == 'a')", DIAG);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "header"));
    assert_eq!(d.message, "`diagnostic_msgs/msg/DiagnosticStatus`, an element of `status`, has no field `header`");
    assert!(d.help.unwrap().contains("level, name, message, hardware_id, values; `it` is the element"));
    let (_, _, d) = finding("any(status, levle > 1)", DIAG);
    assert!(d.help.unwrap().starts_with("did you mean `level`?"));
    let (code, at, d) = finding("count(ranges, range_max < 1)", SCAN);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "range_max"));
    assert!(d.help.as_deref().unwrap_or("").starts_with("write `it` for the element"), "{d:?}");
    // Outside the element, `it` is a field name like any other.
    let (code, at, _) = finding("it > 1", SCAN);
    assert_eq!((code, at.as_str()), (codes::ROS2_UNKNOWN_FIELD, "it"));
}

#[test]
fn division_by_a_constant_zero() {
    for (text, at) in
        [("range_max / 0", "0"), ("range_max / (1 - 1)", "1 - 1"), ("1 / -0.0", "-0.0"), ("abs(1 / (2 * 0))", "2 * 0")]
    {
        let (code, found, d) = finding(text, SCAN);
        assert_eq!((code, found.as_str()), (codes::ROS2_ZERO_DIVISION, at), "{text}");
        assert_eq!(d.primary.text, "this is 0");
    }
    for text in ["range_max / 2", "range_max / (1 - 2)", "range_max / range_min", "0 / 1"] {
        assert!(typed(text, SCAN).zero_divisions.is_empty(), "{text}");
    }
}

#[test]
fn an_index_that_is_not_an_integer() {
    for (text, at, found) in [
        ("status[0.0].level", "0.0", "an index must be an integer, found `0.0`"),
        ("status['a'].level", "'a'", "an index must be an integer, found a string"),
        ("status[true].level", "true", "an index must be an integer, found a boolean"),
        ("status[len(status) / 2].level", "len(status) / 2", "an index must be an integer, found a number"),
        ("status[1e0].level", "1e0", "an index must be an integer, found `1e0`"),
        ("status[-1.0].level", "-1.0", "an index must be an integer, found `-1.0`"),
    ] {
        let (code, place, d) = finding(text, DIAG);
        assert_eq!((code, place.as_str(), d.message.as_str()), (codes::ROS2_BAD_INDEX, at, found), "{text}");
    }
    let (_, _, d) = finding("status[0.0]", DIAG);
    assert!(d.help.unwrap().starts_with("write `[0]`"));
    let (_, _, d) = finding("status[-2.0]", DIAG);
    assert!(d.help.unwrap().starts_with("write `[-2]`"));
    let (_, _, d) = finding("status['motor']", DIAG);
    assert!(d.help.unwrap().contains("find(array, name == 'x')"));
}

#[test]
fn syntax_hints_keep_their_help() {
    let (code, at, d) = finding("level = 2", DIAG);
    assert_eq!((code, at.as_str()), (codes::ROS2_BAD_EXPRESSION, "="));
    assert_eq!(d.message, "malformed expression: `=` is not a comparison; write `==`");
    assert_eq!(d.primary.text, "write `==`");
    let (_, at, d) = finding("0 < range_max < 5", SCAN);
    assert_eq!(at, "< 5");
    assert_eq!(d.help.as_deref(), Some("write `0 < range_max and range_max < 5`"));
    let (_, _, d) = finding("cont(ranges, it > 1)", SCAN);
    assert!(d.help.unwrap().starts_with("did you mean `count`?"));
}
