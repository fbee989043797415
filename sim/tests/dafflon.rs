//! Dafflon et al.'s result on the four-obstacle scene, closed loop (vehicle +
//! LIDAR + selection + controllers + control law): the multi-agent merge
//! against the hard switch.

use situ_sim::baseline::ugv::compare;
use situ_sim::scenario;
use situ_sim::ugv::{Strategy, UgvConfig};

#[test]
fn merge_is_smoother_and_faster_than_the_hard_switch_and_safe() {
    let world = scenario::dafflon_4().world;
    let table = compare(&world, &[Strategy::HardSwitch, Strategy::Merge], 1, &UgvConfig::default());
    println!("{table}");
    let hard = table.row(Strategy::HardSwitch).expect("hard-switch row");
    let merge = table.row(Strategy::Merge).expect("merge row");
    for r in [hard, merge] {
        assert_eq!(r.collisions, 0, "{}: no collision", r.strategy);
        assert!(r.closest_distance > 0.3, "{}: safe closest distance, {:.2} m", r.strategy, r.closest_distance);
        assert!(r.time_to_goal.is_some(), "{}: reaches the target", r.strategy);
    }
    // Smaller steering-rate peaks (the paper's Fig. 5: no discontinuity).
    assert!(
        merge.max_steer_rate * 5.0 < hard.max_steer_rate,
        "steering-rate peaks: {} vs {}",
        merge.max_steer_rate,
        hard.max_steer_rate
    );
    assert!(merge.rms_steer_rate < hard.rms_steer_rate);
    // Speed: both reach vmax on the free stretch (the top speed is capped
    // there); the merge keeps its speed among the obstacles, so its mean
    // speed is higher and it arrives sooner.
    assert!(merge.max_speed >= hard.max_speed - 0.05, "top speed {} vs {}", merge.max_speed, hard.max_speed);
    assert!(merge.mean_speed > hard.mean_speed + 0.1, "mean speed {} vs {}", merge.mean_speed, hard.mean_speed);
    assert!(merge.time_to_goal < hard.time_to_goal);
    // A larger margin in time: the smallest time to collision is longer.
    assert!(merge.min_ttc.unwrap_or(f64::INFINITY) > hard.min_ttc.unwrap_or(f64::INFINITY));
}
