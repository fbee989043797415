//! A board that journals its log, killed and started again from its
//! journal: the same state, facts and FSM states; what went stale during
//! the gap is stale at the first heartbeat (`situ_runtime::journal`).

use situ_compiler::bundle::{self, Content, Value};
use situ_runtime::bus::inproc::{Capacity, InProc};
use situ_runtime::bus::{Bus, EventMsg};
use situ_runtime::journal::{self, Journal, JournalError, Opened};
use situ_runtime::realtime::{self, RealtimeConfig};
use situ_runtime::record::Memory;
use situ_runtime::runner::{BoardRunner, Shared};
use situ_runtime::standby::Entry;
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;

fn content(src: &str) -> Arc<Content> {
    let c = situ_compiler::check_source("t.situ", src);
    let front: Vec<_> = c.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front.is_empty(), "{front:?}");
    Arc::new(bundle::build(&c))
}

const MS: u64 = 1_000_000;

const RULES: &str = "states { IT initial RS RO EM }
    agent LADAR sensor { stale after 300ms event LAOBS { distance: f64 } }
    agent GPS sensor { stale after 10s event FIX { quality: i64 } }
    agent Supervisor interface {
        event SVRDY
        function mission
        function monitor
        fsm {
            Briefing initial => run mission()
            Watching         => run monitor()
            Briefing -> Watching on SVRDY
        }
    }
    rule go { when state == IT and FIX(quality > 2) then RS }
    rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
    rule clear { when state == RO and LAOBS(distance >= 30.0) then RS }
    rule blind { when state in {RS, RO} and stale LADAR then EM }";

fn board(c: &Arc<Content>) -> (Shared, BoardRunner) {
    let bus: Arc<dyn Bus> = Arc::new(InProc::new(c.agents.len(), Capacity::default()));
    let shared = Shared::new(c.clone(), bus, None);
    let mut b = BoardRunner::new(c.clone());
    b.start(&shared, 0);
    (shared, b)
}

fn post(shared: &Shared, b: &mut BoardRunner, c: &Content, event: &str, at_ms: u64, payload: Vec<Value>) {
    let ev = c.event_id(event).unwrap();
    let agent = c.events[ev as usize].agent;
    shared.bus.send_event(EventMsg { agent, event: ev, time: at_ms * MS, payload, urgent: false });
    b.pump(shared, at_ms * MS);
    b.flush_log(false);
}

/// A mission of a few events and heartbeats, journaled to `path`; the
/// board is dropped as a killed process leaves it (no finish).
fn first_board(c: &Arc<Content>, path: &Path) -> (u32, Vec<Option<situ_runtime::rete::MatchedFact>>, Vec<Option<u32>>) {
    let (shared, mut b) = board(c);
    let (j, r) = Journal::open(path, c).unwrap();
    assert!(r.entries.is_empty());
    b.set_log_out(Some(Box::new(j)));
    post(&shared, &mut b, c, "FIX", 10, vec![Value::I64(1)]);
    post(&shared, &mut b, c, "FIX", 20, vec![Value::I64(4)]);
    post(&shared, &mut b, c, "SVRDY", 25, vec![]);
    post(&shared, &mut b, c, "LAOBS", 30, vec![Value::F64(50.0)]);
    b.tick(&shared, 100 * MS);
    post(&shared, &mut b, c, "LAOBS", 130, vec![Value::F64(12.5)]);
    // Refused: stamped before the board's clock.
    post(&shared, &mut b, c, "LAOBS", 5, vec![Value::F64(99.0)]);
    b.tick(&shared, 200 * MS);
    b.flush_log(false);
    assert_eq!(b.board.state_name(), "RO");
    assert!(b.counters.refused.values().sum::<u64>() >= 1);
    let facts = (0..c.agents.len() as u32).map(|a| b.board.engine().fact(a)).collect();
    let fsm = (0..c.agents.len() as u32).map(|a| shared.org().fsm_state(a)).collect();
    (b.board.state(), facts, fsm)
}

#[test]
fn a_board_started_again_from_its_journal_has_the_state_facts_and_fsm_states_it_had() {
    let c = content(RULES);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("board.journal");
    let (state, facts, fsm) = first_board(&c, &path);

    let (j, r) = Journal::open(&path, &c).unwrap();
    assert_eq!(r.dropped, 0);
    let (shared, mut b) = board(&c);
    assert_eq!(b.board.state_name(), "IT");
    let said = journal::recover(&mut b, &shared, &j, &r);
    assert_eq!(b.board.state(), state);
    for a in 0..c.agents.len() as u32 {
        assert_eq!(b.board.engine().fact(a), facts[a as usize], "agent {}", c.agents[a as usize].name);
        assert_eq!(shared.org().fsm_state(a), fsm[a as usize], "agent {}", c.agents[a as usize].name);
    }
    assert_eq!(shared.org().state(), state, "the organisation follows");
    assert!(said.contains(&format!("recovered {} entries", r.entries.len())), "{said}");
    assert!(said.contains("state RO, facts of LADAR, GPS, Supervisor"), "{said}");
}

#[test]
fn what_went_stale_during_the_gap_is_stale_at_the_first_heartbeat() {
    let c = content(RULES);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("board.journal");
    first_board(&c, &path);
    let (j, r) = Journal::open(&path, &c).unwrap();
    let (shared, mut b) = board(&c);
    journal::recover(&mut b, &shared, &j, &r);
    b.set_log_out(Some(Box::new(j)));
    let ladar = c.agent_id("LADAR").unwrap();
    let gps = c.agent_id("GPS").unwrap();
    assert!(!b.board.engine().is_stale(ladar));
    // Down for 2 s: LADAR's 300 ms have passed, GPS's 10 s have not.
    let change = b.tick(&shared, 2_200 * MS).expect("the rule of a stale LADAR fires");
    assert_eq!(c.states[change.to as usize].name, "EM");
    assert!(b.board.engine().is_stale(ladar));
    assert!(!b.board.engine().is_stale(gps));
    assert!(b.board.engine().fact(gps).is_some());
    b.flush_log(false);
    drop(b);
    // The journal went on: a third board has the state after the gap.
    let (j, r) = Journal::open(&path, &c).unwrap();
    let (shared, mut b) = board(&c);
    journal::recover(&mut b, &shared, &j, &r);
    assert_eq!(b.board.state_name(), "EM");
    assert!(b.board.engine().is_stale(ladar));
}

#[test]
fn the_journal_of_another_bundle_is_refused() {
    let c = content(RULES);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("board.journal");
    first_board(&c, &path);
    let other = content(&RULES.replace("distance < 30.0", "distance < 40.0"));
    let err = Journal::open(&path, &other).unwrap_err();
    assert!(matches!(err, JournalError::OtherBundle { .. }), "{err}");
    assert!(Opened::open(&path, &other).is_err());
}

#[test]
fn a_real_time_run_with_a_journal_starts_from_it_and_says_so() {
    let c = content(RULES);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("board.journal");
    let (state, _, _) = first_board(&c, &path);
    let before = Journal::open(&path, &c).unwrap().1.entries.len();
    let told = Arc::new(Mutex::new(Vec::new()));
    let t = told.clone();
    let opened = Opened::open(&path, &c).unwrap().telling(move |text| t.lock().unwrap().push(text.to_string()));
    let memory = Arc::new(Mutex::new(Memory::default()));
    let config = RealtimeConfig { journal: Some(opened), stop_on_final: false, ..RealtimeConfig::default() };
    let agents = (0..c.agents.len()).map(|_| None).collect();
    let mut changes = Vec::new();
    let summary = realtime::run(
        c.clone(),
        agents,
        Some(Box::new(memory.clone())),
        config,
        Duration::from_millis(100),
        &mut |ch| changes.push(ch.to),
    );
    let m = memory.lock().unwrap();
    let said: Vec<&str> =
        m.diagnostics.iter().map(|(_, t)| t.as_str()).filter(|t| t.starts_with("recovered")).collect();
    assert_eq!(said.len(), 1, "{:?}", m.diagnostics);
    assert!(said[0].contains("state RO"), "{}", said[0]);
    assert_eq!(told.lock().unwrap().as_slice(), said.as_slice());
    // The wall clock is decades after the journal's times: LADAR is stale
    // at the first heartbeat, and the rule of a blind robot fires from RO.
    assert_eq!(changes.first().copied(), Some(c.state_id("EM").unwrap()), "from {state}");
    assert_eq!(summary.final_state, "EM");
    assert_eq!(summary.path, ["RO", "EM"], "the run started where the journal left it");
    drop(m);
    // The run wrote its own entries after the recovered ones: the
    // heartbeat that made LADAR stale, at the wall clock.
    let (_, r) = Journal::open(&path, &c).unwrap();
    assert!(r.entries.len() > before, "{:?}", r.entries);
    assert!(matches!(r.entries[before].entry, Entry::Tick { time } if time > 1_000_000_000 * MS), "{:?}", r.entries);
}
