use situ_sim::control::*;
use situ_sim::geom::Pose;
use situ_sim::vehicle::*;
fn run(g: &Gains, x0: f64, y0: f64, th0: f64) -> (f64, f64, f64) {
    let params = VehicleParams::urban();
    let mut veh = Vehicle::new(params, Pose::new(x0, y0, th0));
    let target = Target { pose: Pose::new(30.0, 2.0, 0.2), v: 0.3, curvature: 0.0 };
    let mut best = (f64::INFINITY, 0.0, 0.0);
    for i in 0..3000 {
        let inp = target_reaching(&veh.state.pose, &target);
        let cmd = control_law(&inp, g, &params, params.max_speed);
        veh.step(cmd, 0.05);
        let e = posture_errors(&veh.state.pose, &target.pose);
        if e.d < best.0 { best = (e.d, e.etheta, i as f64 * 0.05); }
    }
    best
}
fn main() {
    for kd in [0.05, 0.1, 0.2] { for kl in [0.05, 0.1, 0.2, 0.5] { for kt in [0.3, 0.5, 1.0, 1.5] { for krt in [0.0, 0.1, 0.5] {
        let g = Gains { kd, kl, ko: 1.0, kx: 1.0, krt, ktheta: kt };
        let r: Vec<_> = [(0.0, 0.0, 0.0), (0.0, 4.0, -0.5), (2.0, -5.0, 1.0), (0.0, 0.0, 1.2)].iter().map(|&(x,y,t)| run(&g,x,y,t)).collect();
        let worst = r.iter().map(|x| x.0).fold(0.0, f64::max);
        let wth = r.iter().map(|x| x.1.abs()).fold(0.0, f64::max);
        let tt = r.iter().map(|x| x.2).fold(0.0, f64::max);
        { println!("kd {kd} kl {kl} kt {kt} krt {krt}: worst d {worst:.3} eth {wth:.2} t {tt:.1}"); }
    }}}}
}
