//! The agent runtime in one process, 12 agents, wall clock:
//!
//! 1. **data**: 6 sensors send to 6 processing agents along the links of
//!    their tables, through the full running cycle (status, table, routing,
//!    the bus's queues); the figure is data messages delivered per second;
//! 2. **status fan-out**: the Bulletinboard's broadcast of a new state to
//!    12 agents shared among one worker thread per core, as the real-time
//!    scheduler runs them: from the broadcast to the last agent seeing it,
//!    p50 / p99 / max, over 10,000 broadcasts;
//! 3. **one wake-up**: the floor under the fan-out, the same bell
//!    (`Doorbell`: a mutex and a condition variable) rung 10,000 times for
//!    one sleeping thread, from the ring to the thread running again.
//!
//! `FIFO=1` runs the workers and the woken thread under `SCHED_FIFO`
//! (priority 50; it needs the privilege, and says when it is refused), as a
//! robot's real-time computer would; `WORKERS=N` sets the workers;
//! `ONLY=latency` skips the data figure.
//!
//! `cargo run --release -p situ-runtime-tests --example stack_bench`

use situ_compiler::bundle::Content;
use situ_runtime::agent::{self, Agent, Body, Context};
use situ_runtime::bus::inproc::{Capacity, InProc};
use situ_runtime::bus::{Bus, Doorbell, StatusMsg};
use situ_runtime::realtime::{self, RealtimeConfig};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

fn content() -> Arc<Content> {
    let mut src = String::from("states { RUN initial }\n");
    for i in 0..6 {
        src.push_str(&format!(
            "agent S{i} sensor {{ rate 1000Hz function sense table {{ _ => run sense() to P{i} }} }}\n\
             agent P{i} processing {{ function use table {{ _ => run use() from S{i} }} }}\n"
        ));
    }
    let c = situ_compiler::check_source("bench.situ", &src);
    assert_eq!(c.errors(), 0, "{:?}", c.diagnostics);
    Arc::new(situ_compiler::bundle::build(&c))
}

struct Sensor(String, Body);
impl Agent for Sensor {
    fn name(&self) -> &str {
        &self.0
    }
    fn functions(&self) -> Vec<String> {
        vec!["sense".into()]
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        for _ in 0..32 {
            cx.send(self.1.clone());
        }
    }
}

struct Consumer(String);
impl Agent for Consumer {
    fn name(&self) -> &str {
        &self.0
    }
    fn functions(&self) -> Vec<String> {
        vec!["use".into()]
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        std::hint::black_box(cx.inputs().len());
    }
}

fn data() {
    let c = content();
    let mut agents: Vec<Box<dyn Agent>> = Vec::new();
    let body = Body::local([0u8; 64]);
    for i in 0..6 {
        agents.push(Box::new(Sensor(format!("S{i}"), body.clone())));
        agents.push(Box::new(Consumer(format!("P{i}"))));
    }
    let bound = agent::bind(&c, agents, true).unwrap();
    // A throughput figure: the sensors step at 10 kHz, over the rules'
    // 1 kHz (the most a rules file may declare, E0123).
    let rates = (0..6).map(|i| (format!("S{i}"), 10_000.0)).collect();
    let config = RealtimeConfig { capacity: Capacity { data: 256, events: 1024 }, rates, ..RealtimeConfig::default() };
    let secs = 3.0;
    let s = realtime::run(c, bound, None, config, Duration::from_secs_f64(secs), &mut |_| {});
    let delivered: u64 = s.agents.iter().filter(|(n, _)| n.starts_with('P')).map(|(_, a)| a.data_in).sum();
    let sent: u64 = s.agents.iter().filter(|(n, _)| n.starts_with('S')).map(|(_, a)| a.data_out).sum();
    println!(
        "data: {:.0} messages/s delivered ({delivered} in {:.2} s; {sent} sent, {} dropped to keep the latest)",
        delivered as f64 / s.duration_s,
        s.duration_s,
        s.bus.data_overflow
    );
}

/// Puts the calling thread under `SCHED_FIFO` when `FIFO=1`; whether it is.
fn real_time() -> bool {
    if std::env::var("FIFO").as_deref() != Ok("1") {
        return false;
    }
    let param = libc::sched_param { sched_priority: 50 };
    // SAFETY: sched_setscheduler(2) on the calling thread (pid 0) with a
    // valid parameter; it only changes how the kernel schedules it.
    let r = unsafe { libc::sched_setscheduler(0, libc::SCHED_FIFO, &param) };
    if r != 0 {
        eprintln!("SCHED_FIFO refused: {}", std::io::Error::last_os_error());
    }
    r == 0
}

/// p50, p99 and max of latencies in ns, in µs.
fn quantiles(lat: &mut [u64]) -> (f64, f64, f64) {
    lat.sort_unstable();
    let q = |p: f64| lat[((lat.len() as f64 * p) as usize).min(lat.len() - 1)] as f64 / 1e3;
    (q(0.5), q(0.99), lat[lat.len() - 1] as f64 / 1e3)
}

/// One thread asleep on a `Doorbell`, rung `ROUNDS` times: from the ring
/// to the thread running again. Nothing else of the runtime: the kernel's
/// wake-up, the floor under every fan-out.
fn wake_up() {
    const ROUNDS: usize = 10_000;
    let bell = Arc::new(Doorbell::default());
    let start = Instant::now();
    let woke = Arc::new(AtomicU64::new(0));
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let mut lat = Vec::with_capacity(ROUNDS);
    let fifo = std::sync::atomic::AtomicBool::new(false);
    std::thread::scope(|scope| {
        let (bell2, woke2, stop2, fifo) = (bell.clone(), woke.clone(), stop.clone(), &fifo);
        scope.spawn(move || {
            fifo.store(real_time(), Ordering::Release);
            while !stop2.load(Ordering::Acquire) {
                if bell2.wait_until(Instant::now() + Duration::from_millis(100)) {
                    woke2.store(start.elapsed().as_nanos() as u64, Ordering::Release);
                }
            }
        });
        for _ in 0..ROUNDS {
            woke.store(0, Ordering::Release);
            // Let the thread go back to sleep first.
            std::thread::sleep(Duration::from_micros(200));
            let t0 = start.elapsed().as_nanos() as u64;
            bell.ring();
            let mut t = woke.load(Ordering::Acquire);
            while t == 0 {
                std::hint::spin_loop();
                t = woke.load(Ordering::Acquire);
            }
            lat.push(t.saturating_sub(t0));
        }
        stop.store(true, Ordering::Release);
        bell.ring();
    });
    let (p50, p99, max) = quantiles(&mut lat);
    println!(
        "one wake-up{}: p50 {p50:.1} µs, p99 {p99:.1} µs, max {max:.1} µs ({ROUNDS} rings)",
        if fifo.load(Ordering::Acquire) { " (SCHED_FIFO)" } else { "" }
    );
}

/// The fan-out as the real-time scheduler does it: the agents shared among
/// one worker thread per core, each sleeping on a bell its agents' mailboxes
/// ring; an agent has seen the status when its worker has read it.
fn fan_out() {
    const AGENTS: usize = 12;
    const ROUNDS: usize = 10_000;
    let workers: usize = std::env::var("WORKERS")
        .ok()
        .and_then(|w| w.parse().ok())
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let bus = Arc::new(InProc::new(AGENTS, Capacity::default()));
    let start = Instant::now();
    let seen: Arc<Vec<AtomicU64>> = Arc::new((0..AGENTS).map(|_| AtomicU64::new(0)).collect());
    let acks = Arc::new(AtomicU64::new(0));
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let mut lat = Vec::with_capacity(ROUNDS);
    let main = std::thread::current();
    std::thread::scope(|scope| {
        for w in 0..workers {
            let mine: Vec<u32> = (0..AGENTS as u32).filter(|a| *a as usize % workers == w).collect();
            let bell = Arc::new(Doorbell::default());
            for &a in &mine {
                bus.set_doorbell(a, bell.clone());
            }
            let (bus, seen, acks, stop, main) = (bus.clone(), seen.clone(), acks.clone(), stop.clone(), main.clone());
            scope.spawn(move || {
                real_time();
                let mut last = [0u64; AGENTS];
                while !stop.load(Ordering::Acquire) {
                    for &a in &mine {
                        if !bus.attention(a).input {
                            continue;
                        }
                        if let Some(st) = bus.status(a) {
                            if st.seq != last[a as usize] {
                                last[a as usize] = st.seq;
                                seen[a as usize].store(start.elapsed().as_nanos() as u64, Ordering::Release);
                                if acks.fetch_add(1, Ordering::AcqRel) + 1 == AGENTS as u64 {
                                    main.unpark();
                                }
                            }
                        }
                    }
                    bell.wait_until(Instant::now() + Duration::from_millis(100));
                }
            });
        }
        for round in 1..=ROUNDS as u64 {
            acks.store(0, Ordering::Release);
            let t0 = start.elapsed().as_nanos() as u64;
            bus.send_status(StatusMsg { state: (round % 2) as u32, time: t0, seq: round });
            // Out of the way of the workers until the last agent has seen it.
            while acks.load(Ordering::Acquire) < AGENTS as u64 {
                std::thread::park_timeout(Duration::from_millis(10));
            }
            let last = seen.iter().map(|s| s.load(Ordering::Acquire)).max().unwrap_or(t0);
            lat.push(last.saturating_sub(t0));
        }
        stop.store(true, Ordering::Release);
        bus.close();
    });
    let (p50, p99, max) = quantiles(&mut lat);
    let fifo = if std::env::var("FIFO").as_deref() == Ok("1") { ", SCHED_FIFO asked" } else { "" };
    println!(
        "status fan-out to {AGENTS} agents on {workers} workers{fifo}: p50 {p50:.1} µs, p99 {p99:.1} µs, max {max:.1} µs ({ROUNDS} broadcasts)"
    );
}

fn main() {
    println!("{} cores", std::thread::available_parallelism().map_or(1, |n| n.get()));
    if std::env::var("ONLY").as_deref() != Ok("latency") {
        data();
    }
    fan_out();
    wake_up();
}
