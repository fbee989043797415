//! The tests of `situ_runtime::bulletinboard` that compile a situ source (moved
//! here so that the runtime does not depend on the compiler).

use situ_compiler::bundle::{self, Content, Value};
use situ_runtime::bulletinboard::*;
use std::sync::Arc;

fn content(src: &str) -> Arc<Content> {
    let c = situ_compiler::check_source("t.situ", src);
    let front: Vec<_> = c.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front.is_empty(), "{front:?}");
    Arc::new(bundle::build(&c))
}

const V1: &str = "states { IT initial RS RO EM }
    agent LADAR sensor { stale after 300ms event LAOBS { distance: f64 } event LAOBN }
    agent GPS sensor { event FIX }
    rule go { when state == IT and FIX then RS }
    rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }";

#[test]
fn posts_broadcasts_and_remembers() {
    let mut bb = Bulletinboard::new(content(V1));
    let rx = bb.subscribe();
    assert!(bb.post_named("LAOBS", 10, &[Value::F64(50.0)]).unwrap().is_none());
    let change = bb.post_named("FIX", 20, &[]).unwrap().unwrap();
    assert_eq!(bb.state_name(), "RS");
    assert_eq!(rx.try_recv().unwrap(), change);
    assert!(bb.post_named("NOPE", 30, &[]).is_err());
    assert_eq!(bb.counters(), Counters { posted: 3, rejected: 1, firings: 1, changes: 1 });
    assert_eq!(bb.history().count(), 1);
    assert!(bb.explain(&change).contains("rule `go`"));
}

#[test]
fn the_history_is_bounded() {
    let src = "states { A initial B }
        agent S sensor { event X event Y }
        rule ab { when state == A and X then B }
        rule ba { when state == B and Y then A }";
    let mut bb = Bulletinboard::new(content(src));
    bb.set_history_capacity(3);
    for i in 0..10u64 {
        bb.post_named(if i % 2 == 0 { "X" } else { "Y" }, i, &[]).unwrap();
    }
    assert_eq!(bb.counters().changes, 10);
    let kept: Vec<u64> = bb.history().map(|c| c.time).collect();
    assert_eq!(kept, [7, 8, 9]);
}

#[test]
fn a_hot_swap_carries_the_memory_and_fires_the_new_rules() {
    let mut bb = Bulletinboard::new(content(V1));
    bb.post_named("FIX", 10, &[]).unwrap();
    bb.post_named("LAOBS", 20, &[Value::F64(40.0)]).unwrap();
    assert_eq!(bb.state_name(), "RS");
    // The new rules see obstacles from 50 m, and GPS lost its event.
    let v2 = V1
        .replace("distance < 30.0", "distance < 50.0")
        .replace("event FIX", "event FIX2")
        .replace("and FIX", "and FIX2");
    let report = bb.swap(content(&v2)).unwrap();
    assert_eq!(report.carried, ["LADAR"]);
    assert_eq!(report.dropped, [("GPS".to_string(), "event `FIX` is gone".to_string())]);
    assert_eq!(bb.state_name(), "RO", "the carried LAOBS(40) fires the new rule");
    assert!(report.change.unwrap().changed());
    // Time carried over: LADAR goes stale 300 ms after its report.
    bb.post_named("FIX2", 400_000_000, &[]).unwrap();
    assert!(bb.engine().is_stale(0));
}

#[test]
fn a_failed_swap_leaves_the_old_rules_running() {
    let mut bb = Bulletinboard::new(content(V1));
    bb.post_named("FIX", 10, &[]).unwrap();
    let err = bb.swap(content(&V1.replace("RS ", "RX ").replace("then RS", "then RX").replace("== RS", "== RX")));
    assert_eq!(err, Err(SwapError::StateMissing { state: "RS".into() }));
    let oscillating = format!(
        "{V1}\nrule back {{ when state == RO and LAOBN then RS }}\nrule forth {{ when state == RS and LAOBN then RO }}"
    );
    bb.post_named("LAOBN", 20, &[]).unwrap();
    assert!(matches!(bb.swap(content(&oscillating)), Err(SwapError::Cascade(_))));
    assert_eq!(bb.state_name(), "RS");
    bb.post_named("LAOBS", 30, &[Value::F64(10.0)]).unwrap();
    assert_eq!(bb.state_name(), "RO", "the old rules still run");
}
