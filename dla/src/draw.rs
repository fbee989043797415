//! A picture of DLA's maps and plans as one SVG document, written by hand.
//!
//! [`draw`] shows, in one deterministic SVG string (same input, same bytes):
//! - the occupancy grid, each cell shaded by its probability of being
//!   occupied (free light, unknown a neutral grey, occupied dark), quantised
//!   to [`SHADES`] shades; cells of equal shade are merged into rectangles
//!   (runs along a row, then equal runs of consecutive rows), so a structured
//!   grid of 200 × 200 cells takes a few hundred rectangles, not 40,000;
//! - the pyramid's regions, if given, as the outlines of their cells (the
//!   borders between regions), coloured by class: free, occupied, unexplored;
//! - the route's regions filled with a highlight and numbered in order
//!   (1, 2, …) by a label at each centroid;
//! - the planned path and the driven trajectory as polylines, the start and
//!   the goal as markers, a legend, the title and a scale bar in metres.
//!
//! The map is drawn in metres inside a group whose transform scales it to
//! pixels and flips the y axis (up in the world, up in the picture): the
//! points of the polylines are the world coordinates, written with three
//! decimals (`x,y`). Labels, legend, title and scale bar are in pixels,
//! outside that group, so that their text is upright.

use super::grid::OccupancyGrid;
use super::pyramid::{Pyramid, RegionClass};
use situ_sim::geom::Vec2;
use std::fmt::Write;

/// Number of grey shades the occupancy probabilities are quantised to.
pub const SHADES: usize = 11;

/// Width of the map in pixels (its longer side when taller than wide).
const MAP_PX: f64 = 720.0;
/// Margins around the map (pixels): left, top (title), right (legend), bottom (scale bar).
const LEFT: f64 = 20.0;
const TOP: f64 = 44.0;
const RIGHT: f64 = 200.0;
const BOTTOM: f64 = 56.0;

const FREE_COLOUR: &str = "#2ca02c";
const OCCUPIED_COLOUR: &str = "#8c1c13";
const UNEXPLORED_COLOUR: &str = "#17becf";
const ROUTE_COLOUR: &str = "#ffb000";
const PATH_COLOUR: &str = "#1f4fd6";
const TRAJECTORY_COLOUR: &str = "#c2189b";
const START_COLOUR: &str = "#00a000";
const GOAL_COLOUR: &str = "#e00000";

/// The grey level (0–255) of quantised shade `k` of [`SHADES`]: probability
/// 0 is near white, 0.5 a neutral grey, 1 near black.
fn grey(k: usize) -> u8 {
    let p = k as f64 / (SHADES - 1) as f64;
    (245.0 - 210.0 * p).round() as u8
}

/// The quantised shade of a probability.
fn shade(p: f64) -> usize {
    let p = if p.is_finite() { p.clamp(0.0, 1.0) } else { 0.5 };
    (p * (SHADES - 1) as f64).round() as usize
}

/// Escapes text for XML content and attribute values.
fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            c if (c as u32) < 0x20 && c != '\t' && c != '\n' && c != '\r' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A rectangle of cells `[x0, x1) × [y0, y1)` of one key.
struct CellRect<K> {
    x0: usize,
    y0: usize,
    x1: usize,
    y1: usize,
    key: K,
}

/// Covers the cells of a `w × h` grid that have a key with rectangles of
/// equal keys: runs of equal keys along each row, then equal runs (same
/// columns, same key) of consecutive rows merged into one rectangle. The
/// rectangles are returned in a deterministic order (by bottom row, then
/// left column).
fn merge_cells<K: PartialEq + Copy>(w: usize, h: usize, key: impl Fn(usize, usize) -> Option<K>) -> Vec<CellRect<K>> {
    let mut done = Vec::new();
    // The rectangles still growing upwards, by left column (increasing).
    let mut open: Vec<CellRect<K>> = Vec::new();
    for y in 0..h {
        let mut runs: Vec<(usize, usize, K)> = Vec::new();
        let mut x = 0;
        while x < w {
            match key(x, y) {
                None => x += 1,
                Some(k) => {
                    let x0 = x;
                    x += 1;
                    while x < w && key(x, y) == Some(k) {
                        x += 1;
                    }
                    runs.push((x0, x, k));
                }
            }
        }
        let mut next = Vec::with_capacity(runs.len());
        let mut old = open.into_iter().peekable();
        for (x0, x1, k) in runs {
            // Close the open rectangles that start left of this run.
            while let Some(r) = old.next_if(|r| r.x0 < x0) {
                done.push(r);
            }
            match old.next_if(|r| r.x0 == x0) {
                Some(mut r) if r.x1 == x1 && r.key == k => {
                    r.y1 = y + 1;
                    next.push(r);
                }
                Some(r) => {
                    done.push(r);
                    next.push(CellRect { x0, y0: y, x1, y1: y + 1, key: k });
                }
                None => next.push(CellRect { x0, y0: y, x1, y1: y + 1, key: k }),
            }
        }
        done.extend(old);
        open = next;
    }
    done.extend(open);
    done.sort_by_key(|r| (r.y0, r.x0));
    done
}

/// The outline of a set of regions: per region, the edges of its cells that
/// border another region or the grid's edge, merged into maximal straight
/// segments, as cell-corner coordinates `(x0, y0, x1, y1)`.
fn outlines(p: &Pyramid, w: usize, h: usize) -> Vec<Vec<(usize, usize, usize, usize)>> {
    let n = p.regions().len();
    let mut segments: Vec<Vec<(usize, usize, usize, usize)>> = vec![Vec::new(); n];
    // The lines between rows (horizontal edges), then between columns
    // (vertical ones): `line` crosses the grid, `at` runs along it.
    for vertical in [false, true] {
        let (lines, along) = if vertical { (w, h) } else { (h, w) };
        let cell = |line: usize, at: usize| if vertical { p.region_of(line, at) } else { p.region_of(at, line) };
        for line in 0..=lines {
            for at in 0..along {
                let before = (line > 0).then(|| cell(line - 1, at));
                let after = (line < lines).then(|| cell(line, at));
                if before == after {
                    continue;
                }
                for r in [before, after].into_iter().flatten() {
                    let s = &mut segments[r];
                    match s.last_mut() {
                        Some(last) if vertical && last.0 == line && last.2 == line && last.3 == at => last.3 = at + 1,
                        Some(last) if !vertical && last.1 == line && last.3 == line && last.2 == at => last.2 = at + 1,
                        _ => s.push(if vertical { (line, at, line, at + 1) } else { (at, line, at + 1, line) }),
                    }
                }
            }
        }
    }
    segments
}

fn class_colour(c: RegionClass) -> &'static str {
    match c {
        RegionClass::Free => FREE_COLOUR,
        RegionClass::Occupied => OCCUPIED_COLOUR,
        RegionClass::Unexplored => UNEXPLORED_COLOUR,
    }
}

/// A length of 1, 2 or 5 times a power of ten, at most `max` (and positive).
fn nice_length(max: f64) -> f64 {
    if !(max.is_finite() && max > 0.0) {
        return 1.0;
    }
    let p = 10f64.powf(max.log10().floor());
    [5.0, 2.0, 1.0].into_iter().map(|m| m * p).find(|&l| l <= max).unwrap_or(p)
}

/// Formats a scale-bar length without trailing zeros ("0.5 m", "2 m").
fn metres(l: f64) -> String {
    let s = format!("{l:.3}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    format!("{s} m")
}

/// Draws a grid, optionally its pyramid's regions and a route over them, a
/// planned path, a driven trajectory, the start and the goal (all in metres,
/// world frame) as one SVG document titled `title`.
///
/// - `pyramid` must have been built from `grid`; a pyramid of other
///   dimensions is not drawn (nor the route).
/// - `route` lists region ids in the order crossed (as returned by
///   [`plan_route`](super::route::plan_route)); ids out of range are skipped.
///   Each is highlighted and labelled with its rank (1, 2, …) at its
///   centroid, in an element `<text class="route-label" …>`.
/// - `path` (as returned by [`plan_path`](super::route::plan_path)) is the
///   polyline `<polyline class="path" points="x,y …"/>`, `trajectory` the
///   polyline `<polyline class="trajectory" …/>`, both in metres with three
///   decimals (non-finite points are skipped; empty ones are not drawn).
///
/// The output depends only on the input: the same input gives the same bytes.
#[allow(clippy::too_many_arguments)]
pub fn draw(
    grid: &OccupancyGrid,
    pyramid: Option<&Pyramid>,
    route: &[usize],
    path: &[Vec2],
    trajectory: &[(f64, f64)],
    start: (f64, f64),
    goal: (f64, f64),
    title: &str,
) -> String {
    let (w, h) = (grid.width(), grid.height());
    let cell = grid.cell_size();
    let o = grid.origin();
    let (wm, hm) = ((w as f64 * cell).max(cell), (h as f64 * cell).max(cell));
    // Pixels per metre: the longer side of the map is MAP_PX wide.
    let s = MAP_PX / wm.max(hm);
    let (map_w, map_h) = (wm * s, hm * s);
    let (width, height) = (LEFT + map_w + RIGHT, TOP + map_h + BOTTOM);
    // World (m) to picture (px).
    let px = |x: f64, y: f64| (LEFT + (x - o.x) * s, TOP + (hm - (y - o.y)) * s);
    // A length of `p` pixels in metres (stroke widths inside the map group).
    let m = |p: f64| p / s;
    let pyramid = pyramid.filter(|p| p.width() == w && p.height() == h);

    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width:.1}" height="{height:.1}" viewBox="0 0 {width:.1} {height:.1}" font-family="sans-serif">"#
    );
    let title = escape(title);
    let _ = writeln!(svg, "<title>{title}</title>");
    let _ = writeln!(svg, r##"<rect x="0" y="0" width="{width:.1}" height="{height:.1}" fill="#ffffff"/>"##);
    let _ = writeln!(svg, r#"<text class="title" x="{LEFT:.1}" y="28.0" font-size="18">{title}</text>"#);

    // The map, in metres: x right, y up.
    let _ = writeln!(
        svg,
        r#"<g class="map" transform="translate({:.4} {:.4}) scale({s:.6} {:.6})">"#,
        LEFT - s * o.x,
        TOP + s * (hm + o.y),
        -s
    );
    let cx = |x: usize| o.x + x as f64 * cell;
    let cy = |y: usize| o.y + y as f64 * cell;
    let _ = writeln!(svg, r#"<g class="grid" stroke="none" shape-rendering="crispEdges">"#);
    for r in merge_cells(w, h, |x, y| Some(shade(grid.probability(x, y)))) {
        let g = grey(r.key);
        let _ = writeln!(
            svg,
            r##"<rect x="{:.3}" y="{:.3}" width="{:.3}" height="{:.3}" fill="#{g:02x}{g:02x}{g:02x}"/>"##,
            cx(r.x0),
            cy(r.y0),
            (r.x1 - r.x0) as f64 * cell,
            (r.y1 - r.y0) as f64 * cell,
        );
    }
    let _ = writeln!(svg, "</g>");

    let route: Vec<usize> = match pyramid {
        Some(p) => route.iter().copied().filter(|&r| r < p.regions().len()).collect(),
        None => Vec::new(),
    };
    if let Some(p) = pyramid {
        let mut on_route = vec![false; p.regions().len()];
        for &r in &route {
            on_route[r] = true;
        }
        let _ = writeln!(
            svg,
            r#"<g class="route" fill="{ROUTE_COLOUR}" fill-opacity="0.40" stroke="none" shape-rendering="crispEdges">"#
        );
        for r in merge_cells(w, h, |x, y| on_route[p.region_of(x, y)].then_some(())) {
            let _ = writeln!(
                svg,
                r#"<rect x="{:.3}" y="{:.3}" width="{:.3}" height="{:.3}"/>"#,
                cx(r.x0),
                cy(r.y0),
                (r.x1 - r.x0) as f64 * cell,
                (r.y1 - r.y0) as f64 * cell,
            );
        }
        let _ = writeln!(svg, "</g>");

        let segments = outlines(p, w, h);
        let _ = writeln!(svg, r#"<g class="regions" fill="none" stroke-width="{:.4}">"#, m(1.0));
        // Occupied, then unexplored, then free on top; by id within a class.
        for class in [RegionClass::Occupied, RegionClass::Unexplored, RegionClass::Free] {
            for region in p.regions().iter().filter(|r| r.class == class) {
                let mut d = String::new();
                for &(x0, y0, x1, y1) in &segments[region.id] {
                    let _ = write!(d, "M{:.3} {:.3}L{:.3} {:.3}", cx(x0), cy(y0), cx(x1), cy(y1));
                }
                if !d.is_empty() {
                    let _ = writeln!(
                        svg,
                        r#"<path data-region="{}" stroke="{}" d="{d}"/>"#,
                        region.id,
                        class_colour(class)
                    );
                }
            }
        }
        let _ = writeln!(svg, "</g>");
    }

    let points = |it: &mut dyn Iterator<Item = (f64, f64)>| {
        let mut out = String::new();
        for (x, y) in it.filter(|(x, y)| x.is_finite() && y.is_finite()) {
            if !out.is_empty() {
                out.push(' ');
            }
            let _ = write!(out, "{x:.3},{y:.3}");
        }
        out
    };
    let path_points = points(&mut path.iter().map(|q| (q.x, q.y)));
    if !path_points.is_empty() {
        let _ = writeln!(
            svg,
            r#"<polyline class="path" fill="none" stroke="{PATH_COLOUR}" stroke-width="{:.4}" stroke-linejoin="round" points="{path_points}"/>"#,
            m(2.0)
        );
    }
    let trajectory_points = points(&mut trajectory.iter().copied());
    if !trajectory_points.is_empty() {
        let _ = writeln!(
            svg,
            r#"<polyline class="trajectory" fill="none" stroke="{TRAJECTORY_COLOUR}" stroke-width="{:.4}" stroke-dasharray="{:.4} {:.4}" stroke-linejoin="round" points="{trajectory_points}"/>"#,
            m(2.0),
            m(6.0),
            m(3.0)
        );
    }
    if start.0.is_finite() && start.1.is_finite() {
        let _ = writeln!(
            svg,
            r##"<circle class="start" cx="{:.3}" cy="{:.3}" r="{:.4}" fill="{START_COLOUR}" stroke="#000000" stroke-width="{:.4}"/>"##,
            start.0,
            start.1,
            m(6.0),
            m(1.0)
        );
    }
    if goal.0.is_finite() && goal.1.is_finite() {
        let (x, y, d) = (goal.0, goal.1, m(7.0));
        let _ = writeln!(
            svg,
            r##"<polygon class="goal" points="{:.3},{y:.3} {x:.3},{:.3} {:.3},{y:.3} {x:.3},{:.3}" fill="{GOAL_COLOUR}" stroke="#000000" stroke-width="{:.4}"/>"##,
            x - d,
            y + d,
            x + d,
            y - d,
            m(1.0)
        );
    }
    let _ = writeln!(svg, "</g>");

    // Route labels, upright, in pixels.
    if let Some(p) = pyramid {
        let _ = writeln!(svg, r#"<g class="route-labels" font-size="11" text-anchor="middle">"#);
        for (k, &r) in route.iter().enumerate() {
            let c = p.region(r).centroid;
            let (x, y) = px(c.x, c.y);
            let _ = writeln!(
                svg,
                r##"<circle cx="{x:.1}" cy="{y:.1}" r="8.0" fill="#ffffff" fill-opacity="0.85" stroke="{ROUTE_COLOUR}" stroke-width="1.5"/>"##
            );
            let _ = writeln!(
                svg,
                r#"<text class="route-label" data-region="{r}" x="{x:.1}" y="{:.1}">{}</text>"#,
                y + 4.0,
                k + 1
            );
        }
        let _ = writeln!(svg, "</g>");
    }

    // The frame of the map.
    let _ = writeln!(
        svg,
        r##"<rect x="{LEFT:.1}" y="{TOP:.1}" width="{map_w:.1}" height="{map_h:.1}" fill="none" stroke="#000000" stroke-width="1"/>"##
    );

    // Scale bar: a round length of at most a quarter of the map's width.
    let bar = nice_length(wm / 4.0);
    let (bx, by) = (LEFT, TOP + map_h + 30.0);
    let bw = bar * s;
    let _ = writeln!(svg, r##"<g class="scale" stroke="#000000" stroke-width="2" font-size="12">"##);
    let _ = writeln!(svg, r#"<path fill="none" d="M{bx:.1} {:.1}V{by:.1}H{:.1}V{:.1}"/>"#, by - 6.0, bx + bw, by - 6.0);
    let _ = writeln!(svg, r#"<text x="{:.1}" y="{:.1}" stroke="none">{}</text>"#, bx + bw + 8.0, by + 4.0, metres(bar));
    let _ = writeln!(svg, "</g>");

    // Legend: a mark and a label per line.
    let lx = LEFT + map_w + 16.0;
    type Mark = Box<dyn Fn(f64) -> String>;
    let swatch = |fill: String, stroke: &'static str| -> Mark {
        Box::new(move |y: f64| {
            format!(
                r#"<rect x="{lx:.1}" y="{:.1}" width="22.0" height="12.0" {fill} stroke="{stroke}" stroke-width="1.5"/>"#,
                y - 6.0
            )
        })
    };
    let mut legend: Vec<(Mark, &str)> = Vec::new();
    for (p, label) in [(0.0, "free cell"), (0.5, "unknown cell"), (1.0, "occupied cell")] {
        let g = grey(shade(p));
        legend.push((swatch(format!(r##"fill="#{g:02x}{g:02x}{g:02x}""##), "#000000"), label));
    }
    if pyramid.is_some() {
        legend.push((swatch(r#"fill="none""#.into(), FREE_COLOUR), "free region"));
        legend.push((swatch(r#"fill="none""#.into(), OCCUPIED_COLOUR), "occupied region"));
        legend.push((swatch(r#"fill="none""#.into(), UNEXPLORED_COLOUR), "unexplored region"));
        legend.push((swatch(format!(r#"fill="{ROUTE_COLOUR}" fill-opacity="0.40""#), "none"), "route (numbered)"));
    }
    legend.push((
        Box::new(move |y: f64| {
            format!(r#"<path d="M{lx:.1} {y:.1}H{:.1}" stroke="{PATH_COLOUR}" stroke-width="2"/>"#, lx + 22.0)
        }),
        "planned path",
    ));
    legend.push((
        Box::new(move |y: f64| {
            format!(
                r#"<path d="M{lx:.1} {y:.1}H{:.1}" stroke="{TRAJECTORY_COLOUR}" stroke-width="2" stroke-dasharray="6 3"/>"#,
                lx + 22.0
            )
        }),
        "trajectory",
    ));
    legend.push((
        Box::new(move |y: f64| {
            format!(
                r##"<circle cx="{:.1}" cy="{y:.1}" r="6.0" fill="{START_COLOUR}" stroke="#000000" stroke-width="1"/>"##,
                lx + 11.0
            )
        }),
        "start",
    ));
    legend.push((
        Box::new(move |y: f64| {
            format!(
                r##"<polygon points="{:.1},{y:.1} {:.1},{:.1} {:.1},{y:.1} {:.1},{:.1}" fill="{GOAL_COLOUR}" stroke="#000000" stroke-width="1"/>"##,
                lx + 4.0,
                lx + 11.0,
                y - 7.0,
                lx + 18.0,
                lx + 11.0,
                y + 7.0
            )
        }),
        "goal",
    ));
    let _ = writeln!(svg, r#"<g class="legend" font-size="12">"#);
    for (k, (mark, label)) in legend.iter().enumerate() {
        let y = TOP + 8.0 + 20.0 * k as f64;
        let _ = writeln!(svg, "{}", mark(y));
        let _ = writeln!(svg, r#"<text x="{:.1}" y="{:.1}">{label}</text>"#, lx + 30.0, y + 4.0);
    }
    let _ = writeln!(svg, "</g>");
    svg.push_str("</svg>\n");
    svg
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn merged_rectangles_cover_each_cell_once_with_its_key() {
        let (w, h) = (7, 5);
        let key = |x: usize, y: usize| if (x + 2 * y).is_multiple_of(5) { None } else { Some((x / 3 + y / 2) % 2) };
        let rects = merge_cells(w, h, key);
        let mut seen = vec![0; w * h];
        for r in &rects {
            for y in r.y0..r.y1 {
                for x in r.x0..r.x1 {
                    seen[y * w + x] += 1;
                    assert_eq!(key(x, y), Some(r.key));
                }
            }
        }
        for y in 0..h {
            for x in 0..w {
                assert_eq!(seen[y * w + x], usize::from(key(x, y).is_some()), "cell ({x}, {y})");
            }
        }
        // A uniform grid is one rectangle.
        assert_eq!(merge_cells(9, 4, |_, _| Some(1)).len(), 1);
    }

    #[test]
    fn scale_lengths_are_round() {
        assert_eq!(nice_length(3.7), 2.0);
        assert_eq!(nice_length(0.6), 0.5);
        assert_eq!(nice_length(12.0), 10.0);
        assert_eq!(metres(0.5), "0.5 m");
        assert_eq!(metres(20.0), "20 m");
    }
}
