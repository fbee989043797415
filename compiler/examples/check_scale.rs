//! How `check` scales with the number of rules: generates rule sets of
//! 100, 1,000 and 10,000 rules over 50 agents and 40 states and times a full
//! check (parse, resolve, every static check). Run it in release:
//! `cargo run --release -p situ-compiler --example check_scale [-- SIZES...]`.
//!
//! The rules are built like a real rule base grown large: each state has
//! rules on several agents' events, with payload ranges that partition the
//! readings, saliences in bands, and exits that keep every state reachable.
//! Saliences come in bands per agent; the checker still has to prove, for
//! every pair of rules that share a state, that they cannot conflict and
//! that neither shadows the other.

use std::fmt::Write as _;
use std::time::Instant;

const STATES: usize = 40;
const AGENTS: usize = 50;

fn generate(rules: usize) -> String {
    let mut s = String::from("states {\n    S0 initial\n");
    for i in 1..STATES {
        let _ = writeln!(s, "    S{i}{}", if i == STATES - 1 { " final" } else { "" });
    }
    s.push_str("}\n");
    for a in 0..AGENTS {
        let _ = writeln!(
            s,
            "agent A{a} sensor {{ stale after 500ms event E{a}a {{ d: f64, side: {{left, right}} }} event E{a}b {{ n: i64 }} }}"
        );
    }
    // Rule i: in state i % STATES, on agent (i / STATES) % AGENTS; the band
    // of the range is i / (STATES * AGENTS), so rules sharing a state and an
    // event have disjoint ranges.
    for i in 0..rules {
        let state = i % STATES;
        let agent = (i / STATES) % AGENTS;
        let band = i / (STATES * AGENTS);
        let target = (state + 1 + (i / STATES) % 3) % STATES;
        // Rules of one state on different agents can hold together, so each
        // agent has its own salience band: no conflicts, many pairs to prove.
        let salience = agent;
        let lo = band as f64 * 10.0;
        let cond = match (i / STATES) % 3 {
            0 => format!(
                "E{agent}a(d in {lo:.1}..{:.1}, side == left) and not stale A{}",
                lo + 10.0,
                (agent + 7) % AGENTS
            ),
            1 => format!("E{agent}a(d in {lo:.1}..{:.1}, side == right) x2", lo + 10.0),
            _ => format!("E{agent}a(d in {lo:.1}..{:.1}) and not E{}b(n > 3)", lo + 10.0, (agent + 1) % AGENTS),
        };
        let _ = writeln!(s, "rule r{i} salience {salience} {{ when state == S{state} and {cond} then S{target} }}");
    }
    s
}

fn main() {
    let sizes: Vec<usize> = std::env::args().skip(1).filter_map(|a| a.parse().ok()).collect();
    let sizes = if sizes.is_empty() { vec![100, 1_000, 10_000] } else { sizes };
    let mut results = Vec::new();
    for n in sizes {
        let src = generate(n);
        let start = Instant::now();
        let checked = situ_compiler::check_source("scale.situ", &src);
        let elapsed = start.elapsed();
        let findings = checked.visible().count();
        let mut codes: Vec<&str> = checked.visible().map(|d| d.code).collect();
        codes.dedup();
        println!(
            "{n:>6} rules, {:>7} bytes: check {:>9.1} ms, {findings} findings {codes:?}",
            src.len(),
            elapsed.as_secs_f64() * 1e3
        );
        results.push((n, elapsed.as_secs_f64()));
    }
    for w in results.windows(2) {
        println!("{} -> {} rules: {:.1}x the time", w[0].0, w[1].0, w[1].1 / w[0].1);
    }
}
