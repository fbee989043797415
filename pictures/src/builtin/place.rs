//! Where the built-in layout puts things: ranks, orders, positions, edge
//! paths (straight in the ranks, curved in the gaps) and edge labels.

use super::{font, text_size, Picture, NODESEP, RANKSEP, SINK, SLOT};
use std::collections::HashMap;

/// Where everything goes: ranks, orders, positions, and each edge's path
/// as a list of points, straight runs and gap crossings alternating.
pub(super) struct Placed {
    /// Per node: centre (x, y).
    pub(super) centre: Vec<(f64, f64)>,
    /// Per edge: the points from its tail's box to its head's box.
    pub(super) paths: Vec<Vec<(f64, f64)>>,
    /// Per edge: where its label goes.
    pub(super) labels: Vec<Option<(f64, f64)>>,
    pub(super) width: f64,
    pub(super) height: f64,
}

/// Ranks: cycles broken by reversing the back edges of a depth-first
/// search, then longest path; a node with successors only is pulled to
/// one rank before the nearest of them.
fn ranks(n: usize, edges: &[(usize, usize)]) -> (Vec<usize>, Vec<bool>) {
    let mut out: Vec<Vec<(usize, usize)>> = vec![Vec::new(); n];
    for (k, &(a, b)) in edges.iter().enumerate() {
        out[a].push((b, k));
    }
    // 0 unvisited, 1 on the stack, 2 done.
    let mut colour = vec![0u8; n];
    let mut reversed = vec![false; edges.len()];
    for root in 0..n {
        if colour[root] != 0 {
            continue;
        }
        let mut stack = vec![(root, 0usize)];
        colour[root] = 1;
        while let Some(&mut (v, ref mut i)) = stack.last_mut() {
            if *i < out[v].len() {
                let (w, k) = out[v][*i];
                *i += 1;
                match colour[w] {
                    0 => {
                        colour[w] = 1;
                        stack.push((w, 0));
                    }
                    1 => reversed[k] = true,
                    _ => {}
                }
            } else {
                colour[v] = 2;
                stack.pop();
            }
        }
    }
    let dag: Vec<(usize, usize)> = edges
        .iter()
        .zip(&reversed)
        .filter(|((a, b), _)| a != b)
        .map(|(&(a, b), &r)| if r { (b, a) } else { (a, b) })
        .collect();
    let mut rank = vec![0usize; n];
    // Longest path: relax until stable (at most n rounds on a DAG).
    for _ in 0..n {
        let mut changed = false;
        for &(a, b) in &dag {
            if rank[b] < rank[a] + 1 {
                rank[b] = rank[a] + 1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    for v in 0..n {
        let has_in = dag.iter().any(|&(_, b)| b == v);
        let next = dag.iter().filter(|&&(a, _)| a == v).map(|&(_, b)| rank[b]).min();
        if let (false, Some(m)) = (has_in, next) {
            rank[v] = m.saturating_sub(1).max(rank[v]);
        }
    }
    (rank, reversed)
}

pub(super) fn place(p: &Picture) -> Placed {
    let n = p.nodes.len();
    let pairs: Vec<(usize, usize)> = p.edges.iter().map(|e| (e.from, e.to)).collect();
    let (mut rank, _) = ranks(n, &pairs);
    let sink = |v: usize| p.nodes[v].attrs.contains_key(SINK);
    if let Some(last) = (0..n).filter(|&v| !sink(v)).map(|v| rank[v] + 1).max() {
        for v in (0..n).filter(|&v| sink(v)) {
            rank[v] = rank[v].max(last);
        }
    }
    let top = rank.iter().copied().max().unwrap_or(0) + 1;
    // The layers: real nodes, then a slot per rank an edge passes.
    // An item is (Some(node), None) or (None, Some(edge)).
    let mut layers: Vec<Vec<Item>> = vec![Vec::new(); top];
    for v in 0..n {
        layers[rank[v]].push(Item::Node(v));
    }
    // Each edge's chain: its low end, a slot in every rank between, its high end.
    let mut up: HashMap<(Item, usize), Vec<Item>> = HashMap::new();
    let mut down: HashMap<(Item, usize), Vec<Item>> = HashMap::new();
    for (k, &(a, b)) in pairs.iter().enumerate() {
        let (low, high) = if rank[a] <= rank[b] { (a, b) } else { (b, a) };
        let (r0, r1) = (rank[low], rank[high]);
        if r0 == r1 {
            continue;
        }
        for layer in layers.iter_mut().take(r1).skip(r0 + 1) {
            layer.push(Item::Slot(k));
        }
        let at = |r: usize| {
            if r == r0 {
                Item::Node(low)
            } else if r == r1 {
                Item::Node(high)
            } else {
                Item::Slot(k)
            }
        };
        for r in r0..r1 {
            down.entry((at(r), r)).or_default().push(at(r + 1));
            up.entry((at(r + 1), r + 1)).or_default().push(at(r));
        }
    }
    let neighbours = |it: &Item, r: usize, above: bool| -> &[Item] {
        let m = if above { &up } else { &down };
        m.get(&(it.clone(), r)).map_or(&[], Vec::as_slice)
    };
    // Orders: barycentres of the neighbours in the previous (then the next) layer.
    for _ in 0..6 {
        for above in [true, false] {
            let range: Vec<usize> = if above { (1..top).collect() } else { (0..top.saturating_sub(1)).rev().collect() };
            for r in range {
                let other = if above { r - 1 } else { r + 1 };
                let position: HashMap<&Item, usize> = layers[other].iter().enumerate().map(|(i, it)| (it, i)).collect();
                let mut keyed: Vec<(f64, usize, Item)> = layers[r]
                    .iter()
                    .enumerate()
                    .map(|(i, it)| {
                        let ps: Vec<f64> = neighbours(it, r, above)
                            .iter()
                            .filter_map(|x| position.get(x))
                            .map(|&i| i as f64)
                            .collect();
                        let key = if ps.is_empty() { i as f64 } else { ps.iter().sum::<f64>() / ps.len() as f64 };
                        (key, i, it.clone())
                    })
                    .collect();
                keyed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                layers[r] = keyed.into_iter().map(|(_, _, it)| it).collect();
            }
        }
    }
    // Sizes along the rank axis (thickness) and across it (extent).
    let lr = p.lr;
    let extent = |it: &Item| match it {
        Item::Node(v) => {
            if lr {
                p.nodes[*v].h
            } else {
                p.nodes[*v].w
            }
        }
        Item::Slot(_) => SLOT,
    };
    let thick: Vec<f64> = layers
        .iter()
        .map(|l| {
            l.iter()
                .filter_map(|it| match it {
                    Item::Node(v) => Some(if lr { p.nodes[*v].w } else { p.nodes[*v].h }),
                    Item::Slot(_) => None,
                })
                .fold(SLOT, f64::max)
        })
        .collect();
    // The gaps: room for the labels of the edges that leave a rank.
    let mut gap = vec![RANKSEP; top];
    let mut label_gap: Vec<Option<usize>> = vec![None; p.edges.len()];
    for (k, e) in p.edges.iter().enumerate() {
        let Some(label) = e.attrs.get("label").filter(|l| !l.is_empty()) else { continue };
        let (r0, r1) = (rank[e.from].min(rank[e.to]), rank[e.from].max(rank[e.to]));
        if r0 == r1 {
            continue;
        }
        let (tw, th) = text_size(label, font(&e.attrs, 12.0));
        gap[r0] = gap[r0].max(if lr { tw + 24.0 } else { th + 24.0 });
        label_gap[k] = Some(r0);
    }
    // Positions across the ranks: packed, then pulled toward the
    // neighbours' mean a few times, keeping the order and the spacing.
    let mut across: Vec<Vec<f64>> = layers
        .iter()
        .map(|l| {
            let mut x = 0.0;
            l.iter()
                .map(|it| {
                    let c = x + extent(it) / 2.0;
                    x += extent(it) + NODESEP;
                    c
                })
                .collect()
        })
        .collect();
    for _ in 0..8 {
        for r in 0..top {
            let mut desired: Vec<f64> = Vec::with_capacity(layers[r].len());
            for (i, it) in layers[r].iter().enumerate() {
                let mut sum = 0.0;
                let mut count = 0.0;
                for (other, above) in [(r.wrapping_sub(1), true), (r + 1, false)] {
                    if other >= top {
                        continue;
                    }
                    for nb in neighbours(it, r, above) {
                        if let Some(j) = layers[other].iter().position(|x| x == nb) {
                            sum += across[other][j];
                            count += 1.0;
                        }
                    }
                }
                desired.push(if count > 0.0 { sum / count } else { across[r][i] });
            }
            // Forward: no closer than the spacing; then shift the layer so
            // that it sits on average where it wants to be.
            let mut xs = desired.clone();
            for i in 1..xs.len() {
                let min = xs[i - 1] + (extent(&layers[r][i - 1]) + extent(&layers[r][i])) / 2.0 + NODESEP;
                if xs[i] < min {
                    xs[i] = min;
                }
            }
            let shift = desired.iter().zip(&xs).map(|(d, x)| d - x).sum::<f64>() / xs.len().max(1) as f64;
            across[r] = xs.iter().map(|x| x + shift).collect();
        }
    }
    squeeze(&layers, &mut across, &extent);
    let lowest = (0..top)
        .flat_map(|r| layers[r].iter().zip(&across[r]).map(|(it, x)| x - extent(it) / 2.0).collect::<Vec<_>>())
        .fold(f64::INFINITY, f64::min);
    let lowest = if lowest.is_finite() { lowest } else { 0.0 };
    let mut start = vec![0.0; top];
    let mut at = 0.0;
    for r in 0..top {
        start[r] = at;
        at += thick[r] + gap[r];
    }
    let along_total = at - gap.last().copied().unwrap_or(0.0);
    let across_total = (0..top)
        .flat_map(|r| layers[r].iter().zip(&across[r]).map(|(it, x)| x + extent(it) / 2.0).collect::<Vec<_>>())
        .fold(0.0, f64::max)
        - lowest;
    let xy = |along: f64, acr: f64| -> (f64, f64) {
        if lr {
            (along, acr - lowest)
        } else {
            (acr - lowest, along)
        }
    };
    let mut centre = vec![(0.0, 0.0); n];
    let mut slot_at: HashMap<(usize, usize), f64> = HashMap::new();
    for r in 0..top {
        for (it, &x) in layers[r].iter().zip(&across[r]) {
            match it {
                Item::Node(v) => centre[*v] = xy(start[r] + thick[r] / 2.0, x),
                Item::Slot(k) => {
                    slot_at.insert((*k, r), x);
                }
            }
        }
    }
    let acr_of = |v: usize| if lr { centre[v].1 + lowest } else { centre[v].0 + lowest };
    let half = |v: usize| if lr { p.nodes[v].w / 2.0 } else { p.nodes[v].h / 2.0 };
    let along_of = |v: usize| if lr { centre[v].0 } else { centre[v].1 };
    // Parallel edges between one pair of nodes: spread across the box side.
    let mut parallel: HashMap<(usize, usize), usize> = HashMap::new();
    let mut paths = Vec::with_capacity(p.edges.len());
    let mut labels = Vec::with_capacity(p.edges.len());
    let mut loops: Vec<(usize, (f64, f64))> = Vec::new();
    for (k, e) in p.edges.iter().enumerate() {
        let key = (e.from.min(e.to), e.from.max(e.to));
        let nth = *parallel.entry(key).and_modify(|c| *c += 1).or_insert(0) as f64;
        let spread = if nth == 0.0 {
            0.0
        } else {
            6.0 * nth.div_euclid(2.0).max(1.0) * if nth % 2.0 == 1.0 { 1.0 } else { -1.0 }
        };
        let (a, b) = (e.from, e.to);
        if a == b {
            // A loop on the far side of the box.
            let (c_al, c_ac, h) = (along_of(a), acr_of(a), half(a));
            let pts = [
                (c_al + h, c_ac - 8.0),
                (c_al + h + 22.0, c_ac - 14.0),
                (c_al + h + 22.0, c_ac + 14.0),
                (c_al + h, c_ac + 8.0),
            ];
            paths.push(pts.iter().map(|&(al, ac)| xy(al, ac)).collect());
            labels.push(None);
            loops.push((k, xy(c_al + h + 26.0, c_ac)));
            continue;
        }
        let (low, high) = if rank[a] <= rank[b] { (a, b) } else { (b, a) };
        let (r0, r1) = (rank[low], rank[high]);
        // Points along the rank axis, from low to high.
        let mut pts: Vec<(f64, f64)> = Vec::new();
        let c0 = acr_of(low) + spread;
        pts.push((along_of(low) + half(low), c0));
        pts.push((start[r0] + thick[r0], c0));
        for r in r0 + 1..r1 {
            let c = slot_at.get(&(k, r)).copied().unwrap_or(c0);
            pts.push((start[r], c));
            pts.push((start[r] + thick[r], c));
        }
        let c1 = acr_of(high) + spread;
        pts.push((start[r1], c1));
        pts.push((along_of(high) - half(high), c1));
        let label = label_gap[k].map(|_| (xy(pts[1].0, pts[1].1), xy(pts[2].0, pts[2].1)));
        let mut path: Vec<(f64, f64)> = pts.into_iter().map(|(al, ac)| xy(al, ac)).collect();
        if low != a {
            path.reverse();
        }
        paths.push(path);
        labels.push(label);
    }
    let (width, height) = if lr { (along_total, across_total) } else { (across_total, along_total) };
    let mut placed = Placed { centre, paths, labels: vec![None; p.edges.len()], width, height };
    for (k, at) in loops {
        placed.labels[k] = Some(at);
    }
    placed.labels = place_labels(p, &placed, &labels);
    fit(p, &mut placed);
    placed
}

/// Closes the bands across the picture that no rank uses (what pulling
/// toward the neighbours may leave between two parts of the graph) down to
/// twice the spacing.
fn squeeze(layers: &[Vec<Item>], across: &mut [Vec<f64>], extent: &dyn Fn(&Item) -> f64) {
    let mut spans: Vec<(f64, f64)> = layers
        .iter()
        .zip(across.iter())
        .flat_map(|(l, xs)| l.iter().zip(xs).map(|(it, &x)| (x - extent(it) / 2.0, x + extent(it) / 2.0)))
        .collect();
    spans.sort_by(|a, b| a.0.total_cmp(&b.0));
    // Each empty band: where it starts and how much to take out of it.
    let mut cuts: Vec<(f64, f64)> = Vec::new();
    let mut reach = f64::NEG_INFINITY;
    for (a, b) in spans {
        if reach.is_finite() && a - reach > 2.0 * NODESEP {
            cuts.push((reach, a - reach - 2.0 * NODESEP));
        }
        reach = reach.max(b);
    }
    for xs in across.iter_mut() {
        for x in xs.iter_mut() {
            *x -= cuts.iter().filter(|c| *x > c.0).map(|c| c.1).sum::<f64>();
        }
    }
}

/// The control points of the cubic that crosses a gap from `a` to `b`:
/// half-way along the rank axis. The SVG draws it (`path_d`) and labels are
/// kept off it (`on_crossing`) with these same points.
pub(super) fn crossing_controls(a: (f64, f64), b: (f64, f64), lr: bool) -> ((f64, f64), (f64, f64)) {
    if lr {
        let m = (a.0 + b.0) / 2.0;
        ((m, a.1), (m, b.1))
    } else {
        let m = (a.1 + b.1) / 2.0;
        ((a.0, m), (b.0, m))
    }
}

/// A point of the gap crossing from `a` to `b` (the curve the SVG draws there).
fn on_crossing(a: (f64, f64), b: (f64, f64), t: f64, lr: bool) -> (f64, f64) {
    let (c1, c2) = crossing_controls(a, b, lr);
    let u = 1.0 - t;
    let f = |p: f64, q: f64, r: f64, s: f64| u * u * u * p + 3.0 * u * u * t * q + 3.0 * u * t * t * r + t * t * t * s;
    (f(a.0, c1.0, c2.0, b.0), f(a.1, c1.1, c2.1, b.1))
}

/// The labels' centres: beside their edge's first gap crossing, at the
/// first of a few places along it that overlaps no box and no label
/// placed before.
fn place_labels(p: &Picture, placed: &Placed, crossings: &[Option<Crossing>]) -> Vec<Option<(f64, f64)>> {
    let mut taken: Vec<[f64; 4]> = p
        .nodes
        .iter()
        .zip(&placed.centre)
        .map(|(n, &(x, y))| [x - n.w / 2.0, y - n.h / 2.0, x + n.w / 2.0, y + n.h / 2.0])
        .collect();
    let overlaps = |r: &[f64; 4], taken: &[[f64; 4]]| {
        taken.iter().any(|o| r[0] < o[2] && o[0] < r[2] && r[1] < o[3] && o[1] < r[3])
    };
    let mut out = Vec::with_capacity(p.edges.len());
    for (k, e) in p.edges.iter().enumerate() {
        let (Some((a, b)), Some(label)) = (crossings.get(k).copied().flatten(), e.attrs.get("label")) else {
            // A loop's label: beside its box.
            out.push(placed.labels.get(k).copied().flatten());
            continue;
        };
        let (tw, th) = text_size(label, font(&e.attrs, 12.0));
        let mut best = None;
        'search: for t in [0.5, 0.35, 0.65, 0.2, 0.8, 0.1, 0.9] {
            let (x, y) = on_crossing(a, b, t, p.lr);
            let sides: [(f64, f64); 2] = if p.lr {
                [(0.0, -th / 2.0 - 2.0), (0.0, th / 2.0 + 2.0)]
            } else {
                [(tw / 2.0 + 4.0, 0.0), (-tw / 2.0 - 4.0, 0.0)]
            };
            for (dx, dy) in sides {
                let (cx, cy) = (x + dx, y + dy);
                let r = [cx - tw / 2.0, cy - th / 2.0, cx + tw / 2.0, cy + th / 2.0];
                if best.is_none() {
                    best = Some(((cx, cy), r));
                }
                if !overlaps(&r, &taken) {
                    best = Some(((cx, cy), r));
                    break 'search;
                }
            }
        }
        let ((cx, cy), r) = best.expect("a candidate");
        taken.push(r);
        out.push(Some((cx, cy)));
    }
    out
}

/// Moves everything so that the boxes, the edges and the labels start at
/// (0, 0), and sizes the picture to hold them all.
fn fit(p: &Picture, placed: &mut Placed) {
    let mut b = [f64::INFINITY, f64::INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY];
    let mut grow = |x0: f64, y0: f64, x1: f64, y1: f64| {
        b = [b[0].min(x0), b[1].min(y0), b[2].max(x1), b[3].max(y1)];
    };
    for (n, &(x, y)) in p.nodes.iter().zip(&placed.centre) {
        grow(x - n.w / 2.0, y - n.h / 2.0, x + n.w / 2.0, y + n.h / 2.0);
    }
    for path in &placed.paths {
        for &(x, y) in path {
            grow(x, y, x, y);
        }
    }
    for (e, at) in p.edges.iter().zip(&placed.labels) {
        if let (Some((x, y)), Some(label)) = (at, e.attrs.get("label")) {
            let (tw, th) = text_size(label, font(&e.attrs, 12.0));
            grow(x - tw / 2.0, y - th / 2.0, x + tw / 2.0, y + th / 2.0);
        }
    }
    if !b[0].is_finite() {
        return;
    }
    let (dx, dy) = (-b[0], -b[1]);
    for c in &mut placed.centre {
        *c = (c.0 + dx, c.1 + dy);
    }
    for path in &mut placed.paths {
        for q in path.iter_mut() {
            *q = (q.0 + dx, q.1 + dy);
        }
    }
    for l in placed.labels.iter_mut().flatten() {
        *l = (l.0 + dx, l.1 + dy);
    }
    placed.width = b[2] - b[0];
    placed.height = b[3] - b[1];
}

/// The two ends of an edge's first gap crossing.
type Crossing = ((f64, f64), (f64, f64));

#[derive(Clone, PartialEq, Eq, Hash, Debug)]
enum Item {
    Node(usize),
    Slot(usize),
}
