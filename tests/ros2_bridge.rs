//! `situ ros2`, the bridge, against ROS 2's own middleware: Eclipse Cyclone
//! DDS (the `cyclonedds` Python package, `bridge-ros2/tests/peer.py`) plays
//! the AMR of `tests/ros2/amr.situ` — its lifecycle nodes, its laser, goals
//! and navigator, and a late subscriber of `/situ/state` — over DDS on this
//! host. The bridge runs as a user runs it, the real binary. A last scenario
//! has rules of their own (`tests/ros2/heartbeat.situ`) that read
//! `/diagnostics`, where the bridge writes its own status: it must not read
//! it back.
//!
//! A missing `python3` or `cyclonedds` fails the test: install the test
//! requirements with `python3 -m pip install -r examples/python/requirements.txt`.
#![cfg(feature = "ros2")]

use serde_json::Value as Json;
use std::collections::BTreeMap;
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

fn root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The rules and the map of the AMR.
const AMR: (&str, &str) = ("tests/ros2/amr.situ", "tests/ros2/amr.toml");
/// The AMR's nodes and publishers, and the heartbeat scenario.
const PEER: &str = "bridge-ros2/tests/peer.py";
/// The recipe of docs/ros2.md, "A manipulator": its rules, its map (a
/// package of the robot's own through `msg_path`), and its peer.
const MANIPULATOR: (&str, &str) =
    ("tests/ros2/manipulator/manipulator.situ", "tests/ros2/manipulator/manipulator.toml");
const MANIPULATOR_PEER: &str = "bridge-ros2/tests/manipulator_peer.py";

fn bridge((rules, map): (&str, &str), domain: u16, extra: &[&std::ffi::OsStr]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_situ"))
        .current_dir(root())
        .args(["ros2", rules, "--map", map, "--rmw", "cyclonedds"])
        .args(["--domain", &domain.to_string(), "--duration", "60"])
        .args(extra)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the situ binary")
}

/// Runs the peer's scenario beside a bridge; the peer's lines, and the
/// bridge's exit code and stderr after a Ctrl-C.
fn scenario(name: &str, domain: u16, extra: &[&std::ffi::OsStr]) -> (Vec<Json>, i32, String) {
    scenario_then(AMR, PEER, name, domain, extra, libc::SIGINT, Duration::ZERO)
}

/// As [`scenario`], the bridge stopped by `signal` `after` the peer ended.
fn scenario_then(
    files: (&str, &str),
    peer: &str,
    name: &str,
    domain: u16,
    extra: &[&std::ffi::OsStr],
    signal: i32,
    after: Duration,
) -> (Vec<Json>, i32, String) {
    let mut bridge = bridge(files, domain, extra);
    let peer = Command::new("python3")
        .current_dir(root())
        .args([peer, name, "--domain", &domain.to_string()])
        .output()
        .unwrap_or_else(|e| panic!("cannot run python3 ({e}): the test needs python3 with cyclonedds"));
    std::thread::sleep(after);
    // SAFETY: kill(2) on our own child's pid; SIGINT is what Ctrl-C sends.
    unsafe { libc::kill(bridge.id() as i32, signal) };
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(s) = bridge.try_wait().expect("wait") {
            break s;
        }
        assert!(Instant::now() < deadline, "the bridge did not stop on SIGINT");
        std::thread::sleep(Duration::from_millis(20));
    };
    let out = bridge.wait_with_output().expect("the bridge's output");
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    let text = String::from_utf8_lossy(&peer.stdout).to_string();
    assert_eq!(
        peer.status.code(),
        Some(0),
        "the peer failed ({}); it needs cyclonedds (examples/python/requirements.txt)\npeer:\n{text}{}\nbridge:\n{stderr}",
        peer.status,
        String::from_utf8_lossy(&peer.stderr),
    );
    let lines = text.lines().map(|l| serde_json::from_str(l).expect("a JSON line")).collect();
    (lines, status.code().unwrap_or(-1), stderr)
}

/// The lifecycle requests the nodes answered, in order: (node, transition).
fn transitions(lines: &[Json]) -> Vec<(String, String)> {
    lines
        .iter()
        .filter_map(|l| l.get("transition"))
        .map(|t| (t["node"].as_str().unwrap().to_string(), t["label"].as_str().unwrap().to_string()))
        .collect()
}

fn states(lines: &[Json]) -> Vec<&str> {
    lines.iter().filter_map(|l| l.get("state")?.as_str()).collect()
}

/// The links between the lifecycle nodes in each state of amr.situ (writer, reader).
fn links(state: &str) -> &'static [(&'static str, &'static str)] {
    match state {
        "NAVIGATING" => &[("/costmap", "/planner"), ("/planner", "/controller")],
        "RECOVERING" => &[("/costmap", "/recovery"), ("/recovery", "/controller")],
        _ => &[],
    }
}

#[test]
fn a_mission_drives_the_lifecycle_nodes_in_order() {
    let bag = std::env::temp_dir().join(format!("situ-ros2-bag-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&bag);
    let (lines, code, stderr) = scenario("mission", 41, &["--record".as_ref(), bag.as_os_str()]);
    assert_eq!(code, 0, "{stderr}");
    assert!(lines.iter().any(|l| l.get("done").is_some()), "{lines:?}");
    let sent = transitions(&lines);
    let (configure, rest) = sent.split_at(4);
    let mut configured: Vec<&str> =
        configure.iter().filter_map(|(n, l)| (l == "configure").then_some(n.as_str())).collect();
    configured.sort();
    assert_eq!(configured, ["/controller", "/costmap", "/planner", "/recovery"], "{sent:?}");
    let pairs = |xs: &[(&str, &str)]| xs.iter().map(|(n, l)| (n.to_string(), l.to_string())).collect::<Vec<_>>();
    let expected = pairs(&[
        // NAVIGATING: writers first.
        ("/costmap", "activate"),
        ("/planner", "activate"),
        ("/controller", "activate"),
        // RECOVERING: the controller gets its new writer before losing the old one.
        ("/recovery", "activate"),
        ("/planner", "deactivate"),
        // NAVIGATING again.
        ("/planner", "activate"),
        ("/recovery", "deactivate"),
        // ARRIVED: readers first.
        ("/controller", "deactivate"),
        ("/planner", "deactivate"),
        ("/costmap", "deactivate"),
    ]);
    assert_eq!(rest, expected.as_slice());
    // The late subscriber got IDLE (latched), then every change in order.
    assert_eq!(states(&lines), ["IDLE", "NAVIGATING", "RECOVERING", "NAVIGATING", "ARRIVED"]);

    // Never a reader active without its writer, in the links of the state entered.
    let mut active: BTreeMap<String, bool> = BTreeMap::new();
    let mut state = "IDLE";
    for l in &lines {
        if let Some(s) = l.get("state").and_then(Json::as_str) {
            state = s;
        }
        if let Some(t) = l.get("transition") {
            active.insert(t["node"].as_str().unwrap().into(), t["to"] == "active");
            for (w, r) in links(state) {
                if active.get(*r) == Some(&true) && t["label"] == "activate" {
                    assert_eq!(active.get(*w), Some(&true), "{r} active without {w} in {state}: {l}");
                }
            }
        }
    }

    // /situ/agents: the planner asleep and inactive at the end, the controller's node named.
    let last = lines.iter().rev().find_map(|l| l.get("agents")).expect("an /situ/agents message");
    assert_eq!(last["Planner"]["message"], "sleeping");
    assert_eq!(last["Planner"]["lifecycle"], "inactive");
    assert_eq!(last["Scan"]["lifecycle"], Json::Null);
    // The bridge's own account.
    assert!(stderr.contains("ended in ARRIVED"), "{stderr}");
    assert!(stderr.contains("message to first lifecycle request: p50"), "{stderr}");

    // The recording is a ROS 2 bag that rosbags (PyPI) reads with no type
    // but the bag's own definitions.
    assert_mission_bag(&read_bag(&bag));
    std::fs::remove_dir_all(&bag).unwrap();
}

fn read_bag(bag: &Path) -> Json {
    let out = Command::new("python3").arg(root().join("bridge-ros2/tests/read_bag.py")).arg(bag).output().unwrap();
    assert!(
        out.status.success(),
        "rosbags could not read the bag ({}): {}; the test needs rosbags (examples/python/requirements.txt)",
        out.status,
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

fn assert_mission_bag(read: &Json) {
    assert_eq!(read["states"], serde_json::json!(["IDLE", "NAVIGATING", "RECOVERING", "NAVIGATING", "ARRIVED"]));
    assert_eq!(read["types"]["/scan"], "sensor_msgs/msg/LaserScan");
    assert_eq!(read["types"]["/situ/agents"], "diagnostic_msgs/msg/DiagnosticArray");
    assert_eq!(read["counts"]["/goal_reached"].as_u64().map(|n| n >= 1), Some(true));
    // The last scan the peer sent was clear (1.5 m), and it was recorded as sent.
    assert_eq!(read["nearest"].as_f64(), Some(1.5));
}

#[test]
fn a_killed_bridge_leaves_a_bag_that_reads_up_to_its_last_second() {
    let bag = std::env::temp_dir().join(format!("situ-ros2-killed-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&bag);
    // SIGKILL 1.5 s after the mission: no clean end, one flush (a second) since the last message.
    let (lines, code, _) = scenario_then(
        AMR,
        PEER,
        "mission",
        43,
        &["--record".as_ref(), bag.as_os_str()],
        libc::SIGKILL,
        Duration::from_millis(1500),
    );
    assert_eq!(code, -1, "killed, not exited");
    assert!(lines.iter().any(|l| l.get("done").is_some()));
    assert_mission_bag(&read_bag(&bag));
    std::fs::remove_dir_all(&bag).unwrap();
}

#[test]
fn a_node_that_never_answers_is_its_failure_event() {
    let (lines, code, stderr) = scenario("silent-planner", 42, &[]);
    assert_eq!(code, 0, "{stderr}");
    assert!(lines.iter().any(|l| l.get("done").is_some()), "{lines:?}");
    assert_eq!(states(&lines).last(), Some(&"FAULT"));
    let errors: Vec<&str> = lines.iter().filter_map(|l| l.get("error")?.as_str()).collect();
    assert!(errors.iter().any(|e| e.contains("/planner did not answer configure within 500ms")), "{errors:?}");
    // Nothing was activated: FAULT wants every node asleep.
    assert!(transitions(&lines).iter().all(|(_, l)| l == "configure"), "{lines:?}");
    assert!(stderr.contains("ended in FAULT") && stderr.contains("1 failures"), "{stderr}");
}

/// A map that reads `/diagnostics`, where the bridge writes its own status
/// once a second (`tests/ros2/heartbeat.toml`: any status is a fault). The
/// bridge ignores its own writers: the rules stay in RUNNING through three
/// of its statuses, and move to FAULT on the first the peer writes.
#[test]
fn the_bridge_does_not_read_its_own_status() {
    let files = ("tests/ros2/heartbeat.situ", "tests/ros2/heartbeat.toml");
    let (lines, code, stderr) = scenario_then(files, PEER, "heartbeat", 45, &[], libc::SIGINT, Duration::ZERO);
    assert_eq!(code, 0, "{stderr}");
    assert!(lines.iter().any(|l| l.get("done").is_some()), "{lines:?}\n{stderr}");
    assert_eq!(states(&lines), ["RUNNING", "FAULT"], "{stderr}");
    let ignored = lines.iter().find(|l| l["step"] == "own status ignored").expect("the quiet part");
    assert!(ignored["statuses"].as_u64().is_some_and(|n| n >= 3), "{ignored}");
    // The bridge took its own statuses off its reader and let them go.
    let own: u64 = stderr
        .lines()
        .find_map(|l| l.strip_prefix("situ ros2: ")?.split_once(" messages of its own writers ignored"))
        .and_then(|(n, _)| n.parse().ok())
        .unwrap_or_else(|| panic!("no count of ignored messages: {stderr}"));
    assert!(own >= 3, "{stderr}");
    assert!(stderr.contains("ended in FAULT") && stderr.contains("1 state changes"), "{stderr}");
    // The map's warning is said when the bridge starts, not only by `situ check`.
    assert!(stderr.contains("W0421"), "{stderr}");
}

/// A manipulator scenario (`manipulator_peer.py`): the states the peer saw
/// on `/situ/state`, and the bridge's stderr.
fn manipulator(name: &str, domain: u16, extra: &[&std::ffi::OsStr]) -> (Vec<String>, String) {
    let (lines, code, stderr) =
        scenario_then(MANIPULATOR, MANIPULATOR_PEER, name, domain, extra, libc::SIGINT, Duration::ZERO);
    assert_eq!(code, 0, "{stderr}");
    assert!(lines.iter().any(|l| l.get("done").is_some()), "{lines:?}\n{stderr}");
    (states(&lines).into_iter().map(str::to_string).collect(), stderr)
}

/// The recipe's pick: the last goal of the navigation's status list (not
/// an older one) brings PICKING; the arm within 0.05 rad of its reference
/// and the elbow far from its limit do not fault; the gripper's own
/// message (`picker_msgs/GripperState`, its constant `HOLDING`) ends it.
#[test]
fn the_manipulator_picks_on_joint_states_goal_statuses_and_its_own_messages() {
    let bag = std::env::temp_dir().join(format!("situ-ros2-pick-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&bag);
    let (states, stderr) = manipulator("pick", 50, &["--record".as_ref(), bag.as_os_str()]);
    assert_eq!(states, ["IDLE", "DRIVING", "PICKING", "DONE"], "{stderr}");
    assert!(stderr.contains("ended in DONE"), "{stderr}");
    // rosbags reads every message with the bag's own definitions only: the
    // robot's own package's among them.
    let read = read_bag(&bag);
    assert_eq!(read["states"], serde_json::json!(["IDLE", "DRIVING", "PICKING", "DONE"]));
    for (topic, ty) in [
        ("/gripper/state", "picker_msgs/msg/GripperState"),
        ("/joint_states", "sensor_msgs/msg/JointState"),
        ("/navigate_to_pose/_action/status", "action_msgs/msg/GoalStatusArray"),
        ("/arm_controller/controller_state", "control_msgs/msg/JointTrajectoryControllerState"),
    ] {
        assert_eq!(read["types"][topic], ty, "{read}");
        assert!(read["counts"][topic].as_u64().is_some_and(|n| n >= 1), "{topic}: {read}");
    }
    std::fs::remove_dir_all(&bag).unwrap();
}

#[test]
fn any_aborted_goal_of_the_status_list_faults_the_manipulator() {
    let (states, stderr) = manipulator("aborted", 51, &[]);
    assert_eq!(states, ["IDLE", "DRIVING", "FAULT"], "{stderr}");
}

/// The elbow is found by its name among the joints: the shoulder past the
/// limit first changes nothing.
#[test]
fn the_elbow_found_by_name_past_its_limit_faults_the_manipulator() {
    let (states, stderr) = manipulator("elbow", 52, &[]);
    assert_eq!(states, ["IDLE", "DRIVING", "FAULT"], "{stderr}");
}

/// A joint 0.3 rad off the controller's reference (the largest `abs` of
/// `error.positions`, one of them negative) faults the pick.
#[test]
fn the_arm_off_its_trajectory_faults_the_manipulator() {
    let (states, stderr) = manipulator("arm", 53, &[]);
    assert_eq!(states, ["IDLE", "DRIVING", "PICKING", "FAULT"], "{stderr}");
}

fn situ(dir: &Path, args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_situ")).current_dir(dir).args(args).output().expect("the situ binary")
}

#[test]
fn a_bad_map_is_refused_with_its_findings() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("bad.toml"), "[[node]]\nagent = \"Planner\"\nnode = \"planner\"\n").unwrap();
    let rules = root().join("tests/ros2/amr.situ");
    let o = situ(dir.path(), &["ros2", rules.to_str().unwrap(), "--map", "bad.toml", "--duration", "1"]);
    assert_eq!(o.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(stdout.contains("E0414") && stdout.contains("bad.toml:3:8"), "{stdout}");
    let o = situ(dir.path(), &["ros2", rules.to_str().unwrap(), "--map", "missing.toml"]);
    assert_eq!(o.status.code(), Some(2));
}

#[test]
fn the_bridge_reads_the_robots_own_packages() {
    let dir = tempfile::tempdir().unwrap();
    let (rules, map) = (root().join("tests/ros2/arm.situ"), root().join("tests/ros2/arm.toml"));
    let msgs = root().join("tests/ros2/msgs");
    let run = |extra: &[&str]| {
        let mut args = vec!["ros2", rules.to_str().unwrap(), "--map", map.to_str().unwrap()];
        args.extend(["--domain", "46", "--duration", "0.3"]);
        args.extend(extra);
        Command::new(env!("CARGO_BIN_EXE_situ"))
            .current_dir(dir.path())
            .args(&args)
            .env_remove("AMENT_PREFIX_PATH")
            .output()
            .expect("the situ binary")
    };
    // Without its package the map is refused: its type is unknown.
    let o = run(&[]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("E0402"), "{}", String::from_utf8_lossy(&o.stdout));
    // With it the bridge runs and reads the topic.
    let o = run(&["--msg-path", msgs.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("reading /arm/status"), "{stderr}");
    let o = run(&["--msg-path", "nowhere"]);
    assert_eq!(o.status.code(), Some(2));
}

/// The bridge reads an action's feedback (a type ROS 2 generates from an
/// `.action`), an action's status and JointState, all from the definitions
/// situ carries, and a constant by name (`GoalStatus.STATUS_ABORTED`).
#[test]
fn the_bridge_reads_actions_and_joint_states() {
    let domain = "47";
    let bridge = Command::new(env!("CARGO_BIN_EXE_situ"))
        .current_dir(root())
        .args(["ros2", "tests/ros2/actions.situ", "--map", "tests/ros2/actions.toml", "--domain", domain])
        .args(["--duration", "60"])
        .env_remove("AMENT_PREFIX_PATH")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the situ binary");
    let peer = Command::new("python3")
        .current_dir(root())
        .args(["bridge-ros2/tests/action_peer.py", domain])
        .output()
        .unwrap_or_else(|e| panic!("cannot run python3 ({e}): the test needs python3 with cyclonedds"));
    // SAFETY: kill(2) on our own child's pid; SIGINT is what Ctrl-C sends.
    unsafe { libc::kill(bridge.id() as i32, libc::SIGINT) };
    let out = bridge.wait_with_output().expect("the bridge's output");
    let (seen, stderr) = (String::from_utf8_lossy(&peer.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(
        peer.status.code(),
        Some(0),
        "peer:\n{seen}{}\nbridge:\n{stderr}",
        String::from_utf8_lossy(&peer.stderr)
    );
    let states: Vec<Json> = seen.lines().map(|l| serde_json::from_str(l).expect("a JSON line")).collect();
    let states: Vec<&str> = states.iter().filter_map(|l| l["state"].as_str()).collect();
    // IDLE may pass before the peer's reader matches.
    assert!(states.ends_with(&["GRIPPING", "STALLED", "ABORTED"]), "{states:?} {stderr}");
    assert!(stderr.contains("0 refused"), "{stderr}");
}

#[test]
fn a_signed_bundle_runs_and_an_unsigned_one_is_refused_under_trust() {
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path();
    let rules = root().join("tests/ros2/amr.situ");
    let map = root().join("tests/ros2/amr.toml");
    let (rules, map) = (rules.to_str().unwrap(), map.to_str().unwrap());
    assert_eq!(situ(p, &["key", "new", "robot"]).status.code(), Some(0));
    assert_eq!(situ(p, &["build", rules, "-o", "signed.json", "--sign", "robot.key"]).status.code(), Some(0));
    assert_eq!(situ(p, &["build", rules, "-o", "unsigned.json"]).status.code(), Some(0));
    let run = |bundle: &str, trust: bool| {
        let mut args = vec!["ros2", bundle, "--map", map, "--domain", "44", "--duration", "0.5"];
        if trust {
            args.extend(["--trust", "robot.pub"]);
        }
        situ(p, &args)
    };
    let o = run("signed.json", true);
    assert_eq!(o.status.code(), Some(0), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stderr).contains("ended in IDLE"));
    let o = run("unsigned.json", true);
    assert_eq!(o.status.code(), Some(2), "{}", String::from_utf8_lossy(&o.stderr));
    // A bundle's map is checked against its agents and events: a mistake is a finding.
    std::fs::write(
        p.join("typo.toml"),
        std::fs::read_to_string(map).unwrap().replace("pose.position.x", "pose.position.q"),
    )
    .unwrap();
    let o = situ(p, &["ros2", "unsigned.json", "--map", "typo.toml", "--duration", "0.5"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&o.stdout).contains("E0403"), "{}", String::from_utf8_lossy(&o.stdout));
}
