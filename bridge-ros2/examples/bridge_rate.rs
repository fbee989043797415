//! The bridge's speed over DDS on loopback: the AMR of `tests/ros2/amr.situ`
//! with its four lifecycle nodes served by a second DDS participant
//! (ros2-client, rmw_cyclonedds's service mapping), and a laser driver
//! publishing `sensor_msgs/LaserScan` of 360 ranges.
//!
//! 1. **Latency**: a scan that blocks (or clears) the way is published; the
//!    time until the first `change_state` request it causes reaches the
//!    node (`recovery` activate, or `planner` activate) — message → state
//!    change → request, both DDS hops included. p50 and p99 over the flips.
//! 2. **Rate**: LaserScans at 10 kHz for a few seconds; how many the bridge
//!    took, against how many were published.
//!
//! `cargo run --release -p situ-bridge-ros2 --example bridge_rate [FLIPS] [SECONDS]`
//! (docs/performance.md). Domain 77; nothing else must use it.

use ros2_client::service::ServiceMapping;
use ros2_client::{Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions, QosProfile, ServiceTypeName};
use situ_bridge_ros2::core::Core;
use situ_bridge_ros2::dds::{self, Options, Rmw};
use situ_bridge_ros2::msgs::{
    ChangeStateRequest, ChangeStateResponse, GetStateRequest, GetStateResponse, Header, LaserScan, Point, Pose,
    PoseStamped, Quaternion, State,
};
use situ_compiler::{bundle, check_source};
use situ_grammar::diag::FileId;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const DOMAIN: u16 = 77;
const RULES: &str = include_str!("../../tests/ros2/amr.situ");
const MAP: &str = include_str!("../../tests/ros2/amr.toml");
const NODES: [&str; 4] = ["costmap", "planner", "recovery", "controller"];

fn scan(nearest: f32) -> LaserScan {
    let mut ranges = vec![3.0f32; 360];
    ranges[90] = nearest;
    LaserScan {
        header: Header::default(),
        angle_min: -std::f32::consts::PI,
        angle_max: std::f32::consts::PI,
        angle_increment: 0.0175,
        time_increment: 0.0,
        scan_time: 0.1,
        range_min: 0.05,
        range_max: 10.0,
        ranges,
        intensities: vec![100.0; 360],
    }
}

/// The change_state requests the nodes received: (node, transition id, when).
type Log = Arc<Mutex<Vec<(usize, u8, Instant)>>>;

/// Serves the four lifecycle nodes until `stop`.
fn serve(log: Log, stop: Arc<AtomicBool>) {
    let context = Context::with_options(ContextOptions::new().domain_id(DOMAIN)).expect("participant");
    let mut node = context
        .new_node(NodeName::new("/", "amr_nodes").unwrap(), NodeOptions::new().enable_rosout(false))
        .expect("node");
    let qos = QosProfile::publisher_default().history(ros2_client::qos::History::KeepLast { depth: 10 });
    let mut servers = Vec::new();
    for n in NODES {
        let change = node
            .create_server::<ChangeStateRequest, ChangeStateResponse>(
                ServiceMapping::Cyclone,
                &Name::new(&format!("/{n}"), "change_state").unwrap(),
                &ServiceTypeName::new("lifecycle_msgs", "ChangeState"),
                qos.clone(),
                qos.clone(),
            )
            .expect("server");
        let get = node
            .create_server::<GetStateRequest, GetStateResponse>(
                ServiceMapping::Cyclone,
                &Name::new(&format!("/{n}"), "get_state").unwrap(),
                &ServiceTypeName::new("lifecycle_msgs", "GetState"),
                qos.clone(),
                qos.clone(),
            )
            .expect("server");
        servers.push((change, get, 1u8));
    }
    while !stop.load(Ordering::Relaxed) {
        for (i, (change, get, state)) in servers.iter_mut().enumerate() {
            while let Ok(Some((id, _))) = get.receive_request() {
                let _ = get
                    .send_response(id, GetStateResponse { current_state: State { id: *state, label: String::new() } });
            }
            while let Ok(Some((id, rq))) = change.receive_request() {
                log.lock().unwrap().push((i, rq.transition.id, Instant::now()));
                *state = match rq.transition.id {
                    1 | 4 => 2,
                    3 => 3,
                    _ => *state,
                };
                let _ = change.send_response(id, ChangeStateResponse { success: true });
            }
        }
        std::thread::sleep(Duration::from_micros(50));
    }
}

fn percentile(sorted: &[f64], p: f64) -> f64 {
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let flips: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(200);
    let seconds: f64 = args.next().and_then(|a| a.parse().ok()).unwrap_or(3.0);

    let checked = check_source("amr.situ", RULES);
    let content = Arc::new(bundle::build(&checked));
    let core =
        Core::new(content, &checked.model, MAP, &situ_ros2_map::Registry::carried(), FileId(1)).expect("the map");
    let stop = Arc::new(AtomicBool::new(false));
    let options = Options {
        domain: DOMAIN,
        rmw: Rmw::CycloneDds,
        heartbeat: Duration::from_millis(10),
        duration: None,
        stop: stop.clone(),
    };
    let bridge = std::thread::spawn(move || dds::run(core, &options, None));
    let log: Log = Arc::default();
    let server = {
        let (log, stop) = (log.clone(), stop.clone());
        std::thread::spawn(move || serve(log, stop))
    };

    let context = Context::with_options(ContextOptions::new().domain_id(DOMAIN)).expect("participant");
    let mut node = context
        .new_node(NodeName::new("/", "amr_drivers").unwrap(), NodeOptions::new().enable_rosout(false))
        .expect("node");
    // Reliable, and deep enough that a burst is not overwritten before it is sent.
    let reliable = QosProfile::publisher_default().history(ros2_client::qos::History::KeepLast { depth: 1000 });
    let topic = |name: &str, pkg: &str, ty: &str| {
        node.create_topic(&Name::parse(name).unwrap(), MessageTypeName::new(pkg, ty), &reliable).unwrap()
    };
    let (scan_topic, goal_topic) =
        (topic("/scan", "sensor_msgs", "LaserScan"), topic("/goal_pose", "geometry_msgs", "PoseStamped"));
    let scans = node.create_publisher::<LaserScan>(&scan_topic, None).unwrap();
    let goals = node.create_publisher::<PoseStamped>(&goal_topic, None).unwrap();

    // Wait for the nodes to be configured, then start the mission.
    let requests = |node: usize, id: u8| log.lock().unwrap().iter().filter(|r| r.0 == node && r.1 == id).count();
    let wait = |what: &dyn Fn() -> bool, secs: u64| {
        let end = Instant::now() + Duration::from_secs(secs);
        while !what() {
            assert!(Instant::now() < end, "timed out");
            std::thread::sleep(Duration::from_micros(100));
        }
    };
    wait(&|| (0..4).all(|n| requests(n, 1) == 1), 20);
    let pose = Pose {
        position: Point { x: 4.0, y: 2.0, z: 0.0 },
        orientation: Quaternion { w: 1.0, ..Quaternion::default() },
    };
    let goal = PoseStamped { header: Header::default(), pose };
    let navigating = || requests(3, 3) >= 1;
    let end = Instant::now() + Duration::from_secs(20);
    // Messages published before the rate phase (the bridge may have missed
    // some of the first, before discovery: an upper bound).
    let mut before_rate = 0u64;
    while !navigating() {
        assert!(Instant::now() < end, "the goal was not heard");
        let _ = goals.publish(goal.clone());
        let _ = scans.publish(scan(2.0));
        before_rate += 2;
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(100));

    // 1. Latency: blocked → recovery activated; cleared → planner activated.
    let mut latencies = Vec::new();
    for i in 0..flips {
        let (nearest, node, id) = if i % 2 == 0 { (0.3, 2, 3) } else { (1.5, 1, 3) };
        let before = requests(node, id);
        let sent = Instant::now();
        let _ = scans.publish(scan(nearest));
        before_rate += 1;
        wait(&|| requests(node, id) > before, 5);
        let at = log.lock().unwrap().iter().rev().find(|r| r.0 == node && r.1 == id).unwrap().2;
        latencies.push(at.duration_since(sent).as_secs_f64() * 1e6);
        // Let the second request of the switch (a deactivation) pass, and the laser settle.
        std::thread::sleep(Duration::from_millis(5));
    }
    latencies.sort_by(f64::total_cmp);
    println!(
        "latency, scan published -> first change_state request received ({} flips): p50 {:.0} µs, p99 {:.0} µs, max {:.0} µs",
        flips,
        percentile(&latencies, 0.5),
        percentile(&latencies, 0.99),
        percentile(&latencies, 1.0)
    );

    // 2. Rate: 10 kHz of LaserScans (clear: no state change).
    // Ten per millisecond, sleeping between: a spinning publisher would take
    // a whole core of the two the bridge shares.
    let start = Instant::now();
    let mut published = 0u64;
    let mut next = start;
    let message = scan(1.5);
    while start.elapsed().as_secs_f64() < seconds {
        for _ in 0..10 {
            if scans.publish(message.clone()).is_ok() {
                published += 1;
            }
        }
        next += Duration::from_millis(1);
        std::thread::sleep(next.saturating_duration_since(Instant::now()));
    }
    let elapsed = start.elapsed().as_secs_f64();
    std::thread::sleep(Duration::from_millis(500));
    stop.store(true, Ordering::Relaxed);
    let report = bridge.join().unwrap().expect("the bridge");
    server.join().unwrap();
    let during = report.counters.messages.saturating_sub(before_rate);
    println!(
        "rate: {published} LaserScans published in {elapsed:.2} s ({:.0}/s); the bridge took {} in all ({} refused), at least {:.1} % of the burst",
        published as f64 / elapsed,
        report.counters.messages,
        report.counters.refused,
        100.0 * during.min(published) as f64 / published.max(1) as f64
    );
    println!(
        "the bridge's own work: {:.1} µs per message (decode, map, rules, outputs)",
        report.busy.as_secs_f64() * 1e6 / report.counters.messages.max(1) as f64
    );
}
