//! The wiring of a state as a run saw it (`wiring-STATE.svg` of `situ run
//! --out`): every agent with the mode and function it had when the state
//! first came to rest (FSMs included: what their history made of them),
//! the links of that moment, a title and a legend. Laid out here, in
//! columns by kind (sensors, processing, interfaces, actuators), so that
//! the modes' styles survive in the SVG. Deterministic.

use super::chart::esc;
use crate::organise::Organisation;
use situ_compiler::bundle::{AgentKind, Content, Mode};
use std::fmt::Write as _;

/// The organisation at one moment.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// When (ns).
    pub time: u64,
    pub state: u32,
    /// Per agent: its mode and function.
    pub agents: Vec<(Mode, Option<String>)>,
    /// The links of the moment, `(from, to)`.
    pub links: Vec<(u32, u32)>,
}

impl Snapshot {
    pub fn take(org: &Organisation, time: u64) -> Snapshot {
        let n = org.content().agents.len() as u32;
        Snapshot {
            time,
            state: org.state(),
            agents: (0..n).map(|a| (org.mode(a), org.function(a).map(str::to_string))).collect(),
            links: org.links(),
        }
    }
}

const BOX_W: f64 = 170.0;
const BOX_H: f64 = 42.0;
const COL: f64 = 250.0;
const ROW: f64 = 66.0;
const TOP: f64 = 78.0;
const LEFT: f64 = 30.0;

/// The SVG of a snapshot.
pub fn svg(content: &Content, snap: &Snapshot) -> String {
    let order = [AgentKind::Sensor, AgentKind::Processing, AgentKind::Interface, AgentKind::Actuator];
    let columns: Vec<Vec<usize>> = order
        .iter()
        .map(|k| (0..content.agents.len()).filter(|&a| content.agents[a].kind == *k).collect::<Vec<_>>())
        .filter(|c| !c.is_empty())
        .collect();
    let mut place = vec![(0.0, 0.0); content.agents.len()];
    for (c, column) in columns.iter().enumerate() {
        for (r, &a) in column.iter().enumerate() {
            place[a] = (LEFT + c as f64 * COL, TOP + r as f64 * ROW);
        }
    }
    let rows = columns.iter().map(Vec::len).max().unwrap_or(1);
    let width = (LEFT * 2.0 + (columns.len().max(1) - 1) as f64 * COL + BOX_W).max(760.0);
    let height = TOP + rows as f64 * ROW + 50.0;
    let state = &content.states[snap.state as usize];
    let mut title = state.name.clone();
    if let Some(d) = &state.description {
        title = format!("{title} — {d}");
    }
    let mut s = String::new();
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.0}" height="{height:.0}" viewBox="0 0 {width:.0} {height:.0}" font-family="sans-serif" font-size="12">"##
    );
    s.push_str(
        "<defs><marker id=\"arrow\" viewBox=\"0 0 10 10\" refX=\"10\" refY=\"5\" markerWidth=\"7\" \
         markerHeight=\"7\" orient=\"auto-start-reverse\"><path d=\"M0,0 L10,5 L0,10 z\" fill=\"#333\"/></marker>\
         </defs>\n",
    );
    let _ = writeln!(s, r##"<rect width="100%" height="100%" fill="white"/>"##);
    let _ = writeln!(s, r##"<text x="{LEFT}" y="24" font-size="15" font-weight="bold">{}</text>"##, esc(&title));
    let _ = writeln!(
        s,
        r##"<text x="{LEFT}" y="44" fill="#444">as the run first saw it, at {:.3} s (a dashed arrow: to or from an agent not running)</text>"##,
        snap.time as f64 * 1e-9
    );
    // Links first, under the boxes.
    for &(from, to) in &snap.links {
        let (Some(&(fx, fy)), Some(&(tx, ty))) = (place.get(from as usize), place.get(to as usize)) else { continue };
        let live = [from, to].iter().all(|&a| snap.agents.get(a as usize).is_some_and(|m| m.0 == Mode::Running));
        let (x1, y1, x2, y2) = if tx > fx {
            (fx + BOX_W, fy + BOX_H / 2.0, tx, ty + BOX_H / 2.0)
        } else if tx < fx {
            (fx, fy + BOX_H / 2.0, tx + BOX_W, ty + BOX_H / 2.0)
        } else {
            (fx + BOX_W, fy + BOX_H / 2.0, tx + BOX_W, ty + BOX_H / 2.0)
        };
        // Same column: an arc on the right; otherwise a gentle curve.
        let (cx, cy) = if tx == fx {
            (x1 + 40.0 + (y2 - y1).abs() * 0.15, (y1 + y2) / 2.0)
        } else {
            ((x1 + x2) / 2.0, (y1 + y2) / 2.0 - 12.0)
        };
        let style = if live { "stroke=\"#333\"" } else { "stroke=\"#999\" stroke-dasharray=\"5,4\"" };
        let _ = writeln!(
            s,
            r##"<path d="M{x1:.1},{y1:.1} Q{cx:.1},{cy:.1} {x2:.1},{y2:.1}" fill="none" {style} marker-end="url(#arrow)"><title>{} → {}</title></path>"##,
            esc(&content.agents[from as usize].name),
            esc(&content.agents[to as usize].name)
        );
    }
    for (a, def) in content.agents.iter().enumerate() {
        let (x, y) = place[a];
        let (mode, function) = snap.agents.get(a).cloned().unwrap_or((Mode::Sleeping, None));
        let (fill, stroke) = match mode {
            Mode::Running => ("fill=\"#c7e9c0\"", "stroke=\"#333\""),
            Mode::Waiting => ("fill=\"#fff2b3\"", "stroke=\"#333\" stroke-dasharray=\"6,3\""),
            Mode::Sleeping => ("fill=\"#f4f4f4\"", "stroke=\"#aaa\" stroke-dasharray=\"2,3\""),
        };
        let what = match (mode, &function) {
            (Mode::Sleeping, _) => "sleeping".to_string(),
            (m, Some(f)) => format!("{} {f}()", m.adjective()),
            (m, None) => m.adjective().to_string(),
        };
        let _ = writeln!(
            s,
            r##"<g><title>{} ({:?}): {what}</title><rect x="{x:.1}" y="{y:.1}" width="{BOX_W}" height="{BOX_H}" rx="4" {fill} {stroke}/><text x="{:.1}" y="{:.1}" text-anchor="middle" font-weight="bold">{}</text><text x="{:.1}" y="{:.1}" text-anchor="middle" fill="#333">{}</text></g>"##,
            esc(&def.name),
            def.kind,
            x + BOX_W / 2.0,
            y + 17.0,
            esc(&def.name),
            x + BOX_W / 2.0,
            y + 33.0,
            esc(&what)
        );
    }
    // The legend.
    let ly = height - 26.0;
    let legend = [
        ("fill=\"#c7e9c0\" stroke=\"#333\"", "running"),
        ("fill=\"#fff2b3\" stroke=\"#333\" stroke-dasharray=\"6,3\"", "waiting (reports events, sends nothing)"),
        ("fill=\"#f4f4f4\" stroke=\"#aaa\" stroke-dasharray=\"2,3\"", "sleeping"),
    ];
    let mut lx = LEFT;
    for (style, text) in legend {
        let _ = writeln!(
            s,
            r##"<rect x="{lx:.1}" y="{:.1}" width="22" height="14" {style}/><text x="{:.1}" y="{ly:.1}">{text}</text>"##,
            ly - 11.0,
            lx + 28.0
        );
        lx += 40.0 + 7.0 * text.len() as f64;
    }
    s.push_str("</svg>\n");
    s
}
