use situ_sim::{outdoor, scenario};
fn main() {
    let w = scenario::outdoor_default().world;
    let m = outdoor::run_mission(w, 1, 600.0);
    println!("{:?}", m.summary);
    println!("{:?}", m.architecture.transitions);
    println!("{:?}", m.architecture.time_in_state);
    let mut rates: Vec<(f64, f64, String)> = m.samples.windows(2).map(|w| ((w[1].steer_cmd - w[0].steer_cmd).abs() / 0.05, w[1].t, w[1].label.clone())).collect();
    rates.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!("top rates {:?}", &rates[..8]);
    let verbose = std::env::args().count() > 1;
    if verbose { for s in m.samples.iter().step_by(20) {
        println!("{:.1} {} x {:.1} y {:.2} v {:.2} vc {:.2} g {:.3} cl {:?}", s.t, s.label, s.x, s.y, s.v, s.v_cmd, s.steer_cmd, s.closest.map(|c| (c*100.0).round()/100.0));
    }}
}
