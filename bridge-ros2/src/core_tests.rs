//! The bridge's decisions on the AMR of `tests/ros2/amr.situ`: messages in,
//! the state and the lifecycle requests out, nodes answering or not.

use super::*;
use crate::msgs::{LaserScan, Point, Pose, PoseStamped, Quaternion};
use serde::Serialize;
use situ_compiler::{bundle, check_source};

const RULES: &str = include_str!("../../tests/ros2/amr.situ");
const MAP: &str = include_str!("../../tests/ros2/amr.toml");
const S: u64 = 1_000_000_000;
/// A start time far from 0, as the wall clock is.
const T0: u64 = 1_700_000_000 * S;

/// The nodes of amr.toml, by number.
const COSTMAP: usize = 0;
const PLANNER: usize = 1;
const RECOVERY: usize = 2;
const CONTROLLER: usize = 3;

fn core() -> Core {
    let checked = check_source("amr.situ", RULES);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    let content = Arc::new(bundle::build(&checked));
    Core::new(content, &checked.model, MAP, &situ_ros2_map::Registry::carried(), FileId(1))
        .unwrap_or_else(|e| panic!("{e:?}"))
}

fn cdr<T: Serialize>(msg: &T) -> Vec<u8> {
    crate::msgs::to_cdr(msg).unwrap()
}

fn scan(nearest: f32) -> Vec<u8> {
    let mut ranges = vec![3.0f32; 360];
    ranges[90] = nearest;
    cdr(&LaserScan {
        header: Header::default(),
        angle_min: -std::f32::consts::PI,
        angle_max: std::f32::consts::PI,
        angle_increment: 0.0175,
        time_increment: 0.0,
        scan_time: 0.1,
        range_min: 0.05,
        range_max: 10.0,
        ranges,
        intensities: Vec::new(),
    })
}

fn goal(x: f64, y: f64) -> Vec<u8> {
    let pose = Pose { position: Point { x, y, z: 0.0 }, orientation: Quaternion { w: 1.0, ..Quaternion::default() } };
    cdr(&PoseStamped { header: Header::default(), pose })
}

fn requests(out: &[Output]) -> Vec<(usize, &'static str)> {
    out.iter()
        .filter_map(|o| match o {
            Output::ChangeState { node, transition } => Some((*node, transition.label())),
            _ => None,
        })
        .collect()
}

fn states(out: &[Output]) -> Vec<&str> {
    out.iter()
        .filter_map(|o| match o {
            Output::State(s) => Some(s.as_str()),
            _ => None,
        })
        .collect()
}

/// Answers every request with success, in turn, until none is left;
/// returns them in the order they were sent.
fn answer_all(core: &mut Core, mut out: Vec<Output>, now: u64) -> Vec<(usize, &'static str)> {
    let mut sent = Vec::new();
    while let Some((node, label)) = requests(&out).first().copied() {
        sent.push((node, label));
        assert!(sent.len() < 20, "no end: {sent:?}");
        out = core.on_change_state(node, true, now);
    }
    sent
}

/// A bridge whose four nodes answered `get_state` (unconfigured) and were configured.
fn started() -> Core {
    let mut core = core();
    let out = core.start(T0);
    assert_eq!(states(&out), ["IDLE"]);
    let asked: Vec<usize> =
        out.iter().filter_map(|o| if let Output::GetState { node } = o { Some(*node) } else { None }).collect();
    assert_eq!(asked, [0, 1, 2, 3]);
    let mut sent = Vec::new();
    for node in asked {
        let out = core.on_get_state(node, 1, T0);
        sent.extend(answer_all(&mut core, out, T0));
    }
    // Each node is configured as soon as its state is known; IDLE wants them all inactive.
    assert_eq!(sent, [(0, "configure"), (1, "configure"), (2, "configure"), (3, "configure")]);
    assert!(core.nodes().iter().all(|n| n.state == NodeState::Inactive));
    core
}

#[test]
fn a_goal_activates_the_chain_writers_first() {
    let mut core = started();
    let out = core.on_message("/goal_pose", &goal(4.0, 2.0), T0 + S);
    assert_eq!(states(&out), ["NAVIGATING"]);
    let sent = answer_all(&mut core, out, T0 + S);
    assert_eq!(sent, [(COSTMAP, "activate"), (PLANNER, "activate"), (CONTROLLER, "activate")]);
    assert_eq!(core.nodes()[RECOVERY].state, NodeState::Inactive);
}

#[test]
fn an_obstacle_hands_the_controller_to_recovery_without_a_gap() {
    let mut core = started();
    let out = core.on_message("/goal_pose", &goal(4.0, 2.0), T0 + S);
    answer_all(&mut core, out, T0 + S);
    let out = core.on_message("/scan", &scan(0.3), T0 + 2 * S);
    assert_eq!(states(&out), ["RECOVERING"]);
    // The controller stays active: its new writer comes up before its old one goes down.
    assert_eq!(answer_all(&mut core, out, T0 + 2 * S), [(RECOVERY, "activate"), (PLANNER, "deactivate")]);
    let out = core.on_message("/scan", &scan(1.5), T0 + 2 * S + S / 10);
    assert_eq!(states(&out), ["NAVIGATING"]);
    assert_eq!(answer_all(&mut core, out, T0 + 2 * S + S / 10), [(PLANNER, "activate"), (RECOVERY, "deactivate")]);
}

#[test]
fn arrival_puts_every_node_to_sleep_readers_first() {
    let mut core = started();
    let out = core.on_message("/goal_pose", &goal(1.0, 0.0), T0 + S);
    answer_all(&mut core, out, T0 + S);
    let reached = cdr(&true);
    let out = core.on_message("/goal_reached", &reached, T0 + 2 * S);
    assert_eq!(states(&out), ["ARRIVED"]);
    // The controller reads the planner, which reads the costmap.
    assert_eq!(
        answer_all(&mut core, out, T0 + 2 * S),
        [(CONTROLLER, "deactivate"), (PLANNER, "deactivate"), (COSTMAP, "deactivate")]
    );
}

#[test]
fn a_planner_that_does_not_answer_is_its_failure_event() {
    let mut core = started();
    let out = core.on_message("/goal_pose", &goal(4.0, 2.0), T0 + S);
    assert_eq!(requests(&out), [(COSTMAP, "activate")]);
    let out = core.on_change_state(COSTMAP, true, T0 + S);
    assert_eq!(requests(&out), [(PLANNER, "activate")]);
    // 400 ms: still waiting (its timeout is 500 ms); nothing else is sent meanwhile.
    assert!(requests(&core.on_tick(T0 + S + 400_000_000)).is_empty());
    let out = core.on_tick(T0 + S + 600_000_000);
    assert_eq!(states(&out), ["FAULT"], "{out:?}");
    let diagnostics: Vec<&DiagnosticStatus> = out
        .iter()
        .filter_map(|o| if let Output::Diagnostics(a) = o { Some(&a.status) } else { None })
        .flatten()
        .collect();
    assert!(diagnostics
        .iter()
        .any(|d| d.level == level::ERROR && d.message.contains("/planner did not answer activate")));
    assert_eq!(core.counters().failures, 1);
    // FAULT puts the others to sleep; the planner is asked its state again.
    assert!(out.contains(&Output::GetState { node: PLANNER }));
    assert_eq!(answer_all(&mut core, out, T0 + 2 * S), [(COSTMAP, "deactivate")]);
}

#[test]
fn a_refused_transition_is_reported_and_not_insisted_on() {
    let mut core = started();
    let out = core.on_message("/goal_pose", &goal(4.0, 2.0), T0 + S);
    assert_eq!(requests(&out), [(COSTMAP, "activate")]);
    let out = core.on_change_state(COSTMAP, false, T0 + S);
    // The costmap has no failure event: the others are driven on.
    assert_eq!(requests(&out), [(PLANNER, "activate")]);
    let sent = answer_all(&mut core, out, T0 + S);
    assert_eq!(sent, [(PLANNER, "activate"), (CONTROLLER, "activate")]);
    assert_eq!(core.nodes()[COSTMAP].state, NodeState::Inactive);
    assert_eq!(core.state_name(), "NAVIGATING");
}

#[test]
fn a_silent_laser_is_a_stale_event() {
    let mut core = started();
    let out = core.on_message("/goal_pose", &goal(4.0, 2.0), T0 + S);
    answer_all(&mut core, out, T0 + S);
    core.on_message("/scan", &scan(2.0), T0 + S);
    assert!(states(&core.on_tick(T0 + S + 400_000_000)).is_empty());
    assert_eq!(states(&core.on_tick(T0 + S + 600_000_000)), ["FAULT"]);
}

#[test]
fn bad_messages_are_counted_and_reported_once_a_second() {
    let mut core = started();
    for _ in 0..1000 {
        assert!(core.on_message("/scan", &[0, 1, 0, 0, 7], T0 + S).is_empty());
    }
    assert_eq!(core.counters().refused, 1000);
    let out = core.on_tick(T0 + 2 * S);
    let Some(Output::Diagnostics(a)) = out.iter().find(|o| matches!(o, Output::Diagnostics(_))) else {
        panic!("no diagnostics in {out:?}")
    };
    let scan = a.status.iter().find(|s| s.name == "situ: /scan").expect("a status for /scan");
    assert_eq!(scan.level, level::WARN);
    assert_eq!(scan.values[0].value, "1000");
    // Reported once: the next report has no status for /scan.
    let out = core.on_tick(T0 + 4 * S);
    let Some(Output::Diagnostics(a)) = out.iter().find(|o| matches!(o, Output::Diagnostics(_))) else { panic!() };
    assert!(a.status.iter().all(|s| s.name != "situ: /scan"));
    assert_eq!(core.state_name(), "IDLE");
}

#[test]
fn a_missing_value_posts_no_event_and_says_why() {
    let mut core = started();
    let empty = cdr(&LaserScan { header: Header::default(), range_max: 10.0, ..LaserScan::default() });
    assert!(states(&core.on_message("/scan", &empty, T0 + S)).is_empty());
    // Both entries of `/scan` read `min(ranges)`: two refusals, no event.
    assert_eq!((core.counters().refused, core.counters().events), (2, 0));
    let out = core.on_tick(T0 + 2 * S);
    let Some(Output::Diagnostics(a)) = out.iter().find(|o| matches!(o, Output::Diagnostics(_))) else {
        panic!("no diagnostics in {out:?}")
    };
    let scan = a.status.iter().find(|s| s.name == "situ: /scan").expect("a status for /scan");
    assert_eq!(scan.message, "CLEAR: when: `min(ranges)` is missing: `min` of an array that is empty");
}

#[test]
fn a_sample_the_middleware_could_not_hand_over_is_counted_and_reported() {
    let mut core = started();
    core.on_unreadable("/scan", "not read: unknown representation id 00 0c");
    core.on_unreadable("/scan", "not read: unknown representation id 00 0c");
    assert_eq!((core.counters().messages, core.counters().refused), (2, 2));
    let out = core.on_tick(T0 + 2 * S);
    let Some(Output::Diagnostics(a)) = out.iter().find(|o| matches!(o, Output::Diagnostics(_))) else {
        panic!("no diagnostics in {out:?}")
    };
    let scan = a.status.iter().find(|s| s.name == "situ: /scan").expect("a status for /scan");
    assert_eq!(
        (scan.message.as_str(), scan.values[0].value.as_str()),
        ("not read: unknown representation id 00 0c", "2")
    );
}

#[test]
fn an_xcdr2_scan_is_read_as_its_xcdr1() {
    // A LaserScan has no 8-byte field and no sequence of structures: its
    // XCDR2 (`00 07`) is its XCDR1 under another header.
    let mut core = started();
    let mut bytes = scan(0.2);
    bytes[1] = 7;
    core.on_message("/scan", &bytes, T0 + S);
    assert_eq!((core.counters().messages, core.counters().refused, core.counters().events), (1, 0, 1));
}

#[test]
fn encapsulations_not_read_are_refused_with_their_identifier() {
    let mut core = started();
    let mut mutable = scan(2.0);
    mutable[1] = 0x0b; // PL_CDR2: mutable types, not read
    assert!(core.on_message("/scan", &mutable, T0 + S).is_empty());
    let mut cut = scan(2.0);
    cut[1] = 7;
    cut.truncate(30); // XCDR2 cut short
    assert!(core.on_message("/scan", &cut, T0 + S).is_empty());
    assert_eq!((core.counters().messages, core.counters().refused), (2, 2));
    let reported = |core: &mut Core, t: u64| {
        let out = core.on_tick(t);
        let Some(Output::Diagnostics(a)) = out.into_iter().find(|o| matches!(o, Output::Diagnostics(_))) else {
            panic!("no diagnostics")
        };
        a.status.into_iter().find(|s| s.name == "situ: /scan").expect("a status for /scan")
    };
    let last = reported(&mut core, T0 + 2 * S);
    assert_eq!(last.values[0].value, "2");
    assert!(last.message.starts_with("LaserScan: XCDR2: "), "{last:?}");
    core.on_message("/scan", &mutable, T0 + 3 * S);
    let last = reported(&mut core, T0 + 4 * S);
    assert!(last.message.contains("encapsulation 00 0b"), "{last:?}");
}

#[test]
fn the_agents_say_mode_function_links_and_lifecycle() {
    let mut core = started();
    let out = core.on_message("/goal_pose", &goal(4.0, 2.0), T0 + S);
    answer_all(&mut core, out, T0 + S);
    let Output::Agents(a) = core.agents(T0 + S) else { panic!("not the agents") };
    let find = |name: &str| a.status.iter().find(|s| s.name == name).unwrap();
    let value = |s: &DiagnosticStatus, k: &str| s.values.iter().find(|v| v.key == k).unwrap().value.clone();
    let planner = find("Planner");
    assert_eq!(planner.message, "running plan()");
    assert_eq!(planner.hardware_id, "/planner");
    assert_eq!((value(planner, "reads"), value(planner, "sends")), ("Costmap".into(), "Controller".into()));
    assert_eq!(value(planner, "lifecycle"), "active");
    let recovery = find("Recovery");
    assert_eq!((recovery.message.as_str(), value(recovery, "lifecycle")), ("sleeping", "inactive".into()));
    assert!(find("Scan").values.iter().all(|v| v.key != "lifecycle"));
}
