//! The explored abstraction as a Promela model, for the spin model checker
//! (`situ export --promela`): the same graph, the same properties, checked
//! by another tool.
//!
//! The model is one process that walks the abstract state graph of
//! [`Graph`]: `node` is the abstract state, each step picks one of its
//! successors nondeterministically (with the gap the edge takes), and a node
//! that was not expanded (beyond the depth or state bound) ends the run (a
//! valid end state). Per property k, the arrays `pk_p` and `pk_q` give the
//! premise and the consequent at every node.
//!
//! The properties are compiled with `-DPROP=k` (one at a time):
//! - every property but an unbounded `eventually` is the monitor of
//!   [`monitor`](super::monitor) written in Promela, run at each point, with
//!   an `assert` where the monitor reports a violation: spin's safety search
//!   (`pan` built with `-DSAFETY`) finds an assertion violation exactly when
//!   the property fails on a run of the graph;
//! - `always (P -> eventually Q)` without a bound is the LTL formula
//!   `[] (P -> <> Q)` (acceptance cycles: `pan -a`); it is exported only
//!   when the graph is closed, since spin would stutter at the unexpanded
//!   nodes.

use super::explore::Graph;
use super::monitor::{Kind, Monitor};
use situ_compiler::bundle::Content;
use situ_compiler::spec::PropertySpec;
use std::fmt::Write as _;

/// The Promela text of a graph explored for `properties`.
pub fn export(c: &Content, graph: &Graph, properties: &[&PropertySpec]) -> String {
    let n = graph.nodes.len();
    let mut out = String::new();
    let _ = writeln!(out, "/* situ export --promela: the abstraction of {} */", c.source);
    let _ = writeln!(
        out,
        "/* {} abstract states, {} edges, {}complete to {} events. */",
        n,
        graph.edges.len(),
        if graph.closed { "closed, " } else { "" },
        graph.complete_depth
    );
    for (k, p) in properties.iter().enumerate() {
        let m = Monitor::new(p);
        let kind = match (m.is_liveness() && !m.never, graph.closed) {
            (false, _) => "safety",
            (true, true) => "liveness",
            (true, false) => "skipped",
        };
        let _ = writeln!(out, "/* PROP={k} kind={kind}: {} */", p.name.replace("*/", "* /"));
    }
    let _ = writeln!(out, "#ifndef PROP\n#define PROP 0\n#endif");
    let _ = writeln!(out, "#define NODES {n}");
    // Nanoseconds in a Promela `int`: gaps beyond 2^31 - 1 ns (2.1 s) are clamped.
    let gaps: Vec<String> = graph.alphabet.gaps.iter().map(|g| (*g).min(i32::MAX as u64).to_string()).collect();
    // The tables are constant after the first steps: hidden, out of the state vector.
    let _ = writeln!(out, "hidden int gaps[{}];", gaps.len());
    let _ = writeln!(out, "hidden byte expanded[NODES];\nhidden byte error[NODES];");
    for k in 0..properties.len() {
        let _ = writeln!(out, "hidden byte p{k}_p[NODES];\nhidden byte p{k}_q[NODES];");
    }
    let _ = writeln!(out, "int node = 0;\nint next = 0;\nbyte gap = 0;");
    let _ = writeln!(out, "bit pending = 0;\nint events = 0;\nint nanos = 0;");
    // Liveness as LTL (closed graphs only).
    for (k, p) in properties.iter().enumerate() {
        let m = Monitor::new(p);
        if m.is_liveness() && !m.never && graph.closed {
            let _ = writeln!(out, "#if PROP == {k}\nltl live {{ [] (p{k}_p[node] -> <> p{k}_q[node]) }}\n#endif");
        }
    }
    // The monitor of the selected property, at each point.
    let _ = writeln!(out, "inline monitor() {{\n  d_step {{");
    let _ = writeln!(out, "    assert(error[node] == 0);");
    for (k, p) in properties.iter().enumerate() {
        let m = Monitor::new(p);
        let _ = writeln!(out, "#if PROP == {k}");
        out.push_str(&monitor_code(k, &m));
        let _ = writeln!(out, "#endif");
    }
    let _ = writeln!(out, "  }}\n}}");
    // The walk: the tables first, in d_steps short enough for spin.
    let mut init = Vec::new();
    for (i, g) in gaps.iter().enumerate() {
        init.push(format!("gaps[{i}] = {g};"));
    }
    for (id, node) in graph.nodes.iter().enumerate() {
        if node.expanded {
            init.push(format!("expanded[{id}] = 1;"));
        }
        if node.error.is_some() {
            init.push(format!("error[{id}] = 1;"));
        }
        for k in 0..properties.len() {
            let (p, q) = graph.point(id as u32, k);
            if p {
                init.push(format!("p{k}_p[{id}] = 1;"));
            }
            if q {
                init.push(format!("p{k}_q[{id}] = 1;"));
            }
        }
    }
    let _ = writeln!(out, "active proctype walk() {{");
    for chunk in init.chunks(200) {
        let _ = writeln!(out, "  d_step {{\n    {}\n  }};", chunk.join("\n    "));
    }
    let _ = writeln!(out, "  gap = 0;\n  monitor();");
    let _ = writeln!(out, "end:\n  do\n  :: expanded[node] ->\n    if");
    for (id, node) in graph.nodes.iter().enumerate() {
        if !node.expanded {
            continue;
        }
        let (s, e) = graph.succ[id];
        if s == e {
            continue;
        }
        let _ = writeln!(out, "    :: node == {id} ->\n      if");
        for edge in &graph.edges[s as usize..e as usize] {
            let _ = writeln!(out, "      :: next = {}; gap = {}", edge.to, edge.gap);
        }
        let _ = writeln!(out, "      fi");
    }
    let _ = writeln!(out, "    fi;\n    node = next;\n    monitor()\n  od\n}}");
    out
}

/// The monitor of property `k` in Promela (see [`Monitor::step`]).
fn monitor_code(k: usize, m: &Monitor) -> String {
    let (p, q) = (format!("p{k}_p[node]"), format!("p{k}_q[node]"));
    let g = "gaps[gap]";
    match (m.kind, m.never) {
        (Kind::Now, false) => format!("    assert(!({p} && !{q}));\n"),
        (Kind::Now, true) => format!("    assert(!(!{p} || {q}));\n"),
        (Kind::Next, never) => {
            let bad = if never { q.clone() } else { format!("!{q}") };
            let mut s = format!("    if\n    :: pending -> assert(!({bad}))\n    :: else -> skip\n    fi;\n");
            if never {
                s.push_str(&format!("    assert({p});\n"));
            }
            s.push_str(&format!("    pending = {p};\n"));
            s
        }
        (Kind::Eventually { events, nanos }, never) => {
            if m.is_liveness() && !never {
                return "    skip;\n".into();
            }
            let ecap = events.map_or(0, |n| n + 1);
            let ncap = nanos.map_or(0, |d| d.saturating_add(1)).min(i32::MAX as u64);
            let mut s = format!(
                "    if\n    :: pending ->\n      events = events + 1; if :: events > {ecap} -> events = {ecap} :: else -> skip fi;\n      nanos = nanos + {g}; if :: nanos > {ncap} || nanos < 0 -> nanos = {ncap} :: else -> skip fi\n    :: else -> skip\n    fi;\n"
            );
            let over_time = nanos.map_or("0".to_string(), |d| format!("nanos > {d}"));
            if !never {
                let over_events = events.map_or("0".to_string(), |n| format!("events >= {n}"));
                s.push_str(&format!(
                    "    if\n    :: pending -> assert(!({over_time})); if :: {q} -> pending = 0; events = 0; nanos = 0 :: else -> assert(!({over_events})) fi\n    :: else -> skip\n    fi;\n"
                ));
                s.push_str(&format!(
                    "    if\n    :: !pending && {p} && !{q} -> pending = 1; events = 0; nanos = 0\n    :: else -> skip\n    fi;\n"
                ));
            } else {
                let over_events = events.map_or("0".to_string(), |n| format!("events > {n}"));
                s.push_str(&format!(
                    "    if\n    :: pending && ({over_time} || {over_events}) -> pending = 0; events = 0; nanos = 0\n    :: pending -> assert(!{q})\n    :: else -> skip\n    fi;\n"
                ));
                s.push_str(&format!("    assert({p} && !{q});\n    pending = 1; events = 0; nanos = 0;\n"));
            }
            s
        }
    }
}
