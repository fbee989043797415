//! The REPL session of `situ_runtime::repl` on compiled sources.

use situ_runtime::repl::*;
use std::sync::Arc;

const RULES: &str = "states { RS initial RO EM }\n\
    agent LADAR sensor { stale after 300ms event LAOBS { distance: f64, kind: {car, tree} } event LAOBN }\n\
    agent Fusion processing { function fuse table { RO => run fuse() from LADAR _ => sleep } }\n\
    rule obstacle salience 10 { when state == RS and LAOBS(distance < 30.0) then RO }\n\
    rule clear { when state == RO and LAOBN x3 then RS }\n\
    rule silent salience 100 { when state in {RS, RO} and stale LADAR then EM }\n";

fn session(src: &str) -> Session {
    let checked = situ_compiler::check_source("r.situ", src);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    Session::new(Arc::new(situ_compiler::bundle::build(&checked)))
}

fn text(r: Result<Reply, ReplError>) -> String {
    match r {
        Ok(Reply::Text(t)) => t,
        other => panic!("expected text, got {other:?}"),
    }
}

#[test]
fn events_move_the_state_and_the_organisation() {
    let mut s = session(RULES);
    assert_eq!(text(s.execute("LAOBS distance=12 kind=car")), "RS -> RO (obstacle)");
    assert!(text(s.execute("agents")).contains("Fusion  running fuse() from LADAR"));
    let why = text(s.execute("why"));
    assert!(why.contains("rule `obstacle`") && why.contains("r.situ:4:"), "{why}");
    assert!(why.contains("LAOBS(distance: 12.0, kind: car)"), "{why}");
    assert_eq!(text(s.execute("LADAR.LAOBN x3")), "RO -> RS (clear)");
    assert!(text(s.execute("facts")).contains("LADAR: LAOBN x3"));
}

#[test]
fn time_passes_and_undo_takes_it_back() {
    let mut s = session(RULES);
    text(s.execute("LAOBN"));
    assert_eq!(text(s.execute("wait 400ms")), "RS -> EM (silent)");
    assert!(text(s.execute("undo")).contains("RS at 0.000s"));
    assert_eq!(s.state(), "RS");
    assert!(s.execute("undo").is_ok());
    assert_eq!(s.execute("undo"), Err(ReplError::NothingToUndo));
    assert_eq!(ReplError::NothingToUndo.to_string(), "nothing to undo");
}

#[test]
fn bad_lines_are_errors_and_change_nothing() {
    let mut s = session(RULES);
    for (line, expected) in [
        ("LAOBZ distance=1", "did you mean `LAOBS`"),
        ("LAOBS distanc=1 kind=car", "did you mean `distance`"),
        ("LAOBS distance=near kind=car", "`distance` is a number"),
        ("LAOBS distance=1 kind=bus", "one of car, tree"),
        ("LAOBS distance=1", "kind missing"),
        ("Fusion.LAOBN", "an event of `LADAR`, not of `Fusion`"),
        ("wait soon", "not a duration"),
        ("wait 2days", "not a duration"),
        ("LAOBN x0", "repeat count"),
        ("save", "one file name"),
    ] {
        let e = s.execute(line).expect_err(line).to_string();
        assert!(e.contains(expected), "{line}: {e}");
    }
    assert_eq!(s.state(), "RS");
    assert_eq!(text(s.execute("facts")), "no facts at 0.000s");
}

#[test]
fn the_saved_test_reproduces_the_session() {
    let mut s = session(RULES);
    text(s.execute("LAOBS distance=12 kind=tree"));
    text(s.execute("wait 100ms"));
    text(s.execute("LAOBN x3"));
    let block = s.test_block("session", None);
    assert!(block.contains("on LAOBS(distance: 12.0, kind: tree) at 0ms\n    expect state RO"), "{block}");
    assert!(
        block.contains("on LAOBN at 100ms\n    on LAOBN at 100ms\n    on LAOBN at 100ms\n    expect state RS"),
        "{block}"
    );
    let checked = situ_compiler::check_source("r.situ", &format!("{RULES}\n{block}"));
    assert_eq!(checked.errors(), 0, "{block}\n{:?}", checked.diagnostics);
}

#[test]
fn reload_keeps_the_facts_and_says_what_changed() {
    let mut s = session(RULES);
    text(s.execute("LAOBS distance=12 kind=car"));
    let changed = RULES.replace("LAOBN x3 then RS", "LAOBN x2 then RS");
    let checked = situ_compiler::check_source("r.situ", &changed);
    let report = s.reload(Arc::new(situ_compiler::bundle::build(&checked))).unwrap();
    assert!(report.contains("rule `clear` changed") && report.contains("facts kept: LADAR"), "{report}");
    assert_eq!(s.state(), "RO");
    assert_eq!(text(s.execute("LAOBN x2")), "RO -> RS (clear)");
}

#[test]
fn words_complete_events_fields_and_symbols() {
    let s = session(RULES);
    let w = s.words();
    for x in ["LAOBS", "LADAR.LAOBS", "distance=", "kind=tree", "Fusion", "wait"] {
        assert!(w.iter().any(|y| y == x), "{x}");
    }
}

/// A camera that sleeps except in A: a run never reports its `SEEN` in B.
const CAMERA: &str = "states { A initial B }\n\
    agent Cam sensor { event SEEN function look table { A => wait look() _ => sleep } }\n\
    agent Clock sensor { event TICK }\n\
    rule go { when state == A and TICK then B }\n\
    rule seen { when state == A and SEEN then B }\n";

#[test]
fn a_sleeping_agents_event_is_dropped_as_a_run_drops_it() {
    let mut s = session(CAMERA);
    assert_eq!(text(s.execute("TICK")), "A -> B (go)");
    let dropped = text(s.execute("Cam.SEEN"));
    assert_eq!(
        dropped,
        "dropped: `Cam` sleeps in B, and a sleeping agent is not stepped: a run never reports its `SEEN` now; nothing changed"
    );
    assert_eq!(s.state(), "B");
    assert!(!text(s.execute("facts")).contains("Cam"), "no fact of the camera");
    assert!(text(s.execute("undo")).starts_with("took back TICK"), "the drop is no step");
}

#[test]
fn a_repeat_stops_where_its_agent_falls_asleep() {
    let mut s = session(CAMERA);
    let out = text(s.execute("SEEN x3"));
    let (posted, dropped) = out.split_once('\n').unwrap();
    assert_eq!(posted, "A -> B (seen)");
    assert!(dropped.starts_with("dropped: `Cam` sleeps in B") && dropped.ends_with("(2 of the 3 not posted)"), "{out}");
    assert!(text(s.execute("facts")).starts_with("Cam: SEEN at"), "one SEEN, not three");
    assert_eq!(s.test_block("t", None).matches("on SEEN").count(), 1);
}
