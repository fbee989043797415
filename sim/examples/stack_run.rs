//! Runs a rules file's stack on a scenario and prints the tables: a tool
//! for tuning the stack without the CLI.
//!
//! ```sh
//! cargo run --release -p situ-sim --example stack_run -- rules/outdoor.situ [SCENARIO] [SEED]
//! ```
//!
//! Environment: `RATES=Gps:20,LPL:20` sets agents' rates over the rules;
//! `PROGRESS=1` prints the live line every simulated second; `STEER=1` the
//! largest steering-rate steps, and `WINDOW=T` the samples around T seconds.
use situ_compiler::loader::FsLoader;
use situ_sim::scenario;
use situ_sim::stack::{Recording, Registry, StackConfig, StackRun};
use std::sync::Arc;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rules = args.get(1).map_or("rules/outdoor.situ", String::as_str);
    let checked = situ_compiler::check(std::path::Path::new(rules), &FsLoader).expect("rules read");
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    let kind = Registry::sim().of(&content).expect("a known stack");
    let name = args.get(2).map_or(kind.default_scenario(), String::as_str);
    let sc = scenario::builtin(name).expect("a built-in scenario");
    let seed = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(1);
    let mut cfg = StackConfig { seed, until: kind.default_until(), ..StackConfig::default() };
    if let Ok(r) = std::env::var("RATES") {
        for kv in r.split(',') {
            let (k, v) = kv.split_once(':').expect("NAME:HZ");
            cfg.rates.insert(k.into(), v.parse().expect("a rate"));
        }
    }
    let start = std::time::Instant::now();
    let mut run = StackRun::new(content, kind, &sc.world, cfg, Recording::default()).expect("agents bound");
    run.run(&mut |r| {
        if std::env::var_os("PROGRESS").is_some() {
            eprintln!("{}", r.progress().line())
        }
    });
    let report = run.finish().expect("finished");
    println!("{}", report.runtime.table());
    println!("{}", report.table());
    println!("wall {:.3} s", start.elapsed().as_secs_f64());
    if std::env::var_os("STEER").is_some() {
        let sm = &report.metrics.samples;
        let mut rates: Vec<(f64, f64, String, f64, f64)> = sm
            .windows(2)
            .map(|w| {
                ((w[1].steer_cmd - w[0].steer_cmd) / 0.02, w[1].t, w[1].label.clone(), w[0].steer_cmd, w[1].steer_cmd)
            })
            .collect();
        rates.sort_by(|a, b| b.0.abs().total_cmp(&a.0.abs()));
        for r in rates.iter().take(3) {
            println!("{r:?}");
        }
        if let Ok(w) = std::env::var("WINDOW") {
            let t: f64 = w.parse().unwrap_or(0.0);
            for s in sm.iter().filter(|s| (s.t - t).abs() < 0.5) {
                println!(
                    "{:.2} {} x {:.2} y {:.2} th {:.3} v {:.2} steer {:.3} cmd v {:.2} steer {:.3}",
                    s.t, s.label, s.x, s.y, s.theta, s.v, s.steer, s.v_cmd, s.steer_cmd
                );
            }
        }
    }
}
