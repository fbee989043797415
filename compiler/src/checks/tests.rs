use super::domain::Domain;
use super::situation::Situation;
use crate::check_source;
use crate::model::{Type, Value};
use situ_grammar::ast::CmpOp;

fn real(op: CmpOp, v: f64) -> Domain {
    Domain::of_comparison(&Type::F64, op, Value::F64(v))
}

#[test]
fn open_and_closed_ends_meet_exactly() {
    assert!(real(CmpOp::Lt, 30.0).intersect(&real(CmpOp::Ge, 30.0)).is_empty());
    assert!(!real(CmpOp::Le, 30.0).intersect(&real(CmpOp::Ge, 30.0)).is_empty());
    assert!(real(CmpOp::Lt, 30.0).intersect(&real(CmpOp::Gt, 30.0)).is_empty());
    let ne = real(CmpOp::Ne, 5.0);
    assert!(ne.intersect(&real(CmpOp::Eq, 5.0)).is_empty());
    assert!(!ne.intersect(&real(CmpOp::Ge, 5.0)).is_empty());
}

#[test]
fn nan_satisfies_no_comparison_but_escapes_them() {
    let full = Domain::full(&Type::F64);
    let nan_only = full.subtract(&real(CmpOp::Lt, 1.0)).subtract(&real(CmpOp::Ge, 1.0));
    assert!(!nan_only.is_empty(), "NaN is neither < 1 nor >= 1");
    assert!(nan_only.intersect(&real(CmpOp::Ne, 1.0)).is_empty(), "NaN is not even != 1");
    assert!(real(CmpOp::Lt, f64::NAN).is_empty());
}

#[test]
fn integers_are_discrete() {
    let lt = Domain::of_comparison(&Type::I64, CmpOp::Lt, Value::I64(3));
    let gt = Domain::of_comparison(&Type::I64, CmpOp::Gt, Value::I64(2));
    assert!(lt.intersect(&gt).is_empty(), "no integer is > 2 and < 3");
    let ge = Domain::of_comparison(&Type::I64, CmpOp::Ge, Value::I64(i64::MAX));
    assert_eq!(ge.sample(&Type::I64), Some(serde_json::json!(i64::MAX)));
}

#[test]
fn symbols_subtract() {
    let ty = Type::Symbols(vec!["left".into(), "right".into()]);
    let left = Domain::of_comparison(&ty, CmpOp::Eq, Value::Symbol(0));
    let rest = Domain::full(&ty).subtract(&left);
    assert_eq!(rest.sample(&ty), Some(serde_json::json!("right")));
    assert!(rest.subtract(&Domain::of_comparison(&ty, CmpOp::Eq, Value::Symbol(1))).is_empty());
}

const STACK: &str = "states { IT initial RS RO }
agent LADAR sensor {
    stale after 200ms
    event LAOBS { distance: f64, side: {left, right} }
    event LAOBN
}
agent GPS sensor { stale after 1s event FIX { error: f64 } }
";

fn rules(body: &str) -> crate::Checked {
    let c = check_source("t.situ", &format!("{STACK}{body}"));
    // Only the front end must be satisfied; the static checks are what is tested.
    let front_end: Vec<_> = c.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front_end.is_empty(), "{front_end:?}");
    c
}

#[test]
fn two_events_of_one_agent_never_hold_together() {
    let c = rules("rule a { when LAOBS and LAOBN then RO }");
    let err = Situation::of_rule(&c.model, &c.model.rules[0]).unwrap_err();
    assert!(err.reason.contains("one latest event"), "{}", err.reason);
    assert_eq!(err.origins.len(), 2);
}

#[test]
fn rules_meet_on_overlapping_ranges_only() {
    let c = rules(
        "rule near { when LAOBS(distance < 30.0) then RO }
         rule far { when LAOBS(distance >= 30.0) then RS }
         rule edge { when LAOBS(distance <= 30.0, side == left) then RS }",
    );
    let m = &c.model;
    let sit = |i: usize| Situation::of_rule(m, &m.rules[i]).unwrap();
    assert!(sit(0).meet(m, &sit(1)).is_err());
    let both = sit(1).meet(m, &sit(2)).unwrap().witness(m).unwrap();
    assert_eq!(both.json["facts"][0]["payload"]["distance"], 30.0);
    assert_eq!(both.json["facts"][0]["payload"]["side"], "left");
    assert!(!both.widened);
}

#[test]
fn negations_are_escaped_or_refuted() {
    let c = rules(
        "rule a { when LAOBS(distance < 10.0) and not LAOBS(distance < 20.0) then RO }
         rule b { when LAOBS(distance < 30.0) and not LAOBS(distance < 20.0) then RO }
         rule c { when LAOBS x2 and not LAOBS x3 then RO }
         rule d { when stale GPS and not FIX then RO }
         rule e { when stale GPS and FIX then RO }",
    );
    let m = &c.model;
    let witness = |i: usize| Situation::of_rule(m, &m.rules[i]).and_then(|s| s.witness(m));
    assert!(witness(0).is_err());
    let b = witness(1).unwrap();
    assert_eq!(b.json["facts"][0]["payload"]["distance"], 20.0);
    let c3 = witness(2).unwrap();
    assert_eq!(c3.json["facts"][0]["run"], 2);
    assert!(witness(3).is_ok());
    assert!(witness(4).is_err());
}

#[test]
fn variables_widen_instead_of_guessing() {
    let c = rules("rule v { when LAOBS(distance: ?d) and FIX(error > ?d) then RO }");
    let w = Situation::of_rule(&c.model, &c.model.rules[0]).unwrap().witness(&c.model).unwrap();
    assert!(w.widened);
}

#[test]
fn witnesses_read_like_events() {
    let c = rules("rule w { when state == RS and LAOBS(distance in 0.0..12.0, side == right) x3 then RO }");
    let w = Situation::of_rule(&c.model, &c.model.rules[0]).unwrap().witness(&c.model).unwrap();
    assert_eq!(w.describe(), "state RS with LAOBS(distance: 0.0, side: right) x3");
}

#[test]
fn neighbouring_floats_leave_nothing_between() {
    let below = 30.0f64.next_down();
    assert!(real(CmpOp::Lt, 30.0).intersect(&real(CmpOp::Gt, below)).is_empty());
    assert!(!real(CmpOp::Le, 30.0).intersect(&real(CmpOp::Gt, below)).is_empty());
    let huge = real(CmpOp::Ge, f64::MAX);
    assert_eq!(huge.sample(&Type::F64), Some(serde_json::json!(f64::MAX)));
    assert!(real(CmpOp::Gt, f64::MAX).intersect(&real(CmpOp::Lt, f64::INFINITY)).is_empty());
}

#[test]
fn a_rule_guarded_on_its_own_target_never_fires() {
    let c = rules("rule again { when state == RO and LAOBS then RO }");
    let err = Situation::of_rule(&c.model, &c.model.rules[0]).unwrap_err();
    assert!(err.reason.contains("own target"), "{}", err.reason);
}

#[test]
fn a_variable_bound_twice_is_an_exact_equality() {
    let c = rules(
        "rule apart { when LAOBS(distance: ?d, distance < 5.0) and FIX(error: ?d, error > 10.0) then RO }
         rule close { when LAOBS(distance: ?d, distance > 2.0) and FIX(error: ?d, error < 3.0) then RO }
         rule agree { when LAOBS(distance: ?d) and FIX(error: ?d) then RO }
         rule near { when LAOBS(distance < 1.0) then RS }
         rule far { when FIX(error > 1.0) then RS }",
    );
    let m = &c.model;
    let sit = |i: usize| Situation::of_rule(m, &m.rules[i]);
    let err = sit(0).unwrap_err();
    assert!(err.reason.contains("`?d` makes `LAOBS.distance` and `FIX.error` equal"), "{}", err.reason);
    // Satisfiable: the witness gives both fields one value, between 2 and 3.
    let w = sit(1).unwrap().witness(m).unwrap();
    assert!(!w.widened);
    let facts = w.json["facts"].as_array().unwrap();
    let d = facts[0]["payload"]["distance"].as_f64().unwrap();
    assert_eq!(facts[1]["payload"]["error"].as_f64(), Some(d));
    assert!(2.0 < d && d < 3.0, "{d}");
    // The equality survives a meet: narrowing one side narrows the other.
    let agree = sit(2).unwrap();
    assert!(agree.meet(m, &sit(3).unwrap()).unwrap().meet(m, &sit(4).unwrap()).is_err());
    assert!(agree.meet(m, &sit(3).unwrap()).unwrap().witness(m).is_ok_and(|w| !w.widened));
}

#[test]
fn an_equality_on_nan_never_holds() {
    // Only NaN escapes both negations, and NaN equals nothing: with `?d`
    // bound twice there is no memory; with two variables there is one.
    let c = rules(
        "rule twice { when LAOBS(distance: ?d) and FIX(error: ?d) and not LAOBS(distance <= 0.0) and not LAOBS(distance > 0.0) then RO }
         rule apart { when LAOBS(distance: ?d) and FIX(error: ?e) and not LAOBS(distance <= 0.0) and not LAOBS(distance > 0.0) then RO }",
    );
    let m = &c.model;
    assert!(Situation::of_rule(m, &m.rules[0]).unwrap().witness(m).is_err());
    let w = Situation::of_rule(m, &m.rules[1]).unwrap().witness(m).unwrap();
    assert_eq!(w.json["facts"][0]["payload"]["distance"], "NaN");
}

#[test]
fn a_variable_in_a_negation_widens() {
    let c = rules("rule v { when LAOBS(distance: ?d) and not FIX(error: ?d) then RO }");
    let w = Situation::of_rule(&c.model, &c.model.rules[0]).unwrap().witness(&c.model).unwrap();
    assert!(w.widened, "an inequality with a variable is not decided exactly");
}

/// A ring of `n` states, each left on another agent's event.
fn ring(n: usize) -> String {
    let mut s = String::from("states { IT initial");
    for i in 1..=n {
        s.push_str(&format!(" P{i}"));
    }
    s.push_str(" }\nagent Supervisor interface { event SVRDY }\n");
    for i in 1..=n {
        s.push_str(&format!("agent A{i} sensor {{ event E{i} }}\n"));
    }
    s.push_str("rule ready { when state == IT and SVRDY then P1 }\n");
    for i in 1..=n {
        s.push_str(&format!("rule p{i} {{ when state == P{i} and E{i} then P{} }}\n", i % n + 1));
    }
    s
}

#[test]
fn oscillations_of_up_to_six_rules_are_found() {
    for n in 2..=7 {
        let c = check_source("ring.situ", &ring(n));
        let found = c.diagnostics.iter().filter(|d| d.code == crate::codes::OSCILLATION).count();
        assert_eq!(found, usize::from(n <= 6), "a ring of {n} rules: {:?}", c.diagnostics);
    }
}

#[test]
fn infinities_are_values_at_the_ends() {
    let (inf, ninf) = (f64::INFINITY, f64::NEG_INFINITY);
    assert!(real(CmpOp::Gt, inf).is_empty(), "nothing is above inf");
    assert!(real(CmpOp::Lt, ninf).is_empty(), "nothing is below -inf");
    assert!(real(CmpOp::Ne, inf).intersect(&real(CmpOp::Eq, inf)).is_empty());
    assert!(real(CmpOp::Ne, inf).intersect(&real(CmpOp::Gt, f64::MAX)).is_empty(), "above MAX is inf only");
    assert!(!real(CmpOp::Lt, inf).intersect(&real(CmpOp::Eq, ninf)).is_empty(), "-inf < inf");
    assert_eq!(real(CmpOp::Ge, inf).sample(&Type::F64), Some(serde_json::json!("inf")));
    assert_eq!(real(CmpOp::Le, ninf).sample(&Type::F64), Some(serde_json::json!("-inf")));
}

#[test]
fn non_finite_literals_are_payloads_not_rule_tests() {
    let c = rules(
        "rule r { when state == IT and LAOBS(distance < inf, side == left) then RS }
         test \"t\" { given state IT on LAOBS(distance: NaN, side: left), LAOBS(distance: -inf, side: left) expect state RS }",
    );
    assert!(c.diagnostics.iter().all(|d| d.code != "E0201" && d.code != "E0203"), "{:?}", c.diagnostics);
    let c = check_source("t.situ", &format!("{STACK}rule r {{ when state == IT and LAOBS(distance != NaN) then RS }}"));
    assert!(c.diagnostics.iter().any(|d| d.code == "E0203"), "{:?}", c.diagnostics);
}

#[test]
fn a_state_that_fans_out_reports_a_bounded_number_of_conflicts() {
    // One state leading to 60 others on the same condition: every pair of
    // those rules conflicts (1,770 pairs); each rule is reported with at
    // most `MAX_PER_RULE` of the rules after it, the last saying so.
    use super::conflicts::MAX_PER_RULE;
    let n = 60;
    let states: Vec<String> = (0..n).map(|i| format!("S{i}")).collect();
    let mut src = format!("states {{ A initial {} }}\n", states.join(" "));
    for s in &states {
        src.push_str(&format!(
            "rule to_{s} {{ when state == A then {s} }}\nrule back_{s} {{ when state == {s} then A }}\n"
        ));
    }
    // Runs of rules to one state, among them: never compared with each other.
    for k in 0..200 {
        src.push_str(&format!("rule again_{k} {{ when state == A then S0 }}\n"));
    }
    let c = check_source("fan.situ", &src);
    let conflicts: Vec<_> = c.diagnostics.iter().filter(|d| d.code == "E0302").collect();
    // Every `to_*` rule has at least ten partners after it (the later
    // `to_*`, and for all but `to_S0` the `again_*`): ten findings each,
    // where all pairs would be 1,770 + 59 × 200. The `back_*` rules are in
    // other states, and `to_S0` and the `again_*` rules share their target.
    assert_eq!(conflicts.len(), n * MAX_PER_RULE);
    let said =
        |d: &&&situ_grammar::diag::Diagnostic| d.help.as_deref().is_some_and(|h| h.contains("are enough to show"));
    assert_eq!(conflicts.iter().filter(said).count(), n, "the tenth finding of each rule says so");
    assert!(conflicts.iter().all(|d| !(d.message.contains("`to_S0`") && d.message.contains("`again_"))));
    assert!(conflicts.iter().all(|d| d.message.matches("`again_").count() < 2));
}
