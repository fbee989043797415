//! Faults between hosts: situ's distributed stack on test hosts made of
//! Linux network namespaces (tests/faults/lab.rs), with partitions, killed
//! processes, a restarted router, and delay and loss between the hosts.
//! Every test makes its own namespaces and removes them; a machine without
//! `ip`, `nft` or the privilege fails the test with the reason.
//! docs/reliability.md ("Faults between hosts") describes the scenarios and
//! their figures.
#![cfg(feature = "zenoh")]

#[path = "faults/lab.rs"]
mod lab;
#[path = "faults/stack.rs"]
#[allow(dead_code)]
mod stack;

use lab::Lab;
use stack::*;
use std::time::Duration;

const LONG: Duration = Duration::from_secs(60);

#[test]
fn figure_5_runs_across_three_hosts() {
    let mut lab = Lab::new(&["board", "sensors", "pipeline"]);
    let procs = fig5_peers();
    let deploy = write_deployment(&lab, "fig5", &procs, None);
    let running = start(&mut lab, &fig5_rules(), &deploy, &procs);
    let at = format!("tcp/{}:7449", lab.addr("pipeline"));
    let observer = observe(&mut lab, "pipeline", &at, "client", "fig5");
    for p in ["board", "sensors", "pipeline"] {
        wait_state(&mut lab, &running, p, "RO", LONG);
    }
    std::thread::sleep(Duration::from_secs(2));
    stop_all(&mut lab, &running);
    for p in ["board", "sensors", "pipeline"] {
        let out = lab.stdout(running.procs[p]);
        assert!(out.contains("path: RS → RO\n"), "{p} followed RS -> RO:\n{}", lab.outputs());
    }
    let seen = seen(&lab, observer);
    check_monotonic(&seen).unwrap();
    assert!(seen.iter().any(|s| s.state == "RO"), "{seen:?}");
    let g: Vec<f64> = gaps(&seen).iter().map(|g| g.1).collect();
    let (p50, p99, max) = percentiles(&g);
    eprintln!("baseline: {} statuses seen by the pipeline host; gaps p50 {p50:.0} ms, p99 {p99:.0} ms, max {max:.0} ms", seen.len());
    assert!(safe_mode_periods(&recording(&lab, "pipeline")).is_empty());
}
