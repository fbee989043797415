//! Pictures, as Graphviz DOT text: the state transition graph (from the
//! static checks), the wiring graph of each state and the Rete network
//! (from a bundle). `situ graph` prints them or renders them to SVG.

use crate::bundle::{AlphaNode, Behaviour, BetaKind, Check, Content, Mode, Operand, Test};
use crate::checks::transitions::Transitions;
use crate::model::Model;
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// A DOT string literal.
fn q(s: &str) -> String {
    format!("\"{}\"", s.replace('\\', "\\\\").replace('"', "\\\"").replace('\n', "\\n"))
}

/// The state transition graph: an edge `s -> t` labelled with the rules
/// that can take the state from `s` to `t`; the initial state bold, final
/// states double-bordered, states unreachable from the initial one red.
pub fn states(model: &Model, tr: &Transitions) -> String {
    let mut out = String::from("digraph states {\n  rankdir=LR;\n  node [shape=ellipse, fontname=\"Helvetica\"];\n");
    let reachable = model.initial.map(|i| tr.shortest_paths(model, i));
    for (i, s) in model.states.iter().enumerate() {
        let mut attrs = vec![format!("label={}", q(&s.name))];
        if model.initial.is_some_and(|x| x.index() == i) {
            attrs.push("penwidth=3".into());
        }
        if s.is_final {
            attrs.push("peripheries=2".into());
        }
        if reachable.as_ref().is_some_and(|r| r[i].is_none()) {
            attrs.push("color=red, fontcolor=red, style=dashed, xlabel=\"unreachable\"".into());
        }
        let _ = writeln!(out, "  {} [{}];", q(&s.name), attrs.join(", "));
    }
    let mut edges: BTreeMap<(usize, usize), Vec<&str>> = BTreeMap::new();
    for e in &tr.edges {
        let names = edges.entry((e.from.index(), e.to.index())).or_default();
        let rule = model.rules[e.rule.0 as usize].name.as_str();
        if !names.contains(&rule) {
            names.push(rule);
        }
    }
    for ((from, to), rules) in edges {
        let label = if rules.len() > 3 {
            format!("{}, … ({})", rules[..2].join(", "), rules.len())
        } else {
            rules.join(", ")
        };
        let _ =
            writeln!(out, "  {} -> {} [label={}];", q(&model.states[from].name), q(&model.states[to].name), q(&label));
    }
    out.push_str("}\n");
    out
}

/// The wiring graph of one state, or of every state as clusters: agents
/// coloured by mode, a solid edge per link; the links of FSM agents are
/// dashed and say in which FSM state they are present.
pub fn wiring(c: &Content, state: Option<u32>) -> String {
    let mut out = String::from("digraph wiring {\n  rankdir=LR;\n  node [shape=box, fontname=\"Helvetica\"];\n");
    match state {
        Some(s) => wiring_body(c, s, "", &mut out),
        None => {
            for s in 0..c.states.len() as u32 {
                let name = &c.states[s as usize].name;
                let _ = writeln!(out, "  subgraph {} {{\n  label={};", q(&format!("cluster_{name}")), q(name));
                wiring_body(c, s, &format!("{name}/"), &mut out);
                out.push_str("  }\n");
            }
        }
    }
    out.push_str("}\n");
    out
}

fn wiring_body(c: &Content, s: u32, prefix: &str, out: &mut String) {
    let id = |a: u32| q(&format!("{prefix}{}", c.agents[a as usize].name));
    for (i, a) in c.agents.iter().enumerate() {
        let (mode, function) = match &a.behaviour {
            Behaviour::Always => (Some(Mode::Running), None),
            Behaviour::Table { actions } => match &actions[s as usize] {
                Some(act) => (Some(act.mode), act.function),
                None => (Some(Mode::Sleeping), None),
            },
            Behaviour::Fsm(_) => (None, None),
        };
        let mut label = a.name.clone();
        if let Some(f) = function {
            label.push_str(&format!("\n{}()", a.functions[f as usize].name));
        }
        let style = match mode {
            Some(Mode::Running) => "style=filled, fillcolor=\"#c8e6c9\"".to_string(),
            Some(Mode::Waiting) => {
                label.push_str("\n(waiting)");
                "style=\"filled,dashed\", fillcolor=\"#fff9c4\"".into()
            }
            Some(Mode::Sleeping) => {
                label.push_str("\n(sleeping)");
                "style=\"filled,dotted\", fillcolor=\"#eeeeee\", fontcolor=\"#757575\"".into()
            }
            None => {
                label.push_str("\n(FSM)");
                "style=filled, fillcolor=\"#bbdefb\"".into()
            }
        };
        let _ = writeln!(out, "  {} [label={}, {style}];", id(i as u32), q(&label));
    }
    let w = &c.wiring[s as usize];
    for &(from, to) in &w.links {
        let _ = writeln!(out, "  {} -> {};", id(from), id(to));
    }
    for l in &w.fsm_links {
        let Behaviour::Fsm(f) = &c.agents[l.agent as usize].behaviour else { continue };
        let when = format!("{} in {}", c.agents[l.agent as usize].name, f.states[l.fsm_state as usize].name);
        let _ = writeln!(out, "  {} -> {} [style=dashed, label={}];", id(l.from), id(l.to), q(&when));
    }
}

/// The Rete network: alpha nodes (ellipses) feed beta nodes (boxes: joins,
/// and `not` nodes) as their right input (dashed); beta chains end in the
/// rules (notes).
pub fn rete(c: &Content) -> String {
    let net = &c.network;
    let mut out = String::from("digraph rete {\n  rankdir=TB;\n  node [fontname=\"Helvetica\"];\n");
    for (i, a) in net.alpha.iter().enumerate() {
        let _ = writeln!(out, "  a{i} [shape=ellipse, label={}];", q(&alpha_label(c, a)));
    }
    for (i, b) in net.beta.iter().enumerate() {
        let kind = match b.kind {
            BetaKind::Join => "join",
            BetaKind::Negative => "not",
        };
        let event = match &net.alpha[b.alpha as usize] {
            AlphaNode::Event { event, .. } => Some(*event),
            _ => None,
        };
        let mut label = kind.to_string();
        for t in &b.tests {
            if let Some(e) = event {
                label.push_str(&format!("\n{}", test_label(c, e, t)));
            }
        }
        let style = if b.kind == BetaKind::Negative { ", style=filled, fillcolor=\"#ffcdd2\"" } else { "" };
        let _ = writeln!(out, "  b{i} [shape=box, label={}{style}];", q(&label));
        let _ = writeln!(out, "  a{} -> b{i} [style=dashed];", b.alpha);
        if let Some(p) = b.parent {
            let _ = writeln!(out, "  b{p} -> b{i};");
        }
    }
    for t in &net.terminals {
        let r = &c.rules[t.rule as usize];
        let label = format!("{}\nsalience {} -> {}", r.name, r.salience, c.states[r.target as usize].name);
        let _ = writeln!(out, "  r{} [shape=note, style=filled, fillcolor=\"#c8e6c9\", label={}];", t.rule, q(&label));
        let _ = writeln!(out, "  b{} -> r{};", t.beta, t.rule);
    }
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
            let f = a
                .events
                .iter()
                .find_map(|&ev| c.events[ev as usize].fields.get(*field as usize).map(|f| (ev, f)))
                .map_or("?".to_string(), |(ev, f)| format!("{}.{}", c.events[ev as usize].name, f.name));
            f
        }
    };
    match &t.check {
        Check::Compare { op, rhs } => format!("{field} {} {}", op.symbol(), operand(rhs)),
        Check::Range { lo, hi, inclusive } => {
            format!("{field} in {}{}{}", operand(lo), if *inclusive { "..=" } else { ".." }, operand(hi))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_source;

    const SRC: &str = "states { IT initial RS RO GL final LOST }
        agent LADAR sensor { event LAOBS { distance: f64 } event LAOBN function detect table { RO => run detect() to Fusion  _ => wait detect() } }
        agent Fusion processing { function fuse table { RO => run fuse() from LADAR  _ => sleep } }
        rule go { when state == IT and LAOBN then RS }
        rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
        rule clear { when state == RO and LAOBN x3 then RS }
        rule done { when state == RS and LAOBN x9 then GL }";

    #[test]
    fn the_states_view_marks_unreachable_states() {
        let c = check_source("t.situ", SRC);
        let tr = Transitions::build(&c.model);
        let dot = states(&c.model, &tr);
        assert!(dot.contains("\"LOST\" [label=\"LOST\", color=red"), "{dot}");
        assert!(dot.contains("\"RS\" -> \"RO\" [label=\"obstacle\"]"), "{dot}");
        assert!(dot.contains("\"IT\" [label=\"IT\", penwidth=3]"), "{dot}");
        assert!(dot.contains("\"GL\" [label=\"GL\", peripheries=2]"), "{dot}");
    }

    #[test]
    fn the_wiring_view_shows_modes_and_links() {
        let c = check_source("t.situ", SRC);
        let content = crate::bundle::build(&c);
        let ro = content.state_id("RO").unwrap();
        let dot = wiring(&content, Some(ro));
        assert!(dot.contains("\"LADAR\" -> \"Fusion\";"), "{dot}");
        let rs = wiring(&content, Some(content.state_id("RS").unwrap()));
        assert!(!rs.contains("->"), "{rs}");
        assert!(rs.contains("(sleeping)") && rs.contains("(waiting)"), "{rs}");
        assert!(wiring(&content, None).contains("subgraph \"cluster_RO\""));
    }

    #[test]
    fn the_rete_view_names_tests_and_rules() {
        let c = check_source("t.situ", SRC);
        let content = crate::bundle::build(&c);
        let dot = rete(&content);
        assert!(dot.contains("LAOBS(distance < 30.0)"), "{dot}");
        assert!(dot.contains("LAOBN x3"), "{dot}");
        assert!(dot.contains("obstacle\\nsalience 0 -> RO"), "{dot}");
    }
}
