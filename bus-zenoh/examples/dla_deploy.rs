//! DLA's stack (`rules/dla.situ`) over Zenoh, in the processes of a
//! deployment file: peer to peer (`examples/dla/deploy-peers.toml`, a full
//! mesh) or through a router (`examples/dla/deploy-router.toml`, every
//! process a client of one router process). This program is the
//! Bulletinboard's process; it spawns every other process of the file
//! (itself, with `--child`), each opened as the file says (its agents, its
//! mode, its endpoints), and measures
//!
//! 1. **event to state to every agent process**: RoutePlanner's process
//!    reports `ROUTE(number: n, regions: 4)`, which takes Planning or
//!    Replanning to Following, then PathPlanner's reports
//!    `PATH_BLOCKED(route: n)`, which takes Following to Replanning, and so
//!    on, one event every 50 ms (within the agents' event limits); the time
//!    from the event's stamp to the last agent process seeing the new state;
//! 2. **data**: messages per second from PathPlanner's process (the
//!    deliberative layer) to Reactive's (the reactive layer).
//!
//! The Bulletinboard's process runs the engine and broadcasts the status
//! (repeated every 200 ms, as the Bulletinboard does). The other processes
//! report what they saw on `bench/<robot>/report` through their own
//! sessions (the same links as the stack's messages); all read one clock
//! (this host's), so one-way times are exact.
//!
//! `cargo run --release -p situ-bus-zenoh --example dla_deploy -- peers|router [ROUNDS]`

use situ_bus_zenoh::deploy::Deployment;
use situ_bus_zenoh::{Placement, Router, ZenohBus};
use situ_compiler::bundle::{Content, Value};
use situ_runtime::agent::Body;
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::{Bus, DataMsg, Doorbell, EventMsg, StatusMsg};
use situ_runtime::rete::Engine;
use std::collections::BTreeMap;
use std::path::PathBuf;
use std::process::{Child, Command};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};
use zenoh::Wait;

/// Data messages from the deliberative process to the reactive one.
const DATA: i64 = 200_000;
/// Between two events of the rounds: each of the two planners reports at
/// most 10 a second, within its limit (20 a second for PathPlanner's 5 Hz).
const PACE: Duration = Duration::from_millis(50);

fn now_ns() -> u64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64)
}

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The rules and the deployment file of `topology` (`peers` or `router`).
fn load(topology: &str) -> (Arc<Content>, Deployment, PathBuf) {
    let c = situ_compiler::check(&root().join("rules/dla.situ"), &situ_compiler::loader::FsLoader).expect("dla.situ");
    assert_eq!(c.errors(), 0, "rules/dla.situ has errors");
    let c = Arc::new(situ_compiler::bundle::build(&c));
    let names: Vec<String> = c.agents.iter().map(|a| a.name.clone()).collect();
    let path = root().join(format!("examples/dla/deploy-{topology}.toml"));
    let d = Deployment::load(&path, &names).unwrap_or_else(|e| panic!("{e}"));
    (c, d, path)
}

fn report_key(robot: &str) -> String {
    format!("bench/{robot}/report")
}

fn go_key(robot: &str) -> String {
    format!("bench/{robot}/go")
}

/// One process of the deployment other than the Bulletinboard's.
fn child(topology: &str, name: &str, rounds: u64) {
    let (c, d, _) = load(topology);
    let p = d.process(name).expect("a process of the file");
    if p.routes_only() {
        let _router = Router::open(&d.zenoh_config(p)).expect("router");
        std::thread::sleep(Duration::from_secs(3600)); // until killed
        return;
    }
    let agent = |n: &str| c.agent_id(n).expect("an agent of dla.situ");
    let here = |n: &str| p.agents.iter().any(|a| a == n);
    let bus = ZenohBus::open(
        c.clone(),
        Placement::of(&d, p, &c),
        &d.zenoh_config(p),
        Capacity { data: 1 << 20, events: 1 << 16 },
    )
    .expect("bus");
    let session = bus.session().clone();
    let report = |msg: serde_json::Value| {
        let _ = session.put(report_key(&d.robot), msg.to_string()).wait();
    };
    let go = Arc::new(AtomicBool::new(false));
    let _go = {
        let go = go.clone();
        session.declare_subscriber(go_key(&d.robot)).callback(move |_| go.store(true, Ordering::Release)).wait()
    };
    let me = agent(&p.agents[0]);
    let bell = Arc::new(Doorbell::default());
    bus.set_doorbell(me, bell.clone());
    let (route, blocked) = (c.event_id("ROUTE").unwrap(), c.event_id("PATH_BLOCKED").unwrap());
    let following = c.state_id("Following").unwrap();
    let (mut seq, mut state) = (0u64, c.initial);
    // The latest event of the rounds: after how many flips, and when.
    let mut posted: Option<(u64, Instant)> = None;
    let mut rounds_done = false;
    let (mut received, mut first_data, mut quiet_since) = (0i64, None::<Instant>, Instant::now());
    let mut out = Vec::new();
    let start = Instant::now();
    while start.elapsed() < Duration::from_secs(600) {
        if let Some(st) = bus.status(me) {
            if st.seq != seq {
                (seq, state) = (st.seq, st.state);
                report(serde_json::json!({ "process": name, "seq": seq, "at": now_ns() }));
            }
        }
        // The rounds: the state at `seq` is the result of `seq - 1` events;
        // the next event once the previous one's state is seen (again if
        // that state has not come within a second), `PACE` after it.
        let flips = seq.saturating_sub(1);
        let since = posted.map(|(_, t)| t.elapsed());
        let due = since.is_none_or(|e| e >= PACE);
        let fresh = posted.is_none_or(|(f, _)| f != flips) || since.is_some_and(|e| e > Duration::from_secs(1));
        if go.load(Ordering::Acquire) && seq > 0 && flips < rounds && due && fresh {
            let (event, by, payload) = if state == following {
                (blocked, "PathPlanner", vec![Value::I64((seq / 2) as i64)])
            } else {
                (route, "RoutePlanner", vec![Value::I64(seq.div_ceil(2) as i64), Value::I64(4)])
            };
            if here(by) {
                bus.send_event(EventMsg { agent: agent(by), event, time: now_ns(), payload, urgent: false });
                posted = Some((flips, Instant::now()));
            }
        }
        if flips >= rounds && here("PathPlanner") && !rounds_done {
            rounds_done = true;
            std::thread::sleep(Duration::from_millis(300));
            let body = Body::json(serde_json::json!({ "subgoal": [1.5, 2.0], "route": seq / 2 }));
            let (from, to) = (agent("PathPlanner"), agent("Reactive"));
            let t0 = Instant::now();
            for n in 0..DATA {
                bus.send_data(DataMsg { from, to, time: n as u64, urgent: false, body: body.clone() });
            }
            report(serde_json::json!({ "process": name, "sent_ns": t0.elapsed().as_nanos() as u64 }));
        }
        if here("Reactive") && received >= 0 {
            out.clear();
            bus.recv_data(agent("Reactive"), &mut out);
            let n = out.iter().filter(|m| m.from == agent("PathPlanner")).count() as i64;
            if n > 0 {
                first_data.get_or_insert_with(Instant::now);
                received += n;
                quiet_since = Instant::now();
            }
            // All of it, or what came before the stream stopped for 0.5 s
            // (data is keep-latest: Zenoh drops it under congestion).
            let quiet = first_data.is_some() && quiet_since.elapsed() > Duration::from_millis(500);
            if received >= DATA || (quiet && received > 0) {
                let ns = quiet_since.duration_since(first_data.unwrap_or(quiet_since)).as_nanos() as u64;
                report(serde_json::json!({ "process": name, "received": received, "ns": ns }));
                received = -1;
            }
        }
        bell.wait_until(Instant::now() + Duration::from_millis(1));
    }
}

fn quantiles(mut v: Vec<u64>) -> String {
    if v.is_empty() {
        return "no complete round".into();
    }
    v.sort_unstable();
    let q = |p: f64| v[((v.len() as f64 * p) as usize).min(v.len() - 1)] as f64 / 1e3;
    format!("p50 {:.0} µs, p99 {:.0} µs, max {:.0} µs ({} rounds)", q(0.5), q(0.99), q(1.0), v.len())
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("--child") {
        return child(&args[2], &args[3], args[4].parse().expect("ROUNDS"));
    }
    let topology = args.get(1).map(String::as_str).unwrap_or("");
    if !matches!(topology, "peers" | "router") {
        eprintln!("usage: dla_deploy peers|router [ROUNDS]");
        std::process::exit(2);
    }
    let rounds: u64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(300);
    let (c, d, path) = load(topology);
    // The others first: a client's session waits for its router.
    let exe = std::env::current_exe().unwrap();
    let mut children: Vec<Child> = d
        .processes
        .iter()
        .filter(|p| !p.board)
        .map(|p| Command::new(&exe).args(["--child", topology, &p.name, &rounds.to_string()]).spawn().unwrap())
        .collect();
    let board = d.board();
    let bus = ZenohBus::open(
        c.clone(),
        Placement::of(&d, board, &c),
        &d.zenoh_config(board),
        Capacity { data: 64, events: 1 << 16 },
    )
    .expect("the Bulletinboard's bus");
    let (tx, rx) = mpsc::channel::<serde_json::Value>();
    let _reports = bus
        .session()
        .declare_subscriber(report_key(&d.robot))
        .callback(move |s| {
            if let Ok(v) = serde_json::from_slice(&s.payload().to_bytes()) {
                let _ = tx.send(v);
            }
        })
        .wait()
        .expect("subscriber");
    // The processes whose agents must see each state.
    let watchers: Vec<&str> = d.processes.iter().filter(|p| !p.agents.is_empty()).map(|p| p.name.as_str()).collect();
    let connections: usize = d.processes.iter().map(|p| p.connect.len()).sum();
    let mut engine = Engine::new(c.clone());
    // Per status: when the event that caused it was stamped, and when each
    // agent process saw it.
    let mut rounds_seen: BTreeMap<u64, (u64, Vec<u64>)> = BTreeMap::new();
    rounds_seen.insert(1, (0, vec![0; watchers.len()]));
    let (mut seq, mut sent_at) = (1u64, Instant::now() - Duration::from_secs(1));
    let (mut sent_ns, mut received) = (None::<u64>, None::<(u64, u64)>);
    let complete = |r: &BTreeMap<u64, (u64, Vec<u64>)>| r.iter().filter(|(s, r)| **s > 1 && !r.1.contains(&0)).count();
    let deadline = Instant::now() + Duration::from_secs(60) + PACE * 2 * rounds as u32;
    let mut going = false;
    while Instant::now() < deadline
        && (complete(&rounds_seen) < rounds as usize || received.is_none() || sent_ns.is_none())
    {
        let mut got = Vec::new();
        let _ = bus.recv_events(&mut got);
        for e in got {
            if let Ok(Some(ch)) = engine.post(e.event, e.time, &e.payload) {
                seq += 1;
                bus.send_status(StatusMsg { state: ch.to, time: now_ns(), seq });
                sent_at = Instant::now();
                rounds_seen.insert(seq, (e.time, vec![0; watchers.len()]));
            }
        }
        if sent_at.elapsed() >= Duration::from_millis(200) {
            bus.send_status(StatusMsg { state: engine.state(), time: now_ns(), seq });
            sent_at = Instant::now();
            if going && seq == 1 {
                let _ = bus.session().put(go_key(&d.robot), "go").wait();
            }
        }
        while let Ok(r) = rx.try_recv() {
            let process = r["process"].as_str().unwrap_or("");
            if let (Some(s), Some(at)) = (r["seq"].as_u64(), r["at"].as_u64()) {
                let i = watchers.iter().position(|w| *w == process);
                if let (Some(i), Some(round)) = (i, rounds_seen.get_mut(&s)) {
                    round.1[i] = at;
                }
            }
            sent_ns = sent_ns.or(r["sent_ns"].as_u64());
            if let (Some(n), Some(ns)) = (r["received"].as_u64(), r["ns"].as_u64()) {
                received = Some((n, ns));
            }
        }
        // Every agent process follows the initial state: the rounds begin.
        if !going && !rounds_seen[&1].1.contains(&0) {
            going = true;
            let _ = bus.session().put(go_key(&d.robot), "go").wait();
        }
        let _ = bus.wait_events(Instant::now() + Duration::from_millis(1));
    }
    let e2e: Vec<u64> = rounds_seen
        .iter()
        .filter(|(s, r)| **s > 1 && !r.1.contains(&0))
        .map(|(_, (t_event, seen))| seen.iter().max().unwrap().saturating_sub(*t_event))
        .collect();
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    println!(
        "DLA over Zenoh, {topology} ({}): {} processes, {connections} connection(s); load {}",
        path.strip_prefix(root()).unwrap_or(&path).display(),
        d.processes.len(),
        load.split_whitespace().take(3).collect::<Vec<_>>().join(" ")
    );
    println!("event to state to every agent process ({}): {}", watchers.len(), quantiles(e2e));
    match received {
        Some((n, ns)) => println!(
            "data deliberative -> reactive: {:.0} messages/s received ({n} of {DATA} in {:.2} s; sent in {})",
            n as f64 / (ns as f64 * 1e-9),
            ns as f64 * 1e-9,
            sent_ns.map_or("?".into(), |s| format!("{:.2} s", s as f64 * 1e-9))
        ),
        None => println!("data deliberative -> reactive: no report from the reactive process in time"),
    }
    for ch in &mut children {
        let _ = ch.kill();
        let _ = ch.wait();
    }
}
