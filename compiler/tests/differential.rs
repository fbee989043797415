//! Differential test of the static checks: random small rule sets are
//! checked, and what the checker says about conflicts (E0302: a memory that
//! activates both rules and no rule of higher salience) and reachability
//! (E0301) is compared with a brute-force enumeration of every
//! working memory over a domain that covers every interval the rules' constants
//! cut (and NaN). They must agree exactly. Positive patterns may bind the
//! variable `?x` to their `d`: bound twice in a rule, it is an equality
//! (which NaN never satisfies), decided exactly too.

use proptest::prelude::*;
use situ_compiler::check_source;
use std::collections::BTreeSet;

const STATES: [&str; 4] = ["IT", "RS", "RO", "EM"];
/// Agent -> its events; every event has one f64 field `d`, except `N*`.
const AGENTS: [(&str, [&str; 2]); 2] = [("LADAR", ["LAOBS", "LAOBN"]), ("STCCD", ["STOBS", "STOBN"])];
const CONSTS: [f64; 2] = [10.0, 30.0];

#[derive(Debug, Clone)]
struct Cond {
    event: usize,                // index into all events (agent = event / 2)
    cmp: Option<(usize, usize)>, // (operator, constant) for `d`, only for `*OBS`
    run: u64,
    negated: bool,
    /// `d: ?x` (only on positive patterns with a field).
    bind: bool,
}

#[derive(Debug, Clone)]
struct Rule {
    guard: Option<BTreeSet<usize>>,
    conds: Vec<Cond>,
    target: usize,
    salience: i64,
}

const OPS: [&str; 6] = ["<", "<=", ">", ">=", "==", "!="];

fn event_name(e: usize) -> &'static str {
    AGENTS[e / 2].1[e % 2]
}

fn has_field(e: usize) -> bool {
    e.is_multiple_of(2)
}

fn cond() -> impl Strategy<Value = Cond> {
    (0..4usize, 0..6usize, 0..2usize, 1..3u64, prop::bool::weighted(0.3), prop::bool::weighted(0.4)).prop_map(
        |(event, op, c, run, negated, bind)| Cond {
            event,
            cmp: has_field(event).then_some((op, c)),
            run,
            negated,
            bind: bind && has_field(event) && !negated,
        },
    )
}

fn rule() -> impl Strategy<Value = Rule> {
    (
        prop::option::weighted(0.7, prop::collection::btree_set(0..4usize, 1..3)),
        prop::collection::vec(cond(), 1..3),
        0..4usize,
        prop::sample::select(vec![0i64, 0, 0, 1]),
    )
        .prop_map(|(guard, conds, target, salience)| Rule { guard, conds, target, salience })
}

fn source(rules: &[Rule]) -> String {
    let mut s = String::from("states { IT initial RS RO EM }\n");
    for (agent, events) in AGENTS {
        s.push_str(&format!("agent {agent} sensor {{ event {} {{ d: f64 }} event {} }}\n", events[0], events[1]));
    }
    for (i, r) in rules.iter().enumerate() {
        let mut parts = Vec::new();
        if let Some(g) = &r.guard {
            let names: Vec<&str> = g.iter().map(|&x| STATES[x]).collect();
            parts.push(format!("state in {{{}}}", names.join(", ")));
        }
        for c in &r.conds {
            let mut p = event_name(c.event).to_string();
            if let Some((op, k)) = c.cmp {
                let bind = if c.bind { "d: ?x, " } else { "" };
                p.push_str(&format!("({bind}d {} {:.1})", OPS[op], CONSTS[k]));
            }
            if c.run > 1 {
                p.push_str(&format!(" x{}", c.run));
            }
            parts.push(if c.negated { format!("not {p}") } else { p });
        }
        s.push_str(&format!(
            "rule r{i} salience {} {{ when {} then {} }}\n",
            r.salience,
            parts.join(" and "),
            STATES[r.target]
        ));
    }
    s
}

/// One agent's latest fact: (event, d, run), or none.
type Fact = Option<(usize, f64, u64)>;

fn values() -> Vec<f64> {
    let mut v = vec![f64::NAN, -1.0, 100.0];
    for c in CONSTS {
        v.extend([c - 0.5, c, c + 0.5]);
    }
    v
}

fn facts(agent: usize) -> Vec<Fact> {
    let mut out = vec![None];
    for e in [agent * 2, agent * 2 + 1] {
        for run in 1..=3 {
            if has_field(e) {
                out.extend(values().into_iter().map(|d| Some((e, d, run))));
            } else {
                out.push(Some((e, 0.0, run)));
            }
        }
    }
    out
}

fn compare(d: f64, op: usize, k: f64) -> bool {
    match op {
        0 => d < k,
        1 => d <= k,
        2 => d > k,
        3 => d >= k,
        4 => d == k,
        _ => !d.is_nan() && d != k, // NaN satisfies no comparison, not even `!=`
    }
}

fn holds(r: &Rule, state: usize, memory: &[Fact; 2]) -> bool {
    if r.guard.as_ref().is_some_and(|g| !g.contains(&state)) || r.target == state {
        return false;
    }
    let each = r.conds.iter().all(|c| {
        let matches = match memory[c.event / 2] {
            Some((e, d, run)) => e == c.event && run >= c.run && c.cmp.is_none_or(|(op, k)| compare(d, op, CONSTS[k])),
            None => false,
        };
        matches != c.negated
    });
    // Every binding of `?x` after the first must equal it (`==`: never NaN).
    let bound: Vec<f64> =
        r.conds.iter().filter(|c| c.bind).filter_map(|c| memory[c.event / 2].map(|(_, d, _)| d)).collect();
    each && (bound.len() < 2 || bound.iter().all(|d| *d == bound[0]))
}

fn memories() -> Vec<[Fact; 2]> {
    let mut out = Vec::new();
    for a in facts(0) {
        for b in facts(1) {
            out.push([a, b]);
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn conflicts_and_reachability_match_brute_force(rules in prop::collection::vec(rule(), 2..7)) {
        let src = source(&rules);
        let checked = check_source("gen.situ", &src);
        let front_end: Vec<_> = checked.diagnostics.iter().filter(|d| d.code < "E0300").collect();
        prop_assert!(front_end.is_empty(), "{src}\n{front_end:?}");
        let memories = memories();

        // Conflicts: same salience, different targets, one memory and state
        // activating both and no rule of higher salience (which would fire
        // first and mask them).
        let mut expected = BTreeSet::new();
        for i in 0..rules.len() {
            for j in i + 1..rules.len() {
                let (a, b) = (&rules[i], &rules[j]);
                if a.salience != b.salience || a.target == b.target {
                    continue;
                }
                let masked = |s: usize, m: &[Fact; 2]| rules.iter().any(|h| h.salience > a.salience && holds(h, s, m));
                let both =
                    (0..4).any(|s| memories.iter().any(|m| holds(a, s, m) && holds(b, s, m) && !masked(s, m)));
                if both {
                    expected.insert(format!("rules `r{i}` and `r{j}` conflict"));
                }
            }
        }
        let found: BTreeSet<String> =
            checked.diagnostics.iter().filter(|d| d.code == "E0302").map(|d| d.message.clone()).collect();
        prop_assert_eq!(&found, &expected, "{}", src);

        // Reachability: an edge s -> t when some memory activates a rule to t in s.
        let mut reached = BTreeSet::from([0usize]);
        let mut frontier = vec![0usize];
        while let Some(s) = frontier.pop() {
            for r in &rules {
                if !reached.contains(&r.target) && memories.iter().any(|m| holds(r, s, m)) {
                    reached.insert(r.target);
                    frontier.push(r.target);
                }
            }
        }
        let expected: BTreeSet<String> = (0..4)
            .filter(|s| !reached.contains(s))
            .map(|s| format!("state `{}` is unreachable from `IT`", STATES[s]))
            .collect();
        let found: BTreeSet<String> =
            checked.diagnostics.iter().filter(|d| d.code == "E0301").map(|d| d.message.clone()).collect();
        prop_assert_eq!(&found, &expected, "{}", src);
    }
}
