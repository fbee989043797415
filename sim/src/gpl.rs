//! GPL, global path planning: A* (petgraph) on the a-priori road graph from
//! the vehicle's pose to the goal, re-planning when the path is found
//! infeasible (a blocked edge), and the events GPRS / GPRT / GPRB / GPCC /
//! GPGL{remaining} describing the path ahead.
//!
//! Edge costs are travel times (length over 10 m/s on road, 4 m/s on
//! cross-country tracks), the heuristic the straight-line distance to
//! the goal edge's end node at 10 m/s (admissible). The start leaves its edge in the direction of the
//! vehicle's heading (no U-turn), unless that way is blocked.

use crate::agent::{Event, Value};
use crate::geom::{wrap_angle, Piece, Pose, Vec2};
use crate::world::{EdgeKind, World};
use petgraph::algo::astar;
use petgraph::graph::{EdgeIndex, NodeIndex};
use petgraph::visit::{EdgeFiltered, EdgeRef};
use serde::Serialize;
use std::collections::BTreeSet;
use std::fmt;

/// One piece of the global path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathPiece {
    /// The road-graph edge it lies on.
    pub edge: EdgeIndex,
    /// Its geometry, oriented along the path (possibly a part of the edge).
    pub piece: Piece,
    /// Road or cross-country track.
    pub kind: EdgeKind,
    /// Arc length of its start along the whole path (m).
    pub s0: f64,
}

/// A global path from the start to the goal.
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalPath {
    /// The pieces, in order.
    pub pieces: Vec<PathPiece>,
    /// Total length (m).
    pub length: f64,
    /// Arc lengths of the junctions (road degree ≥ 3) the path goes through.
    pub junctions: Vec<f64>,
    /// Arc lengths where the path changes from road to track or back.
    pub kind_changes: Vec<f64>,
}

impl GlobalPath {
    fn index_at(&self, s: f64) -> usize {
        let i = self.pieces.partition_point(|p| p.s0 <= s);
        i.saturating_sub(1).min(self.pieces.len().saturating_sub(1))
    }

    /// The piece at arc length `s`.
    pub fn piece_at(&self, s: f64) -> &PathPiece {
        &self.pieces[self.index_at(s)]
    }

    /// The point at arc length `s` (clamped to the path; straight on beyond its end).
    pub fn point(&self, s: f64) -> Vec2 {
        if s > self.length {
            let last = self.pieces[self.pieces.len() - 1].piece;
            return last.end_point() + crate::geom::unit(last.heading(last.length())) * (s - self.length);
        }
        let p = self.piece_at(s);
        p.piece.point(s - p.s0)
    }

    /// The heading at arc length `s`.
    pub fn heading(&self, s: f64) -> f64 {
        let p = self.piece_at(s.min(self.length));
        p.piece.heading(s.min(self.length) - p.s0)
    }

    /// The signed curvature at arc length `s`.
    pub fn curvature(&self, s: f64) -> f64 {
        if s > self.length {
            return 0.0;
        }
        self.piece_at(s).piece.curvature()
    }

    /// Road or track at arc length `s`.
    pub fn kind(&self, s: f64) -> EdgeKind {
        self.piece_at(s.clamp(0.0, self.length)).kind
    }

    /// Projects a point onto the path near `hint` (searching from 10 m behind
    /// to `window` m ahead of it, the whole path when nothing there is within
    /// 10 m): `(s, lateral)`, lateral positive left.
    pub fn project(&self, p: Vec2, hint: f64, window: f64) -> (f64, f64) {
        let mut best: Option<(f64, f64, f64)> = None;
        for pc in &self.pieces {
            let len = pc.piece.length();
            if pc.s0 + len < hint - 10.0 || pc.s0 > hint + window {
                continue;
            }
            let pr = pc.piece.project(p);
            let s = pc.s0 + pr.s;
            let better = match best {
                None => true,
                Some((_, _, d)) => pr.distance < d - 1e-9,
            };
            if better {
                best = Some((s, pr.lateral, pr.distance));
            }
        }
        match best {
            Some((s, l, d)) if d <= 10.0 || window >= self.length + 10.0 => (s, l),
            // Lost the thread (a jump, a re-plan): search the whole path.
            _ if window < self.length + 10.0 => self.project(p, -10.0, self.length + 20.0),
            _ => (hint, 0.0),
        }
    }

    /// The end point (the goal as the map reaches it).
    pub fn end(&self) -> Vec2 {
        self.point(self.length)
    }
}

/// Why GPL found no path.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum GplError {
    /// The world has no road or track.
    NoRoads,
    /// No path to the goal avoids the blocked edges.
    NoPath {
        /// The blocked edges' ids.
        blocked: Vec<String>,
    },
}

impl fmt::Display for GplError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GplError::NoRoads => write!(f, "the map has no road or track"),
            GplError::NoPath { blocked } => write!(f, "no path to the goal avoids the blocked roads {blocked:?}"),
        }
    }
}

impl std::error::Error for GplError {}

/// GPL's events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum GplEvent {
    /// `GPRS`: the path ahead is a straight road.
    Straight,
    /// `GPRT`: the path ahead is a road turn.
    Turn,
    /// `GPRB`: the path ahead takes a branch.
    Branch,
    /// `GPCC`: the path ahead is cross-country.
    CrossCountry,
    /// `GPGL{remaining}`: near the goal.
    Goal {
        /// Distance left along the path (m).
        remaining: f64,
    },
}

impl Event for GplEvent {
    fn name(&self) -> &'static str {
        match self {
            GplEvent::Straight => "GPRS",
            GplEvent::Turn => "GPRT",
            GplEvent::Branch => "GPRB",
            GplEvent::CrossCountry => "GPCC",
            GplEvent::Goal { .. } => "GPGL",
        }
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        match *self {
            GplEvent::Goal { remaining } => vec![("remaining", Value::F64(remaining))],
            _ => vec![],
        }
    }
}

/// GPL's figures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GplConfig {
    /// Speed used for the cost of road edges (m/s).
    pub road_speed: f64,
    /// Speed used for the cost of cross-country tracks (m/s).
    pub track_speed: f64,
    /// GPGL is reported within this distance of the goal (m).
    pub goal_radius: f64,
    /// GPRB is reported this far before a junction (m).
    pub branch_ahead: f64,
    /// GPRT is reported this far before a turn (m).
    pub turn_ahead: f64,
}

impl Default for GplConfig {
    fn default() -> Self {
        GplConfig { road_speed: 10.0, track_speed: 4.0, goal_radius: 30.0, branch_ahead: 40.0, turn_ahead: 20.0 }
    }
}

/// GPL's report for one tick.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct GplReport {
    /// The event.
    pub event: GplEvent,
    /// The vehicle's arc length along the path (m).
    pub s: f64,
    /// Lateral offset from the path (m, left positive).
    pub lateral: f64,
    /// Distance left (m).
    pub remaining: f64,
}

/// The GPL agent.
#[derive(Debug, Clone)]
pub struct Gpl {
    /// Figures.
    pub cfg: GplConfig,
    /// Edges found infeasible.
    pub blocked: BTreeSet<EdgeIndex>,
    /// The current path.
    pub path: Option<GlobalPath>,
    /// The vehicle's progress along it (m).
    pub s: f64,
    /// How many times it planned.
    pub plans: u32,
}

impl Default for Gpl {
    fn default() -> Self {
        Self::new(GplConfig::default())
    }
}

impl Gpl {
    /// A planner with no path yet.
    pub fn new(cfg: GplConfig) -> Self {
        Gpl { cfg, blocked: BTreeSet::new(), path: None, s: 0.0, plans: 0 }
    }

    /// `plan()` / `replan()`: a path from `pose` to the goal avoiding the
    /// blocked edges; it replaces the current one.
    pub fn plan(&mut self, world: &World, pose: &Pose) -> Result<&GlobalPath, GplError> {
        let path = plan_path(world, pose, &self.blocked, &self.cfg)?;
        self.plans += 1;
        self.s = 0.0;
        Ok(self.path.insert(path))
    }

    /// Marks an edge infeasible (e.g. LPL found the road blocked).
    pub fn block(&mut self, edge: EdgeIndex) {
        self.blocked.insert(edge);
    }

    /// The edge of the current path at arc length `s`.
    pub fn edge_at(&self, s: f64) -> Option<EdgeIndex> {
        self.path.as_ref().map(|p| p.piece_at(s).edge)
    }

    /// Where the vehicle is along the path, and the event for the path ahead.
    /// `None` without a path.
    pub fn report(&mut self, world: &World, pose: &Pose) -> Option<GplReport> {
        let path = self.path.as_ref()?;
        let (s, lateral) = path.project(pose.pos(), self.s, 60.0);
        self.s = s;
        let remaining = (path.length - s).max((pose.pos() - world.goal.position).norm().min(path.length - s + 5.0));
        let remaining = remaining.max(0.0);
        let event = if remaining < self.cfg.goal_radius {
            GplEvent::Goal { remaining }
        } else if path.kind(s) == EdgeKind::CrossCountry {
            GplEvent::CrossCountry
        } else if path.junctions.iter().any(|&j| j >= s - 1.0 && j - s <= self.cfg.branch_ahead) {
            GplEvent::Branch
        } else if (0..=((self.cfg.turn_ahead / 2.0) as usize)).any(|k| {
            path.curvature(s + 2.0 * k as f64).abs() >= 0.002 && path.kind(s + 2.0 * k as f64) == EdgeKind::Road
        }) {
            GplEvent::Turn
        } else {
            GplEvent::Straight
        };
        Some(GplReport { event, s, lateral, remaining })
    }
}

fn edge_cost(world: &World, e: EdgeIndex, cfg: &GplConfig) -> f64 {
    let w = &world.roads.graph[e];
    w.piece.length() / if w.kind == EdgeKind::Road { cfg.road_speed } else { cfg.track_speed }
}

/// A* from `pose` to the world's goal avoiding `blocked`.
pub fn plan_path(
    world: &World,
    pose: &Pose,
    blocked: &BTreeSet<EdgeIndex>,
    cfg: &GplConfig,
) -> Result<GlobalPath, GplError> {
    let net = &world.roads;
    let g = &net.graph;
    let (e0, pr0) = net.nearest_edge(pose.pos(), None).ok_or(GplError::NoRoads)?;
    let (ge, prg) = net.nearest_edge(world.goal.position, None).ok_or(GplError::NoRoads)?;
    let (a0, b0) = g.edge_endpoints(e0).ok_or(GplError::NoRoads)?;
    let (ga, gb) = g.edge_endpoints(ge).ok_or(GplError::NoRoads)?;
    let p0 = g[e0].piece;
    let len0 = p0.length();
    let forward = wrap_angle(p0.heading(pr0.s) - pose.theta).cos() >= 0.0;
    let goal_piece = g[ge].piece;
    let glen = goal_piece.length();

    // Candidate: (cost, pieces).
    let mut best: Option<(f64, Vec<(EdgeIndex, Piece)>)> = None;
    // Directions to leave the start edge: forward first; backward (a U-turn)
    // only when the forward way is blocked.
    let dirs: Vec<bool> = if blocked.contains(&e0) { vec![!forward] } else { vec![forward, !forward] };
    for (k, dir) in dirs.iter().enumerate() {
        if k == 1 && best.is_some() {
            break;
        }
        let (exit, first) = if *dir { (b0, p0.sub(pr0.s, len0)) } else { (a0, p0.reversed().sub(len0 - pr0.s, len0)) };
        // Same edge, goal ahead.
        if e0 == ge {
            let ahead = if *dir { prg.s >= pr0.s } else { prg.s <= pr0.s };
            if ahead {
                let piece = if *dir { p0.sub(pr0.s, prg.s) } else { p0.reversed().sub(len0 - pr0.s, len0 - prg.s) };
                let cost = piece.length();
                if best.as_ref().is_none_or(|(c, _)| cost < *c) {
                    best = Some((cost, vec![(e0, piece)]));
                }
                continue;
            }
        }
        let filtered = EdgeFiltered::from_fn(g, |e: petgraph::graph::EdgeReference<'_, _>| {
            !blocked.contains(&e.id()) && e.id() != ge && e.id() != e0
        });
        for (end, last) in [(ga, goal_piece.sub(0.0, prg.s)), (gb, goal_piece.reversed().sub(0.0, glen - prg.s))] {
            let target = g[end].position;
            let heuristic = |n: NodeIndex| (g[n].position - target).norm() / cfg.road_speed;
            let found = astar(&filtered, exit, |n| n == end, |e| edge_cost(world, e.id(), cfg), heuristic);
            let Some((cost, nodes)) = found else { continue };
            let mut pieces = vec![(e0, first)];
            for w in nodes.windows(2) {
                let e = g
                    .edges_connecting(w[0], w[1])
                    .filter(|e| !blocked.contains(&e.id()) && e.id() != ge && e.id() != e0)
                    .min_by(|x, y| x.weight().piece.length().total_cmp(&y.weight().piece.length()))
                    .map(|e| e.id());
                let Some(e) = e else { continue };
                pieces.push((e, net.oriented(e, w[0])));
            }
            if e0 != ge || exit != end {
                pieces.push((ge, last));
            }
            let total = cost + first.length() / cfg.road_speed + last.length() / cfg.road_speed;
            if best.as_ref().is_none_or(|(c, _)| total < *c) {
                best = Some((total, pieces));
            }
        }
    }
    let Some((_, raw)) = best else {
        return Err(GplError::NoPath { blocked: blocked.iter().map(|e| g[*e].id.clone()).collect() });
    };
    let mut pieces = Vec::new();
    let mut s0 = 0.0;
    let mut junctions = Vec::new();
    let mut kind_changes = Vec::new();
    for (i, (e, piece)) in raw.iter().enumerate() {
        let len = piece.length();
        if len < 1e-9 && raw.len() > 1 {
            continue;
        }
        let kind = g[*e].kind;
        if let Some(prev) = pieces.last().map(|p: &PathPiece| p.kind) {
            if prev != kind {
                kind_changes.push(s0);
            }
        }
        // The node at the start of every piece but the first.
        if i > 0 {
            if let Some(n) = g.node_indices().find(|n| (g[*n].position - piece.start_point()).norm() < 1e-6) {
                if net.road_degree(n) >= 3 {
                    junctions.push(s0);
                }
            }
        }
        pieces.push(PathPiece { edge: *e, piece: *piece, kind, s0 });
        s0 += len;
    }
    if pieces.is_empty() {
        return Err(GplError::NoRoads);
    }
    Ok(GlobalPath { pieces, length: s0, junctions, kind_changes })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario;

    #[test]
    fn astar_plans_the_default_mission() {
        let w = scenario::outdoor_default().world;
        let mut gpl = Gpl::default();
        let path = gpl.plan(&w, &w.start).expect("a path").clone();
        let ids: Vec<&str> = path.pieces.iter().map(|p| w.roads.graph[p.edge].id.as_str()).collect();
        assert_eq!(
            ids,
            ["r1", "t1", "r2", "t2", "r4", "c1", "c2"],
            "through the junction to the east, not the dead end"
        );
        assert!((path.end() - w.goal.position).norm() < 1e-6);
        assert_eq!(path.junctions.len(), 1);
        assert_eq!(path.kind_changes.len(), 1);
        // The events along the way.
        let at = |x: f64, y: f64, th: f64, gpl: &mut Gpl| gpl.report(&w, &Pose::new(x, y, th)).expect("report").event;
        assert_eq!(at(50.0, -1.75, 0.0, &mut gpl), GplEvent::Straight);
        assert_eq!(at(290.0, -1.75, 0.0, &mut gpl), GplEvent::Turn);
        assert_eq!(at(341.75, 170.0, 1.57, &mut gpl), GplEvent::Branch);
        assert_eq!(at(560.0, 220.0, 0.0, &mut gpl), GplEvent::CrossCountry);
        match at(740.0, 256.0, 0.38, &mut gpl) {
            GplEvent::Goal { remaining } => assert!((remaining - 10.77).abs() < 0.5, "{remaining}"),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn replans_around_a_blocked_edge() {
        let mut w = scenario::outdoor_default().world;
        // A second way east from J: straight on to K, then a track to the field.
        let k = w.roads.graph.node_indices().find(|n| w.roads.graph[*n].id == "K").expect("K");
        let wn = w.roads.graph.node_indices().find(|n| w.roads.graph[*n].id == "W").expect("W");
        let piece = Piece::Line { a: w.roads.graph[k].position, b: w.roads.graph[wn].position };
        w.roads.graph.add_edge(k, wn, crate::world::RoadEdge { id: "kw".into(), kind: EdgeKind::CrossCountry, piece });
        let mut gpl = Gpl::default();
        let first = gpl.plan(&w, &w.start).expect("path").clone();
        let t2 = first.pieces.iter().find(|p| w.roads.graph[p.edge].id == "t2").expect("via t2").edge;
        gpl.block(t2);
        let pose = Pose::new(341.75, 150.0, std::f64::consts::FRAC_PI_2);
        let second = gpl.plan(&w, &pose).expect("re-planned").clone();
        let ids: Vec<&str> = second.pieces.iter().map(|p| w.roads.graph[p.edge].id.as_str()).collect();
        assert_eq!(ids, ["r2", "r3", "kw", "c2"]);
        assert_eq!(gpl.plans, 2);
        // Block that way too: no path.
        let r3 = second.pieces[1].edge;
        gpl.block(r3);
        let err = gpl.plan(&w, &pose).expect_err("no way left");
        assert!(err.to_string().contains("t2") && err.to_string().contains("r3"), "{err}");
    }
}
