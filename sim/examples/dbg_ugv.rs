use situ_sim::{scenario, ugv};
fn main() {
    let s = scenario::dafflon_4();
    let cfg = ugv::UgvConfig::default();
    let c = ugv::compare(&s.world, &[ugv::Strategy::HardSwitch, ugv::Strategy::Merge], 5, &cfg);
    println!("{c}");
    for m in &c.runs {
        for near in [1.0, 1.5, 2.0, 3.0] {
            let a = m.samples.iter().filter(|s| s.closest.is_some_and(|c| c < near)).map(|s| s.v).fold(0.0, f64::max);
            let cm = m.samples.iter().filter(|s| s.closest.is_some_and(|c| c < near)).map(|s| s.v_cmd).fold(0.0, f64::max);
            println!("{} near {near}: actual top {a:.2} cmd top {cm:.2}", m.controller);
        }
    }
    for m in &c.runs {
        if std::env::args().count() < 2 { continue; }
        println!("== {}", m.controller);
        for s in m.samples.iter().step_by(10) {
            println!("{:.1} x {:.2} y {:.2} v {:.2} g {:.3} {} cl {:.2}", s.t, s.x, s.y, s.v_cmd, s.steer_cmd, s.label, s.closest.unwrap_or(-1.0));
        }
    }
}
#[allow(dead_code)]
fn extra() {}
