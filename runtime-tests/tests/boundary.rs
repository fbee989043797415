//! Time at the boundary (`docs/language.md` 10.7): an event stamped further
//! ahead of the Bulletinboard's clock than the skew bound is refused,
//! counted and recorded, and never ages the other facts; one stamped
//! behind its agent's previous event is out of order. The Bulletinboard's
//! events monitor ([`BoardRunner`]) on an in-process bus, clock in hand.

use situ_compiler::bundle::{Content, Value};
use situ_runtime::bus::inproc::{Capacity, InProc};
use situ_runtime::bus::{Bus, EventMsg};
use situ_runtime::record::{SharedMemory, Sink, Verdict};
use situ_runtime::runner::{BoardRunner, Shared, DEFAULT_MAX_SKEW};
use std::sync::Arc;

const MS: u64 = 1_000_000;
const S: u64 = 1_000 * MS;

fn fig5() -> Arc<Content> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../examples/fig5/fig5.situ");
    let c = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("readable");
    assert_eq!(c.errors(), 0);
    Arc::new(situ_compiler::bundle::build(&c))
}

/// A Bulletinboard with a recorder, on an in-process bus.
struct Board {
    content: Arc<Content>,
    shared: Shared,
    runner: BoardRunner,
    memory: SharedMemory,
}

impl Board {
    fn new() -> Board {
        let content = fig5();
        let bus: Arc<dyn Bus> = Arc::new(InProc::new(content.agents.len(), Capacity::default()));
        let memory = SharedMemory::default();
        let shared = Shared::new(content.clone(), bus, Some(Box::new(memory.clone()) as Box<dyn Sink>));
        let mut runner = BoardRunner::new(content.clone());
        runner.start(&shared, 0);
        Board { content, shared, runner, memory }
    }

    /// `agent` reports `event` stamped `time`; the Bulletinboard takes it
    /// when its clock says `now`.
    fn report(&mut self, event: &str, time: u64, payload: Vec<Value>, now: u64) {
        let id = self.content.event_id(event).expect("an event of fig5");
        let agent = self.content.events[id as usize].agent;
        self.shared.bus.send_event(EventMsg { agent, event: id, time, payload, urgent: false });
        self.runner.pump(&self.shared, now);
    }

    /// Every sensor and Drive report as they should, at `t`, then the heartbeat.
    fn all_well(&mut self, t: u64) {
        self.report("RFRS", t, vec![], t);
        self.report("LAOBN", t, vec![], t);
        self.report("DRSTOP", t, vec![], t);
        self.runner.tick(&self.shared, t);
    }

    fn state(&self) -> &str {
        self.runner.board.state_name()
    }

    fn refused(&self, key: &str) -> u64 {
        self.runner.counters.refused.get(key).copied().unwrap_or(0)
    }
}

#[test]
fn one_event_from_the_future_is_refused_and_the_mission_goes_on() {
    let t0 = 10 * S;
    let clock = t0 + 20 * MS;
    for future in [clock + 5 * S, i64::MAX as u64, u64::MAX, clock + DEFAULT_MAX_SKEW + 1] {
        let ahead = future - clock;
        let mut b = Board::new();
        b.all_well(t0);
        assert_eq!(b.state(), "RS");
        // One well-formed LADAR event stamped `ahead` of the clock.
        b.report("LAOBN", future, vec![], clock);
        assert_eq!(b.state(), "RS", "{ahead}: the other facts did not age");
        assert_eq!(b.refused("from the future"), 1, "{ahead}: {:?}", b.runner.counters.refused);
        assert_eq!(b.runner.board.engine().now(), t0, "{ahead}: the clock did not move");
        // Valid events keep the stack where it is, LADAR's included (its
        // previous time is not the refused one's).
        for i in 1..=20 {
            b.all_well(t0 + i * 100 * MS);
        }
        assert_eq!(b.state(), "RS", "{ahead}");
        assert_eq!(b.runner.counters.refused.values().sum::<u64>(), 1, "{:?}", b.runner.counters.refused);
        // Recorded: the event with its verdict, and a diagnostic.
        let rec = b.memory.snapshot();
        let refused: Vec<_> = rec.events.iter().filter(|e| matches!(e.verdict, Verdict::Refused(_))).collect();
        assert_eq!(refused.len(), 1);
        assert_eq!(refused[0].time, future);
        assert!(rec.diagnostics.iter().any(|(_, t)| t.contains("from the future")), "{:?}", rec.diagnostics);
    }
}

#[test]
fn an_event_within_the_skew_is_taken() {
    let mut b = Board::new();
    let t0 = 10 * S;
    b.all_well(t0);
    // A host whose clock is 40 ms ahead: within the default 50 ms.
    b.report("LAOBS", t0 + 40 * MS, vec![Value::F64(12.0), Value::F64(0.5)], t0);
    assert_eq!(b.state(), "RO");
    assert_eq!(b.runner.counters.refused.values().sum::<u64>(), 0);
}

#[test]
fn the_skew_bound_is_configurable() {
    let mut b = Board::new();
    b.runner.set_max_skew(0);
    let t0 = 10 * S;
    b.all_well(t0);
    b.report("LAOBN", t0 + 1, vec![], t0);
    assert_eq!(b.refused("from the future"), 1);
    b.report("LAOBN", t0, vec![], t0);
    assert_eq!(b.refused("from the future"), 1, "at the clock is not ahead");
}

#[test]
fn an_event_behind_its_agents_previous_one_is_refused() {
    let mut b = Board::new();
    let t0 = 10 * S;
    b.all_well(t0);
    b.report("LAOBN", t0 - 1, vec![], t0 + MS);
    assert_eq!(b.refused("out of order"), 1);
    assert_eq!(b.state(), "RS");
}
