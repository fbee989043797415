//! The pictures and metrics.json of a run are written, and are the same
//! for the same run.

use situ_sim::{plot, scenario, ugv};
use std::path::PathBuf;

#[test]
fn a_run_writes_metrics_and_pictures() {
    let world = scenario::dafflon_4().world;
    let m = situ_sim::baseline::ugv::run(&world, ugv::Strategy::HardSwitch, 1, &ugv::UgvConfig::default());
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("pictures-hard-switch");
    plot::write_run(&dir, &world, &m).expect("written");
    let traj = std::fs::read_to_string(dir.join("trajectory.svg")).expect("trajectory.svg");
    let time = std::fs::read_to_string(dir.join("timeline.svg")).expect("timeline.svg");
    let json = std::fs::read_to_string(dir.join("metrics.json")).expect("metrics.json");
    assert!(
        traj.starts_with("<svg") && traj.contains("AvoidCCW") && traj.contains("Reaching"),
        "the legend names the labels"
    );
    assert!(time.starts_with("<svg") && time.contains("speed (m/s)"));
    assert!(json.contains("\"max_steer_rate\""));
    // Deterministic pictures.
    assert_eq!(traj, plot::trajectory_svg(&world, &m.samples, "dafflon-4 — hard-switch").expect("again"));
}
