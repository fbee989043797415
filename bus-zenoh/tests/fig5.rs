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

/// Runs one node of the deployment for `secs` (starting after `delay`);
/// returns its summary.
pub fn node(
    c: &Arc<Content>,
    d: &Deployment,
    name: &str,
    delay: f64,
    secs: f64,
    log: &demo::Log,
) -> (situ_runtime::summary::Summary, situ_runtime::record::Memory) {
    std::thread::sleep(Duration::from_secs_f64(delay));
    let p = d.process(name).unwrap();
    let placement = Placement::of(d, p, c);
    let bus = ZenohBus::open(c.clone(), placement, &d.zenoh_config(p), Capacity::default()).unwrap();
    let bus: Arc<dyn Bus> = Arc::new(bus);
    let mine: Vec<Box<dyn agent::Agent>> = demo::fig5(Duration::from_millis(1500), log.clone())
        .into_iter()
        .filter(|a| p.agents.iter().any(|n| n == a.name()))
        .collect();
    let bound = agent::bind(c, mine, false).unwrap();
    let config = RealtimeConfig { board: p.board, stop_on_final: false, ..RealtimeConfig::default() };
    let memory = situ_runtime::record::SharedMemory::default();
    let sink = Some(Box::new(memory.clone()) as Box<dyn situ_runtime::record::Sink>);
    let summary = realtime::run_on(c.clone(), bound, sink, config, Duration::from_secs_f64(secs), bus, &mut |_| {});
    (summary, memory.snapshot())
}

#[test]
fn a_silent_process_is_an_emergency_and_a_silent_board_a_safe_mode() {
    let c = content();
    let d = deployment(&c, port());
    let log: demo::Log = Arc::new(Mutex::new(Vec::new()));
    let (board, sensors, pipeline) = std::thread::scope(|scope| {
        let b = scope.spawn(|| node(&c, &d, "board", 0.0, 4.0, &log));
        // The sensors' process dies at 2.5 s: LADAR and RFCCD fall silent.
        let s = scope.spawn(|| node(&c, &d, "sensors", 0.0, 2.5, &log));
        // The pipeline outlives the Bulletinboard by 2 s.
        let p = scope.spawn(|| node(&c, &d, "pipeline", 0.0, 6.0, &log));
        (b.join().unwrap(), s.join().unwrap(), p.join().unwrap())
    });
    let ((board, _), (sensors, _), (pipeline, pipeline_rec)) = (board, sensors, pipeline);
    assert_eq!(sensors.path, ["RS", "RO"]);
    // The silent sensors are an emergency; Drive, standing, ends it at once
    // (EM -> SP in one cascade: the state at rest goes from RO to SP).
    assert_eq!(board.path, ["RS", "RO", "SP"]);
    assert!(board.rules_fired.contains_key("ladar_silent") || board.rules_fired.contains_key("camera_silent"));
    assert_eq!(board.rules_fired.get("halted"), Some(&1));
    let ro = board.states.iter().find(|s| s.state == "RO").unwrap().seconds;
    // RO from ~1.5 s to the sensors' silence (2.5 s) plus `stale after 500ms`.
    assert!((0.9..2.5).contains(&ro), "RO for {ro} s");
    // The pipeline followed, then the Bulletinboard fell silent at 4 s:
    // safe mode.
    assert_eq!(pipeline.path, ["RS", "RO", "SP"]);
    assert!(pipeline_rec.diagnostics.iter().any(|(_, t)| t.contains("safe mode")), "{:?}", pipeline_rec.diagnostics);
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
                let placement = Placement::of(d, p, &c);
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

#[test]
fn a_bulletinboard_that_comes_back_resumes_from_the_current_events() {
    let c = content();
    let d = deployment(&c, port());
    let log: demo::Log = Arc::new(Mutex::new(Vec::new()));
    let ((first, _), (second, _), (sensors, _), (pipeline, rec)) = std::thread::scope(|scope| {
        let b1 = scope.spawn(|| node(&c, &d, "board", 0.0, 3.0, &log));
        // A new Bulletinboard on the same endpoint 1.5 s later.
        let b2 = scope.spawn(|| node(&c, &d, "board", 4.5, 2.5, &log));
        let s = scope.spawn(|| node(&c, &d, "sensors", 0.0, 7.5, &log));
        let p = scope.spawn(|| node(&c, &d, "pipeline", 0.0, 7.5, &log));
        (b1.join().unwrap(), b2.join().unwrap(), s.join().unwrap(), p.join().unwrap())
    });
    assert_eq!(first.path, ["RS", "RO"]);
    assert_eq!(second.path, ["RS", "RO"]);
    // The new Bulletinboard starts from its initial state (RS) and the
    // sensors' current reports take it to RO again; the other processes
    // may or may not have seen the RS in between (they were reconnecting),
    // but they end in the state it broadcasts.
    for p in [&sensors, &pipeline] {
        assert_eq!(p.path[..2], ["RS", "RO"]);
        assert_eq!(p.final_state, "RO", "{:?}", p.path);
    }
    let texts: Vec<&str> = rec.diagnostics.iter().map(|(_, t)| t.as_str()).collect();
    assert!(texts.iter().any(|t| t.contains("safe mode (every agent waits)")), "{texts:?}");
    assert!(texts.iter().any(|t| t.contains("safe mode ends")), "{texts:?}");
}
