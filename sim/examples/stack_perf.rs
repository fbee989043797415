//! Wall time of one hour of simulated mission through the real stack: the
//! default mission on `rules/outdoor.situ` (the compiled rules deciding the
//! state, the runtime's simulated-time scheduler stepping the twelve agents
//! at their rates, the physics at 100 Hz), driven again and again with a new
//! seed each time. `--samples` keeps every metrics sample too (closest
//! distance and time to collision at 50 Hz); without it the summary only.
//!
//! ```sh
//! cargo run --release -p situ-sim --example stack_perf [-- --samples]
//! ```
use situ_compiler::loader::FsLoader;
use situ_sim::scenario;
use situ_sim::stack::{outdoor::Outdoor, Recording, StackConfig, StackRun};
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
    let checked = situ_compiler::check(&path, &FsLoader).expect("the rules read");
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    let world = scenario::outdoor_default().world;
    let samples = std::env::args().any(|a| a == "--samples");
    let hour = 3600.0;
    let start = Instant::now();
    let (mut simulated, mut missions, mut steps, mut events) = (0.0, 0u64, 0u64, 0u64);
    while simulated < hour {
        let cfg = StackConfig { seed: missions + 1, until: hour - simulated, samples, ..StackConfig::default() };
        let mut run = StackRun::new(content.clone(), std::sync::Arc::new(Outdoor), &world, cfg, Recording::default())
            .expect("every agent bound");
        run.run(&mut |_| {});
        let report = run.finish().expect("finished");
        simulated += report.runtime.duration_s;
        steps += report.runtime.agents.values().map(|a| a.steps).sum::<u64>();
        events += report.runtime.board.accepted;
        missions += 1;
    }
    let wall = start.elapsed().as_secs_f64();
    println!(
        "simulated {simulated:.0} s ({missions} missions, {steps} agent steps, {events} events) in {wall:.3} s wall: {:.0}× real time",
        simulated / wall
    );
}
