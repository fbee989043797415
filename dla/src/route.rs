//! The deliberative planners of DLA: a route planner over the topological
//! map (the succession of regions to cross) and a path planner between
//! consecutive regions on the metric map by potential fields (Poncela et
//! al. 2002).
//!
//! The route is an A* search (petgraph) on the adjacency graph of the
//! regions the robot may cross: free regions, and unexplored ones at a
//! higher cost when allowed. An edge costs the distance between the two
//! centroids, times [`RouteParams::unexplored_cost`] when it touches an
//! unexplored region; the heuristic, the straight distance to the goal
//! region's centroid, is admissible.
//!
//! The path descends, cell by cell on the grid, a potential attractive to
//! the next region's centroid (to the goal in the last region) and
//! repulsive near occupied cells, moving only through the route's regions
//! and never cutting the corner of a cell it may not enter. When the
//! descent is stuck (a local minimum, such as the inside of a U-shaped
//! obstacle, or a cell already visited) it falls back to a wavefront
//! search (Dijkstra, moves dearer near obstacles: through the middle of a
//! door) to the next region or the goal.

use super::grid::{CellClass, OccupancyGrid};
use super::pyramid::{Pyramid, RegionClass};
use petgraph::graph::{NodeIndex, UnGraph};
use situ_sim::geom::Vec2;
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Options of the route planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RouteParams {
    /// Whether the route may cross unexplored regions.
    pub allow_unexplored: bool,
    /// Factor (≥ 1) on the cost of an edge that touches an unexplored region.
    pub unexplored_cost: f64,
}

impl Default for RouteParams {
    fn default() -> Self {
        RouteParams { allow_unexplored: false, unexplored_cost: 3.0 }
    }
}

fn traversable(class: RegionClass, params: &RouteParams) -> bool {
    match class {
        RegionClass::Free => true,
        RegionClass::Unexplored => params.allow_unexplored,
        RegionClass::Occupied => false,
    }
}

/// The sequence of regions from the region of `start` to that of `goal`
/// (both points in metres on `grid`, the grid `pyramid` was built from), or
/// `None` when a point is off the grid, in a region the robot may not
/// cross, or the goal cannot be reached.
pub fn plan_route(
    pyramid: &Pyramid,
    grid: &OccupancyGrid,
    start: Vec2,
    goal: Vec2,
    params: &RouteParams,
) -> Option<Vec<usize>> {
    let from = pyramid.region_at(grid, start)?;
    let to = pyramid.region_at(grid, goal)?;
    let regions = pyramid.regions();
    if !traversable(regions[from].class, params) || !traversable(regions[to].class, params) {
        return None;
    }
    if from == to {
        return Some(vec![from]);
    }
    let mut graph: UnGraph<usize, f64> = UnGraph::default();
    let mut node = vec![NodeIndex::end(); regions.len()];
    for r in regions.iter().filter(|r| traversable(r.class, params)) {
        node[r.id] = graph.add_node(r.id);
    }
    let factor = params.unexplored_cost.max(1.0);
    for r in regions.iter().filter(|r| traversable(r.class, params)) {
        for &n in pyramid.neighbours(r.id) {
            if n > r.id && traversable(regions[n].class, params) {
                let mut cost = (r.centroid - regions[n].centroid).norm();
                if r.class == RegionClass::Unexplored || regions[n].class == RegionClass::Unexplored {
                    cost *= factor;
                }
                graph.add_edge(node[r.id], node[n], cost);
            }
        }
    }
    let target = regions[to].centroid;
    let (_, nodes) = petgraph::algo::astar(
        &graph,
        node[from],
        |n| n == node[to],
        |e| *e.weight(),
        |n| (regions[graph[n]].centroid - target).norm(),
    )?;
    Some(nodes.into_iter().map(|n| graph[n]).collect())
}

/// Options of the potential-field path planner.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathParams {
    /// Gain of the attractive potential (per metre to the target).
    pub attractive: f64,
    /// Gain of the repulsive potential.
    pub repulsive: f64,
    /// Distance (m) beyond which occupied cells do not repel.
    pub influence: f64,
    /// Largest number of descent steps per leg before falling back to the
    /// wavefront search.
    pub max_steps: usize,
}

impl Default for PathParams {
    fn default() -> Self {
        PathParams { attractive: 1.0, repulsive: 0.5, influence: 1.0, max_steps: 100_000 }
    }
}

/// Distance (in cells) from every cell to the nearest occupied cell, by a
/// two-pass chamfer transform (weights 1 and √2); `f32::INFINITY` when the
/// grid has no occupied cell.
pub fn obstacle_distance(grid: &OccupancyGrid) -> Vec<f32> {
    let (w, h) = (grid.width(), grid.height());
    let mut d: Vec<f32> =
        (0..w * h).map(|i| if grid.class_index(i) == CellClass::Occupied { 0.0 } else { f32::INFINITY }).collect();
    let s2 = std::f32::consts::SQRT_2;
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let mut v = d[i];
            if x > 0 {
                v = v.min(d[i - 1] + 1.0);
            }
            if y > 0 {
                v = v.min(d[i - w] + 1.0);
                if x > 0 {
                    v = v.min(d[i - w - 1] + s2);
                }
                if x + 1 < w {
                    v = v.min(d[i - w + 1] + s2);
                }
            }
            d[i] = v;
        }
    }
    for y in (0..h).rev() {
        for x in (0..w).rev() {
            let i = y * w + x;
            let mut v = d[i];
            if x + 1 < w {
                v = v.min(d[i + 1] + 1.0);
            }
            if y + 1 < h {
                v = v.min(d[i + w] + 1.0);
                if x + 1 < w {
                    v = v.min(d[i + w + 1] + s2);
                }
                if x > 0 {
                    v = v.min(d[i + w - 1] + s2);
                }
            }
            d[i] = v;
        }
    }
    d
}

const MOVES: [(i64, i64); 8] = [(1, 0), (0, 1), (-1, 0), (0, -1), (1, 1), (-1, 1), (-1, -1), (1, -1)];

/// The cells reachable in one move from cell `i` among `allowed`: the eight
/// neighbours, a diagonal only when both cells beside it are allowed.
fn moves(w: usize, h: usize, allowed: &[bool], i: usize) -> impl Iterator<Item = usize> + '_ {
    let (x, y) = ((i % w) as i64, (i / w) as i64);
    MOVES.iter().filter_map(move |&(dx, dy)| {
        let (nx, ny) = (x + dx, y + dy);
        if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
            return None;
        }
        let n = ny as usize * w + nx as usize;
        if !allowed[n] {
            return None;
        }
        if dx != 0 && dy != 0 {
            let a = y as usize * w + nx as usize;
            let b = ny as usize * w + x as usize;
            if !allowed[a] || !allowed[b] {
                return None;
            }
        }
        Some(n)
    })
}

/// The cheapest chain of moves from `from` to the first cell where `done`
/// holds (Dijkstra): a move costs its length (1 or √2 cells), more near
/// obstacles, so that the fallback keeps to the middle of a door rather
/// than shaving its jamb: within `influence` cells of an occupied cell a
/// move costs `1 + 4 (1 − d / influence)²` times its length, `d` the cell's
/// distance to the nearest occupied one (`dist`, in cells).
fn wavefront(
    w: usize,
    h: usize,
    allowed: &[bool],
    dist: &[f32],
    influence: f32,
    from: usize,
    done: impl Fn(usize) -> bool,
) -> Option<Vec<usize>> {
    let mut parent = vec![u32::MAX; w * h];
    let mut cost = vec![f32::INFINITY; w * h];
    parent[from] = from as u32;
    cost[from] = 0.0;
    // Costs are non-negative f32: their bits order as the numbers do.
    let mut queue = BinaryHeap::from([Reverse((0u32, from))]);
    while let Some(Reverse((bits, c))) = queue.pop() {
        let here = f32::from_bits(bits);
        if here > cost[c] {
            continue;
        }
        if c != from && done(c) {
            let mut path = vec![c];
            let mut k = c;
            while parent[k] as usize != from {
                k = parent[k] as usize;
                path.push(k);
            }
            path.reverse();
            return Some(path);
        }
        for n in moves(w, h, allowed, c) {
            let length = if n % w != c % w && n / w != c / w { std::f32::consts::SQRT_2 } else { 1.0 };
            let near = (1.0 - dist[n] / influence).max(0.0);
            let next = here + length * (1.0 + 4.0 * near * near);
            if next < cost[n] {
                cost[n] = next;
                parent[n] = c as u32;
                queue.push(Reverse((next.to_bits(), n)));
            }
        }
    }
    None
}

/// A path from `start` to `goal` (metres) through the regions of `route`
/// (as returned by [`plan_route`]), by potential fields with a wavefront
/// fallback: the centres of the cells crossed, each a move of one cell
/// (straight or diagonal) from the last, starting at `start` and ending at
/// `goal` exactly. `None` when `start` is not in the route's first region,
/// `goal` not in its last, or the route's regions do not connect them.
pub fn plan_path(
    grid: &OccupancyGrid,
    pyramid: &Pyramid,
    route: &[usize],
    start: Vec2,
    goal: Vec2,
    params: &PathParams,
) -> Option<Vec<Vec2>> {
    let (w, h) = (grid.width(), grid.height());
    let (first, last) = (*route.first()?, *route.last()?);
    let (sx, sy) = grid.cell_of(start)?;
    let (gx, gy) = grid.cell_of(goal)?;
    if pyramid.region_of(sx, sy) != first || pyramid.region_of(gx, gy) != last {
        return None;
    }
    // Where each route region first appears, and the cells one may enter.
    let mut position = vec![usize::MAX; pyramid.regions().len()];
    for (k, &r) in route.iter().enumerate() {
        if position[r] == usize::MAX {
            position[r] = k;
        }
    }
    let mut allowed = vec![false; w * h];
    for &r in route {
        if pyramid.region(r).class == RegionClass::Occupied {
            return None;
        }
        for &c in pyramid.cells(r) {
            allowed[c as usize] = grid.class_index(c as usize) != CellClass::Occupied;
        }
    }
    let dist = obstacle_distance(grid);
    let cell = grid.cell_size();
    let potential = |c: usize, target: Vec2| -> f64 {
        let p = grid.center(c % w, c / w);
        let mut u = params.attractive * (p - target).norm();
        let d = (dist[c] as f64 * cell).max(cell * 0.5);
        if d < params.influence {
            let k = 1.0 / d - 1.0 / params.influence;
            u += params.repulsive * k * k;
        }
        u
    };
    let goal_cell = gy * w + gx;
    let mut path = vec![sy * w + sx];
    let mut current = path[0];
    let mut leg = 0usize;
    let mut visited = vec![u32::MAX; w * h];
    while current != goal_cell {
        let (target, next_region) = if leg + 1 < route.len() {
            (pyramid.region(route[leg + 1]).centroid, Some(route[leg + 1]))
        } else {
            (goal, None)
        };
        let reached = |c: usize| match next_region {
            Some(r) => pyramid.region_of_index(c) == r,
            None => c == goal_cell,
        };
        visited[current] = leg as u32;
        let mut steps = 0;
        let mut stuck = false;
        while !reached(current) {
            let here = potential(current, target);
            let best = moves(w, h, &allowed, current)
                .filter(|&n| visited[n] != leg as u32)
                .map(|n| (potential(n, target), n))
                .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            match best {
                Some((u, n)) if u < here && steps < params.max_steps => {
                    current = n;
                    visited[n] = leg as u32;
                    path.push(n);
                    steps += 1;
                }
                _ => {
                    stuck = true;
                    break;
                }
            }
        }
        if stuck {
            let influence = (params.influence / cell) as f32;
            let tail = wavefront(w, h, &allowed, &dist, influence, current, reached)?;
            current = *tail.last().expect("a found path is not empty");
            path.extend(tail);
        }
        // Entering a later region of the route skips the legs between.
        let at = position[pyramid.region_of_index(current)];
        leg = if at != usize::MAX && at > leg { at } else { leg + 1 };
        if leg >= route.len() {
            leg = route.len() - 1;
        }
    }
    let mut points: Vec<Vec2> = path.iter().map(|&c| grid.center(c % w, c / w)).collect();
    points[0] = start;
    if points.len() == 1 {
        points.push(goal);
    } else {
        *points.last_mut().expect("not empty") = goal;
    }
    Some(points)
}
