//! Wall time of one hour of simulated outdoor mission (world + vehicle +
//! sensors at 20 Hz + Fusion, GPL, LPL, Drive + the simple situation logic),
//! the default mission driven again and again. Without arguments the
//! metrics keep the summary only; `--samples` records every tick too
//! (closest distance and time to collision included).
//!
//! ```sh
//! cargo run --release -p situ-sim --example perf [-- --samples]
//! ```
use situ_sim::baseline::outdoor::OutdoorSim;
use situ_sim::scenario;
use std::time::Instant;

fn main() {
    let world = scenario::outdoor_default().world;
    let hour = 3600.0;
    let start = Instant::now();
    let (mut simulated, mut missions, mut ticks) = (0.0, 0u32, 0u64);
    while simulated < hour {
        let sim = OutdoorSim::new(world.clone(), missions as u64 + 1);
        let mut sim = if std::env::args().any(|a| a == "--samples") { sim } else { sim.without_samples() };
        while !sim.done && sim.t < hour - simulated {
            sim.step();
            ticks += 1;
        }
        simulated += sim.t;
        missions += 1;
    }
    let wall = start.elapsed().as_secs_f64();
    println!(
        "simulated {simulated:.0} s ({missions} missions, {ticks} ticks at 20 Hz) in {wall:.3} s wall: {:.0}× real time, {:.1} µs per tick",
        simulated / wall,
        wall * 1e6 / ticks as f64
    );
}
