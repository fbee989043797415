//! The Zenoh bus on loopback, in real processes: this program starts a
//! Bulletinboard process and spawns 10 agent processes (itself, with
//! `--child N`), all on `tcp/127.0.0.1`, and measures
//!
//! 1. **status fan-out**: from the Bulletinboard's broadcast to the last of
//!    the 10 agent processes receiving it;
//! 2. **event to state to every agent**: from agent 1 (a process of its own)
//!    reporting an event to the last agent process receiving the state the
//!    Bulletinboard deduced from it;
//! 3. **data**: messages per second from agent 0 (the Bulletinboard's
//!    process) to agent 2 (another process).
//!
//! Agents report when they saw a status as events of their own (`SEEN`);
//! all processes read one clock (this host's), so one-way times are exact.
//!
//! `cargo run --release -p situ-bus-zenoh --example zenoh_bench [-- ROUNDS]`

use situ_bus_zenoh::{Placement, ZenohBus};
use situ_compiler::bundle::{Content, Value};
use situ_runtime::agent::Body;
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::bus::{Bus, DataMsg, EventMsg, StatusMsg};
use situ_runtime::rete::Engine;
use std::collections::BTreeMap;
use std::process::{Child, Command};
use std::sync::Arc;
use std::time::{Duration, Instant};

/// Agent 0 lives in the Bulletinboard's process; agents 1 to 10 each in a process of their own.
const AGENTS: usize = 11;
const DATA: i64 = 200_000;

fn now_ns() -> u64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_nanos() as u64)
}

fn content() -> Arc<Content> {
    let mut src = String::from("states { S0 initial S1 }\n");
    for i in 0..AGENTS {
        src.push_str(&format!(
            "agent A{i} sensor {{ event UP{i} event DOWN{i} event SEEN{i} {{ seq: i64, seen: i64 }} event DONE{i} {{ n: i64, ns: i64 }} \
             function f table {{ _ => run f() to A{} }} }}\n",
            (i + 1) % AGENTS
        ));
    }
    src.push_str("rule up { when state == S0 and UP1 then S1 }\nrule down { when state == S1 and DOWN1 then S0 }\n");
    let c = situ_compiler::check_source("bench.situ", &src);
    assert_eq!(c.errors(), 0, "{:?}", c.diagnostics.iter().filter(|d| d.code.starts_with('E')).collect::<Vec<_>>());
    Arc::new(situ_compiler::bundle::build(&c))
}

fn config(listen: Option<u16>, connect: Option<u16>) -> String {
    let ep = |p: Option<u16>| p.map(|p| vec![format!("tcp/127.0.0.1:{p}")]).unwrap_or_default();
    serde_json::json!({
        "mode": "peer",
        "listen": { "endpoints": ep(listen) },
        "connect": { "endpoints": ep(connect), "retry": { "period_init_ms": 100, "period_max_ms": 200 } },
        "scouting": { "multicast": { "enabled": false } },
    })
    .to_string()
}

fn child(i: usize, port: u16, rounds: usize) {
    let c = content();
    let mut local = vec![false; AGENTS];
    local[i] = true;
    let placement = Placement { robot: "bench".into(), local, board: false };
    let bus =
        ZenohBus::open(c.clone(), placement, &config(None, Some(port)), Capacity { data: 1 << 20, events: 1 << 16 })
            .expect("bus");
    let id = |name: String| c.event_id(&name).unwrap();
    let (seen, done, up, down) =
        (id(format!("SEEN{i}")), id(format!("DONE{i}")), id(format!("UP{i}")), id(format!("DOWN{i}")));
    let report = |event: u32, payload: Vec<Value>| {
        bus.send_event(EventMsg { agent: i as u32, event, time: now_ns(), payload, urgent: false })
    };
    let mut last = 0;
    let start = Instant::now();
    let (mut received, mut first_data) = (0i64, None::<Instant>);
    let mut out = Vec::new();
    // Agent 1 reports the events that flip the state, one per round, once
    // every process has joined (after 2 s) and each time it saw the last flip.
    let mut next_flip = Some(Instant::now() + Duration::from_secs(2));
    let mut flips = 0u64;
    // Sleep on the agent's bell, as the real-time scheduler does: woken by
    // what arrives, not by polling.
    let bell = Arc::new(situ_runtime::bus::Doorbell::default());
    bus.set_doorbell(i as u32, bell.clone());
    let mut quiet_since = Instant::now();
    while start.elapsed() < Duration::from_secs(120) {
        if let Some(st) = bus.status(i as u32) {
            if st.seq != last {
                last = st.seq;
                report(seen, vec![Value::I64(st.seq as i64), Value::I64(now_ns() as i64)]);
                if i == 1 && st.seq > 1 {
                    next_flip = Some(Instant::now() + Duration::from_millis(2));
                }
            }
        }
        if i == 1 && flips < rounds as u64 && next_flip.is_some_and(|t| Instant::now() >= t) {
            flips += 1;
            report(if flips % 2 == 1 { up } else { down }, vec![]);
            next_flip = Some(Instant::now() + Duration::from_secs(1)); // again if lost
        }
        if i == 2 {
            out.clear();
            bus.recv_data(2, &mut out);
            if !out.is_empty() {
                first_data.get_or_insert_with(Instant::now);
                received += out.len() as i64;
                quiet_since = Instant::now();
            }
            // All of it, or what came before the stream stopped for 0.5 s
            // (Zenoh drops data under congestion: it is data, keep-latest).
            let quiet = first_data.is_some() && quiet_since.elapsed() > Duration::from_millis(500);
            if received >= DATA || (quiet && received > 0) {
                let ns = quiet_since.duration_since(first_data.unwrap_or(quiet_since)).as_nanos() as i64;
                report(done, vec![Value::I64(received), Value::I64(ns)]);
                received = i64::MIN;
            }
        }
        bell.wait_until(Instant::now() + Duration::from_millis(1));
    }
}

fn quantiles(mut v: Vec<u64>) -> String {
    v.sort_unstable();
    let q = |p: f64| v[((v.len() as f64 * p) as usize).min(v.len() - 1)] as f64 / 1e3;
    format!(
        "p50 {:.0} µs, p99 {:.0} µs, max {:.0} µs ({} rounds)",
        q(0.5),
        q(0.99),
        v[v.len() - 1] as f64 / 1e3,
        v.len()
    )
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(pos) = args.iter().position(|a| a == "--child") {
        let arg = |k: usize| args.get(pos + k).and_then(|a| a.parse::<u64>().ok()).expect("--child N PORT ROUNDS");
        return child(arg(1) as usize, arg(2) as u16, arg(3) as usize);
    }
    let rounds: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(500);
    let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
    let c = content();
    // The Bulletinboard's process also plays agent 0 (the reporter) and the
    // sender of the data: it is the one that times the rounds.
    let mut local = vec![false; AGENTS];
    local[0] = true;
    let placement = Placement { robot: "bench".into(), local, board: true };
    let bus = ZenohBus::open(c.clone(), placement, &config(Some(port), None), Capacity { data: 64, events: 1 << 16 })
        .expect("bus");
    let exe = std::env::current_exe().unwrap();
    let mut children: Vec<Child> = (1..AGENTS)
        .map(|i| {
            Command::new(&exe)
                .args(["--child", &i.to_string(), &port.to_string(), &rounds.to_string()])
                .spawn()
                .unwrap()
        })
        .collect();
    let mut engine = Engine::new(c.clone());
    let mut fan = Vec::new();
    let mut e2e = Vec::new();
    let seen_ids: BTreeMap<u32, usize> = (1..AGENTS).map(|i| (c.event_id(&format!("SEEN{i}")).unwrap(), i)).collect();
    let done = c.event_id("DONE2").unwrap();
    let mut done_payload = None;
    // Per status broadcast: when it was sent, the event that caused it, and
    // when each agent process saw it.
    let mut rounds_seen: BTreeMap<u64, (u64, u64, Vec<u64>)> = BTreeMap::new();
    let mut seq = 1u64;
    bus.send_status(StatusMsg { state: engine.state(), time: now_ns(), seq });
    let deadline = Instant::now() + Duration::from_secs(60 + rounds as u64 / 50);
    while Instant::now() < deadline && rounds_seen.values().filter(|r| r.2.iter().all(|&t| t > 0)).count() < rounds {
        let mut got = Vec::new();
        let _ = bus.recv_events(&mut got);
        for e in got {
            if let Some(&i) = seen_ids.get(&e.event) {
                if let [Value::I64(s), Value::I64(at)] = e.payload.as_slice() {
                    if let Some(r) = rounds_seen.get_mut(&(*s as u64)) {
                        r.2[i - 1] = *at as u64;
                    }
                }
            } else if e.event == done {
                done_payload = Some(e.payload.clone());
            } else if let Ok(Some(ch)) = engine.post(e.event, e.time, &e.payload) {
                seq += 1;
                let t_status = now_ns();
                bus.send_status(StatusMsg { state: ch.to, time: t_status, seq });
                rounds_seen.insert(seq, (t_status, e.time, vec![0; AGENTS - 1]));
            }
        }
        let _ = bus.wait_events(Instant::now() + Duration::from_millis(1));
    }
    for (t_status, t_event, seen) in rounds_seen.values() {
        if seen.iter().all(|&t| t > 0) {
            let last = *seen.iter().max().unwrap();
            fan.push(last.saturating_sub(*t_status));
            e2e.push(last.saturating_sub(*t_event));
        }
    }
    println!("Zenoh on loopback: the Bulletinboard's process and {} agent processes", AGENTS - 1);
    println!("status fan-out to every agent process: {}", quantiles(fan));
    println!("event to state to every agent process: {}", quantiles(e2e));
    // Data: agent 0 (this process) to agent 2 (another process).
    let body = Body::json(serde_json::json!({ "x": 1.0, "y": 2.0 }));
    let t0 = Instant::now();
    for n in 0..DATA {
        bus.send_data(DataMsg { from: 0, to: 2, time: n as u64, urgent: false, body: body.clone() });
    }
    let sent_in = t0.elapsed();
    let deadline = Instant::now() + Duration::from_secs(30);
    while done_payload.is_none() && Instant::now() < deadline {
        let mut got = Vec::new();
        let _ = bus.recv_events(&mut got);
        done_payload = got.into_iter().find(|e| e.event == done).map(|e| e.payload);
        std::thread::sleep(Duration::from_millis(5));
    }
    match done_payload.as_deref() {
        Some([Value::I64(n), Value::I64(ns)]) => println!(
            "data between two processes: {:.0} messages/s received ({n} of {DATA} in {:.2} s; sent in {:.2} s)",
            *n as f64 / (*ns as f64 * 1e-9),
            *ns as f64 * 1e-9,
            sent_in.as_secs_f64()
        ),
        _ => println!("data between two processes: the receiver did not get all {DATA} messages within 30 s"),
    }
    for ch in &mut children {
        let _ = ch.kill();
        let _ = ch.wait();
    }
}
