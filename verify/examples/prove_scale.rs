//! How far the unbounded checker goes: a generated patrol robot with N
//! range sensors (N + 3 agents, 3N + 4 rules, N + 5 states), its four
//! properties proved by IC3 for runs of any length, timed.
//!
//!   cargo run --release -p situ-verify --example prove_scale -- 2 4 8 16 24
//!
//! Each line: sensors, rules, latches, and-gates, the time to build the
//! circuit and to prove every property (seconds), and the verdicts.

use situ_compiler::{bundle, spec};
use situ_verify::abstraction::Alphabet;
use situ_verify::model::Model;
use situ_verify::{prove, Verdict};
use std::fmt::Write as _;
use std::sync::Arc;
use std::time::Instant;

/// The rules of a patrol over `n` legs, one range sensor per leg.
fn patrol(n: usize) -> String {
    let legs: Vec<String> = (0..n).map(|i| format!("P{i}")).collect();
    let all = legs.join(", ");
    let mut s = String::new();
    let _ = writeln!(s, "states {{ Idle initial {} Avoid EM SP final }}", legs.join(" "));
    let _ = writeln!(s, "agent Tc interface {{ stale after 1s event HB event STOP }}");
    let _ = writeln!(s, "agent Nav processing {{ event WP {{ leg: i64 }} }}");
    let _ = writeln!(s, "agent Drive actuator {{ function go table {{ {all} => run go()  _ => sleep }} }}");
    for i in 0..n {
        let _ = writeln!(
            s,
            "agent S{i} sensor {{ stale after {}ms event OBS{i} {{ distance: f64 }} event CLR{i} }}",
            200 + 100 * i
        );
    }
    let _ = writeln!(s, "rule start {{ when state == Idle and HB then P0 }}");
    for i in 0..n {
        let _ = writeln!(s, "rule leg{i} {{ when state == P{i} and WP(leg == {i}) then P{} }}", (i + 1) % n);
        let _ = writeln!(
            s,
            "rule avoid{i} salience 50 {{ when state in {{{all}}} and OBS{i}(distance < 5.0) then Avoid }}"
        );
        let _ = writeln!(s, "rule silent{i} salience 90 {{ when state in {{{all}, Avoid}} and stale S{i} then EM }}");
    }
    let clear: Vec<String> = (0..n).map(|i| format!("not OBS{i}(distance < 5.0)")).collect();
    let _ = writeln!(s, "rule resume salience 40 {{ when state == Avoid and HB and {} then P0 }}", clear.join(" and "));
    let _ = writeln!(s, "rule estop salience 100 {{ when state in {{Idle, {all}, Avoid}} and STOP then EM }}");
    let _ = writeln!(s, "rule stop {{ when state == EM and STOP then SP }}");
    let _ = writeln!(s, "property \"a stop is final\" {{ always (state == SP -> next state == SP) }}");
    let _ = writeln!(
        s,
        "property \"an emergency is left only to stop\" {{ always (state == EM -> next state in {{EM, SP}}) }}"
    );
    let _ = writeln!(s, "property \"a silent sensor never patrols\" {{ never (stale S0 and state in {{{all}}}) }}");
    let _ = writeln!(s, "property \"Drive runs only on patrol\" {{ always (Drive running -> state in {{{all}}}) }}");
    s
}

fn main() {
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let sizes = if sizes.is_empty() { vec![2, 4, 8] } else { sizes };
    println!("sensors  rules  latches  gates  build_s  prove_s  verdicts");
    for n in sizes {
        let text = patrol(n);
        let checked = situ_compiler::check_source("patrol.situ", &text);
        let errors: Vec<_> = checked.diagnostics.iter().filter(|d| d.code.starts_with('E')).collect();
        if !errors.is_empty() {
            eprintln!("patrol({n}) has errors: {errors:?}\n{text}");
            std::process::exit(1);
        }
        let content = Arc::new(bundle::build(&checked));
        let spec = spec::lower(&checked);
        let props: Vec<_> = spec.properties.iter().collect();
        let start = Instant::now();
        let alphabet = std::sync::Arc::new(Alphabet::new(&content, &props));
        let model = match Model::build(&content, &alphabet, &props) {
            Ok(m) => m,
            Err(why) => {
                println!("{n:>7}  no circuit: {}", why.0);
                continue;
            }
        };
        let built = start.elapsed().as_secs_f64();
        let start = Instant::now();
        let verdicts: Vec<&str> = props
            .iter()
            .enumerate()
            .map(|(i, p)| {
                match prove::prove(
                    &content,
                    &alphabet,
                    &model,
                    i,
                    p,
                    situ_verify::ic3::Limits::frames(prove::MAX_FRAMES),
                ) {
                    Some(Verdict::Inductive { sampled: None, .. }) => "proved",
                    Some(Verdict::Inductive { .. }) => "exhausted",
                    Some(Verdict::Failed(_)) => "FAILED",
                    _ => "unknown",
                }
            })
            .collect();
        println!(
            "{n:>7}  {:>5}  {:>7}  {:>5}  {built:>7.2}  {:>7.2}  {}",
            content.rules.len(),
            model.aig.latches().len(),
            model.aig.len() - 1 - model.aig.latches().len() - model.aig.inputs().len(),
            start.elapsed().as_secs_f64(),
            verdicts.join(" ")
        );
    }
}
