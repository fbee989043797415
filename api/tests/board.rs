//! The embedded board (`situ_api::Board`) on a rules file of its own
//! (`fixtures/picker.situ`): names, payloads, the admission rule of a
//! running stack, the answers as data, and a reload that keeps the facts.

use situ_api::{Arg, Board, BoardError, Clock, FieldValue, Posted};
use std::sync::Arc;

const MS: u64 = 1_000_000;

fn board_of(text: &str, clock: Clock) -> Board {
    let checked = situ_api::check(situ_api::Input::Text { name: "picker.situ", text }).expect("the rules check");
    let built = situ_api::build(&checked, &Default::default()).expect("the rules build");
    let program = situ_api::load(&built.bytes, &situ_api::Trust::Any).expect("the bundle loads");
    Board::new(Arc::new(program.content), clock)
}

fn picker(clock: Clock) -> Board {
    board_of(include_str!("fixtures/picker.situ"), clock)
}

fn post(b: &mut Board, event: &str, at: u64, args: &[(&str, Arg)]) -> Posted {
    let id = b.event(event).expect("a known event");
    let payload = b.payload(id, args).expect("a payload that fits");
    b.post(id, Some(at), &payload).expect("a well-formed post")
}

#[test]
fn an_order_starts_a_pick_and_why_names_the_rule_its_line_and_facts() {
    let mut b = picker(Clock::Manual);
    assert_eq!(b.state(), "IDLE");
    assert!(b.why().is_none());
    post(&mut b, "BATT", 0, &[("charge", Arg::F64(80.0))]);
    let posted = post(&mut b, "Scanner.ORDER", 10 * MS, &[("item", Arg::I64(7))]);
    let Posted::Taken { change: Some(change), error: None } = posted else { panic!("not a change: {posted:?}") };
    assert_eq!(
        (change.from.as_str(), change.to.as_str(), change.rules.as_slice()),
        ("IDLE", "PICKING", &["order".to_string()][..])
    );
    let why = b.why().expect("a change");
    assert_eq!(why.firings.len(), 1);
    let fired = &why.firings[0];
    assert_eq!((fired.rule.as_str(), fired.line), ("order", 49));
    assert!(fired.text.starts_with("rule order"), "{}", fired.text);
    let events: Vec<&str> = fired.facts.iter().map(|f| f.event.as_str()).collect();
    assert_eq!(events, ["ORDER", "BATT"]);
    assert_eq!(fired.facts[0].fields, [("item".to_string(), FieldValue::I64(7))]);
    let arm = b.agents().into_iter().find(|a| a.name == "Arm").expect("Arm");
    assert_eq!((arm.mode, arm.function.as_deref()), ("running", Some("reach")));
    assert_eq!((arm.from.as_slice(), arm.to.as_slice()), (&["Scanner".to_string()][..], &["Gripper".to_string()][..]));
    assert_eq!(b.counters().accepted, 2);
    assert_eq!(b.counters().changes, 1);
}

#[test]
fn late_and_sleeping_agents_events_are_not_taken_and_counted() {
    let mut b = picker(Clock::Manual);
    post(&mut b, "BATT", 100 * MS, &[("charge", Arg::F64(50.0))]);
    // Stamped before the battery's latest accepted event.
    let late = post(&mut b, "BATT", 50 * MS, &[("charge", Arg::F64(5.0))]);
    assert!(matches!(&late, Posted::NotTaken(r) if r.key == "out of order"), "{late:?}");
    assert_eq!(b.state(), "IDLE");
    // Low battery: charging, where the arm sleeps and never reports.
    post(&mut b, "BATT", 200 * MS, &[("charge", Arg::F64(10.0))]);
    assert_eq!(b.state(), "CHARGING");
    let asleep = post(&mut b, "PICKED", 300 * MS, &[]);
    let Posted::NotTaken(refusal) = &asleep else { panic!("{asleep:?}") };
    assert_eq!(refusal.key, "sleeping");
    let reason = refusal.reason(b.content());
    assert!(reason.contains("`Arm` sleeps in CHARGING"), "{reason}");
    assert_eq!(b.counters().not_taken.get("sleeping"), Some(&1));
    assert_eq!(b.counters().not_taken.get("out of order"), Some(&1));
}

#[test]
fn with_the_system_clock_an_event_from_the_future_is_refused() {
    let mut b = picker(Clock::System);
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap().as_nanos() as u64;
    let future = post(&mut b, "BATT", now + 3_600_000 * MS, &[("charge", Arg::F64(50.0))]);
    assert!(matches!(&future, Posted::NotTaken(r) if r.key == "from the future"), "{future:?}");
    let id = b.event("BATT").unwrap();
    let payload = b.payload(id, &[("charge", Arg::F64(50.0))]).unwrap();
    assert!(matches!(b.post(id, None, &payload).unwrap(), Posted::Taken { .. }));
    assert!(b.now() >= now);
}

#[test]
fn nan_is_taken_and_matches_no_comparison() {
    let mut b = picker(Clock::Manual);
    post(&mut b, "BATT", 0, &[("charge", Arg::F64(f64::NAN))]);
    post(&mut b, "ORDER", 0, &[("item", Arg::I64(1))]);
    assert_eq!(b.state(), "IDLE", "NaN is neither >= 20 nor < 20");
    let facts = b.facts();
    let batt = facts.iter().find(|f| f.agent == "Battery").and_then(|f| f.fact.as_ref()).expect("a fact");
    assert!(matches!(batt.fields[0].1, FieldValue::F64(x) if x.is_nan()));
}

#[test]
fn a_silent_agent_goes_stale_when_time_passes() {
    let mut b = picker(Clock::Manual);
    post(&mut b, "BATT", 0, &[("charge", Arg::F64(80.0))]);
    post(&mut b, "ORDER", 0, &[("item", Arg::I64(3))]);
    assert_eq!(b.state(), "PICKING");
    assert!(b.advance(Some(2_000 * MS)).is_none());
    let change = b.advance(Some(3_500 * MS)).expect("the battery went stale");
    assert_eq!((change.to.as_str(), change.rules.as_slice()), ("FAULT", &["battery_silent".to_string()][..]));
    assert!(b.facts().iter().any(|f| f.agent == "Battery" && f.stale));
}

#[test]
fn the_fsm_follows_its_agents_events() {
    let mut b = picker(Clock::Manual);
    let gripper = |b: &Board| b.agents().into_iter().find(|a| a.name == "Gripper").unwrap();
    assert_eq!((gripper(&b).mode, gripper(&b).fsm_state.as_deref()), ("waiting", Some("Open")));
    post(&mut b, "SUCKED", 0, &[]);
    assert_eq!((gripper(&b).mode, gripper(&b).fsm_state.as_deref()), ("running", Some("Holding")));
}

#[test]
fn a_wrong_name_field_or_value_is_an_error_with_its_code() {
    let b = picker(Clock::Manual);
    let e = b.event("BAT").unwrap_err();
    assert_eq!(e.code(), "unknown-event");
    assert!(matches!(&e, BoardError::UnknownEvent { suggestion: Some(s), .. } if s == "BATT"), "{e}");
    assert_eq!(b.event("Lidar.BATT").unwrap_err().code(), "not-its-agent");
    let obst = b.event("OBST").unwrap();
    let cases: [(&[(&str, Arg)], &str); 5] = [
        (&[("distance", Arg::F64(1.0))], "missing-fields"),
        (&[("distance", Arg::F64(1.0)), ("side", Arg::Symbol("up"))], "field-type"),
        (&[("distance", Arg::Bool(true)), ("side", Arg::Symbol("left"))], "field-type"),
        (&[("distance", Arg::F64(1.0)), ("distance", Arg::F64(1.0)), ("side", Arg::Symbol("left"))], "field-twice"),
        (&[("distanse", Arg::F64(1.0)), ("side", Arg::Symbol("left"))], "unknown-field"),
    ];
    for (args, code) in cases {
        let e = b.payload(obst, args).unwrap_err();
        assert_eq!(e.code(), code, "{e}");
    }
    // An integer is taken for an f64 field.
    assert!(b.payload(obst, &[("distance", Arg::I64(2)), ("side", Arg::Symbol("right"))]).is_ok());
    assert_eq!(
        b.event("ORDER").and_then(|id| b.payload(id, &[("item", Arg::F64(1.5))])).unwrap_err().code(),
        "field-type"
    );
}

#[test]
fn a_reload_keeps_the_state_and_the_facts_that_still_fit() {
    let text = include_str!("fixtures/picker.situ");
    let mut b = board_of(text, Clock::Manual);
    post(&mut b, "BATT", 0, &[("charge", Arg::F64(80.0))]);
    post(&mut b, "ORDER", 0, &[("item", Arg::I64(3))]);
    assert_eq!(b.state(), "PICKING");
    // The new rules stop picking on a lower charge.
    let new = text.replace("BATT(charge < 20.0)", "BATT(charge < 90.0)");
    let content = board_of(&new, Clock::Manual).content().clone();
    let reloaded = b.reload(content).expect("the swap");
    assert!(reloaded.carried.contains(&"Battery".to_string()), "{reloaded:?}");
    let change = reloaded.change.expect("the new rules fire at once on the facts kept");
    assert_eq!((change.from.as_str(), change.to.as_str()), ("PICKING", "CHARGING"));
    assert_eq!(b.state(), "CHARGING");
    // Rules without the current state are refused, and the old stay.
    let other = board_of("states { A initial }\nagent X sensor { event E }\n", Clock::Manual).content().clone();
    assert_eq!(b.reload(other).unwrap_err().code(), "reload");
    assert_eq!(b.state(), "CHARGING");
    assert!(b.event("BATT").is_ok());
}

#[test]
fn an_event_of_the_most_fields_is_built_field_by_field() {
    let fields: Vec<String> = (0..64).map(|i| format!("v{i}: f64")).collect();
    let text = format!("states {{ A initial }}\nagent X sensor {{ event BIG {{ {} }} }}\n", fields.join(", "));
    let b = board_of(&text, Clock::Manual);
    let big = b.event("BIG").unwrap();
    let names: Vec<String> = (0..64).map(|i| format!("v{i}")).collect();
    let all: Vec<(&str, Arg)> = names.iter().map(|n| (n.as_str(), Arg::F64(1.0))).collect();
    assert_eq!(b.payload(big, &all).unwrap().len(), 64);
    let e = b.payload(big, &all[..63]).unwrap_err();
    assert!(matches!(&e, BoardError::MissingFields { missing, .. } if missing == &["v63".to_string()]), "{e}");
    let mut twice = all.clone();
    twice.push(("v63", Arg::F64(2.0)));
    assert_eq!(b.payload(big, &twice).unwrap_err().code(), "field-twice");
    let mut early = all.clone();
    early.push(("v3", Arg::F64(2.0)));
    assert_eq!(b.payload(big, &early).unwrap_err().code(), "field-twice");
}
