//! The fixes of syntax errors: each common mistake gets its message, and
//! applying its first fix gives text that parses.

use situ_grammar::diag::{Diagnostic, FileId};
use situ_grammar::parse;

/// The one syntax error of `src`.
fn error(src: &str) -> Diagnostic {
    let mut errors = parse(src, FileId(0)).errors;
    assert_eq!(errors.len(), 1, "{src}: {errors:#?}");
    errors.remove(0)
}

/// `src` with fix `n` of its error applied.
fn fixed(src: &str, n: usize) -> String {
    let d = error(src);
    let fix = d.fixes.get(n).unwrap_or_else(|| panic!("{src}: no fix {n} in {d:#?}"));
    let mut out = src.to_string();
    let mut edits: Vec<_> = fix.edits.iter().collect();
    edits.sort_by_key(|e| std::cmp::Reverse(e.span.start));
    for e in edits {
        out.replace_range(e.span.start..e.span.end, &e.text);
    }
    out
}

/// The error's message contains `message`, its first fix gives `expected`,
/// and that parses.
#[track_caller]
fn check(src: &str, message: &str, expected: &str) {
    let d = error(src);
    assert!(d.message.contains(message), "{src}: message `{}` lacks `{message}`", d.message);
    let out = fixed(src, 0);
    assert_eq!(out, expected, "{src}");
    let after = parse(&out, FileId(0)).errors;
    assert!(after.is_empty(), "{out}: {after:#?}");
}

const HEAD: &str = "agent B sensor { event BPHIT { side: {left, right} } event BPFREE event RNDRY }\n";

fn rule(body: &str) -> String {
    format!("{HEAD}rule r {{ {body} }}")
}

#[test]
fn a_rule_sets_one_state() {
    check(&rule("when BPHIT then MOWING, FAULT"), "a rule sets one state", &rule("when BPHIT then MOWING"));
    check(&rule("when BPHIT then state == RO"), "a state name", &rule("when BPHIT then RO"));
}

#[test]
fn or_in_a_rule_says_to_write_two_rules() {
    let d = error(&rule("when BPHIT or BPFREE then S"));
    assert!(d.message.contains("cannot be joined with `or`"), "{}", d.message);
    assert!(d.help.as_deref().is_some_and(|h| h.contains("two rules")));
    assert!(d.fixes.is_empty());
    check(
        &rule("when state == RS or state == RT and BPHIT then S"),
        "cannot be joined with `or`",
        &rule("when state in {RS, RT} and BPHIT then S"),
    );
}

#[test]
fn durations_and_frequencies_say_their_units() {
    check(&rule("when RNDRY within 3 then S"), "needs a unit", &rule("when RNDRY within 3s then S"));
    assert_eq!(fixed(&rule("when RNDRY within 3 then S"), 1), rule("when RNDRY within 3ms then S"));
    check("agent A sensor { stale after 200 ms }", "without a space", "agent A sensor { stale after 200ms }");
    check("agent A sensor { stale after 200\n}", "needs a unit", "agent A sensor { stale after 200ms\n}");
    check("agent A sensor { stale after 2m }", "minutes are `min`", "agent A sensor { stale after 2min }");
    check("agent A sensor { stale after 2h }", "no hours", "agent A sensor { stale after 120min }");
    check("agent A sensor { stale after 5sec }", "not a unit of time", "agent A sensor { stale after 5s }");
    check("agent A sensor { rate 10 Hz }", "without a space", "agent A sensor { rate 10Hz }");
    check("agent A sensor { rate 10hz }", "capital H", "agent A sensor { rate 10Hz }");
    check("agent A sensor { rate 10 }", "needs a unit", "agent A sensor { rate 10Hz }");
    check("agent A sensor { stale 300ms }", "expected `after`", "agent A sensor { stale after 300ms }");
    check(
        "property \"p\" { always (A -> eventually B within 3) }",
        "`3 events`",
        "property \"p\" { always (A -> eventually B within 3 events) }",
    );
}

#[test]
fn colon_and_equals_are_told_apart() {
    check(&rule("when BPHIT(side: left) then S"), "`side == left`", &rule("when BPHIT(side == left) then S"));
    check("test \"t\" { on BPHIT(side == left) }", "with `:`", "test \"t\" { on BPHIT(side: left) }");
    check("agent A sensor { event E { d == f64 } }", "declared with `:`", "agent A sensor { event E { d: f64 } }");
    check(&rule("when state = RS then S"), "write `==`", &rule("when state == RS then S"));
    check(&rule("when BPHIT(side <> left) then S"), "write `!=`", &rule("when BPHIT(side != left) then S"));
}

#[test]
fn operators_of_other_languages() {
    check(&rule("when BPHIT && BPFREE then S"), "`and`", &rule("when BPHIT and BPFREE then S"));
    check(&rule("when BPHIT, BPFREE then S"), "not `,`", &rule("when BPHIT and BPFREE then S"));
    check(&rule("when !BPHIT then S"), "`not`", &rule("when not BPHIT then S"));
    check(&rule("when BPHIT AND BPFREE then S"), "found `AND`", &rule("when BPHIT and BPFREE then S"));
    check(&rule("When BPHIT then S"), "found `When`", &rule("when BPHIT then S"));
    check("property \"p\" { never (A || B) }", "`or`", "property \"p\" { never (A or B) }");
    check("property \"p\" { always (A => B) }", "expected `->`", "property \"p\" { always (A -> B) }");
}

#[test]
fn left_out_and_doubled_words() {
    check(&rule("BPHIT then S"), "start with `when`", &rule("when BPHIT then S"));
    check(&rule("when BPHIT S"), "expected `then`", &rule("when BPHIT then S"));
    check(&rule("when BPHIT and and BPFREE then S"), "written twice", &rule("when BPHIT and BPFREE then S"));
    check(&rule("when BPHIT side == left) then S"), "expected `(`", &rule("when BPHIT (side == left) then S"));
    check("property \"p\" { A }", "`always` or `never`", "property \"p\" { always A }");
    check("agent A sensor { table { RS run f() } }", "expected `=>`", "agent A sensor { table { RS => run f() } }");
}

#[test]
fn numbers_and_run_lengths() {
    check(&rule("when BPHIT x 3 then S"), "without a space", &rule("when BPHIT x3 then S"));
    check(&rule("when BPHIT X3 then S"), "small `x`", &rule("when BPHIT x3 then S"));
    check("rule r { when E(d < 30.) then S }", "digits after", "rule r { when E(d < 30.0) then S }");
    check("rule r { when E(d < .5) then S }", "digits before", "rule r { when E(d < 0.5) then S }");
}

#[test]
fn declarations() {
    check("states { A initial, B }", "not separated by commas", "states { A initial B }");
    check("agent A { event E }", "needs a kind", "agent A sensor { event E }");
    assert_eq!(fixed("agent A { event E }", 1), "agent A actuator { event E }");
    check("agent A senso { event E }", "found `senso`", "agent A sensor { event E }");
    check("agent A sensor { event E(d: f64) }", "in braces", "agent A sensor { event E{ d: f64 } }");
    check("agent A sensor { event E { d: float } }", "`f64`", "agent A sensor { event E { d: f64 } }");
    check("agent A sensor { function f() }", "without `()`", "agent A sensor { function f }");
    check("agent A sensor { event E; }", "no `;`", "agent A sensor { event E }");
    check("agent A sensor { table { RS -> sleep } }", "expected `=>`", "agent A sensor { table { RS => sleep } }");
    check("agent A sensor { table { RS => running f() } }", "`run`", "agent A sensor { table { RS => run f() } }");
    check(
        "agent A sensor { event E fsm { X initial => sleep Y => sleep X => Y on E } }",
        "written with `->`",
        "agent A sensor { event E fsm { X initial => sleep Y => sleep X -> Y on E } }",
    );
    check("agent A sensor 'a' { }", "double quotes", "agent A sensor \"a\" { }");
    check("agent A sensor { event E", "never closed", "agent A sensor { event E }");
}

#[test]
fn tests_and_expectations() {
    check("test \"t\" { expect state == RO }", "without `==`", "test \"t\" { expect state RO }");
    check("test \"t\" { expect F runs f() }", "without `()`", "test \"t\" { expect F runs f }");
    check("test \"t\" { expect F is running }", "without `is`", "test \"t\" { expect F running }");
    check("test \"t\" { expect F run }", "found `run`", "test \"t\" { expect F running }");
    check("test \"t\" { on E at 5 }", "needs a unit", "test \"t\" { on E at 5s }");
}

#[test]
fn a_keyword_is_only_called_a_bad_name_where_a_name_belongs() {
    let d = error("agent on sensor { }");
    assert!(d.help.as_deref().is_some_and(|h| h.contains("`on` is a keyword")), "{d:#?}");
    let d = error(&rule("when BPHIT then A then B"));
    assert!(!d.help.as_deref().unwrap_or("").contains("keyword"), "{d:#?}");
}

#[test]
fn expected_lists_do_not_repeat_themselves() {
    let d = error("agent A senso { }");
    assert_eq!(
        d.message,
        "syntax error: expected an agent kind (`sensor`, `actuator`, `processing` or `interface`), found `senso`"
    );
    let d = error(&rule("when BPHIT(side: left) x then S"));
    assert!(!d.message.contains("found a space"), "{}", d.message);
}

#[test]
fn links_after_run_without_a_function_say_how_links_are_written() {
    let agent =
        |entry: &str| format!("agent F processing {{\n    function fuse\n    table {{\n        {entry}\n    }}\n}}");
    check(
        &agent("_ => run from IMU, GPS"),
        "in a table, an agent's links are written after the function it runs: `run fuse() from IMU, GPS`",
        &agent("_ => run fuse() from IMU, GPS"),
    );
    let d = error("agent F processing { table { _ => run from IMU to Drive } }");
    assert!(d.message.contains("`run f() from IMU to Drive`"), "{}", d.message);
    assert!(d.help.as_deref().is_some_and(|h| h.contains("declare one in the agent")), "{:?}", d.help);
    assert!(!d.help.as_deref().unwrap_or("").contains("keyword"), "{:?}", d.help);
    let d = error("agent F processing { function a function b fsm { S initial => run to Drive } }");
    assert!(d.message.starts_with("syntax error: in an FSM,"), "{}", d.message);
    assert_eq!(d.fixes.iter().map(|f| f.title.as_str()).collect::<Vec<_>>(), ["run `a()`", "run `b()`"]);
}

#[test]
fn a_set_of_values_on_a_field_says_how_to_write_it() {
    let d = error(&rule("when BPHIT(side in {left, right}) then S"));
    assert!(d.message.contains("cannot be tested against a set of values"), "{}", d.message);
    let help = d.help.as_deref().unwrap_or("");
    assert!(help.contains("one rule per value (`side == left`, `side == right`)"), "{help}");
    assert_eq!(
        &rule("when BPHIT(side in {left, right}) then S")[d.primary.span.start..d.primary.span.end],
        "in {left, right}"
    );
    check(&rule("when BPHIT(side in {left}) then S"), "against a set", &rule("when BPHIT(side == left) then S"));
    // The system state has a set test of its own.
    assert!(parse(&rule("when state in {A, B} and BPHIT then S"), FileId(0)).errors.is_empty());
}
