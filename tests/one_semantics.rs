//! One semantics (issue 18, language reference §10.4, §10.7, §10.12): the
//! same stream gives the same states in the engine, in `situ bench`, in
//! `situ test`'s system (the engine and the organisation as `situ test`
//! steps them) and in the running stack's Bulletinboard, because every one
//! of them takes or refuses an event by the engine's one acceptance rule
//! (`Engine::admit`). The stream has everything the paths used to disagree
//! on: an event behind its agent's latest (which would complete an `x3`),
//! NaN and ±inf in compared fields, events stamped beyond the skew bound
//! ahead of the clock they arrived at (one at 2^63 − 1 ns), and an event at
//! 2^63 − 1 ns that arrived then.

mod common;

use common::{code, situ, text, write};
use situ_compiler::bundle::Content;
use situ_runtime::bus::inproc::{Capacity, InProc};
use situ_runtime::bus::{Bus, EventMsg};
use situ_runtime::rete::Engine;
use situ_runtime::runner::{BoardRunner, Shared};
use situ_runtime::stream::{self, Event};
use std::sync::Arc;

const RULES: &str = r#"states { IT initial RS RO EM SP final }

agent GPS sensor { stale after 300ms event FIX { error: f64 } }
agent LADAR sensor { stale after 300ms event LAOBS { distance: f64 } event LAOBN }
agent TC sensor { event HB event RESUME }

rule start { when state == IT and FIX(error < 1.0) then RS }
rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
rule clear { when state == RO and LAOBN x3 then RS }
// A distance that is no number passes neither test (§10.3).
rule no_number {
    when state == RS and LAOBS and not LAOBS(distance < 30.0) and not LAOBS(distance >= 30.0)
    then EM
}
rule resume { when state == EM and RESUME and LAOBN and not stale GPS then RS }
rule gps_lost salience 10 { when state in {RS, RO} and stale GPS then EM }
rule ladar_lost salience 10 { when state in {RS, RO} and stale LADAR then EM }
rule halt { when state == EM and HB then SP }
"#;

/// Index: what the event is, and what each part of situ must make of it.
const STREAM: &str = "# situ events v1 one_semantics.situ
10000000 FIX 0.500
20000000 LAOBS NaN
30000000 LAOBN
40000000 RESUME
50000000 LAOBS 12.000
60000000 LAOBN
70000000 LAOBN
65000000 LAOBN
80000000 FIX 0.500
90000000 LAOBN
100000000 LAOBS -inf
110000000 LAOBS inf
10000000000 FIX 0.500 @120000000
130000000 LAOBN
140000000 LAOBN
150000000 LAOBN
9223372036854775807 HB @160000000
160000000 FIX 0.500
9223372036854775807 HB
170000000 LAOBN
";
// 0 FIX: RS. 1 NaN: `no_number`, EM. 2 LAOBN. 3 RESUME: RS.
// 4 LAOBS 12: RO. 5, 6 LAOBN x1, x2. 7 LAOBN at 65 ms, behind LADAR's
// 70 ms: refused (it would have been x3, RS). 8 FIX. 9 LAOBN x3: RS.
// 10 -inf < 30: RO. 11 +inf: nothing in RO. 12 FIX stamped 10 s, arrived at
// 120 ms: from the future, refused (it would have made LADAR stale: EM).
// 13-15 LAOBN x3: RS. 16 HB at 2^63 − 1 that arrived at 160 ms: refused.
// 17 FIX. 18 HB at 2^63 − 1 that arrived then: now moves there, GPS and
// LADAR expire: EM in the first rest, and HB stops: SP in the second.
// (`situ bench` resets then: §10.12.) 19 LAOBN at 170 ms: not behind
// LADAR's 150 ms, taken, already expired.
const EXPECTED: &str = "0 RS\n1 EM\n3 RS\n4 RO\n9 RS\n10 RO\n15 RS\n18 SP\n";

fn content(dir: &std::path::Path) -> (String, Arc<Content>) {
    let path = write(dir, "one_semantics.situ", RULES);
    let checked = situ_compiler::check(std::path::Path::new(&path), &situ_compiler::loader::FsLoader).unwrap();
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    (path, Arc::new(situ_compiler::bundle::build(&checked)))
}

/// The `INDEX STATE` lines of `situ bench --states-out` (§10.12) from the
/// states at rest after each event.
fn lines(c: &Content, initial: u32, states: &[u32]) -> String {
    let mut out = String::new();
    let mut at_rest = initial;
    for (i, &s) in states.iter().enumerate() {
        if s != at_rest {
            out.push_str(&format!("{i} {}\n", c.states[s as usize].name));
            at_rest = s;
        }
    }
    out
}

fn events(c: &Content) -> Vec<Event> {
    let events = stream::parse(c, STREAM).expect("the stream reads");
    assert_eq!(events.len(), 20);
    events
}

/// The engine alone.
fn engine(c: &Arc<Content>) -> String {
    let mut e = Engine::new(c.clone());
    let states: Vec<u32> = events(c)
        .iter()
        .map(|ev| {
            e.set_clock(ev.clock);
            let _ = e.step(ev.event, ev.time, &ev.payload);
            e.state()
        })
        .collect();
    lines(c, c.initial, &states)
}

/// What `situ test` runs: the system of engine and organisation, posted to
/// as a test or a search posts (`System::post`).
fn test_system(c: &Arc<Content>) -> String {
    let mut sys = situ_verify::System::new(c.clone());
    let states: Vec<u32> = events(c)
        .iter()
        .map(|ev| {
            sys.engine.set_clock(ev.clock);
            let _ = sys.post(ev.event, ev.time, &ev.payload);
            sys.engine.state()
        })
        .collect();
    lines(c, c.initial, &states)
}

/// The running stack's Bulletinboard: each event reported on the bus and
/// taken when the Bulletinboard's clock reads its arrival (its `@CLOCK`, or
/// its stamp: the clock never goes back).
fn stack(c: &Arc<Content>) -> (String, BoardRunner) {
    stack_on(c, &events(c))
}

/// [`stack`] on these events.
fn stack_on(c: &Arc<Content>, events: &[Event]) -> (String, BoardRunner) {
    let bus: Arc<dyn Bus> = Arc::new(InProc::new(c.agents.len(), Capacity::default()));
    let shared = Shared::new(c.clone(), bus, None);
    let mut runner = BoardRunner::new(c.clone());
    runner.start(&shared, 0);
    let mut clock = 0u64;
    let states: Vec<u32> = events
        .iter()
        .map(|ev| {
            clock = clock.max(ev.clock.unwrap_or(ev.time));
            // An unknown event is sent as agent 0's: refused as unknown.
            let agent = c.events.get(ev.event as usize).map_or(0, |e| e.agent);
            let msg = EventMsg { agent, event: ev.event, time: ev.time, payload: ev.payload.clone(), urgent: false };
            shared.bus.send_event(msg);
            runner.pump(&shared, clock);
            runner.board.state()
        })
        .collect();
    (lines(c, c.initial, &states), runner)
}

#[test]
fn the_engine_bench_test_and_the_running_stack_reach_the_same_states() {
    let dir = tempfile::tempdir().unwrap();
    let (rules, c) = content(dir.path());

    let by_engine = engine(&c);
    assert_eq!(by_engine, EXPECTED, "the engine");

    let by_test = test_system(&c);
    assert_eq!(by_test, EXPECTED, "situ test's system");

    let (by_stack, runner) = stack(&c);
    assert_eq!(by_stack, EXPECTED, "the running stack");
    let refused = &runner.counters.refused;
    assert_eq!(refused.get("out of order"), Some(&1), "{refused:?}");
    assert_eq!(refused.get("from the future"), Some(&2), "{refused:?}");
    assert_eq!(refused.len(), 2, "NaN and ±inf are taken: {refused:?}");
    assert_eq!(runner.counters.accepted, 17);
    assert_eq!(c.states[runner.board.state() as usize].name, "SP");

    let stream_file = write(dir.path(), "one.events", STREAM);
    let states_file = dir.path().join("one.states");
    let out = situ(&["bench", &rules, "--stream-in", &stream_file, "--states-out", states_file.to_str().unwrap()]);
    assert_eq!(code(&out), 0, "{}", text(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(report["events"], 20);
    assert_eq!(report["refused"], 3, "{report}");
    assert_eq!(std::fs::read_to_string(&states_file).unwrap(), EXPECTED, "situ bench");
}

#[test]
fn without_arrival_clocks_every_event_arrives_at_its_stamp_everywhere() {
    // The same stream without `@CLOCK`: the events from the future are now
    // taken (they arrived when they were stamped), by every part alike.
    let dir = tempfile::tempdir().unwrap();
    let (rules, c) = content(dir.path());
    let plain: String = STREAM.lines().map(|l| format!("{}\n", l.split(" @").next().unwrap())).collect();
    let events = stream::parse(&c, &plain).unwrap();
    assert!(events.iter().all(|e| e.clock.is_none()));
    let mut e = Engine::new(c.clone());
    let states: Vec<u32> = events
        .iter()
        .map(|ev| {
            let _ = e.step(ev.event, ev.time, &ev.payload);
            e.state()
        })
        .collect();
    let by_engine = lines(&c, c.initial, &states);
    // 12: FIX at 10 s moves now: LADAR (110 ms) expires, EM; 16: HB, SP
    // (where `situ bench` resets); the later events are behind their agent
    // or expired at once.
    assert_eq!(by_engine, "0 RS\n1 EM\n3 RS\n4 RO\n9 RS\n10 RO\n12 EM\n16 SP\n");
    let stream_file = write(dir.path(), "plain.events", &plain);
    let states_file = dir.path().join("plain.states");
    let out = situ(&["bench", &rules, "--stream-in", &stream_file, "--states-out", states_file.to_str().unwrap()]);
    assert_eq!(code(&out), 0, "{}", text(&out));
    assert_eq!(std::fs::read_to_string(&states_file).unwrap(), by_engine);
}

/// Lines of a stream that are events whose payload does not fit, and an
/// unknown event (issue 28): refused and counted by every part of situ,
/// which goes on (`situ bench` used to stop at the first, exit 2). After
/// them, the event that starts the next mission (`situ bench` reset at SP
/// (18), where now is 2^63 − 1 ns): RS, and LADAR, silent since the reset,
/// is stale there: EM.
const MISFITS: &str = "180000000 LAOBS near
190000000 FIX
200000000 LAOBN 3
210000000 NOPE
9223372036854775807 FIX 0.500
";

#[test]
fn an_event_that_does_not_fit_is_refused_everywhere_and_the_run_goes_on() {
    let dir = tempfile::tempdir().unwrap();
    let (rules, c) = content(dir.path());
    let all = format!("{STREAM}{MISFITS}");
    let events = stream::parse(&c, &all).expect("every line with a stamp and a name is an event");
    assert_eq!(events.len(), 25);

    let (_, runner) = stack_on(&c, &events);
    let refused = &runner.counters.refused;
    assert_eq!(refused.get("payload"), Some(&3), "{refused:?}");
    assert_eq!(refused.get("unknown event"), Some(&1), "{refused:?}");
    assert_eq!(runner.counters.accepted, 18, "the stack went on: {refused:?}");

    let stream_file = write(dir.path(), "misfits.events", &all);
    let states_file = dir.path().join("misfits.states");
    let out = situ(&["bench", &rules, "--stream-in", &stream_file, "--states-out", states_file.to_str().unwrap()]);
    assert_eq!(code(&out), 0, "{}", text(&out));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("one JSON object");
    assert_eq!(report["events"], 25);
    assert_eq!(report["refused"], 7, "{report}");
    let by_reason = serde_json::json!({"from the future": 2, "out of order": 1, "payload": 3, "unknown event": 1});
    assert_eq!(report["refused_by_reason"], by_reason, "{report}");
    assert_eq!(report["first_refused"]["payload"]["index"], 20, "{report}");
    assert_eq!(
        std::fs::read_to_string(&states_file).unwrap(),
        format!("{EXPECTED}24 EM\n"),
        "the refused lines changed nothing, and the run went on"
    );
    let said = common::stderr(&out);
    assert!(said.contains("7 of 25 events refused"), "{said}");
    assert!(
        said.contains(&format!(
            "payload: 3, the first at {stream_file}:22: field `LAOBS.distance` is f64, the value is not"
        )),
        "{said}"
    );
    assert!(said.contains("out of order: 1, the first at"), "{said}");
}
