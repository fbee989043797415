//! The carried definitions, the search path and its precedence, schemas.

use super::*;
use crate::msgs::search::Place;
use std::fs;
use std::path::{Path, PathBuf};

fn carried() -> Registry {
    Registry::carried()
}

fn names(r: &Registry, msg: &str) -> Vec<&'static str> {
    r.fields(msg).into_iter().map(|(n, _)| n).collect()
}

#[test]
fn every_carried_definition_parses_and_resolves() {
    let r = carried();
    let mut count = 0;
    for (name, entry) in r.inner.packages.values().flat_map(|p| p.types().iter()) {
        let def = entry.as_ref().unwrap_or_else(|e| panic!("{name}: {e}"));
        r.resolve(name).unwrap_or_else(|e| panic!("{name}: {e:?}"));
        assert_eq!(r.fields(name).len(), def.fields.len(), "{name}");
        count += 1;
    }
    assert!(count > 150, "{count} types");
    for pkg in [
        "builtin_interfaces",
        "std_msgs",
        "geometry_msgs",
        "sensor_msgs",
        "nav_msgs",
        "diagnostic_msgs",
        "action_msgs",
        "unique_identifier_msgs",
        "lifecycle_msgs",
        "trajectory_msgs",
        "control_msgs",
    ] {
        assert!(!r.package_types(pkg).is_empty(), "{pkg}");
    }
    for std in ["Int8", "UInt8", "Int16", "UInt16", "UInt32", "UInt64", "Float64MultiArray", "MultiArrayLayout"] {
        assert!(r.lookup(&format!("std_msgs/{std}")).is_some(), "{std}");
    }
}

#[test]
fn real_messages_are_exact() {
    let r = carried();
    assert_eq!(names(&r, "sensor_msgs/msg/JointState"), ["header", "name", "position", "velocity", "effort"]);
    assert_eq!(
        r.field("sensor_msgs/JointState", "name"),
        Some(FieldType::Array(Box::new(FieldType::Prim(Prim::String)), None))
    );
    assert_eq!(names(&r, "action_msgs/msg/GoalStatusArray"), ["status_list"]);
    assert_eq!(names(&r, "action_msgs/msg/GoalStatus"), ["goal_info", "status"]);
    assert_eq!(names(&r, "action_msgs/msg/GoalInfo"), ["goal_id", "stamp"]);
    assert_eq!(
        r.field("unique_identifier_msgs/msg/UUID", "uuid"),
        Some(FieldType::Array(Box::new(FieldType::Prim(Prim::Int)), Some(16)))
    );
    assert_eq!(
        r.constant("action_msgs/msg/GoalStatus", "STATUS_ABORTED").map(|c| &c.value),
        Some(&idl::ConstValue::Int(6))
    );
    assert_eq!(
        names(&r, "control_msgs/msg/JointTrajectoryControllerState"),
        [
            "header",
            "joint_names",
            "reference",
            "feedback",
            "error",
            "output",
            "multi_dof_joint_names",
            "multi_dof_reference",
            "multi_dof_feedback",
            "multi_dof_error",
            "multi_dof_output",
            "speed_scaling_factor"
        ]
    );
    assert_eq!(
        r.field("control_msgs/msg/JointTrajectoryControllerState", "feedback"),
        Some(FieldType::Msg("trajectory_msgs/msg/JointTrajectoryPoint"))
    );
    assert_eq!(names(&r, "diagnostic_msgs/msg/DiagnosticArray"), ["header", "status"]);
    assert_eq!(
        names(&r, "diagnostic_msgs/msg/DiagnosticStatus"),
        ["level", "name", "message", "hardware_id", "values"]
    );
    let c: Vec<&str> = r.constants("diagnostic_msgs/msg/DiagnosticStatus").iter().map(|c| c.name.as_str()).collect();
    assert_eq!(c, ["OK", "WARN", "ERROR", "STALE"]);
    // The action of control_msgs, and what ROS 2 generates of it.
    assert!(r.lookup("control_msgs/action/GripperCommand_FeedbackMessage").is_some());
    assert_eq!(names(&r, "control_msgs/action/GripperCommand_FeedbackMessage"), ["goal_id", "feedback"]);
}

#[test]
fn unknown_types_say_why() {
    let r = carried();
    assert_eq!(r.resolve("LaserScan"), Err(TypeError::Malformed));
    assert_eq!(r.resolve("robot_msgs/msg/Arm"), Err(TypeError::UnknownPackage { package: "robot_msgs".into() }));
    match r.resolve("sensor_msgs/Nothing") {
        Err(TypeError::UnknownType { package, known }) => {
            assert_eq!(package, "sensor_msgs");
            assert!(known.iter().any(|k| k == "JointState"), "{known:?}");
        }
        other => panic!("{other:?}"),
    }
}

/// A fresh temporary folder for one test.
pub(crate) fn temp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("situ-msgs-{name}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    fs::create_dir_all(&dir).unwrap();
    dir
}

fn write(path: &Path, text: &str) {
    fs::create_dir_all(path.parent().unwrap()).unwrap();
    fs::write(path, text).unwrap();
}

#[test]
fn the_three_forms_of_a_user_folder() {
    let root = temp("forms");
    // A prefix, a folder of packages, one package.
    write(&root.join("prefix/share/arm_msgs/msg/Arm.msg"), "float64[6] joints\n");
    write(&root.join("pkgs/grip_msgs/msg/Grip.msg"), "bool closed\n");
    write(&root.join("pkgs/grip_msgs/srv/Close.srv"), "float64 force\n---\nbool ok\n");
    write(&root.join("base_msgs/msg/Base.msg"), "uint8 MODE_AUTO = 2\nuint8 mode\n");
    let user = [root.join("prefix"), root.join("pkgs"), root.join("base_msgs")];
    let r = Registry::load(&SearchPath::with_ament(&user, None));
    assert_eq!(names(&r, "arm_msgs/Arm"), ["joints"]);
    assert_eq!(names(&r, "grip_msgs/Grip"), ["closed"]);
    assert_eq!(names(&r, "grip_msgs/srv/Close_Response"), ["ok"]);
    assert_eq!(names(&r, "base_msgs/Base"), ["mode"]);
    assert!(r.lookup("std_msgs/Header").is_some(), "the carried ones come last");
    let _ = fs::remove_dir_all(root);
}

#[test]
fn a_package_is_read_when_one_of_its_types_is_looked_up() {
    let root = temp("lazy");
    write(&root.join("a_msgs/msg/A.msg"), "bool ok\n");
    write(&root.join("b_msgs/msg/B.msg"), "bool ok\n");
    let r = Registry::load(&SearchPath::with_ament(std::slice::from_ref(&root), None));
    let loaded = |p: &str| r.inner.packages[p].types.get().is_some();
    assert!(!loaded("a_msgs") && !loaded("b_msgs") && !loaded("std_msgs"));
    assert!(r.lookup("a_msgs/A").is_some());
    assert!(loaded("a_msgs") && !loaded("b_msgs") && !loaded("std_msgs"));
    // A file removed after the listing is an error of its type, not a crash.
    fs::remove_file(root.join("b_msgs/msg/B.msg")).unwrap();
    assert!(matches!(r.resolve("b_msgs/B"), Err(TypeError::Broken(e)) if e.line == 0));
    let _ = fs::remove_dir_all(root);
}

#[test]
fn the_first_place_of_a_package_wins() {
    let root = temp("precedence");
    write(&root.join("user/std_msgs/msg/Bool.msg"), "bool mine\n");
    write(&root.join("ament/share/std_msgs/msg/Bool.msg"), "bool theirs\n");
    write(&root.join("ament/share/sensor_msgs/msg/Extra.msg"), "std_msgs/Bool b\n");
    let r = Registry::load(&SearchPath::with_ament(&[root.join("user")], Some(&root.join("ament"))));
    assert_eq!(names(&r, "std_msgs/Bool"), ["mine"]);
    // A package is never merged: std_msgs is the user's only, sensor_msgs AMENT's only.
    assert!(r.lookup("std_msgs/Header").is_none());
    assert!(r.lookup("sensor_msgs/LaserScan").is_none());
    assert_eq!(names(&r, "sensor_msgs/Extra"), ["b"]);
    let sp = r.search_path();
    assert_eq!(sp.places.len(), 3);
    assert_eq!(sp.places[1], Place::Ament(root.join("ament")));
    assert!(sp.describe().ends_with("the definitions situ carries"), "{}", sp.describe());
    let _ = fs::remove_dir_all(root);
}

#[test]
fn broken_definitions_are_errors_of_their_types() {
    let root = temp("broken");
    write(&root.join("robot_msgs/msg/Bad.msg"), "bool ok\nfloat65 x\n");
    write(&root.join("robot_msgs/msg/UsesBad.msg"), "Bad b\n");
    write(&root.join("robot_msgs/msg/Missing.msg"), "# doc\nNowhere n\n");
    write(&root.join("robot_msgs/msg/Good.msg"), "bool ok\n");
    let r = Registry::load(&SearchPath::with_ament(std::slice::from_ref(&root), None));
    assert!(r.lookup("robot_msgs/Good").is_some());
    for (ty, line, what) in [
        ("robot_msgs/Bad", 2, "`float65` is not a type"),
        ("robot_msgs/UsesBad", 2, "`float65` is not a type"),
        ("robot_msgs/Missing", 2, "`robot_msgs/msg/Nowhere`, which is not found"),
    ] {
        match r.resolve(ty) {
            Err(TypeError::Broken(e)) => {
                assert_eq!(e.line, line, "{ty}: {e}");
                assert!(e.message.contains(what), "{ty}: {e}");
            }
            other => panic!("{ty}: {other:?}"),
        }
    }
    match r.resolve("robot_msgs/Bad") {
        Err(TypeError::Broken(e)) => assert!(e.file.ends_with("Bad.msg"), "{}", e.file),
        other => panic!("{other:?}"),
    }
    let _ = fs::remove_dir_all(root);
}

#[test]
fn schemas_as_rosbag2_writes_them() {
    let r = carried();
    let s = r.schema("geometry_msgs/msg/PoseStamped").unwrap();
    let sep = "=".repeat(80);
    let parts: Vec<&str> = s.split(&format!("{sep}\n")).collect();
    let heads: Vec<&str> = parts[1..].iter().map(|p| p.lines().next().unwrap()).collect();
    assert_eq!(
        heads,
        [
            "MSG: std_msgs/msg/Header",
            "MSG: builtin_interfaces/msg/Time",
            "MSG: geometry_msgs/msg/Pose",
            "MSG: geometry_msgs/msg/Point",
            "MSG: geometry_msgs/msg/Quaternion"
        ]
    );
    assert!(parts[0].contains("std_msgs/Header header"));
    // The real text, comments included.
    assert!(parts[1].contains("# Standard metadata for higher-level stamped data types."), "{}", parts[1]);
    assert!(r.schema("std_msgs/msg/Nothing").is_none());
}
