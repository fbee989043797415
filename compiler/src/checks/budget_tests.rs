//! The checks that can need exponential work stop at a budget counted in
//! work, and say so (W0321); on inputs they can decide, they decide.

use super::transitions::Transitions;
use super::{oscillation, shadowed};
use crate::{check_source, codes, Checked};
use std::fmt::Write as _;

/// `k` states all linked to each other: the step `Si -> Sj` needs `Bi_j`
/// and, ascending, `UP`, descending, `DN`. `rivals`: UP and DN are two
/// agents' events, and in every state a rule of higher salience needs both
/// (so every cycle's rules hold together, and none oscillates); otherwise
/// UP and DN are one agent's (so no cycle's rules hold together).
fn dense(k: usize, rivals: bool) -> Checked {
    let mut s = String::from("states {");
    for i in 0..k {
        let _ = write!(s, " S{i}{}", if i == 0 { " initial" } else { "" });
    }
    s.push_str(" F final }\n");
    if rivals {
        s.push_str("agent U sensor { event UP }\nagent D sensor { event DN }\n");
    } else {
        s.push_str("agent U sensor { event UP event DN }\nagent G sensor { event GO }\n");
    }
    for i in 0..k {
        let events: Vec<String> = (0..k).filter(|&j| j != i).map(|j| format!("event B{i}_{j}")).collect();
        let _ = writeln!(s, "agent B{i} sensor {{ {} }}", events.join(" "));
        for j in (0..k).filter(|&j| j != i) {
            let d = if i < j { "UP" } else { "DN" };
            let _ = writeln!(s, "rule r_{i}_{j} {{ when state == S{i} and B{i}_{j} and {d} then S{j} }}");
        }
        let stop = if rivals { "UP and DN" } else { "GO" };
        let _ = writeln!(s, "rule stop_{i} salience 10 {{ when state == S{i} and {stop} then F }}");
    }
    let c = check_source("dense.situ", &s);
    assert_eq!(c.errors(), 0, "{:?}", c.diagnostics.iter().map(|d| &d.message).collect::<Vec<_>>());
    c
}

fn codes_of(found: &[situ_grammar::diag::Diagnostic]) -> Vec<&str> {
    found.iter().map(|d| d.code).collect()
}

#[test]
fn exponentially_many_cycles_stop_at_the_work_budget_with_a_note() {
    // 12 states: over 100,000 cycles of up to 6 states, every one possible.
    let c = dense(12, true);
    let tr = Transitions::build(&c.model);
    let (found, used) = oscillation::check_within(&c.model, &tr, oscillation::WORK);
    assert_eq!(codes_of(&found), [codes::INCOMPLETE_CHECK], "no oscillation, and the note that it stopped");
    assert_eq!(used, oscillation::WORK, "the whole budget, and not a step more");
    let note = &found[0];
    assert_eq!(note.witness.as_ref().unwrap()["check"], codes::OSCILLATION);
    assert!(note.message.contains("stopped at its work budget"), "{}", note.message);
    // The full check reports it too.
    assert!(c.visible().any(|d| d.code == codes::INCOMPLETE_CHECK));
}

#[test]
fn the_work_grows_with_the_cycles_and_the_budget_bounds_it() {
    // A budget that suffices decides without a note; the same input with a
    // budget one step short stops with one.
    let c = dense(5, true);
    let tr = Transitions::build(&c.model);
    let (found, used) = oscillation::check_within(&c.model, &tr, oscillation::WORK);
    assert!(found.is_empty(), "{:?}", codes_of(&found));
    assert!(used > 0 && used < oscillation::WORK, "{used}");
    let (short, short_used) = oscillation::check_within(&c.model, &tr, used - 1);
    assert_eq!(codes_of(&short), [codes::INCOMPLETE_CHECK]);
    assert_eq!(short_used, used - 1);
    let (again, again_used) = oscillation::check_within(&c.model, &tr, used);
    assert!(
        again.is_empty() && again_used == used,
        "the count is deterministic: {again_used} {used} {:?}",
        again.iter().map(|d| &d.message).collect::<Vec<_>>()
    );
}

#[test]
fn rules_that_cannot_hold_together_are_dropped_on_the_path() {
    // The same 12 states with no cycle possible: every path turns once at
    // most, so the work is polynomial (the paths that only ascend), not the
    // 100,000 cycles of states.
    let c = dense(12, false);
    let tr = Transitions::build(&c.model);
    let (found, used) = oscillation::check_within(&c.model, &tr, oscillation::WORK);
    assert!(found.is_empty(), "{:?}", codes_of(&found));
    assert!(used < 20_000, "{used} steps");
}

#[test]
fn an_oscillation_is_found_in_a_dense_graph_before_the_budget() {
    let c = check_source(
        "o.situ",
        "states { IT initial RS RO SP final }
         agent LADAR sensor { event LAOBS { distance: f64 } event LAOBN }
         agent STCCD sensor { event STOBN }
         agent TeleControl interface { event TCTAKE }
         rule start salience 30 { when state == IT and LAOBN then RS }
         rule operator_stop salience 90 { when TCTAKE then SP }
         rule road_obstacle salience 50 { when state == RS and LAOBS(distance < 30.0) then RO }
         rule stereo_clear salience 40 { when state == RO and STOBN then RS }",
    );
    let tr = Transitions::build(&c.model);
    let (found, used) = oscillation::check_within(&c.model, &tr, oscillation::WORK);
    assert_eq!(codes_of(&found), [codes::OSCILLATION]);
    assert!(used < 100, "{used}");
    // With no work at all, it says it stopped instead of saying nothing.
    let (none, _) = oscillation::check_within(&c.model, &tr, 0);
    assert_eq!(codes_of(&none), [codes::INCOMPLETE_CHECK]);
}

#[test]
fn an_undecided_shadowing_is_a_note_not_silence() {
    let c = check_source(
        "s.situ",
        "states { IT initial RS RO EM }
         agent LADAR sensor { event LAOBS { distance: f64 } }
         agent GPS sensor { event FIX }
         rule low { when state == RS and LAOBS(distance < 10.0) and FIX then RO }
         rule high salience 5 { when state == RS and LAOBS(distance < 20.0) then EM }
         rule go { when state == IT and FIX then RS }",
    );
    let tr = Transitions::build(&c.model);
    assert_eq!(codes_of(&shadowed::check(&c.model, &tr)), [codes::SHADOWED_RULE]);
    let starved = shadowed::check_within(&c.model, &tr, 1);
    assert_eq!(codes_of(&starved), [codes::INCOMPLETE_CHECK]);
    assert_eq!(starved[0].witness.as_ref().unwrap()["undecided"][0], "low");
}
