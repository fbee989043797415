//! The state transition graph: one edge per pair of states, labelled with
//! its rules; the rules that leave many states for one target (emergencies,
//! stops) drawn once, from a group node "from any of …"; initial, final,
//! unreachable, trap and dead-end states each with a fill colour and a word
//! of their own, so that every layout engine keeps the distinction.

use super::{header, legend, q};
use crate::bundle::Content;
use crate::checks::transitions::Transitions;
use crate::model::{Model, StateId};
use situ_grammar::diag::{Diagnostic, Severity};
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;

/// A rule that leaves at least this many states for one target is drawn
/// once, from a group node, instead of once per state.
const GROUP_MIN: usize = 3;

/// More rules than this on one edge: the first and a count, every rule in
/// the tooltip.
const LABEL_RULES: usize = 2;

/// What a state is, as the picture tells it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum StateKind {
    Initial,
    Final,
    /// No sequence of events leads to it from the initial state.
    Unreachable,
    /// Reachable, not final, and no rule leads out of it.
    Trap,
    /// Reachable, with a way out, but no final state can be reached from it.
    DeadEnd,
}

impl StateKind {
    /// The word in the node's label and the legend.
    pub fn word(self) -> &'static str {
        match self {
            StateKind::Initial => "initial",
            StateKind::Final => "final",
            StateKind::Unreachable => "unreachable",
            StateKind::Trap => "trap: no way out",
            StateKind::DeadEnd => "dead end: cannot finish",
        }
    }

    /// Node attributes: a fill (kept by every engine), a pen colour, and a
    /// border that Graphviz draws as well.
    fn attrs(self) -> &'static str {
        match self {
            StateKind::Initial => "style=\"rounded,filled,bold\", fillcolor=\"#c8e6c9\", color=\"#1b5e20\", penwidth=3",
            StateKind::Final => "style=\"rounded,filled\", fillcolor=\"#bbdefb\", color=\"#0d47a1\", peripheries=2",
            StateKind::Unreachable => {
                "style=\"rounded,filled,dashed\", fillcolor=\"#ffcdd2\", color=\"#b71c1c\", fontcolor=\"#b71c1c\", penwidth=2"
            }
            StateKind::Trap => "shape=octagon, style=filled, fillcolor=\"#ffe0b2\", color=\"#e65100\", penwidth=2",
            StateKind::DeadEnd => "style=\"rounded,filled\", fillcolor=\"#fff9c4\", color=\"#f57f17\", penwidth=2",
        }
    }
}

/// The kinds of every state (several may apply: an initial trap), in the
/// order of [`StateKind`]; the first one that is a finding styles the node.
fn kinds(model: &Model, tr: &Transitions) -> Vec<Vec<StateKind>> {
    let n = model.states.len();
    let reachable: Vec<bool> = match model.initial {
        Some(i) => tr.shortest_paths(model, i).iter().map(Option::is_some).collect(),
        // No initial state (an error, reported): reachability is unknown.
        None => vec![true; n],
    };
    let finals: Vec<usize> = (0..n).filter(|&s| model.states[s].is_final).collect();
    let mut ends = vec![false; n];
    let mut stack = finals.clone();
    for &f in &finals {
        ends[f] = true;
    }
    while let Some(s) = stack.pop() {
        for e in tr.edges.iter().filter(|e| e.to.index() == s) {
            if !ends[e.from.index()] {
                ends[e.from.index()] = true;
                stack.push(e.from.index());
            }
        }
    }
    (0..n)
        .map(|s| {
            let mut k = Vec::new();
            if model.initial.is_some_and(|i| i.index() == s) {
                k.push(StateKind::Initial);
            }
            let st = &model.states[s];
            if st.is_final {
                k.push(StateKind::Final);
            }
            if !reachable[s] {
                k.push(StateKind::Unreachable);
            } else if !st.is_final {
                if !tr.edges.iter().any(|e| e.from.index() == s) {
                    k.push(StateKind::Trap);
                } else if !finals.is_empty() && !ends[s] {
                    k.push(StateKind::DeadEnd);
                }
            }
            k
        })
        .collect()
}

/// The state transition graph of `model` as DOT, titled `title`; the
/// findings of the check (`diagnostics`) are counted in the caption: with
/// errors, the rules that did not resolve are missing and the caption says
/// so (the picture draws what resolved).
pub fn states(model: &Model, tr: &Transitions, title: &str, diagnostics: &[Diagnostic]) -> String {
    let visible = || diagnostics.iter().filter(|d| !d.allowed);
    let errors = visible().filter(|d| d.severity == Severity::Error).count();
    let warnings = visible().filter(|d| d.severity == Severity::Warning).count();
    let mut caption = format!("{title}: {} states, {} rules", model.states.len(), model.rules.len());
    if errors > 0 || warnings > 0 {
        let _ = write!(caption, "\n{errors} error(s), {warnings} warning(s) (on standard error)");
        if errors > 0 {
            caption.push_str(": rules with errors are not drawn");
        }
    }
    let mut out = header("states", "TB", &caption);
    out.push_str(
        "  node [shape=box, style=\"rounded,filled\", fillcolor=\"#ffffff\"];\n  nodesep=0.35;\n  ranksep=0.5;\n",
    );
    let kinds = kinds(model, tr);
    let name = |s: StateId| model.states[s.index()].name.as_str();
    for (i, s) in model.states.iter().enumerate() {
        let k = &kinds[i];
        let mut label = s.name.clone();
        if !k.is_empty() {
            let words: Vec<&str> = k.iter().map(|k| k.word()).collect();
            let _ = write!(label, "\n{}", words.join(", "));
        }
        // The most telling kind styles the node: a finding before a role.
        let styled = k.last().map(|k| format!(", {}", k.attrs())).unwrap_or_default();
        let tooltip = s.description.as_deref().unwrap_or(&s.name);
        let _ = writeln!(out, "  {} [label={}, tooltip={}{styled}];", q(&s.name), q(&label), q(tooltip));
    }

    // Every possible firing, by rule: the states it leaves.
    let mut from_by_rule: BTreeMap<usize, BTreeSet<StateId>> = BTreeMap::new();
    for e in &tr.edges {
        from_by_rule.entry(e.rule.index()).or_default().insert(e.from);
    }
    // Rules that leave many states: one edge from a group node per (group, target).
    let mut groups: BTreeMap<(Vec<StateId>, StateId), Vec<usize>> = BTreeMap::new();
    let mut pairs: BTreeMap<(StateId, StateId), Vec<usize>> = BTreeMap::new();
    for (&rule, from) in &from_by_rule {
        let target = model.rules[rule].target;
        if from.len() >= GROUP_MIN {
            groups.entry((from.iter().copied().collect(), target)).or_default().push(rule);
        } else {
            for &f in from {
                pairs.entry((f, target)).or_default().push(rule);
            }
        }
    }
    let group_id = |g: &[StateId]| {
        let names: Vec<&str> = g.iter().map(|&s| name(s)).collect();
        format!("any:{}", names.join(","))
    };
    let drawn: BTreeSet<&Vec<StateId>> = groups.keys().map(|(g, _)| g).collect();
    for g in drawn {
        let rest: Vec<&str> =
            model.state_ids().filter(|s| !g.contains(s)).map(|s| model.states[s.index()].name.as_str()).collect();
        let label = if rest.len() * 3 <= g.len() {
            format!("from any state but\n{}", wrap(&rest))
        } else {
            let names: Vec<&str> = g.iter().map(|&s| name(s)).collect();
            format!("from any of\n{}", wrap(&names))
        };
        let _ = writeln!(
            out,
            "  {} [label={}, shape=box, style=\"rounded,filled,dashed\", fillcolor=\"#eeeeee\", color=\"#616161\", fontsize=12];",
            q(&group_id(g)),
            q(&label)
        );
    }
    let rules_label = |rules: &[usize]| {
        let names: Vec<&str> = rules.iter().map(|&r| model.rules[r].name.as_str()).collect();
        let label = if names.len() > LABEL_RULES {
            format!("{}\n+ {} more", names[0], names.len() - 1)
        } else {
            names.join("\n")
        };
        (label, names.join(", "))
    };
    for ((from, to), rules) in &pairs {
        let (label, all) = rules_label(rules);
        let _ = writeln!(out, "  {} -> {} [label={}, tooltip={}];", q(name(*from)), q(name(*to)), q(&label), q(&all));
    }
    for ((g, to), rules) in &groups {
        let (label, all) = rules_label(rules);
        let _ = writeln!(
            out,
            "  {} -> {} [label={}, tooltip={}, penwidth=2, color=\"#616161\"];",
            q(&group_id(g)),
            q(name(*to)),
            q(&label),
            q(&all)
        );
    }

    // The legend: the kinds drawn, and the group node if there is one.
    let mut present: BTreeSet<StateKind> = BTreeSet::new();
    for k in &kinds {
        present.extend(k.iter().copied());
    }
    let mut entries: Vec<(String, String)> =
        present.iter().map(|k| (k.word().to_string(), k.attrs().to_string())).collect();
    if !groups.is_empty() {
        entries.push((
            "rules that leave\nevery state listed".into(),
            "shape=box, style=\"rounded,filled,dashed\", fillcolor=\"#eeeeee\", color=\"#616161\", fontsize=12".into(),
        ));
    }
    legend(&mut out, &entries);
    out.push_str("}\n");
    out
}

/// State names, four to a line.
fn wrap(names: &[&str]) -> String {
    names.chunks(4).map(|c| c.join(" ")).collect::<Vec<_>>().join("\n")
}

/// The states of a bundle whose source is not at hand (the transitions
/// need the static checks), with the changes `edges` (from, to) of a
/// recording as edges, each pair once, in the order first seen.
pub fn bundle_states<'a>(c: &Content, edges: impl IntoIterator<Item = (&'a str, &'a str)>) -> String {
    let text = |s: &str| s.replace('\\', "\\\\").replace('"', "\\\"");
    let mut edges = edges.into_iter().peekable();
    let mut out =
        String::from("digraph states {\n  node [shape=box, style=\"rounded,filled\", fillcolor=\"#ffffff\"];\n");
    let caption = if edges.peek().is_none() { "" } else { "; edges: the changes recorded" };
    let _ = writeln!(
        out,
        "  label=\"{}: {} states (the transitions need the .situ source{caption})\";\n  labelloc=t;",
        text(&c.source),
        c.states.len()
    );
    for (i, s) in c.states.iter().enumerate() {
        let extra = if i == c.initial as usize {
            ", fillcolor=\"#c8e6c9\", penwidth=3"
        } else if s.is_final {
            ", fillcolor=\"#bbdefb\", peripheries=2"
        } else {
            ""
        };
        let _ = writeln!(out, "  \"{}\" [label=\"{}\"{extra}];", text(&s.name), text(&s.name));
    }
    let mut seen = BTreeSet::new();
    for (from, to) in edges {
        if seen.insert((from, to)) {
            let _ = writeln!(out, "  \"{}\" -> \"{}\";", text(from), text(to));
        }
    }
    out.push_str("}\n");
    out
}
