//! `timeline.svg` of a run: the paper's Fig. 5 as a time chart. A band for
//! the system state, then one band per agent showing its mode (running:
//! filled, waiting: hatched, sleeping: empty and dotted) and its function
//! over time, so that who slept, woke and changed function when reads at a
//! glance. Every segment has a tooltip. Deterministic: the same run gives
//! the same bytes.

use super::report::Tracked;
use situ_bundle::{Content, Mode};
use std::fmt::Write as _;

const WIDTH: f64 = 1200.0;
const LEFT: f64 = 150.0;
const RIGHT: f64 = 20.0;
const TOP: f64 = 56.0;
const BAND: f64 = 26.0;
const GAP: f64 = 6.0;
/// The narrowest a visited state or an agent's stretch is drawn, however
/// short it was, so that nothing the run went through is invisible.
pub const MIN_WIDTH: f64 = 4.0;
/// A row of the labels moved above the state band.
const CALLOUT: f64 = 15.0;

/// A colour per index, readable with black text.
const PALETTE: [&str; 10] =
    ["#8dd3c7", "#fdb462", "#bebada", "#fb8072", "#80b1d3", "#b3de69", "#fccde5", "#ffffb3", "#bc80bd", "#ccebc5"];

/// The chart of a run of `end` nanoseconds.
pub fn timeline_svg(content: &Content, tracked: &Tracked, end: u64, title: &str) -> String {
    let end = end.max(1);
    let rows = content.agents.len() + 1;
    let x = |t: u64| LEFT + (t.min(end) as f64 / end as f64) * (WIDTH - LEFT - RIGHT);
    let mut changes: Vec<(u64, u32)> = vec![(0, content.initial)];
    changes.extend(tracked.states.iter().copied());
    // Each state's segment, at least MIN_WIDTH wide; the labels that do not
    // fit their segment go above the band, in as many rows as they need.
    let segments: Vec<(f64, f64, u64, u64, u32)> = changes
        .iter()
        .enumerate()
        .map(|(i, &(t, state))| {
            let until = changes.get(i + 1).map_or(end, |n| n.0);
            let x1 = x(t).min(WIDTH - RIGHT - MIN_WIDTH);
            (x1, x(until).max(x1 + MIN_WIDTH), t, until, state)
        })
        .collect();
    let name = |state: u32| content.states[state as usize].name.as_str();
    let mut moved: Vec<(f64, usize, usize)> = Vec::new();
    let mut row_ends: Vec<f64> = Vec::new();
    for (i, &(x1, x2, _, _, state)) in segments.iter().enumerate() {
        if fits(x1, x2, name(state)) {
            continue;
        }
        let w = text_width(name(state));
        let cx = ((x1 + x2) / 2.0).clamp(LEFT + w / 2.0, WIDTH - RIGHT - w / 2.0);
        let row = match row_ends.iter().position(|&e| e + 4.0 <= cx - w / 2.0) {
            Some(r) => r,
            None => {
                row_ends.push(f64::NEG_INFINITY);
                row_ends.len() - 1
            }
        };
        row_ends[row] = cx + w / 2.0;
        moved.push((cx, row, i));
    }
    let top = TOP + row_ends.len() as f64 * CALLOUT;
    let height = top + rows as f64 * (BAND + GAP) + 70.0;
    let mut s = String::new();
    let _ = writeln!(
        s,
        r##"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{height:.0}" viewBox="0 0 {WIDTH} {height:.0}" font-family="sans-serif" font-size="12">"##
    );
    s.push_str(
        "<defs><pattern id=\"hatch\" width=\"6\" height=\"6\" patternUnits=\"userSpaceOnUse\" \
         patternTransform=\"rotate(45)\"><line x1=\"0\" y1=\"0\" x2=\"0\" y2=\"6\" stroke=\"#555\" \
         stroke-width=\"1.5\"/></pattern></defs>\n",
    );
    let _ = writeln!(s, r##"<rect width="100%" height="100%" fill="white"/>"##);
    let _ = writeln!(s, r##"<text x="{LEFT}" y="20" font-size="15" font-weight="bold">{}</text>"##, esc(title));
    let _ = writeln!(
        s,
        r##"<text x="{LEFT}" y="38" fill="#444">state at rest, then each agent: filled running, hatched waiting, dotted sleeping; the label is its function</text>"##
    );

    // The state band: the short states drawn last, over their neighbours.
    let y0 = top;
    let _ = writeln!(
        s,
        r##"<text x="{}" y="{:.1}" text-anchor="end" font-weight="bold">state</text>"##,
        LEFT - 8.0,
        y0 + 17.0
    );
    let mut order: Vec<usize> = (0..segments.len()).collect();
    order.sort_by(|&a, &b| (x(segments[b].3) - x(segments[b].2)).total_cmp(&(x(segments[a].3) - x(segments[a].2))));
    for &i in &order {
        let (x1, x2, t, until, state) = segments[i];
        let tip = format!("{}: {} – {}", name(state), secs(t), secs(until));
        let _ = writeln!(
            s,
            r##"<rect x="{x1:.2}" y="{y0:.1}" width="{:.2}" height="{BAND}" fill="{}" stroke="#333" stroke-width="0.5"><title>{}</title></rect>"##,
            x2 - x1,
            PALETTE[state as usize % PALETTE.len()],
            esc(&tip)
        );
        label(&mut s, x1, x2, y0, name(state));
    }
    // The moved labels, each with a line down to its segment.
    for &(cx, row, i) in &moved {
        let (x1, x2, _, _, state) = segments[i];
        let ty = TOP + row as f64 * CALLOUT + 11.0;
        let _ = writeln!(
            s,
            r##"<text x="{cx:.2}" y="{ty:.1}" text-anchor="middle">{}</text><line x1="{cx:.2}" y1="{:.1}" x2="{:.2}" y2="{y0:.1}" stroke="#666" stroke-width="0.5"/>"##,
            esc(name(state)),
            ty + 2.0,
            (x1 + x2) / 2.0
        );
    }

    // One band per agent.
    for (a, def) in content.agents.iter().enumerate() {
        let y = top + (a + 1) as f64 * (BAND + GAP);
        let _ = writeln!(
            s,
            r##"<text x="{}" y="{:.1}" text-anchor="end">{}</text>"##,
            LEFT - 8.0,
            y + 17.0,
            esc(&def.name)
        );
        let stretches = tracked.agents.get(a).map(Vec::as_slice).unwrap_or(&[]);
        for (i, st) in stretches.iter().enumerate() {
            let until = stretches.get(i + 1).map_or(end, |n| n.time);
            if until <= st.time && i + 1 < stretches.len() {
                continue;
            }
            let x1 = x(st.time).min(WIDTH - RIGHT - MIN_WIDTH);
            let x2 = x(until).max(x1 + MIN_WIDTH);
            let function = st.function.as_deref();
            let colour = function
                .and_then(|f| def.functions.iter().position(|g| g.name == f))
                .map_or("#d9d9d9", |k| PALETTE[(k + 3) % PALETTE.len()]);
            let mode = match st.mode {
                Mode::Running => "running",
                Mode::Waiting => "waiting",
                Mode::Sleeping => "sleeping",
            };
            let tip = match function {
                Some(f) if st.mode != Mode::Sleeping => {
                    format!("{}: {mode} {f}() {} – {}", def.name, secs(st.time), secs(until))
                }
                _ => format!("{}: {mode} {} – {}", def.name, secs(st.time), secs(until)),
            };
            let w = x2 - x1;
            match st.mode {
                Mode::Running => {
                    let _ = writeln!(
                        s,
                        r##"<rect x="{x1:.2}" y="{y:.1}" width="{w:.2}" height="{BAND}" fill="{colour}" stroke="#333" stroke-width="0.5"><title>{}</title></rect>"##,
                        esc(&tip)
                    );
                }
                Mode::Waiting => {
                    let _ = writeln!(
                        s,
                        r##"<g><title>{}</title><rect x="{x1:.2}" y="{y:.1}" width="{w:.2}" height="{BAND}" fill="{colour}" fill-opacity="0.45" stroke="#333" stroke-width="0.5"/><rect x="{x1:.2}" y="{y:.1}" width="{w:.2}" height="{BAND}" fill="url(#hatch)" fill-opacity="0.5"/></g>"##,
                        esc(&tip)
                    );
                }
                Mode::Sleeping => {
                    let _ = writeln!(
                        s,
                        r##"<rect x="{x1:.2}" y="{:.1}" width="{w:.2}" height="{:.1}" fill="#fafafa" stroke="#999" stroke-dasharray="2,3"><title>{}</title></rect>"##,
                        y + 4.0,
                        BAND - 8.0,
                        esc(&tip)
                    );
                }
            }
            let text = match (st.mode, function) {
                (Mode::Sleeping, _) => "sleep".to_string(),
                (_, Some(f)) => f.to_string(),
                (Mode::Waiting, None) => "wait".to_string(),
                (Mode::Running, None) => "running".to_string(),
            };
            label(&mut s, x1, x2, y, &text);
        }
    }

    // The time axis.
    let axis = top + rows as f64 * (BAND + GAP) + 6.0;
    let _ =
        writeln!(s, r##"<line x1="{LEFT}" y1="{axis:.1}" x2="{:.1}" y2="{axis:.1}" stroke="#333"/>"##, WIDTH - RIGHT);
    let step = tick_step(end);
    let mut t = 0u64;
    while t <= end {
        let xt = x(t);
        let _ = writeln!(
            s,
            r##"<line x1="{xt:.2}" y1="{axis:.1}" x2="{xt:.2}" y2="{:.1}" stroke="#333"/><text x="{xt:.2}" y="{:.1}" text-anchor="middle">{}</text>"##,
            axis + 5.0,
            axis + 18.0,
            secs(t)
        );
        t = match t.checked_add(step) {
            Some(n) => n,
            None => break,
        };
    }
    let _ = writeln!(
        s,
        r##"<text x="{:.1}" y="{:.1}" text-anchor="middle" fill="#444">time (simulated)</text>"##,
        (LEFT + WIDTH - RIGHT) / 2.0,
        axis + 36.0
    );
    s.push_str("</svg>\n");
    s
}

/// The width of a label (12 px sans-serif).
fn text_width(text: &str) -> f64 {
    7.0 * text.chars().count() as f64
}

/// Whether a label fits in a segment.
fn fits(x1: f64, x2: f64, text: &str) -> bool {
    (x2 - x1) >= text_width(text) + 6.0
}

/// A label centred in a segment, when it fits.
fn label(s: &mut String, x1: f64, x2: f64, y: f64, text: &str) {
    if text.is_empty() || !fits(x1, x2, text) {
        return;
    }
    let _ = writeln!(
        s,
        r##"<text x="{:.2}" y="{:.1}" text-anchor="middle">{}</text>"##,
        (x1 + x2) / 2.0,
        y + 17.0,
        esc(text)
    );
}

/// A round tick spacing giving at most ~12 ticks.
fn tick_step(end: u64) -> u64 {
    let mut step: u64 = 1_000_000; // 1 ms
    for m in [1u64, 2, 5].iter().cycle().scan(1u64, |scale, &k| {
        let v = k * *scale;
        if k == 5 {
            *scale = scale.saturating_mul(10);
        }
        Some(v)
    }) {
        step = m.saturating_mul(1_000_000);
        if end / step <= 12 || step >= u64::MAX / 10 {
            break;
        }
    }
    step
}

fn secs(ns: u64) -> String {
    let (whole, frac) = (ns / 1_000_000_000, ns % 1_000_000_000);
    if frac == 0 {
        format!("{whole}s")
    } else {
        let digits = format!("{frac:09}");
        format!("{whole}.{}s", digits.trim_end_matches('0'))
    }
}

pub(crate) fn esc(text: &str) -> String {
    text.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_few() {
        assert_eq!(tick_step(10_000_000_000), 1_000_000_000);
        assert_eq!(tick_step(60_000_000_000), 5_000_000_000);
        assert_eq!(tick_step(3_600_000_000_000), 500_000_000_000);
        assert!(u64::MAX / tick_step(u64::MAX) <= 13);
    }

    #[test]
    fn seconds_are_exact() {
        assert_eq!(secs(60_000_000_000), "60s");
        assert_eq!(secs(90_500_000_000), "90.5s");
        assert_eq!(secs(1), "0.000000001s");
    }

    #[test]
    fn text_is_escaped() {
        assert_eq!(esc("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
    }
}
