//! The agent runtime end to end, in process, in simulated time: the Fig. 5
//! reorganisation of Zhang & Zhu (2005), waiting agents' outputs, urgent
//! data, a flood of events, a silent agent, bad events — asserted on what
//! was recorded, not only on the state.

use situ_compiler::bundle::{Content, Mode, Value};
use situ_runtime::agent::{self, Agent, Body, Context};
use situ_runtime::bus::inproc::Capacity;
use situ_runtime::record::{Fate, Memory, SharedMemory, Verdict};
use situ_runtime::sched::{SimConfig, SimRuntime};
use std::sync::{Arc, Mutex};

const MS: u64 = 1_000_000;

const FIG5: &str = "states { RS initial RO EM SP final }
agent RFCCD sensor { rate 10Hz event RFRS function lines
    table { RS => run lines() to LPL  RO => run lines() to Fusion  _ => sleep } }
agent LADAR sensor { rate 10Hz stale after 300ms event LAOBS { distance: f64 } event LAOBN function detect
    table { RO => run detect() to Fusion  _ => wait detect() } }
agent Fusion processing { rate 10Hz function fuse
    table { RO => run fuse() from RFCCD, LADAR to LPL  _ => sleep } }
agent LPL processing { rate 10Hz function plan
    table { RS => run plan() from RFCCD  RO => run plan() from Fusion  _ => wait } }
rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
rule ladar_silent salience 100 { when state in {RS, RO} and stale LADAR then EM }
";

fn content(src: &str) -> Arc<Content> {
    let c = situ_compiler::check_source("t.situ", src);
    let front: Vec<_> = c.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front.is_empty(), "{front:?}");
    Arc::new(situ_compiler::bundle::build(&c))
}

/// An agent made of a closure.
struct Scripted<F: FnMut(&mut Context<'_>) + Send> {
    name: &'static str,
    functions: &'static [&'static str],
    f: F,
}

impl<F: FnMut(&mut Context<'_>) + Send> Agent for Scripted<F> {
    fn name(&self) -> &str {
        self.name
    }
    fn functions(&self) -> Vec<String> {
        self.functions.iter().map(|s| s.to_string()).collect()
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        (self.f)(cx)
    }
}

fn boxed<F: FnMut(&mut Context<'_>) + Send + 'static>(
    name: &'static str,
    functions: &'static [&'static str],
    f: F,
) -> Box<dyn Agent> {
    Box::new(Scripted { name, functions, f })
}

/// The Fig. 5 stack; LADAR sees an obstacle from 1 s and stops at `silent_at`.
fn fig5(silent_at: u64, lpl_inputs: Arc<Mutex<Vec<(u64, String)>>>) -> Vec<Box<dyn Agent>> {
    vec![
        boxed("RFCCD", &["lines"], |cx| cx.send(Body::local("road"))),
        boxed("LADAR", &["detect"], move |cx| {
            if cx.now() >= silent_at {
                return;
            }
            if cx.now() >= 1_000 * MS {
                cx.report("LAOBS", &[Value::F64(12.0)]).unwrap();
            } else {
                cx.report("LAOBN", &[]).unwrap();
            }
            cx.send(Body::local("scan"));
        }),
        boxed("Fusion", &["fuse"], |cx| {
            let n = cx.inputs().len();
            cx.send(Body::local(n));
        }),
        boxed("LPL", &["plan"], move |cx| {
            let mut seen = lpl_inputs.lock().unwrap();
            for d in cx.inputs() {
                seen.push((d.time, cx.agent_name(d.from).to_string()));
            }
        }),
    ]
}

fn run(src: &str, agents: Vec<Box<dyn Agent>>, config: SimConfig, until_ms: u64) -> (SimRuntime, Memory) {
    let c = content(src);
    let bound = agent::bind(&c, agents, false).unwrap_or_else(|e| panic!("{e}"));
    let memory = SharedMemory::default();
    let mut rt = SimRuntime::new(c, bound, Some(Box::new(memory.clone())), config);
    rt.run_until(until_ms * MS, &mut |_| {});
    let snapshot = memory.snapshot();
    (rt, snapshot)
}

fn agent_id(rt: &SimRuntime, name: &str) -> u32 {
    rt.shared.content.agent_id(name).unwrap()
}

#[test]
fn figure_5_fusion_sleeps_on_the_straight_road_and_wakes_at_the_obstacle() {
    let lpl_inputs = Arc::new(Mutex::new(Vec::new()));
    let (rt, rec) = run(FIG5, fig5(u64::MAX, lpl_inputs.clone()), SimConfig::default(), 2_000);
    let id = |n: &str| agent_id(&rt, n);
    let (rfccd, ladar, fusion, lpl) = (id("RFCCD"), id("LADAR"), id("Fusion"), id("LPL"));
    assert_eq!(rt.shared.content.states[rt.state() as usize].name, "RO");
    let change = rec.changes.iter().find(|c| c.changed()).expect("RS -> RO");
    let t_ro = change.time;
    assert_eq!(t_ro, 1_000 * MS, "LADAR's first LAOBS at 1 s");

    // Data sent at 1 s itself may come before or after the change, in the
    // order the agents stepped: only strictly before or after counts.
    let delivered = |from: u32, to: u32, before: bool| {
        rec.data.iter().any(|d| {
            let side = if before { d.time < t_ro } else { d.time > t_ro };
            d.from == from && d.to == to && d.fate == Fate::Delivered && side
        })
    };
    // Fig. 5a: in RS, RFCCD -> LPL; Fusion asleep: it sends nothing, nobody sends to it.
    assert!(delivered(rfccd, lpl, true));
    assert!(!rec.data.iter().any(|d| d.time < t_ro && (d.from == fusion || d.to == fusion)));
    // LADAR waits in RS: its scans are suppressed, its events still count.
    assert!(rec.data.iter().any(|d| d.from == ladar && d.time < t_ro && d.fate == Fate::Suppressed));
    assert!(rec.events.iter().any(|e| e.agent == ladar && e.time < t_ro && e.verdict == Verdict::Accepted));
    // Fig. 5b: in RO, RFCCD and LADAR -> Fusion -> LPL; RFCCD no longer to LPL.
    assert!(delivered(rfccd, fusion, false) && delivered(ladar, fusion, false) && delivered(fusion, lpl, false));
    assert!(!delivered(rfccd, lpl, false));
    // What LPL read: RFCCD before the obstacle, Fusion after it.
    let seen = lpl_inputs.lock().unwrap();
    assert!(seen.iter().filter(|(t, _)| *t < t_ro).all(|(_, f)| f == "RFCCD"));
    assert!(seen.iter().filter(|(t, _)| *t > t_ro).all(|(_, f)| f == "Fusion"));
    assert!(seen.iter().any(|(_, f)| f == "Fusion"));
    // Fusion's mode changes are recorded: sleeping from the start, running at 1 s.
    let fusion_modes: Vec<(u64, Mode)> =
        rec.modes.iter().filter(|m| m.agent == fusion).map(|m| (m.time, m.mode)).collect();
    assert_eq!(fusion_modes, [(0, Mode::Sleeping), (t_ro, Mode::Running)]);
}

#[test]
fn a_silent_agent_is_seen_stale_within_one_heartbeat() {
    let silent_at = 1_500 * MS;
    let config = SimConfig { heartbeat: 20 * MS, ..SimConfig::default() };
    let (rt, rec) = run(FIG5, fig5(silent_at, Arc::new(Mutex::new(Vec::new()))), config, 3_000);
    assert_eq!(rt.shared.content.states[rt.state() as usize].name, "EM");
    let em = rec.changes.iter().rev().find(|c| c.changed()).unwrap();
    // LADAR's last report came at 1.4 s; stale once more than 300 ms old.
    let last = 1_400 * MS;
    assert!(em.time > last + 300 * MS && em.time <= last + 300 * MS + 20 * MS, "EM at {}", em.time);
    assert_eq!(rec.ticks, [em.time], "the heartbeat that fired is recorded for replays");
}

#[test]
fn an_urgent_datum_steps_its_receiver_at_once() {
    let src = "states { A initial B }
        agent Fast sensor { rate 20Hz function go table { _ => run go() to Slow } }
        agent Slow processing { rate 1Hz event GOT function react table { _ => run react() from Fast } }
        rule got { when state == A and GOT then B }";
    let agents = vec![
        boxed("Fast", &["go"], |cx| {
            if cx.now() == 250 * MS {
                cx.send_urgent(Body::local("brake"));
            } else {
                cx.send(Body::local("tick"));
            }
        }),
        boxed("Slow", &["react"], |cx| {
            if cx.inputs().first().is_some_and(|d| d.urgent) {
                cx.report("GOT", &[]).unwrap();
            }
        }),
    ];
    let (rt, rec) = run(src, agents, SimConfig::default(), 900);
    // The urgent datum arrived at 250 ms, first in Slow's inputs, and Slow
    // reacted then, not at its next period (1 s).
    let change = rec.changes.iter().find(|c| c.changed()).expect("A -> B");
    assert_eq!(change.time, 250 * MS);
    assert_eq!(rt.summary().bus.urgent, 1);
}

#[test]
fn a_flood_of_events_is_counted_and_raised_never_dropped_silently() {
    let src = "states { OK initial FLOODED }
        agent Chatty sensor { rate 10Hz event PING }
        agent Bus processing { event BUSOVF { dropped: i64 } }
        rule flooded salience 100 { when state == OK and BUSOVF(dropped > 0) then FLOODED }";
    let agents = vec![boxed("Chatty", &[], |cx| {
        for _ in 0..1000 {
            cx.report("PING", &[]).unwrap();
        }
    })];
    let config = SimConfig { capacity: Capacity { data: 8, events: 100 }, ..SimConfig::default() };
    let (rt, rec) = run(src, agents, config, 50);
    let s = rt.summary();
    assert_eq!(s.board.lost, 900, "1,000 reported, 100 queued");
    assert_eq!(s.board.accepted, 101, "100 PINGs and the BUSOVF");
    assert_eq!(rt.shared.content.states[rt.state() as usize].name, "FLOODED");
    assert!(rec.diagnostics.iter().any(|(_, t)| t.contains("900 event(s) lost")));
}

#[test]
fn bad_events_are_refused_counted_and_recorded_and_the_run_goes_on() {
    let src = "states { A initial B }
        agent S sensor { rate 10Hz event X { d: f64 } event Y }
        rule r { when state == A and X(d < 1.0) then B }";
    struct Bad {
        step: u32,
    }
    impl Agent for Bad {
        fn name(&self) -> &str {
            "S"
        }
        fn step(&mut self, cx: &mut Context<'_>) {
            self.step += 1;
            match self.step {
                1 => cx.report("X", &[Value::F64(f64::NAN)]).unwrap(), // taken: NaN matches no comparison (§10.3)
                2 => cx.report("X", &[Value::I64(3)]).unwrap(),        // wrong type
                3 => cx.report("Y", &[Value::F64(1.0)]).unwrap(),      // wrong arity
                4 => assert!(cx.report("Z", &[]).is_err(), "not its event: refused at once"),
                _ => cx.report("X", &[Value::F64(0.5)]).unwrap(),
            }
        }
    }
    let (rt, rec) = run(src, vec![Box::new(Bad { step: 0 })], SimConfig::default(), 1_000);
    let s = rt.summary();
    assert_eq!(s.board.refused.get("payload"), Some(&2));
    assert_eq!(s.board.refused.len(), 1, "NaN is a value, as in the engine: {:?}", s.board.refused);
    assert_eq!(rt.shared.content.states[rt.state() as usize].name, "B", "the good event still fires the rule");
    let refused = rec.events.iter().filter(|e| matches!(e.verdict, Verdict::Refused(_))).count();
    assert_eq!(refused, 2);
}

#[test]
fn a_function_no_agent_offers_is_refused_at_start_with_its_name() {
    let c = content(FIG5);
    let agents = vec![boxed("Fusion", &["merge"], |_| {}), boxed("LPL", &["plan"], |_| {})];
    let err = agent::bind(&c, agents, false).err().expect("refused");
    assert_eq!(err.to_string(), "the bundle names functions no registered agent offers: Fusion.fuse");
    let err = agent::bind(&c, vec![boxed("Nobody", &[], |_| {})], false).err().expect("refused");
    assert!(err.to_string().contains("Nobody"));
    let err = agent::bind(&c, vec![boxed("LPL", &["plan"], |_| {})], true).err().expect("refused");
    assert!(err.to_string().contains("RFCCD, LADAR, Fusion"), "{err}");
}

#[test]
fn the_same_run_twice_is_the_same_run() {
    let go = || {
        let (rt, rec) = run(FIG5, fig5(1_500 * MS, Arc::new(Mutex::new(Vec::new()))), SimConfig::default(), 3_000);
        (serde_json::to_string(&rt.summary()).unwrap(), format!("{:?}{:?}{:?}", rec.changes, rec.data, rec.events))
    };
    assert_eq!(go(), go());
}

#[test]
fn in_real_time_an_urgent_datum_interrupts_a_sleeping_receiver() {
    use situ_runtime::realtime::{self, RealtimeConfig};
    // Slow steps once a minute; the run may last 30 s at most. It can only
    // react to Fast's datum if the urgent datum wakes it.
    let src = "states { A initial B final }
        agent Fast sensor { rate 50Hz function go table { _ => run go() to Slow } }
        agent Slow processing { rate 0.0166Hz event GOT function react table { _ => run react() from Fast } }
        rule got { when state == A and GOT then B }";
    let c = content(src);
    let sent = Arc::new(Mutex::new(0u32));
    let s2 = sent.clone();
    let agents = vec![
        boxed("Fast", &["go"], move |cx| {
            let mut n = s2.lock().unwrap();
            *n += 1;
            if *n == 5 {
                cx.send_urgent(Body::local("brake"));
            }
        }),
        boxed("Slow", &["react"], |cx| {
            if cx.inputs().iter().any(|d| d.urgent) {
                cx.report("GOT", &[]).unwrap();
            }
        }),
    ];
    let bound = agent::bind(&c, agents, true).unwrap();
    let mut changes = Vec::new();
    let summary =
        realtime::run(c, bound, None, RealtimeConfig::default(), std::time::Duration::from_secs(30), &mut |ch| {
            changes.push(ch.to)
        });
    assert_eq!(changes, [1], "A -> B");
    assert_eq!(summary.final_state, "B");
    assert_eq!(summary.agents["Slow"].steps, 2, "its first periodic step, then the urgent one");
    assert!(summary.duration_s < 30.0);
    // The workers' steps are in the per-state figures too: no agent sleeps,
    // so every step of every agent is counted in some state, most in A.
    let per_state: u64 = summary.states.iter().map(|f| f.agent_steps).sum();
    let per_agent: u64 = summary.agents.values().map(|a| a.steps).sum();
    assert_eq!(per_state, per_agent, "{:?}", summary.states);
    assert!(summary.states[0].agent_steps >= 5, "Fast stepped 5 times in A: {:?}", summary.states);
}
