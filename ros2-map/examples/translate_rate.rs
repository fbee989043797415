//! How fast a ROS 2 message becomes events: the delivery robot's map
//! (`tests/ros2/delivery.toml` on `tests/ros2/delivery.situ`) translating
//! LaserScan messages of N ranges, from their CDR bytes to the events
//! (decode, `when`, payload), one message after another.
//!
//!   cargo run --release -p situ-ros2-map --example translate_rate -- [RANGES] [MESSAGES]
//!
//! Prints the rate and the per-message latency (p50, p99, max). The issue's
//! goal: the bridge keeps up with 10 kHz of LaserScan-sized messages.

use situ_compiler::loader::FsLoader;
use situ_grammar::diag::FileId;
use situ_ros2_map::Translator;
use std::path::Path;
use std::time::Instant;

/// A sensor_msgs/LaserScan in CDR little-endian, its minimum range `min`.
fn laser_scan(ranges: usize, min: f32, stamp: u32) -> Vec<u8> {
    let mut b = vec![0x00, 0x01, 0x00, 0x00];
    let align = |b: &mut Vec<u8>, n: usize| {
        while !(b.len() - 4).is_multiple_of(n) {
            b.push(0);
        }
    };
    // header: stamp (sec, nanosec), frame_id
    b.extend(stamp.to_le_bytes());
    b.extend(0u32.to_le_bytes());
    let frame = b"laser\0";
    b.extend((frame.len() as u32).to_le_bytes());
    b.extend(frame);
    align(&mut b, 4);
    // angle_min, angle_max, angle_increment, time_increment, scan_time, range_min, range_max
    use std::f32::consts::PI;
    for v in [-PI, PI, PI / 360.0, 0.0, 0.1, 0.05, 30.0] {
        b.extend(v.to_le_bytes());
    }
    b.extend((ranges as u32).to_le_bytes());
    for i in 0..ranges {
        let r = if i == ranges / 2 { min } else { 2.0 + (i % 17) as f32 * 0.1 };
        b.extend(r.to_le_bytes());
    }
    b.extend((ranges as u32).to_le_bytes());
    for _ in 0..ranges {
        b.extend(100.0f32.to_le_bytes());
    }
    b
}

fn main() {
    let mut args = std::env::args().skip(1);
    let ranges: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(720);
    let messages: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(100_000);
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let checked = situ_compiler::check(&root.join("tests/ros2/delivery.situ"), &FsLoader).expect("the rules read");
    let map = std::fs::read_to_string(root.join("tests/ros2/delivery.toml")).expect("the map reads");
    let mut t = Translator::new(&checked.model, &map, &situ_ros2_map::Registry::carried(), FileId(1))
        .unwrap_or_else(|d| panic!("{d:?}"));
    // Obstacle and clear scans in turn: both entries of /scan are evaluated.
    let scans = [laser_scan(ranges, 0.3, 1), laser_scan(ranges, 1.5, 2)];
    let mut lat = Vec::with_capacity(messages);
    let mut produced = 0usize;
    let start = Instant::now();
    for i in 0..messages {
        let t0 = Instant::now();
        let out = t.on_message("/scan", &scans[i % 2]);
        lat.push(t0.elapsed().as_nanos() as u64);
        assert!(out.problems.is_empty(), "{:?}", out.problems);
        produced += out.produced.len();
    }
    let wall = start.elapsed().as_secs_f64();
    assert_eq!(produced, messages, "one event per scan");
    lat.sort_unstable();
    let q = |p: f64| lat[((lat.len() - 1) as f64 * p) as usize] as f64 / 1000.0;
    println!(
        "{messages} LaserScan messages of {ranges} ranges ({} bytes): {:.0} messages/s; per message p50 {:.1} µs, p99 {:.1} µs, max {:.1} µs",
        scans[0].len(),
        messages as f64 / wall,
        q(0.5),
        q(0.99),
        q(1.0)
    );
}
