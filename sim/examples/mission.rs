//! Runs a scenario and writes metrics.json, trajectory.svg and timeline.svg.
//!
//! ```sh
//! cargo run -p situ-sim --example mission -- outdoor-default out/outdoor
//! cargo run -p situ-sim --example mission -- dafflon-4 out/dafflon   # both strategies
//! ```
use situ_sim::baseline::{outdoor, ugv as sim_loop};
use situ_sim::{plot, scenario, ugv};
use std::path::PathBuf;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("outdoor-default", String::as_str);
    let out = PathBuf::from(args.get(2).map_or("out", String::as_str));
    let sc = match scenario::builtin(name) {
        Some(s) => s,
        None => match scenario::load(std::path::Path::new(name)) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("{e}");
                std::process::exit(2);
            }
        },
    };
    if sc.world.vehicle == situ_sim::vehicle::VehicleParams::urban() {
        let table = sim_loop::compare(
            &sc.world,
            &[ugv::Strategy::HardSwitch, ugv::Strategy::Merge],
            1,
            &ugv::UgvConfig::default(),
        );
        println!("{table}");
        for m in &table.runs {
            if let Err(e) = plot::write_run(&out.join(&m.controller), &sc.world, m) {
                eprintln!("{e}");
            }
        }
    } else {
        let m = outdoor::run_mission(sc.world.clone(), 1, 3600.0);
        println!("{:#?}", m.summary);
        if let Err(e) = plot::write_run(&out, &sc.world, &m) {
            eprintln!("{e}");
        }
    }
}
