//! The MCAP recording of a run: read back, every channel holds what was
//! sent; replayed on the same bundle it gives the same states, on changed
//! rules it says where they differ; cut short (a killed process), what was
//! flushed is still there.

use situ_compiler::bundle::{self, Content, Encoding, Value};
use situ_runtime::agent::{self, Agent, Body, Context};
use situ_runtime::record::mcap::{read_messages, topics, McapRecorder};
use situ_runtime::record::{SharedMemory, Sink, Tee};
use situ_runtime::replay::replay;
use situ_runtime::sched::{SimConfig, SimRuntime};
use std::collections::BTreeMap;
use std::sync::Arc;

const MS: u64 = 1_000_000;

const RULES: &str = "states { RS initial RO EM SP final }
agent RFCCD sensor { rate 10Hz function lines table { RS => run lines() to LPL  RO => run lines() to Fusion  _ => sleep } }
agent LADAR sensor { rate 10Hz stale after 300ms event LAOBS { distance: f64, side: {left, right} } event LAOBN
    function detect table { RO => run detect() to Fusion  _ => wait detect() } }
agent Fusion processing { rate 10Hz function fuse table { RO => run fuse() from RFCCD, LADAR to LPL  _ => sleep } }
agent LPL processing { rate 10Hz function plan table { RS => run plan() from RFCCD  RO => run plan() from Fusion  _ => wait } }
rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
rule clear { when state == RO and LAOBN x3 then RS }
rule ladar_silent salience 100 { when state in {RS, RO} and stale LADAR then EM }
";

fn content(src: &str) -> Arc<Content> {
    let c = situ_compiler::check_source("t.situ", src);
    assert!(c.diagnostics.iter().all(|d| d.code >= "E0300"), "{:?}", c.diagnostics);
    Arc::new(bundle::build(&c))
}

struct A(&'static str, &'static str, fn(&mut Context<'_>));

impl Agent for A {
    fn name(&self) -> &str {
        self.0
    }
    fn functions(&self) -> Vec<String> {
        vec![self.1.to_string()]
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        (self.2)(cx)
    }
}

/// LADAR: an obstacle at 25 m on and off every second; silent after 4 s.
fn ladar(cx: &mut Context<'_>) {
    let t = cx.now() / MS;
    if t >= 4_000 {
        return;
    }
    if (t / 1000) % 2 == 1 {
        cx.report("LAOBS", &[Value::F64(25.0), Value::Symbol(1)]).unwrap();
    } else {
        cx.report("LAOBN", &[]).unwrap();
    }
    cx.send(Body::json(serde_json::json!({ "scan": t })));
}

fn agents() -> Vec<Box<dyn Agent>> {
    vec![
        Box::new(A("RFCCD", "lines", |cx| cx.send(Body::json(serde_json::json!({ "lines": 2 }))))),
        Box::new(A("LADAR", "detect", ladar)),
        Box::new(A("Fusion", "fuse", |cx| {
            let n = cx.inputs().len();
            cx.send(Body::local(n))
        })),
        Box::new(A("LPL", "plan", |_| {})),
    ]
}

/// Runs the stack for 6 s, recording to `path`; returns what a memory sink saw.
fn record(path: &std::path::Path) -> (situ_runtime::record::Memory, Arc<Content>) {
    let c = content(RULES);
    let bytes = bundle::encode(&c, Encoding::Json);
    let mcap = McapRecorder::create(path, c.clone(), &bytes).unwrap();
    let memory = SharedMemory::default();
    let tee = Tee(vec![Box::new(mcap), Box::new(memory.clone())]);
    let bound = agent::bind(&c, agents(), true).unwrap();
    let mut rt = SimRuntime::new(c.clone(), bound, Some(Box::new(tee)), SimConfig::default());
    rt.run_until(6_000 * MS, &mut |_| {});
    rt.finish_recording().unwrap();
    (memory.snapshot(), c)
}

#[test]
fn every_channel_holds_what_was_sent() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let (mem, _) = record(&path);
    let (messages, cut) = read_messages(&std::fs::read(&path).unwrap()).unwrap();
    assert!(!cut);
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for (topic, _, _) in &messages {
        *counts.entry(topic.clone()).or_default() += 1;
    }
    let count = |t: &str| counts.get(t).copied().unwrap_or(0);
    assert_eq!(count(topics::EVENTS), mem.events.len());
    assert_eq!(count(topics::EVENTS_LOG), mem.events.len());
    assert_eq!(count(topics::STATE), mem.changes.len());
    assert_eq!(count(topics::DATA), mem.data.len());
    assert_eq!(count(topics::MODES), mem.modes.len());
    assert_eq!(count(topics::TICKS), mem.ticks.len());
    assert_eq!(count(topics::DIAGNOSTICS), mem.diagnostics.len());
    assert!(mem.events.len() > 30 && mem.data.len() > 100 && mem.changes.len() >= 4, "{counts:?}");
    // The state channel has the `state` field Foxglove's State Transitions panel plots.
    let states: Vec<&str> =
        messages.iter().filter(|(t, _, _)| t == topics::STATE).filter_map(|(_, _, m)| m["state"].as_str()).collect();
    assert_eq!(states, ["RO", "RS", "RO", "EM"]);
}

#[test]
fn a_replay_on_the_same_bundle_gives_the_same_states() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let (_, c) = record(&path);
    let bytes = std::fs::read(&path).unwrap();
    let attached = situ_runtime::record::mcap::attached_bundle(&bytes).expect("the bundle is attached");
    assert_eq!(bundle::decode(&attached).unwrap(), *c);
    let report = replay(&bytes, c.clone()).unwrap();
    assert!(report.same(), "{}", report.describe());
    assert_eq!(report.recorded.len(), 4);
    assert!(report.ticks >= 1, "the heartbeat that noticed the silent LADAR is replayed");
    // A rule change: obstacles count from 20 m only. The obstacles (25 m)
    // no longer lead to RO; the silent LADAR (last report at 3.9 s) is
    // noticed by the first heartbeat after 4.2 s.
    let changed = content(&RULES.replace("distance < 30.0", "distance < 20.0"));
    let report = replay(&bytes, changed).unwrap();
    assert_eq!(report.first_difference, Some(0), "{}", report.describe());
    let text = report.describe();
    assert!(text.contains("recorded: 1.000s RS -> RO (obstacle)"), "{text}");
    assert!(text.contains("replayed: 4.210s RS -> EM (ladar_silent)"), "{text}");
}

#[test]
fn a_recording_cut_short_keeps_what_was_flushed() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.mcap");
    let c = content(RULES);
    let mut mcap = McapRecorder::create(&path, c.clone(), b"{}").unwrap();
    let rec = |t: u64| situ_runtime::record::EventRecord {
        time: t,
        agent: 1,
        event: c.event_id("LAOBN").unwrap(),
        payload: vec![],
        urgent: false,
        verdict: situ_runtime::record::Verdict::Accepted,
    };
    for t in 0..100 {
        mcap.event(&rec(t));
    }
    mcap.flush().unwrap();
    let flushed = std::fs::metadata(&path).unwrap().len() as usize;
    for t in 100..150 {
        mcap.event(&rec(t));
    }
    // The process dies: the writer is never finished; what is on disk is
    // at least what the flush wrote.
    std::mem::forget(mcap);
    let bytes = std::fs::read(&path).unwrap();
    let (messages, cut) = read_messages(&bytes[..flushed]).unwrap();
    assert!(cut || messages.len() == 200, "no summary after a kill");
    let events = messages.iter().filter(|(t, _, _)| t == topics::EVENTS).count();
    assert_eq!(events, 100, "everything before the last flush survives");
}
