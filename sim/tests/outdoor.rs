//! The default outdoor mission in closed loop with the simple built-in
//! situation logic: it reaches the goal without collision, visits every
//! driving state of rules/outdoor.situ, and drives faster in the simple road
//! states than near obstacles or cross-country. And determinism: the same
//! scenario and seed give the same metrics to the byte.

use situ_sim::baseline::outdoor::run_mission;
use situ_sim::scenario;
use situ_sim::ugv::{Strategy, UgvConfig};

fn mean_speed_in(m: &situ_sim::metrics::Metrics, states: &[&str]) -> f64 {
    let v: Vec<f64> = m.samples.iter().filter(|s| states.contains(&s.label.as_str())).map(|s| s.v).collect();
    v.iter().sum::<f64>() / v.len().max(1) as f64
}

/// The top commanded speed in some states (the actual speed lags: the car
/// enters RO at road speed and brakes).
fn top_speed_in(m: &situ_sim::metrics::Metrics, states: &[&str]) -> f64 {
    m.samples.iter().filter(|s| states.contains(&s.label.as_str())).map(|s| s.v_cmd).fold(0.0, f64::max)
}

#[test]
fn default_mission_reaches_the_goal_through_every_state() {
    let m = run_mission(scenario::outdoor_default().world, 1, 600.0);
    let s = &m.summary;
    println!(
        "time to goal {:?} s, {:.0} m, closest {:?} m ({:?}), min TTC {:?} s",
        s.time_to_goal, s.distance, s.closest_distance, s.closest_obstacle, s.min_ttc
    );
    let seq: Vec<&str> = m.architecture.transitions.iter().map(|(_, st)| st.as_str()).collect();
    println!("states: {}", seq.join(" → "));
    for (st, t) in &m.architecture.time_in_state {
        println!("  {st}: {t:.1} s, mean {:.2} m/s", mean_speed_in(&m, &[st]));
    }
    assert!(s.goal_reached, "goal reached");
    assert!(s.collisions.is_empty(), "no collision: {:?}", s.collisions);
    assert!(s.closest_distance.is_some_and(|d| d > 0.5), "kept clear of the obstacles");
    assert_eq!(seq, ["IT", "RD", "RS", "RO", "RS", "RT", "RS", "RB", "RT", "RS", "CN", "CO", "CN", "GL"]);
    // Faster in the simple road states than near obstacles or cross-country.
    let road = top_speed_in(&m, &["RS"]);
    for st in ["RO", "CN", "CO"] {
        assert!(road > top_speed_in(&m, &[st]) + 1.0, "RS {road:.1} m/s vs {st} {:.1} m/s", top_speed_in(&m, &[st]));
    }
    assert!(mean_speed_in(&m, &["RS", "RT"]) > mean_speed_in(&m, &["RO", "CN", "CO"]));
    assert!(top_speed_in(&m, &["CO"]) <= 2.0 + 1e-9 && top_speed_in(&m, &["CN"]) <= 4.0 + 1e-9);
    assert!(m.architecture.agents_running.get("RO").is_some_and(|a| a.iter().any(|x| x == "Fusion")));
}

#[test]
fn same_scenario_and_seed_give_the_same_metrics_to_the_byte() {
    let a = run_mission(scenario::outdoor_default().world, 7, 40.0).to_json();
    let b = run_mission(scenario::outdoor_default().world, 7, 40.0).to_json();
    assert_eq!(a.as_bytes(), b.as_bytes());
    let c = run_mission(scenario::outdoor_default().world, 8, 40.0).to_json();
    assert_ne!(a, c, "the seed matters");
    let world = scenario::dafflon_4().world;
    let x = situ_sim::baseline::ugv::run(&world, Strategy::Merge, 3, &UgvConfig::default()).to_json();
    let y = situ_sim::baseline::ugv::run(&world, Strategy::Merge, 3, &UgvConfig::default()).to_json();
    assert_eq!(x.as_bytes(), y.as_bytes());
}
