//! The built-in layout, used when Graphviz is not installed: a layered
//! layout of the DOT that `situ_compiler::graph` writes (the DOT is read by
//! `layout-rs`'s parser, laid out here). Ranks along `rankdir` (cycles
//! broken by a depth-first search, ranks by longest path, sources pulled
//! next to their successors), an edge longer than one rank gets a slot in
//! every rank it passes, orders by barycentres, and an edge is drawn as
//! straight runs inside the ranks (in its own slot) joined by curves that
//! stay in the gaps between ranks: no edge passes over a box other than
//! its ends. The graph's `label` is drawn as a title, the `cluster_legend`
//! subgraph as a legend (swatches and words) under the picture; node
//! boxes keep their fill, pen colour, dashes and words, edges their
//! colour, dashes and labels. The SVG is shaped as Graphviz's (`class="node"`
//! and `class="edge"` groups with a `<title>`), so one reader fits both.

use crate::LayoutError;
use layout::gv::parser::ast;
use layout::gv::DotParser;
use std::collections::HashMap;
use std::fmt::Write as _;

mod place;
use place::place;

/// Space between boxes of one rank, and between ranks.
const NODESEP: f64 = 18.0;
const RANKSEP: f64 = 48.0;
/// A slot of a long edge in a rank it passes.
const SLOT: f64 = 10.0;
const MARGIN: f64 = 12.0;
/// Average width of a character, as a fraction of the font size (Helvetica).
const CHAR: f64 = 0.6;
/// The attribute that marks a node of a `rank=sink` subgraph.
const SINK: &str = "situ-sink";

struct Node {
    id: String,
    label: String,
    attrs: HashMap<String, String>,
    w: f64,
    h: f64,
}

struct Edge {
    from: usize,
    to: usize,
    attrs: HashMap<String, String>,
}

/// What a DOT graph says, for this layout.
struct Picture {
    title: String,
    lr: bool,
    nodes: Vec<Node>,
    edges: Vec<Edge>,
    legend: Vec<Node>,
}

fn font(attrs: &HashMap<String, String>, default: f64) -> f64 {
    attrs.get("fontsize").and_then(|f| f.parse().ok()).unwrap_or(default)
}

fn text_size(label: &str, size: f64) -> (f64, f64) {
    let lines: Vec<&str> = label.split('\n').collect();
    let longest = lines.iter().map(|l| l.chars().count()).max().unwrap_or(0) as f64;
    (longest * size * CHAR, lines.len() as f64 * size * 1.2)
}

fn node(id: &str, attrs: HashMap<String, String>) -> Node {
    let label = attrs.get("label").cloned().unwrap_or_else(|| id.to_string());
    let (tw, th) = text_size(&label, font(&attrs, 14.0));
    Node { id: id.to_string(), label, w: (tw + 18.0).max(54.0), h: (th + 12.0).max(36.0), attrs }
}

/// Reads the DOT: the graph's title and direction, the nodes (with the
/// `node [...]` defaults in scope), the edges, the legend's entries.
fn read(dot: &str) -> Result<Picture, LayoutError> {
    let tree = DotParser::new(dot).process().map_err(LayoutError::Dot)?;
    let mut p = Picture { title: String::new(), lr: false, nodes: Vec::new(), edges: Vec::new(), legend: Vec::new() };
    let mut index: HashMap<String, usize> = HashMap::new();
    let mut edges: Vec<(String, String, HashMap<String, String>)> = Vec::new();
    let mut declared: Vec<(String, HashMap<String, String>, bool)> = Vec::new();
    walk(&tree, &HashMap::new(), &HashMap::new(), true, false, &mut p, &mut declared, &mut edges);
    for (id, attrs, in_legend) in declared {
        if in_legend {
            p.legend.push(node(&id, attrs));
        } else if let Some(&i) = index.get(&id) {
            p.nodes[i].attrs.extend(attrs);
            let again = node(&id, std::mem::take(&mut p.nodes[i].attrs));
            p.nodes[i] = again;
        } else {
            index.insert(id.clone(), p.nodes.len());
            p.nodes.push(node(&id, attrs));
        }
    }
    for (from, to, attrs) in edges {
        let mut at = |id: &str| match index.get(id) {
            Some(&i) => i,
            None => {
                index.insert(id.to_string(), p.nodes.len());
                p.nodes.push(node(id, HashMap::new()));
                p.nodes.len() - 1
            }
        };
        let (from, to) = (at(&from), at(&to));
        p.edges.push(Edge { from, to, attrs });
    }
    Ok(p)
}

#[allow(clippy::too_many_arguments)]
fn walk(
    g: &ast::Graph,
    node_defaults: &HashMap<String, String>,
    edge_defaults: &HashMap<String, String>,
    top: bool,
    in_legend: bool,
    p: &mut Picture,
    declared: &mut Vec<(String, HashMap<String, String>, bool)>,
    edges: &mut Vec<(String, String, HashMap<String, String>)>,
) {
    let mut nd = node_defaults.clone();
    let mut ed = edge_defaults.clone();
    for stmt in &g.list.list {
        match stmt {
            ast::Stmt::Attribute(a) => {
                let target = match a.target {
                    ast::AttrStmtTarget::Node => &mut nd,
                    ast::AttrStmtTarget::Edge => &mut ed,
                    ast::AttrStmtTarget::Graph => {
                        for (k, v) in a.list.iter() {
                            match (k.as_str(), top) {
                                ("label", true) => p.title = v.clone(),
                                ("rankdir", true) => p.lr = v == "LR",
                                // `{ rank=sink; … }`: its nodes in the last rank.
                                ("rank", false) if v == "sink" => {
                                    nd.insert(SINK.into(), "true".into());
                                }
                                _ => {}
                            }
                        }
                        continue;
                    }
                };
                for (k, v) in a.list.iter() {
                    target.insert(k.clone(), v.clone());
                }
            }
            ast::Stmt::Node(n) => {
                let mut attrs = nd.clone();
                attrs.extend(n.list.iter().cloned());
                declared.push((n.id.name.clone(), attrs, in_legend));
            }
            ast::Stmt::Edge(e) => {
                let mut attrs = ed.clone();
                attrs.extend(e.list.iter().cloned());
                let mut prev = e.from.name.clone();
                for (to, _) in &e.to {
                    edges.push((prev.clone(), to.name.clone(), attrs.clone()));
                    prev = to.name.clone();
                }
            }
            ast::Stmt::SubGraph(sub) => {
                let legend = in_legend || sub.name == "cluster_legend";
                walk(sub, &nd, &ed, false, legend, p, declared, edges);
            }
        }
    }
}

fn esc(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

fn colour(attrs: &HashMap<String, String>, key: &str, default: &str) -> String {
    attrs.get(key).map(|c| c.split(':').next().unwrap_or(c).to_string()).unwrap_or_else(|| default.to_string())
}

/// A box's SVG attributes: fill, pen, dashes (as Graphviz draws the style).
fn box_style(attrs: &HashMap<String, String>) -> String {
    let style = attrs.get("style").map(String::as_str).unwrap_or("");
    let fill = if style.contains("filled") { colour(attrs, "fillcolor", "lightgrey") } else { "white".into() };
    let dash = if style.contains("dashed") {
        " stroke-dasharray=\"5,2\""
    } else if style.contains("dotted") {
        " stroke-dasharray=\"1,5\""
    } else {
        ""
    };
    let width: f64 = attrs.get("penwidth").and_then(|w| w.parse().ok()).unwrap_or(1.0);
    let width = if style.contains("bold") { width.max(2.0) } else { width };
    format!("fill=\"{fill}\" stroke=\"{}\" stroke-width=\"{width}\"{dash}", colour(attrs, "color", "black"))
}

fn text_lines(out: &mut String, x: f64, y: f64, label: &str, size: f64, fill: &str, anchor: &str) {
    let lines: Vec<&str> = label.split('\n').collect();
    let top = y - (lines.len() as f64 - 1.0) * size * 1.2 / 2.0;
    for (i, l) in lines.iter().enumerate() {
        let _ = writeln!(
            out,
            "<text text-anchor=\"{anchor}\" x=\"{x:.2}\" y=\"{:.2}\" font-family=\"Helvetica,sans-Serif\" font-size=\"{size:.2}\" fill=\"{fill}\">{}</text>",
            top + i as f64 * size * 1.2 + size * 0.35,
            esc(l)
        );
    }
}

/// The path through the points: straight inside ranks, a cubic across each gap.
fn path_d(pts: &[(f64, f64)], lr: bool) -> String {
    let mut d = format!("M{:.2},{:.2}", pts[0].0, pts[0].1);
    for (i, w) in pts.windows(2).enumerate() {
        let (a, b) = (w[0], w[1]);
        if i % 2 == 1 {
            // A gap crossing: control points half-way along the rank axis.
            let (c1, c2) = place::crossing_controls(a, b, lr);
            let _ = write!(d, " C{:.2},{:.2} {:.2},{:.2} {:.2},{:.2}", c1.0, c1.1, c2.0, c2.1, b.0, b.1);
        } else {
            let _ = write!(d, " L{:.2},{:.2}", b.0, b.1);
        }
    }
    d
}

/// One DOT graph to SVG with the built-in layout.
pub fn svg(dot: &str) -> Result<String, LayoutError> {
    let p = read(dot)?;
    let placed = place(&p);
    let title_size = 18.0;
    let (title_w, title_h) = if p.title.is_empty() { (0.0, 0.0) } else { text_size(&p.title, title_size) };
    let title_h = if p.title.is_empty() { 0.0 } else { title_h + 10.0 };
    // The legend: a row (or rows) of swatches with their words.
    let legend_items: Vec<(f64, &Node)> = p
        .legend
        .iter()
        .map(|n| {
            let words = n.label.replace('\n', " ");
            (36.0 + text_size(&words, 12.0).0 + 16.0, n)
        })
        .collect();
    let legend_w_total: f64 = legend_items.iter().map(|(w, _)| w).sum::<f64>() + 60.0;
    let body_w = placed.width.max(title_w).max(if p.legend.is_empty() { 0.0 } else { 200.0 });
    let row_w = body_w.max(legend_w_total.min(600.0));
    let mut rows: Vec<Vec<(f64, &Node)>> = Vec::new();
    let mut used = f64::INFINITY;
    for &(w, n) in &legend_items {
        if used + w > row_w - 60.0 {
            rows.push(Vec::new());
            used = 0.0;
        }
        used += w;
        rows.last_mut().expect("pushed").push((w, n));
    }
    let legend_h = if rows.is_empty() { 0.0 } else { 14.0 + rows.len() as f64 * 22.0 + 8.0 };
    let width = row_w + 2.0 * MARGIN;
    let height = MARGIN + title_h + placed.height + if legend_h > 0.0 { 16.0 + legend_h } else { 0.0 } + MARGIN;
    let ox = MARGIN + (row_w - placed.width) / 2.0;
    let oy = MARGIN + title_h;
    let mut out = format!(
        "<?xml version=\"1.0\" encoding=\"UTF-8\" standalone=\"no\"?>\n<!-- laid out by situ's built-in layout -->\n\
         <svg width=\"{width:.0}pt\" height=\"{height:.0}pt\" viewBox=\"0.00 0.00 {width:.2} {height:.2}\" \
         xmlns=\"http://www.w3.org/2000/svg\" xmlns:xlink=\"http://www.w3.org/1999/xlink\">\n\
         <g id=\"graph0\" class=\"graph\">\n<polygon fill=\"white\" stroke=\"transparent\" points=\"0,0 {width:.2},0 {width:.2},{height:.2} 0,{height:.2}\"/>\n"
    );
    if !p.title.is_empty() {
        text_lines(&mut out, width / 2.0, MARGIN + title_h / 2.0, &p.title, title_size, "black", "middle");
    }
    let shift = |(x, y): (f64, f64)| (x + ox, y + oy);
    for (k, e) in p.edges.iter().enumerate() {
        let pts: Vec<(f64, f64)> = placed.paths[k].iter().map(|&q| shift(q)).collect();
        if pts.len() < 2 {
            continue;
        }
        let stroke = colour(&e.attrs, "color", "black");
        let dash =
            if e.attrs.get("style").is_some_and(|s| s.contains("dashed")) { " stroke-dasharray=\"5,2\"" } else { "" };
        let width: f64 = e.attrs.get("penwidth").and_then(|w| w.parse().ok()).unwrap_or(1.0);
        let d = if p.nodes[e.from].id == p.nodes[e.to].id {
            format!(
                "M{:.2},{:.2} C{:.2},{:.2} {:.2},{:.2} {:.2},{:.2}",
                pts[0].0, pts[0].1, pts[1].0, pts[1].1, pts[2].0, pts[2].1, pts[3].0, pts[3].1
            )
        } else {
            path_d(&pts, p.lr)
        };
        let _ = writeln!(
            out,
            "<g class=\"edge\">\n<title>{}&#45;&gt;{}</title>\n<path fill=\"none\" stroke=\"{stroke}\" stroke-width=\"{width}\"{dash} d=\"{d}\"/>",
            esc(&p.nodes[e.from].id),
            esc(&p.nodes[e.to].id)
        );
        // The arrowhead, inside the last straight run (outside the head's box).
        // Every edge ends along the rank axis (a loop: back into its box).
        let b = pts[pts.len() - 1];
        let a = pts.iter().rev().find(|q| (q.0 - b.0).abs() + (q.1 - b.1).abs() > 0.5).copied().unwrap_or(pts[0]);
        let (ux, uy) = if e.from == e.to {
            (-1.0, 0.0)
        } else if p.lr {
            ((b.0 - a.0).signum(), 0.0)
        } else {
            (0.0, (b.1 - a.1).signum())
        };
        let back = (b.0 - ux * 9.0, b.1 - uy * 9.0);
        let _ = writeln!(
            out,
            "<polygon fill=\"{stroke}\" stroke=\"{stroke}\" points=\"{:.2},{:.2} {:.2},{:.2} {:.2},{:.2}\"/>",
            b.0,
            b.1,
            back.0 - uy * 3.5,
            back.1 + ux * 3.5,
            back.0 + uy * 3.5,
            back.1 - ux * 3.5
        );
        if let (Some(at), Some(label)) = (placed.labels[k], e.attrs.get("label")) {
            let (x, y) = shift(at);
            text_lines(&mut out, x, y, label, font(&e.attrs, 12.0), &stroke, "middle");
        }
        out.push_str("</g>\n");
    }
    for (v, nd) in p.nodes.iter().enumerate() {
        let (cx, cy) = shift(placed.centre[v]);
        let _ = writeln!(out, "<g class=\"node\">\n<title>{}</title>", esc(&nd.id));
        if let Some(t) = nd.attrs.get("tooltip") {
            let _ = writeln!(out, "<desc>{}</desc>", esc(t));
        }
        let rounded = nd.attrs.get("style").is_some_and(|s| s.contains("rounded"));
        let _ = writeln!(
            out,
            "<rect x=\"{:.2}\" y=\"{:.2}\" width=\"{:.2}\" height=\"{:.2}\" rx=\"{}\" {}/>",
            cx - nd.w / 2.0,
            cy - nd.h / 2.0,
            nd.w,
            nd.h,
            if rounded { 6 } else { 0 },
            box_style(&nd.attrs)
        );
        let fill = colour(&nd.attrs, "fontcolor", "black");
        text_lines(&mut out, cx, cy, &nd.label, font(&nd.attrs, 14.0), &fill, "middle");
        out.push_str("</g>\n");
    }
    if !rows.is_empty() {
        let top = MARGIN + title_h + placed.height + 16.0;
        let _ = writeln!(
            out,
            "<g class=\"legend\">\n<rect x=\"{:.2}\" y=\"{top:.2}\" width=\"{:.2}\" height=\"{legend_h:.2}\" rx=\"6\" fill=\"none\" stroke=\"#9e9e9e\"/>",
            MARGIN,
            row_w
        );
        text_lines(
            &mut out,
            MARGIN + 10.0,
            top + 20.0 + (rows.len() as f64 - 1.0) * 11.0,
            "legend",
            14.0,
            "black",
            "start",
        );
        for (i, row) in rows.iter().enumerate() {
            let y = top + 10.0 + i as f64 * 22.0;
            let mut x = MARGIN + 70.0;
            for (w, nd) in row {
                let _ = writeln!(
                    out,
                    "<rect x=\"{x:.2}\" y=\"{y:.2}\" width=\"28\" height=\"16\" {}/>",
                    box_style(&nd.attrs)
                );
                text_lines(&mut out, x + 36.0, y + 8.0, &nd.label.replace('\n', " "), 12.0, "black", "start");
                x += w;
            }
        }
        out.push_str("</g>\n");
    }
    out.push_str("</g>\n</svg>\n");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The boxes of an SVG of ours, by id: `(x0, y0, x1, y1)`.
    fn boxes(svg: &str) -> HashMap<String, [f64; 4]> {
        let mut out = HashMap::new();
        for part in svg.split("<g class=\"node\">").skip(1) {
            let id = &part[part.find("<title>").unwrap() + 7..part.find("</title>").unwrap()];
            let rect = &part[part.find("<rect").unwrap()..];
            let v = |n: &str| -> f64 {
                let at = rect.find(&format!(" {n}=\"")).unwrap() + n.len() + 3;
                rect[at..at + rect[at..].find('"').unwrap()].parse().unwrap()
            };
            out.insert(id.to_string(), [v("x"), v("y"), v("x") + v("width"), v("y") + v("height")]);
        }
        out
    }

    #[test]
    fn a_long_edge_goes_around_the_box_in_its_way() {
        // a → b → c and a → c: the long edge has its own slot in b's rank.
        let svg = svg("digraph g { rankdir=LR; label=\"T\"; node [shape=box]; a -> b; b -> c; a -> c; }").unwrap();
        let b = boxes(&svg)["b"];
        let long = svg.split("<title>a&#45;&gt;c</title>").nth(1).unwrap();
        let d = &long[long.find(" d=\"").unwrap() + 4..];
        let d = &d[..d.find('"').unwrap()];
        let nums: Vec<f64> = d
            .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
            .filter(|t| !t.is_empty())
            .map(|t| t.parse().unwrap())
            .collect();
        // Every point of the path, ends and control points, is outside b's
        // box (tests/pictures.rs samples the curves themselves).
        for p in nums.chunks_exact(2) {
            let inside = p[0] > b[0] && p[0] < b[2] && p[1] > b[1] && p[1] < b[3];
            assert!(!inside, "({}, {}) in b {b:?}: {d}", p[0], p[1]);
        }
        assert!(svg.contains(">T</text>"), "the title");
    }

    #[test]
    fn cycles_loops_empty_graphs_and_a_legend_lay_out() {
        let svg = svg(
            "digraph g { a -> b; b -> a; a -> a [label=\"self\"]; \
             subgraph cluster_legend { label=\"legend\"; l0 [label=\"kind\", fillcolor=\"#ff0000\", style=filled]; } }",
        )
        .unwrap();
        let ids: Vec<String> = boxes(&svg).into_keys().collect();
        assert_eq!(ids.len(), 2, "the legend is no node: {ids:?}");
        assert!(svg.contains("<g class=\"legend\">") && svg.contains(">kind</text>") && svg.contains("#ff0000"));
        assert_eq!(svg.matches("<g class=\"edge\">").count(), 3);
        assert!(super::svg("digraph g { }").unwrap().contains("</svg>"));
        assert!(super::svg("not a graph").is_err());
    }
}
