//! The example of Fig. 5 over Zenoh, on 127.0.0.1: three nodes (sensors;
//! Fusion, LPL and Drive; the Bulletinboard), each with its own Zenoh
//! session and its own bus, in threads of this test. The processes of
//! `situ up` are tested in the CLI tests; here the bus itself.

use situ_bus_zenoh::deploy::Deployment;
use situ_bus_zenoh::{Placement, ZenohBus};
use situ_compiler::bundle::Content;
use situ_runtime::agent;
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::Bus;
use situ_runtime::demo;
use situ_runtime::realtime::{self, RealtimeConfig};
use std::sync::{Arc, Mutex};
use std::time::Duration;

fn content() -> Arc<Content> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/fig5/fig5.situ");
    let c = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap();
    assert_eq!(c.errors(), 0);
    Arc::new(situ_compiler::bundle::build(&c))
}

/// A free TCP port on 127.0.0.1.
pub fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// The host table: every process listens; each connects to the ones
/// before it (peers do not route for each other: each pair must meet).
fn deployment(c: &Content, board: u16) -> Deployment {
    let (sensors, pipeline) = (port(), port());
    let text = format!(
        r#"robot = "fig5"
[[process]]
name = "board"
board = true
listen = ["tcp/127.0.0.1:{board}"]
[[process]]
name = "sensors"
agents = ["RFCCD", "LADAR"]
listen = ["tcp/127.0.0.1:{sensors}"]
connect = ["tcp/127.0.0.1:{board}"]
[[process]]
name = "pipeline"
agents = ["Fusion", "LPL", "Drive"]
listen = ["tcp/127.0.0.1:{pipeline}"]
connect = ["tcp/127.0.0.1:{board}", "tcp/127.0.0.1:{sensors}"]
"#
    );
    let agents: Vec<String> = c.agents.iter().map(|a| a.name.clone()).collect();
    Deployment::parse(&text, &agents).unwrap()
}

#[test]
fn figure_5_across_three_nodes() {
    let c = content();
    let d = deployment(&c, port());
    let log: demo::Log = Arc::new(Mutex::new(Vec::new()));
    let states = Arc::new(Mutex::new(Vec::new()));
    std::thread::scope(|scope| {
        for p in &d.processes {
            let (c, d, log, states) = (c.clone(), &d, log.clone(), states.clone());
            scope.spawn(move || {
                let local: Vec<bool> = c.agents.iter().map(|a| p.agents.contains(&a.name)).collect();
                let placement = Placement { robot: d.robot.clone(), local: local.clone(), board: p.board };
                let bus = ZenohBus::open(c.clone(), placement, &d.zenoh_config(p), Capacity::default()).unwrap();
                let bus: Arc<dyn Bus> = Arc::new(bus);
                let mine: Vec<Box<dyn agent::Agent>> = demo::fig5(Duration::from_millis(1500), log)
                    .into_iter()
                    .filter(|a| p.agents.iter().any(|n| n == a.name()))
                    .collect();
                let bound = agent::bind(&c, mine, false).unwrap();
                let config = RealtimeConfig { board: p.board, stop_on_final: false, ..RealtimeConfig::default() };
                let summary =
                    realtime::run_on(c.clone(), bound, None, config, Duration::from_secs(4), bus, &mut |_| {});
                states.lock().unwrap().push((p.name.clone(), summary.path.clone()));
            });
        }
    });
    let states = states.lock().unwrap();
    for (name, path) in states.iter() {
        assert_eq!(path, &["RS", "RO"], "{name} followed the Bulletinboard");
    }
    let log = log.lock().unwrap();
    let t_ro = log.iter().filter(|(_, to, from)| to == "Fusion" && from == "LADAR").map(|(t, _, _)| *t).min();
    let t_ro = t_ro.expect("Fusion woke and read LADAR across processes");
    // Fig. 5a: before, LPL read RFCCD; Fig. 5b: after, Fusion (none from RFCCD).
    assert!(log.iter().any(|(t, to, from)| *t < t_ro && to == "LPL" && from == "RFCCD"), "{log:?}");
    assert!(log.iter().any(|(t, to, from)| *t > t_ro && to == "LPL" && from == "Fusion"), "{log:?}");
    let late_rfccd = log.iter().filter(|(t, to, from)| *t > t_ro + 300_000_000 && to == "LPL" && from == "RFCCD");
    assert_eq!(late_rfccd.count(), 0);
}
