//! Robust at the boundary, over Zenoh on 127.0.0.1: the Fig. 5 stack in two
//! processes (the Bulletinboard; the five agents), each with its own
//! session and bus, in threads of this test, and an intruder: a Zenoh
//! session that is not in the deployment and writes on the event keys.
//! The agents never see an obstacle, so the stack must stay in RS: events
//! from the future and floods are refused and counted, and leave the stack
//! in its state.

use situ_bus_zenoh::deploy::Deployment;
use situ_bus_zenoh::wire;
use situ_bus_zenoh::{Placement, ZenohBus};
use situ_compiler::bundle::Content;
use situ_runtime::agent;
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::Bus;
use situ_runtime::demo;
use situ_runtime::realtime::{self, RealtimeConfig};
use situ_runtime::record::{Memory, SharedMemory, Sink};
use situ_runtime::summary::Summary;
use std::path::Path;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};
use zenoh::qos::CongestionControl;
use zenoh::Wait;

fn content() -> Arc<Content> {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/fig5/fig5.situ");
    let c = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap();
    assert_eq!(c.errors(), 0);
    Arc::new(situ_compiler::bundle::build(&c))
}

fn port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

fn deployment(c: &Content, board: u16, agents: u16) -> Deployment {
    let text = format!(
        r#"robot = "edge"
[[process]]
name = "board"
board = true
listen = ["tcp/127.0.0.1:{board}"]
[[process]]
name = "agents"
agents = ["RFCCD", "LADAR", "Fusion", "LPL", "Drive"]
listen = ["tcp/127.0.0.1:{agents}"]
connect = ["tcp/127.0.0.1:{board}"]
"#
    );
    let names: Vec<String> = c.agents.iter().map(|a| a.name.clone()).collect();
    Deployment::parse(&text, &names).unwrap()
}

fn wall_ns() -> u64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos() as u64
}

/// A session of the intruder, to the Bulletinboard's process only, and a
/// publisher per key once the Bulletinboard's subscription is known (or
/// `None` after 10 s).
fn intruder(board: u16, keys: &[String]) -> Option<(zenoh::Session, Vec<zenoh::pubsub::Publisher<'static>>)> {
    let cfg = format!(
        r#"{{ mode: "peer", connect: {{ endpoints: ["tcp/127.0.0.1:{board}"] }},
             scouting: {{ multicast: {{ enabled: false }}, gossip: {{ enabled: false }} }} }}"#
    );
    let session = zenoh::open(zenoh::Config::from_json5(&cfg).unwrap()).wait().unwrap();
    let mut publishers = Vec::new();
    for k in keys {
        let p = session.declare_publisher(k.clone()).congestion_control(CongestionControl::Block).wait().unwrap();
        publishers.push(p);
    }
    let give_up = Instant::now() + Duration::from_secs(10);
    let matched = |ps: &[zenoh::pubsub::Publisher<'static>]| {
        ps.iter().all(|p| p.matching_status().wait().is_ok_and(|m| m.matching()))
    };
    while !matched(&publishers) {
        if Instant::now() > give_up {
            return None;
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Some((session, publishers))
}

/// The tests start several Zenoh sessions each: one at a time, so that they
/// do not starve each other on a small machine.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

/// What one process did: its summary and its recording.
struct Process {
    summary: Summary,
    recording: Memory,
}

/// Runs the two processes until `intrude` is done and 1.5 s more (so that
/// a fact aged by the intruder would have gone stale); `intrude` gets the
/// Bulletinboard's port. Returns what the Bulletinboard's process and the
/// agents' process did, and what `intrude` returned.
fn run<T: Send>(intrude: impl FnOnce(u16) -> T + Send) -> (Process, Process, T) {
    let _one = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let c = content();
    let (board_port, agents_port) = (port(), port());
    let d = deployment(&c, board_port, agents_port);
    let log: demo::Log = Arc::new(Mutex::new(Vec::new()));
    let stop = Arc::new(AtomicBool::new(false));
    let summaries = Arc::new(Mutex::new(Vec::new()));
    let out = std::thread::scope(|scope| {
        for p in &d.processes {
            let (c, d, log, summaries, stop) = (c.clone(), &d, log.clone(), summaries.clone(), stop.clone());
            scope.spawn(move || {
                let placement = Placement::of(d, p, &c);
                let bus = ZenohBus::open(c.clone(), placement, &d.zenoh_config(p), Capacity::default()).unwrap();
                let bus: Arc<dyn Bus> = Arc::new(bus);
                // No obstacle ever: the stack stays in RS unless something
                // from outside takes it elsewhere.
                let mine: Vec<Box<dyn agent::Agent>> = demo::fig5(Duration::from_secs(3600), log)
                    .into_iter()
                    .filter(|a| p.agents.iter().any(|n| n == a.name()))
                    .collect();
                let bound = agent::bind(&c, mine, false).unwrap();
                let config = RealtimeConfig {
                    board: p.board,
                    stop_on_final: false,
                    stop: Some(stop),
                    max_skew: d.max_skew(),
                    ..RealtimeConfig::default()
                };
                let memory = SharedMemory::default();
                let sink = Some(Box::new(memory.clone()) as Box<dyn Sink>);
                // The run ends when the test raises `stop`; 90 s is a bound.
                let s = realtime::run_on(c.clone(), bound, sink, config, Duration::from_secs(90), bus, &mut |_| {});
                summaries.lock().unwrap().push((p.board, Process { summary: s, recording: memory.snapshot() }));
            });
        }
        // Let the stack settle in RS before the intruder comes.
        std::thread::sleep(Duration::from_millis(1000));
        let out = intrude(board_port);
        std::thread::sleep(Duration::from_millis(1500));
        stop.store(true, Ordering::SeqCst);
        out
    });
    let mut summaries = std::mem::take(&mut *summaries.lock().unwrap());
    summaries.sort_by_key(|(board, _)| !*board);
    let mut it = summaries.into_iter().map(|(_, s)| s);
    let (board, agents) = (it.next().unwrap(), it.next().unwrap());
    // The real agents did talk.
    assert!(log.lock().unwrap().iter().any(|(_, to, from)| to == "LPL" && from == "RFCCD"));
    (board, agents, out)
}

fn refused(s: &Summary, key: &str) -> u64 {
    s.board.refused.get(key).copied().unwrap_or(0)
}

/// The recorded diagnostics of a process.
fn diagnostics(p: &Process) -> Vec<&str> {
    p.recording.diagnostics.iter().map(|(_, t)| t.as_str()).collect()
}

/// How many events of `agent` were recorded as refused over its limit.
fn flooded(p: &Process, agent: &str) -> u64 {
    let tail = format!(" event(s) of `{agent}` refused: over its limit");
    diagnostics(p)
        .iter()
        .filter_map(|t| t.strip_prefix("message refused: ")?.split_once(&tail).map(|(n, _)| n.parse::<u64>().unwrap()))
        .sum()
}

#[test]
fn events_from_the_future_are_refused_and_the_stack_stays() {
    let (board, agents, sent) = run(|port| {
        let key = wire::event_key("edge", "LADAR");
        let Some((session, publishers)) = intruder(port, std::slice::from_ref(&key)) else { return 0 };
        // Well-formed LADAR events: 5 s ahead, and at 2^63 - 1 ns.
        let mut sent = 0;
        for time_ns in [wall_ns() + 5_000_000_000, i64::MAX as u64] {
            let e = serde_json::json!({ "v": 1, "agent": "LADAR", "event": "LAOBN", "time_ns": time_ns,
                                        "payload": {} });
            publishers[0].put(e.to_string()).wait().unwrap();
            sent += 1;
        }
        drop(publishers);
        let _ = session.close().wait();
        sent
    });
    assert_eq!(sent, 2, "the intruder met the Bulletinboard");
    let (board, agents) = (&board.summary, &agents.summary);
    assert_eq!(board.path, ["RS"], "{:?}", board.board);
    assert_eq!(agents.path, ["RS"]);
    assert_eq!(refused(board, "from the future"), 2, "{:?}", board.board.refused);
    assert!(board.board.accepted > 0);
}

/// What the flooder sent.
#[derive(Debug, Default)]
struct Flood {
    garbage: u64,
    ladar: u64,
}

#[test]
fn a_flood_on_the_event_keys_leaves_the_stack_in_its_state() {
    let (board, agents, flood) = run(|port| {
        let keys = [wire::event_key("edge", "LADAR"), wire::event_key("edge", "RFCCD")];
        let Some((session, publishers)) = intruder(port, &keys) else { return Flood::default() };
        let mut flood = Flood::default();
        // 12,000 messages as fast as the link takes them: garbage on both
        // keys, and well-formed LADAR events stamped now (LADAR flooding).
        for i in 0..12_000u32 {
            match i % 4 {
                0 => {
                    let e = serde_json::json!({ "v": 1, "agent": "LADAR", "event": "LAOBN", "time_ns": wall_ns(),
                                                "payload": {} });
                    publishers[0].put(e.to_string()).wait().unwrap();
                    flood.ladar += 1;
                }
                1 => {
                    publishers[1]
                        .put(format!("{{\"v\":1,\"agent\":\"RFCCD\",\"event\":\"RFRS\",\"time_ns\":{i}"))
                        .wait()
                        .unwrap();
                    flood.garbage += 1;
                }
                2 => {
                    publishers[0].put(vec![0xffu8; 64]).wait().unwrap();
                    flood.garbage += 1;
                }
                _ => {
                    publishers[1].put(r#"{"v":1,"agent":"RFCCD","event":"LAOBN","time_ns":1}"#).wait().unwrap();
                    flood.garbage += 1;
                }
            }
        }
        drop(publishers);
        let _ = session.close().wait();
        flood
    });
    assert_eq!(flood.ladar + flood.garbage, 12_000, "the intruder met the Bulletinboard");
    let (s, a) = (&board.summary, &agents.summary);
    assert_eq!(s.path, ["RS"], "{:?} {:?}", s.board, s.bus);
    assert_eq!(a.path, ["RS"], "the agents followed the Bulletinboard");
    // The status kept coming: the agents' process never fell into safe mode.
    assert!(!diagnostics(&agents).iter().any(|t| t.contains("safe mode")), "{:?}", diagnostics(&agents));
    // LADAR's flood went over its limit (4 events a period of its 10 Hz, a
    // second's worth at once): the excess was refused before the queue,
    // counted and recorded; no other agent was cut.
    let over = flooded(&board, "LADAR");
    assert!(over > 0 && over < flood.ladar, "{over} of {} refused over the limit", flood.ladar);
    for other in ["RFCCD", "Fusion", "LPL", "Drive"] {
        assert_eq!(flooded(&board, other), 0, "{other}");
    }
    // The garbage is refused too, and counted; nothing is lost in a full
    // queue.
    assert!(s.bus.rejected >= flood.garbage + over, "{:?}", s.bus);
    assert_eq!(s.bus.events_overflow, 0, "{:?}", s.bus);
    assert_eq!(s.board.lost, 0);
    let texts = diagnostics(&board);
    assert!(texts.iter().any(|t| t.contains("not a message of this protocol")), "{texts:?}");
}
