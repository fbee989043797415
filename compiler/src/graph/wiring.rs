//! The wiring graph of a state: agents by mode (running green, waiting
//! yellow, sleeping grey, FSM agents blue, each also said in the label), a
//! solid edge per link, a dashed edge per link of an FSM agent with the FSM
//! state it depends on, drawn only where that FSM state can be active
//! ([`super::fsm`]). A title names the state; a legend explains the
//! colours. For every state at once: clusters in DOT ([`wiring`] with no
//! state), small multiples in SVG ([`wiring_cell`] per state, composed by
//! the command line, with [`wiring_legend`]). The wiring a run saw at one
//! moment ([`wiring_moment`]) is drawn by the same writer.

use super::fsm::all_possible;
use super::{header, legend, q};
use crate::bundle::{Behaviour, Content, FsmLink, Mode, Moment};
use std::fmt::Write as _;

const RUNNING: &str = "style=filled, fillcolor=\"#c8e6c9\", color=\"#1b5e20\"";
const WAITING: &str = "style=\"filled,dashed\", fillcolor=\"#fff9c4\", color=\"#f57f17\"";
const SLEEPING: &str = "style=\"filled,dotted\", fillcolor=\"#eeeeee\", color=\"#9e9e9e\", fontcolor=\"#616161\"";
const FSM: &str = "style=filled, fillcolor=\"#bbdefb\", color=\"#0d47a1\"";

fn state_title(c: &Content, s: u32) -> String {
    let st = &c.states[s as usize];
    match &st.description {
        Some(d) => format!("{}: {d}", st.name),
        None => st.name.clone(),
    }
}

/// The wiring graph of one state, or of every state as clusters.
pub fn wiring(c: &Content, state: Option<u32>) -> String {
    let title = match state {
        Some(s) => format!("Wiring in {}", state_title(c, s)),
        None => format!("Wiring of every state of {}", c.source),
    };
    let mut out = header("wiring", "LR", &title);
    out.push_str("  node [shape=box];\n");
    match state {
        Some(s) => body(c, s, "", false, &mut out),
        None => {
            for s in 0..c.states.len() as u32 {
                let name = &c.states[s as usize].name;
                let _ = writeln!(
                    out,
                    "  subgraph {} {{\n  label={};",
                    q(&format!("cluster_{name}")),
                    q(&state_title(c, s))
                );
                body(c, s, &format!("{name}/"), false, &mut out);
                out.push_str("  }\n");
            }
        }
    }
    legend(&mut out, &legend_entries());
    out.push_str("}\n");
    out
}

/// One state's cell of the small multiples: its title, the agents that
/// are awake and their links; the sleeping agents, and the waiting agents
/// without a link, named under the title.
pub fn wiring_cell(c: &Content, s: u32) -> String {
    let w = &c.wiring[s as usize];
    let fsm = fsm_links(c, s);
    let linked =
        |a: u32| w.links.iter().any(|&(f, t)| f == a || t == a) || fsm.iter().any(|l| l.from == a || l.to == a);
    let listed = |m: Mode| -> Vec<&str> {
        (0..c.agents.len())
            .filter(|&a| mode(c, a, s).0 == Some(m) && (m == Mode::Sleeping || !linked(a as u32)))
            .map(|a| c.agents[a].name.as_str())
            .collect()
    };
    let mut title = state_title(c, s);
    for (word, names) in [("waiting", listed(Mode::Waiting)), ("sleeping", listed(Mode::Sleeping))] {
        if !names.is_empty() {
            let _ = write!(title, "\n{word}: {}", names.join(", "));
        }
    }
    let mut out = header("wiring", "LR", &title);
    out.push_str("  node [shape=box];\n  nodesep=0.15;\n  ranksep=0.35;\n");
    body(c, s, "", true, &mut out);
    out.push_str("}\n");
    out
}

/// The wiring a run saw at one moment, drawn as [`wiring`] draws a state:
/// the same styles, title and legend (`wiring-STATE.svg` of `situ run --out`).
pub fn wiring_moment(c: &Content, m: &Moment) -> String {
    let title = format!("Wiring in {}\n{}", state_title(c, m.state), m.caption);
    let mut out = header("wiring", "LR", &title);
    out.push_str("  node [shape=box];\n");
    let id = |a: u32| q(&c.agents[a as usize].name);
    for (i, a) in c.agents.iter().enumerate() {
        let (mode, function) = m.agents.get(i).cloned().unwrap_or((Mode::Sleeping, None));
        let mut label = a.name.clone();
        if let (Some(f), false) = (&function, mode == Mode::Sleeping) {
            label.push_str(&format!("\n{f}()"));
        }
        let style = match mode {
            Mode::Running => RUNNING,
            Mode::Waiting => {
                label.push_str("\n(waiting)");
                WAITING
            }
            Mode::Sleeping => {
                label.push_str("\n(sleeping)");
                SLEEPING
            }
        };
        let _ = writeln!(out, "  {} [label={}, {style}];", id(i as u32), q(&label));
    }
    for &(from, to) in m.links {
        if (from as usize) < c.agents.len() && (to as usize) < c.agents.len() {
            let _ = writeln!(out, "  {} -> {};", id(from), id(to));
        }
    }
    let mut entries = legend_entries();
    entries.pop();
    legend(&mut out, &entries);
    out.push_str("}\n");
    out
}

/// The FSM links of state `s` whose FSM state can be active in `s`.
fn fsm_links(c: &Content, s: u32) -> Vec<&FsmLink> {
    let possible = all_possible(c);
    c.wiring[s as usize]
        .fsm_links
        .iter()
        .filter(|l| {
            possible.get(l.agent as usize).and_then(Option::as_ref).is_some_and(|p| {
                p.get(s as usize).and_then(|row| row.get(l.fsm_state as usize)).copied().unwrap_or(false)
            })
        })
        .collect()
}

/// The FSM states an FSM agent can be in during state `s`.
fn fsm_states(c: &Content, a: usize, s: u32) -> Vec<&str> {
    let Behaviour::Fsm(f) = &c.agents[a].behaviour else { return Vec::new() };
    let p = super::fsm::possible(c, a as u32, f);
    (0..f.states.len())
        .filter(|&k| p.get(s as usize).is_some_and(|row| row[k]))
        .map(|k| f.states[k].name.as_str())
        .collect()
}

/// The legend of the wiring pictures alone, for the small multiples.
pub fn wiring_legend() -> String {
    let mut out = header("legend", "LR", "");
    out.push_str("  node [shape=box];\n");
    legend(&mut out, &legend_entries());
    out.push_str("}\n");
    out
}

fn legend_entries() -> Vec<(String, String)> {
    vec![
        ("running".into(), RUNNING.into()),
        ("waiting\n(events only)".into(), WAITING.into()),
        ("sleeping".into(), SLEEPING.into()),
        ("FSM agent".into(), FSM.into()),
    ]
}

/// An agent's mode in a state (`None`: an FSM agent) and its function.
fn mode(c: &Content, a: usize, s: u32) -> (Option<Mode>, Option<u32>) {
    match &c.agents[a].behaviour {
        Behaviour::Always => (Some(Mode::Running), None),
        Behaviour::Table { actions } => match &actions[s as usize] {
            Some(act) => (Some(act.mode), act.function),
            None => (Some(Mode::Sleeping), None),
        },
        Behaviour::Fsm(_) => (None, None),
    }
}

/// `compact`: the sleeping agents, and the waiting ones without a link,
/// are left to the title.
fn body(c: &Content, s: u32, prefix: &str, compact: bool, out: &mut String) {
    let id = |a: u32| q(&format!("{prefix}{}", c.agents[a as usize].name));
    let w = &c.wiring[s as usize];
    let fsm = fsm_links(c, s);
    let linked =
        |a: u32| w.links.iter().any(|&(f, t)| f == a || t == a) || fsm.iter().any(|l| l.from == a || l.to == a);
    for (i, a) in c.agents.iter().enumerate() {
        let (mode, function) = mode(c, i, s);
        if compact && (mode == Some(Mode::Sleeping) || (mode == Some(Mode::Waiting) && !linked(i as u32))) {
            continue;
        }
        let mut label = a.name.clone();
        if let Some(f) = function {
            label.push_str(&format!("\n{}()", a.functions[f as usize].name));
        }
        let style = match mode {
            Some(Mode::Running) => RUNNING,
            Some(Mode::Waiting) => {
                label.push_str("\n(waiting)");
                WAITING
            }
            Some(Mode::Sleeping) => {
                label.push_str("\n(sleeping)");
                SLEEPING
            }
            None => {
                let _ = write!(label, "\n(FSM: {})", fsm_states(c, i, s).join(", "));
                FSM
            }
        };
        let _ = writeln!(out, "  {} [label={}, {style}];", id(i as u32), q(&label));
    }
    for &(from, to) in &w.links {
        let _ = writeln!(out, "  {} -> {};", id(from), id(to));
    }
    for l in fsm {
        let Behaviour::Fsm(f) = &c.agents[l.agent as usize].behaviour else { continue };
        let when = format!("{} in {}", c.agents[l.agent as usize].name, f.states[l.fsm_state as usize].name);
        let _ =
            writeln!(out, "  {} -> {} [style=dashed, color=\"#0d47a1\", label={}];", id(l.from), id(l.to), q(&when));
    }
}
