//! The Rete network, one row per rule: each rule's chain of beta nodes
//! (joins and `not` nodes, each labelled with its alpha memory and its
//! tests) runs left to right to the rule, and the rules stand in one column
//! on the right. Shared beta nodes (a chain prefix used by several rules)
//! are where rows branch, filled blue; an alpha memory feeding several
//! nodes is named `αN` wherever it is used, so sharing stays visible
//! without an edge across the page for every use.

use super::{header, legend, q};
use crate::bundle::{AlphaNode, BetaKind, Check, Content, Operand, Test};
use std::fmt::Write as _;

const JOIN: &str = "shape=box, style=filled, fillcolor=\"#ffffff\"";
const NOT: &str = "shape=box, style=filled, fillcolor=\"#ffcdd2\", color=\"#b71c1c\"";
const SHARED: &str = "style=\"filled,bold\", penwidth=2, color=\"#0d47a1\"";
const RULE: &str = "shape=note, style=filled, fillcolor=\"#c8e6c9\"";

/// The Rete network of `c` as DOT, titled with `name`.
pub fn rete(c: &Content, name: &str) -> String {
    let net = &c.network;
    let st = &net.stats;
    let title = format!(
        "Rete network of {name}: {} rules, {} alpha and {} beta nodes ({} and {} without sharing)",
        st.terminals, st.alpha, st.beta, st.alpha_unshared, st.beta_unshared
    );
    let mut out = header("rete", "LR", &title);
    out.push_str("  node [fontsize=12, height=0.3];\n  nodesep=0.08;\n  ranksep=0.25;\n");
    let mut alpha_uses = vec![0usize; net.alpha.len()];
    let mut successors = vec![0usize; net.beta.len()];
    for b in &net.beta {
        alpha_uses[b.alpha as usize] += 1;
        if let Some(p) = b.parent {
            successors[p as usize] += 1;
        }
    }
    for t in &net.terminals {
        successors[t.beta as usize] += 1;
    }
    for (i, b) in net.beta.iter().enumerate() {
        let a = &net.alpha[b.alpha as usize];
        let mut label = match b.kind {
            BetaKind::Join => String::new(),
            BetaKind::Negative => "not ".into(),
        };
        if alpha_uses[b.alpha as usize] > 1 {
            let _ = write!(label, "α{} ", b.alpha);
        }
        label.push_str(&alpha_label(c, a));
        let event = match a {
            AlphaNode::Event { event, .. } => Some(*event),
            _ => None,
        };
        if let Some(e) = event {
            let tests: Vec<String> = b.tests.iter().map(|t| test_label(c, e, t)).collect();
            if !tests.is_empty() {
                let _ = write!(label, " [{}]", tests.join(", "));
            }
        }
        let mut style = if b.kind == BetaKind::Negative { NOT.to_string() } else { JOIN.to_string() };
        if successors[i] > 1 {
            style = format!("{style}, fillcolor=\"#bbdefb\", {SHARED}");
        }
        let _ = writeln!(out, "  b{i} [label={}, {style}];", q(&label));
        if let Some(p) = b.parent {
            let _ = writeln!(out, "  b{p} -> b{i};");
        }
    }
    out.push_str("  { rank=sink;\n");
    for t in &net.terminals {
        let r = &c.rules[t.rule as usize];
        let label = format!("{} → {}  (salience {})", r.name, c.states[r.target as usize].name, r.salience);
        let _ = writeln!(out, "    r{} [label={}, {RULE}];", t.rule, q(&label));
    }
    out.push_str("  }\n");
    for t in &net.terminals {
        let _ = writeln!(out, "  b{} -> r{};", t.beta, t.rule);
    }
    legend(
        &mut out,
        &[
            ("join: memory [tests]".into(), JOIN.into()),
            ("not: memory [tests]".into(), NOT.into()),
            ("shared by several rules".into(), format!("shape=box, fillcolor=\"#bbdefb\", {SHARED}")),
            ("αN: one alpha memory\nused by several nodes".into(), JOIN.into()),
            ("rule → target".into(), RULE.into()),
        ],
    );
    out.push_str("}\n");
    out
}

fn alpha_label(c: &Content, a: &AlphaNode) -> String {
    match a {
        AlphaNode::State { states } => {
            let names: Vec<&str> = states.iter().map(|&s| c.states[s as usize].name.as_str()).collect();
            format!("state in {{{}}}", names.join(", "))
        }
        AlphaNode::Stale { agent } => format!("stale {}", c.agents[*agent as usize].name),
        AlphaNode::Event { event, tests, min_run, within_ns } => {
            let e = &c.events[*event as usize];
            let mut s = e.name.clone();
            if !tests.is_empty() {
                let t: Vec<String> = tests.iter().map(|t| test_label(c, *event, t)).collect();
                s.push_str(&format!("({})", t.join(", ")));
            }
            if *min_run > 1 {
                s.push_str(&format!(" x{min_run}"));
            }
            if let Some(w) = within_ns {
                s.push_str(&format!(" within {}ms", w / 1_000_000));
            }
            s
        }
    }
}

fn test_label(c: &Content, event: u32, t: &Test) -> String {
    let e = &c.events[event as usize];
    let field = e.fields.get(t.field as usize).map_or("?", |f| f.name.as_str());
    let ty = e.fields.get(t.field as usize).map(|f| &f.ty);
    let operand = |o: &Operand| match o {
        Operand::Value(v) => match (ty, v) {
            (Some(crate::bundle::FieldType::Symbols(s)), crate::bundle::Value::Symbol(i)) => {
                s.get(*i as usize).cloned().unwrap_or_default()
            }
            (_, crate::bundle::Value::F64(f)) => format!("{f:?}"),
            (_, crate::bundle::Value::I64(i)) => i.to_string(),
            (_, crate::bundle::Value::Bool(b)) => b.to_string(),
            (_, crate::bundle::Value::Symbol(i)) => format!("#{i}"),
        },
        Operand::Own { field } => e.fields.get(*field as usize).map_or("?".into(), |f| f.name.clone()),
        Operand::Fact { agent, field } => {
            // The field of the agent's fact, named by the first event of the agent that has it.
            let a = &c.agents[*agent as usize];
            a.events
                .iter()
                .find_map(|&ev| c.events[ev as usize].fields.get(*field as usize).map(|f| (ev, f)))
                .map_or("?".to_string(), |(ev, f)| format!("{}.{}", c.events[ev as usize].name, f.name))
        }
    };
    match &t.check {
        Check::Compare { op, rhs } => format!("{field} {} {}", op.symbol(), operand(rhs)),
        Check::Range { lo, hi, inclusive } => {
            format!("{field} in {}{}{}", operand(lo), if *inclusive { "..=" } else { ".." }, operand(hi))
        }
    }
}
