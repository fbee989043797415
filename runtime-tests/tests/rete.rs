//! Unit tests per node kind and per rule of inference.

use situ_bundle::Value::{self, *};
use situ_runtime::rete::*;
use std::sync::Arc;

const MS: u64 = 1_000_000;

const STACK: &str = "states { IT initial RS RO EM SP final }
agent LADAR sensor {
    stale after 300ms
    event LAOBS { distance: f64, height: f64 }
    event LAOBN
}
agent STCCD sensor { event STOBS { distance: f64, side: {left, right} } event STOBN }
agent Hinder processing { event HINDER { influence: f64, active: bool } }
agent Fusion processing { event FURS event FURO { n: i64 } }
";

struct T {
    e: Engine,
}

impl T {
    fn new(rules: &str) -> T {
        let src = format!("{STACK}{rules}");
        let c = situ_compiler::check_source("t.situ", &src);
        let front: Vec<_> = c.diagnostics.iter().filter(|d| d.code < "E0300").collect();
        assert!(front.is_empty(), "{front:?}");
        let content = situ_compiler::bundle::build(&c);
        situ_bundle::codec::validate(&content).expect("a valid bundle");
        T { e: Engine::new(Arc::new(content)) }
    }

    fn id(&self, event: &str) -> u32 {
        self.e.content().event_id(event).unwrap_or_else(|| panic!("no event {event}"))
    }

    fn post(&mut self, event: &str, ms: u64, payload: &[Value]) -> Option<StateChange> {
        let id = self.id(event);
        self.e.post(id, ms * MS, payload).unwrap_or_else(|e| panic!("{}", e.describe(self.e.content())))
    }

    fn state(&self) -> &str {
        &self.e.content().states[self.e.state() as usize].name
    }

    fn clone_engine(&self) -> T {
        T { e: self.e.clone() }
    }

    fn go(&mut self, state: &str) {
        let s = self.e.content().state_id(state).unwrap();
        self.e.force_state(s);
    }
}

#[test]
fn a_pattern_with_constant_tests() {
    let mut t = T::new("rule obstacle { when state == RS and LAOBS(distance < 30.0, height > 0.15) then RO }");
    t.go("RS");
    assert!(t.post("LAOBS", 10, &[F64(40.0), F64(1.0)]).is_none());
    assert!(t.post("LAOBS", 20, &[F64(20.0), F64(0.1)]).is_none());
    let change = t.post("LAOBS", 30, &[F64(20.0), F64(1.0)]).expect("fires");
    assert_eq!(t.state(), "RO");
    assert_eq!(change.firings.len(), 1);
    assert_eq!(change.firings[0].matched[0].payload, vec![F64(20.0), F64(1.0)]);
}

#[test]
fn the_state_guard_gates_the_rule_and_a_state_change_reactivates() {
    let mut t = T::new(
        "rule ready { when state == IT and FURS then RS }
         rule obstacle { when state == RS and LAOBS then RO }",
    );
    assert!(t.post("LAOBS", 10, &[F64(1.0), F64(1.0)]).is_none(), "not in RS yet");
    // Entering RS activates `obstacle` on the fact already there: a cascade.
    let change = t.post("FURS", 20, &[]).expect("fires");
    let names: Vec<&str> = change.firings.iter().map(|f| t.e.content().rules[f.rule as usize].name.as_str()).collect();
    assert_eq!(names, ["ready", "obstacle"]);
    assert_eq!(t.state(), "RO");
}

#[test]
fn negation_holds_without_the_fact_and_fails_with_it() {
    let mut t = T::new("rule clear { when state == RS and LAOBN and not STOBS(distance < 30.0) then RO }");
    t.go("RS");
    t.post("STOBS", 10, &[F64(10.0), Symbol(0)]);
    assert!(t.post("LAOBN", 20, &[]).is_none(), "STOBS within 30 m blocks it");
    // The blocking fact is replaced by one that does not match: it fires.
    assert!(t.post("STOBS", 30, &[F64(50.0), Symbol(1)]).is_some());
    assert_eq!(t.state(), "RO");
}

#[test]
fn run_lengths_count_reports_in_a_row_of_one_event() {
    let mut t = T::new("rule clear { when state == RS and LAOBN x3 then RO }");
    t.go("RS");
    t.post("LAOBN", 10, &[]);
    t.post("LAOBN", 20, &[]);
    t.post("LAOBS", 30, &[F64(50.0), F64(0.1)]); // breaks the run
    t.post("LAOBN", 40, &[]);
    t.post("LAOBN", 50, &[]);
    assert_eq!(t.state(), "RS");
    t.post("LAOBN", 60, &[]);
    assert_eq!(t.state(), "RO");
    assert_eq!(t.e.fact(0).unwrap().run, 3);
}

#[test]
fn windows_close_as_time_passes() {
    let mut t = T::new("rule fresh { when state == RS and FURS within 500ms and not LAOBS then RO }");
    t.go("RS");
    t.post("LAOBS", 0, &[F64(1.0), F64(1.0)]);
    t.post("FURS", 100, &[]);
    // LADAR's fact expires at 300 ms (stale after 300ms): `not LAOBS` holds
    // at 650 ms, but FURS is 550 ms old then.
    assert!(t.post("STOBN", 650, &[]).is_none());
    assert_eq!(t.state(), "RS");
    t.post("FURS", 700, &[]);
    assert_eq!(t.state(), "RO", "within the window again");
}

#[test]
fn a_window_is_inclusive() {
    let mut t = T::new("rule fresh { when state == RS and FURS within 500ms and STOBN then RO }");
    t.go("RS");
    t.post("FURS", 100, &[]);
    t.post("STOBN", 600, &[]);
    assert_eq!(t.state(), "RO", "now - t = 500 ms is within 500 ms");
}

#[test]
fn staleness_expires_facts_and_is_a_condition() {
    let mut t = T::new(
        "rule silent { when state == RS and stale LADAR then EM }
         rule seen { when state == RS and LAOBS then RO }",
    );
    t.go("RS");
    t.post("LAOBN", 0, &[]);
    t.post("STOBN", 300, &[]);
    assert_eq!(t.state(), "RS", "300 ms is not older than 300 ms");
    assert!(!t.e.is_stale(0));
    let change = t.post("STOBN", 301, &[]).expect("fires");
    assert_eq!(t.state(), "EM");
    assert!(t.e.is_stale(0));
    assert!(t.e.fact(0).is_none(), "the expired fact is gone");
    assert_eq!(change.firings[0].stale, vec![0]);
}

#[test]
fn a_stale_agent_starts_a_new_run() {
    let mut t = T::new("rule clear { when state == RS and LAOBN x2 then RO }");
    t.go("RS");
    t.post("LAOBN", 0, &[]);
    t.post("LAOBN", 400, &[]); // the first expired at 300 ms
    assert_eq!(t.e.fact(0).unwrap().run, 1);
    assert_eq!(t.state(), "RS");
    t.post("LAOBN", 500, &[]);
    assert_eq!(t.state(), "RO");
}

#[test]
fn not_stale_holds_for_an_agent_that_never_reported() {
    let mut t = T::new("rule ok { when state == RS and STOBN and not stale LADAR then RO }");
    t.go("RS");
    t.post("STOBN", 10, &[]);
    assert_eq!(t.state(), "RO");
}

#[test]
fn variables_join_facts_of_two_agents() {
    let mut t = T::new(
        "rule near { when state == RS and STOBS(distance <= ?r) and HINDER(influence: ?r, active == true) then RO }",
    );
    t.go("RS");
    t.post("HINDER", 10, &[F64(5.0), Bool(true)]);
    t.post("STOBS", 20, &[F64(6.0), Symbol(0)]);
    assert_eq!(t.state(), "RS");
    // The influence grows: the same STOBS fact now joins.
    t.post("HINDER", 30, &[F64(7.0), Bool(true)]);
    assert_eq!(t.state(), "RO");
}

#[test]
fn a_variable_bound_twice_is_an_equality_and_nan_never_equals() {
    let mut t = T::new("rule same { when state == RS and STOBS(distance: ?d) and LAOBS(distance: ?d) then RO }");
    t.go("RS");
    t.post("STOBS", 10, &[F64(f64::NAN), Symbol(0)]);
    t.post("LAOBS", 20, &[F64(f64::NAN), F64(0.0)]);
    assert_eq!(t.state(), "RS", "NaN is not equal to NaN");
    t.post("STOBS", 30, &[F64(4.0), Symbol(0)]);
    t.post("LAOBS", 40, &[F64(4.0), F64(0.0)]);
    assert_eq!(t.state(), "RO");
}

#[test]
fn a_negation_with_a_variable_of_the_rule() {
    let mut t = T::new("rule differ { when state == RS and STOBS(distance: ?d) and not LAOBS(distance: ?d) then RO }");
    t.go("RS");
    t.post("LAOBS", 10, &[F64(4.0), F64(0.0)]);
    t.post("STOBS", 20, &[F64(4.0), Symbol(0)]);
    assert_eq!(t.state(), "RS", "equal distances: the negation fails");
    t.post("STOBS", 30, &[F64(5.0), Symbol(0)]);
    assert_eq!(t.state(), "RO");
}

#[test]
fn salience_then_specificity_then_recency_then_order() {
    // All four are activated by the same memory in RS.
    let mut t = T::new(
        "rule low { when state == RS and STOBN then EM }
         rule specific salience 5 { when state == RS and STOBN and LAOBN then SP }
         rule general salience 5 { when state == RS and STOBN then EM }",
    );
    t.go("RS");
    t.post("LAOBN", 10, &[]);
    let change = t.post("STOBN", 20, &[]).unwrap();
    assert_eq!(t.e.content().rules[change.firings[0].rule as usize].name, "specific");

    let mut t = T::new(
        "rule by_stereo { when state == RS and STOBN then EM }
         rule by_ladar { when state == RS and LAOBN then SP }",
    );
    t.go("RS");
    // Both appear at once only after a state change; the newer fact wins.
    t.post("STOBN", 10, &[]);
    assert_eq!(t.state(), "EM");
    let mut t = T::new(
        "rule first { when state == IT and FURS then RS }
         rule by_stereo { when state == RS and STOBN then EM }
         rule by_ladar { when state == RS and LAOBN then SP }",
    );
    t.post("LAOBN", 10, &[]);
    t.post("STOBN", 20, &[]);
    t.post("FURS", 30, &[]);
    // In RS both are activated: STOBN (posted after LAOBN) is more recent.
    assert_eq!(t.state(), "EM");
}

#[test]
fn declaration_order_breaks_the_last_tie() {
    let mut t = T::new(
        "rule one { when state == RS and STOBN then EM }
         rule two { when state == RS and STOBN then SP }",
    );
    t.go("RS");
    t.post("STOBN", 10, &[]);
    assert_eq!(t.state(), "EM");
}

#[test]
fn an_oscillation_is_a_cascade_error_naming_the_rules() {
    let mut t = T::new(
        "rule there { when state == RS and STOBN then RO }
         rule back { when state == RO and STOBN then RS }",
    );
    t.go("RS");
    let err = t.e.post(t.id("STOBN"), 10 * MS, &[]).unwrap_err();
    let PostError::Cascade { limit, firings } = &err else { panic!("{err:?}") };
    assert_eq!((*limit, firings.len()), (64, 64));
    let text = err.describe(t.e.content());
    assert!(text.contains("there, back"), "{text}");
}

#[test]
fn rules_that_hold_without_facts_fire_before_the_first_event() {
    let mut t = T::new("rule start { when state == IT and not LAOBS then RS }");
    // The network rests before the event is inserted: `not LAOBS` held.
    let change = t.post("LAOBS", 10, &[F64(1.0), F64(1.0)]).unwrap();
    assert_eq!(change.firings.len(), 1);
    assert_eq!(t.state(), "RS");
}

#[test]
fn bad_events_are_refused_and_change_nothing() {
    let mut t = T::new("rule r { when state == IT and LAOBS then RS }");
    let laobs = t.id("LAOBS");
    assert!(matches!(t.e.post(999, 0, &[]), Err(PostError::UnknownEvent { .. })));
    assert!(matches!(t.e.post(laobs, 0, &[F64(1.0)]), Err(PostError::Arity { .. })));
    assert!(matches!(t.e.post(laobs, 0, &[F64(1.0), I64(1)]), Err(PostError::Type { field: 1, .. })));
    let stobs = t.id("STOBS");
    assert!(matches!(t.e.post(stobs, 0, &[F64(1.0), Symbol(7)]), Err(PostError::Type { .. })));
    assert!(t.e.fact(0).is_none());
    assert_eq!(t.state(), "IT");
}

#[test]
fn reset_forgets_facts_and_keeps_time() {
    let mut t = T::new("rule r { when state == IT and LAOBN x2 then RS }");
    t.post("LAOBN", 10, &[]);
    t.e.reset();
    t.post("LAOBN", 20, &[]);
    assert_eq!(t.state(), "IT", "the run restarted");
    assert_eq!(t.e.now(), 20 * MS);
}

#[test]
fn explanations_speak_in_source_terms() {
    let mut t = T::new("rule obstacle salience 5 { when state == RS and LAOBS(distance < 30.0) then RO }");
    t.go("RS");
    let change = t.post("LAOBS", 1230, &[F64(12.0), F64(0.5)]).unwrap();
    let text = change.explain(t.e.content());
    assert!(text.starts_with("RS -> RO at 1.230s"), "{text}");
    assert!(text.contains("rule `obstacle` (t.situ:10:1, salience 5) fired in RS"), "{text}");
    assert!(text.contains("LAOBS(distance: 12.0, height: 0.5) at 1.230s -> RO"), "{text}");
}

#[test]
fn the_clock_alone_expires_silent_agents() {
    let mut t = T::new("rule silent { when state == RS and stale LADAR then EM }");
    t.go("RS");
    t.post("LAOBN", 0, &[]);
    assert!(t.e.advance(300 * MS).unwrap().is_none(), "not older than 300 ms yet");
    let change = t.e.advance(301 * MS).unwrap().expect("fires without an event");
    assert_eq!(change.firings[0].stale, vec![0]);
    assert_eq!(t.state(), "EM");
    assert!(t.e.advance(100 * MS).unwrap().is_none(), "the clock never goes back");
    assert_eq!(t.e.now(), 301 * MS);
}

// ─── The acceptance rule and the behaviours §10 writes down ───────────────

fn rule_name(t: &T, change: &StateChange, i: usize) -> String {
    t.e.content().rules[change.firings[i].rule as usize].name.clone()
}

#[test]
fn an_event_behind_its_agents_latest_is_refused_and_changes_nothing() {
    // A late LAOBN would have completed the x3 (the run was LAOBN, LAOBN).
    let mut t = T::new("rule clear { when state == RO and LAOBN x3 then RS }");
    t.go("RO");
    t.post("LAOBN", 10, &[]);
    t.post("LAOBN", 20, &[]);
    t.post("STOBN", 30, &[]);
    let laobn = t.id("LAOBN");
    let err = t.e.post(laobn, 15 * MS, &[]).unwrap_err();
    assert_eq!(err, PostError::OutOfOrder { event: laobn, time: 15 * MS, last: 20 * MS });
    assert!(err.describe(t.e.content()).starts_with("out of order: at 15000000 ns"));
    assert_eq!(t.state(), "RO");
    assert_eq!(t.e.fact(0).unwrap().run, 2, "the fact of 20 ms is kept");
    assert_eq!(t.e.now(), 30 * MS);
    // The same time as the agent's latest is not behind it.
    t.post("LAOBN", 20, &[]);
    assert_eq!(t.state(), "RS");
    // Another agent's event stamped before now is taken (§10.4).
    t.post("FURS", 25, &[]);
    assert_eq!(t.e.fact(3).unwrap().time, 25 * MS);
    assert_eq!(t.e.agent_time(0), 20 * MS);
}

#[test]
fn an_event_from_the_future_is_refused_against_the_clock_it_arrived_at() {
    let mut t = T::new("rule silent { when state == RS and stale LADAR then EM }");
    t.go("RS");
    t.post("LAOBN", 1_000, &[]);
    let stobn = t.id("STOBN");
    let ahead = 1_000 * MS + DEFAULT_MAX_SKEW + 1;
    t.e.set_clock(Some(1_000 * MS));
    let err = t.e.step(stobn, ahead, &[]).unwrap_err();
    assert!(matches!(err, StepError::FromTheFuture { clock, .. } if clock == 1_000 * MS), "{err:?}");
    assert_eq!(t.e.now(), 1_000 * MS, "a refused event never moves now");
    assert!(t.e.fact(1).is_none());
    // At the bound it is taken; so is an event at 2^63 − 1 ns that arrived
    // then: without a clock, an event arrives at its stamp.
    t.e.step(stobn, ahead - 1, &[]).unwrap();
    assert_eq!(t.state(), "RS");
    t.e.set_max_skew(0);
    t.e.set_clock(Some(2_000 * MS));
    assert!(t.e.step(stobn, 2_000 * MS + 1, &[]).is_err());
    t.e.set_clock(None);
    t.e.step(stobn, i64::MAX as u64, &[]).unwrap();
    assert_eq!((t.e.now(), t.state()), (i64::MAX as u64, "EM"));
}

#[test]
fn nan_and_the_infinities_are_values_that_match_as_section_10_3_says() {
    let mut t = T::new(
        "rule near { when state == RS and LAOBS(distance < 30.0) then RO }
         rule far { when state == RS and LAOBS(distance >= 1000.0) then EM }",
    );
    t.go("RS");
    assert!(t.post("LAOBS", 10, &[F64(f64::NAN), F64(0.5)]).is_none(), "NaN satisfies no comparison");
    assert!(t.e.fact(0).is_some(), "but it is the agent's latest fact");
    let mut other = t.clone_engine();
    t.post("LAOBS", 20, &[F64(f64::NEG_INFINITY), F64(0.5)]);
    assert_eq!(t.state(), "RO");
    other.post("LAOBS", 20, &[F64(f64::INFINITY), F64(0.5)]);
    assert_eq!(other.state(), "EM");
}

#[test]
fn a_rule_of_stale_and_not_tests_alone_has_no_recency_and_comes_last() {
    // Same salience and specificity (2 tests each); declared first, and
    // LADAR expired after STOBN was posted: `by_fact` still wins.
    let rules = "rule first { when state == IT and FURS then RS }
         rule by_stale { when state == RS and stale LADAR then EM }
         rule by_not { when state == RS and not STOBS then EM }
         rule by_fact { when state == RS and STOBN then SP }";
    let mut t = T::new(rules);
    t.post("LAOBN", 0, &[]);
    t.post("STOBN", 10, &[]);
    let change = t.post("FURS", 400, &[]).unwrap();
    assert_eq!(rule_name(&t, &change, 1), "by_fact");
    assert_eq!(t.state(), "SP");
    // Without a matched fact between them, declaration order decides.
    let mut t = T::new(&rules.replace("and STOBN then SP", "and STOBN and LAOBS then SP"));
    t.post("LAOBN", 0, &[]);
    t.post("STOBN", 10, &[]);
    let change = t.post("FURS", 400, &[]).unwrap();
    assert_eq!(rule_name(&t, &change, 1), "by_stale");
    assert_eq!(t.state(), "EM");
}

#[test]
fn a_run_continues_across_a_gap_of_exactly_stale_after_and_not_one_ns_more() {
    let mut t = T::new("rule clear { when state == RS and LAOBN x2 then RO }");
    t.go("RS");
    let laobn = t.id("LAOBN");
    t.e.post(laobn, 0, &[]).unwrap();
    t.e.post(laobn, 300 * MS, &[]).unwrap();
    assert_eq!(t.e.fact(0).unwrap().run, 2, "now − t = D: not expired, the run goes on");
    assert_eq!(t.state(), "RO");
    t.go("RS");
    t.e.post(laobn, 600 * MS + 1, &[]).unwrap();
    assert_eq!(t.e.fact(0).unwrap().run, 1, "D + 1 ns: expired, a new run");
    assert_eq!(t.state(), "RS");
    // What counts is now, which another agent's event may have moved.
    let stobn = t.id("STOBN");
    t.e.post(stobn, 900 * MS + 2, &[]).unwrap();
    t.e.post(laobn, 900 * MS + 2, &[]).unwrap();
    assert_eq!(t.e.fact(0).unwrap().run, 1);
}

#[test]
fn a_final_state_resets_after_both_rests_and_an_event_that_reached_it_first_is_lost() {
    let mut t = T::new(
        "rule go { when state == IT and STOBN then RS }
         rule silent { when state == RS and stale LADAR then SP }
         rule back { when state == IT and FURS then RO }",
    );
    t.post("LAOBN", 0, &[]);
    t.post("STOBN", 10, &[]);
    assert_eq!(t.state(), "RS");
    assert!(!t.e.reset_if_final(), "RS is not final");
    // FURS at 400 ms: LADAR expires and `silent` fires in the first rest;
    // FURS is inserted in SP, where no rule reads it.
    let change = t.post("FURS", 400, &[]).unwrap();
    assert_eq!((rule_name(&t, &change, 0).as_str(), t.state()), ("silent", "SP"));
    assert!(t.e.fact(3).is_some());
    assert!(t.e.reset_if_final());
    assert_eq!(t.state(), "IT");
    assert!((0..4).all(|a| t.e.fact(a).is_none() && !t.e.is_stale(a)), "facts cleared, no agent stale");
    assert_eq!(t.e.now(), 400 * MS, "now is kept");
    assert_eq!(t.e.agent_time(3), 400 * MS, "so are the agents' clocks");
    // FURS was lost: `back` (IT and FURS) does not fire on it.
    assert!(t.e.settle().unwrap().is_none());
    assert_eq!(t.state(), "IT");
    let furs = t.id("FURS");
    assert!(matches!(t.e.post(furs, 399 * MS, &[]), Err(PostError::OutOfOrder { .. })));
}
