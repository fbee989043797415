//! The world: a road network (a petgraph graph whose edges carry geometry),
//! cross-country areas, static and moving obstacles, a start and a goal, and
//! the queries the sensors and planners need.
//!
//! Roads are undirected (drivable both ways) and `lane_width × lanes` wide,
//! centred on their edge's geometry; their surface is the set of points
//! within half that width of a road edge (so road ends are rounded).
//! Cross-country *tracks* are edges too (kind [`EdgeKind::CrossCountry`]):
//! the a-priori global map's way across an area, used by GPL; they are not
//! road surface.

use crate::geom::{
    contains, densify, dist_point_polygon, polygon_distance, polygons_intersect, unit, v2, wrap_angle, Piece, Pose,
    Vec2,
};
use crate::vehicle::VehicleParams;
use petgraph::graph::{EdgeIndex, NodeIndex, UnGraph};
use petgraph::visit::EdgeRef;
use serde::Serialize;
use std::f64::consts::PI;

/// A node of the road network: a junction, a road end, or a point where the
/// geometry changes (straight to arc).
#[derive(Debug, Clone, PartialEq)]
pub struct RoadNode {
    /// The scenario's name for it.
    pub id: String,
    /// Position (m).
    pub position: Vec2,
}

/// What an edge is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum EdgeKind {
    /// Road surface.
    Road,
    /// A cross-country track of the global map (not road surface).
    CrossCountry,
}

/// An edge of the road network: its geometry runs from the graph edge's
/// source node to its target node.
#[derive(Debug, Clone, PartialEq)]
pub struct RoadEdge {
    /// The scenario's name for it.
    pub id: String,
    /// Road or cross-country track.
    pub kind: EdgeKind,
    /// Geometry from the source node to the target node.
    pub piece: Piece,
}

/// The road network.
#[derive(Debug, Clone)]
pub struct RoadNetwork {
    /// Nodes and edges with geometry.
    pub graph: UnGraph<RoadNode, RoadEdge>,
    /// Width of one lane (m).
    pub lane_width: f64,
    /// Number of lanes (traffic keeps right: with two lanes or more the
    /// planners drive the centre of the rightmost lane).
    pub lanes: u32,
}

impl RoadNetwork {
    /// Half the road width (m).
    pub fn half_width(&self) -> f64 {
        self.lane_width * self.lanes as f64 / 2.0
    }

    /// The lateral offset of the driving lane from the centre line (m,
    /// negative is right).
    pub fn lane_offset(&self) -> f64 {
        if self.lanes >= 2 {
            -self.lane_width * (self.lanes as f64 - 1.0) / 2.0
        } else {
            0.0
        }
    }

    /// The number of road (not track) edges at a node.
    pub fn road_degree(&self, n: NodeIndex) -> usize {
        self.graph.edges(n).filter(|e| e.weight().kind == EdgeKind::Road).count()
    }

    /// The geometry of an edge travelled away from node `from`.
    pub fn oriented(&self, e: EdgeIndex, from: NodeIndex) -> Piece {
        let (a, _) = self.graph.edge_endpoints(e).unwrap_or((from, from));
        let piece = self.graph[e].piece;
        if a == from {
            piece
        } else {
            piece.reversed()
        }
    }

    /// The other end of an edge.
    pub fn other_end(&self, e: EdgeIndex, n: NodeIndex) -> NodeIndex {
        match self.graph.edge_endpoints(e) {
            Some((a, b)) if a == n => b,
            Some((a, _)) => a,
            None => n,
        }
    }

    /// The nearest edge to a point, of the given kind (any kind with `None`),
    /// with the projection onto it. Ties go to the lower edge index.
    pub fn nearest_edge(&self, p: Vec2, kind: Option<EdgeKind>) -> Option<(EdgeIndex, crate::geom::Projection)> {
        let mut best: Option<(EdgeIndex, crate::geom::Projection)> = None;
        for e in self.graph.edge_references() {
            if kind.is_some_and(|k| e.weight().kind != k) {
                continue;
            }
            let pr = e.weight().piece.project(p);
            if best.as_ref().is_none_or(|(_, b)| pr.distance < b.distance) {
                best = Some((e.id(), pr));
            }
        }
        best
    }

    /// Whether a point is on the road surface.
    pub fn on_road(&self, p: Vec2) -> bool {
        let hw = self.half_width();
        self.graph
            .edge_references()
            .any(|e| e.weight().kind == EdgeKind::Road && e.weight().piece.project(p).distance <= hw)
    }
}

/// An off-road area the vehicle may cross.
#[derive(Debug, Clone, PartialEq)]
pub struct Area {
    /// The scenario's name for it.
    pub id: String,
    /// Boundary polygon.
    pub polygon: Vec<Vec2>,
}

/// How an obstacle moves.
#[derive(Debug, Clone, PartialEq)]
pub enum Motion {
    /// It stays where its polygon is.
    Static,
    /// Its polygon, given at the path's first waypoint, is carried along the
    /// path at a constant speed.
    Path {
        /// Waypoints (m), at least two.
        waypoints: Vec<Vec2>,
        /// Speed along the path (m/s).
        speed: f64,
        /// What happens at the path's end.
        repeat: Repeat,
    },
}

/// What a moving obstacle does at the end of its path.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Repeat {
    /// Stops there.
    Stop,
    /// Jumps back to the start.
    Loop,
    /// Comes back along the path, and again.
    PingPong,
}

/// An obstacle: a polygon with a height, static or moving.
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacle {
    /// The scenario's name for it.
    pub id: String,
    /// Polygon at time 0 (m).
    pub polygon: Vec<Vec2>,
    /// Height (m).
    pub height: f64,
    /// Static or moving.
    pub motion: Motion,
}

impl Obstacle {
    /// The translation of the polygon at time `t` (s).
    pub fn offset_at(&self, t: f64) -> Vec2 {
        match &self.motion {
            Motion::Static => Vec2::zeros(),
            Motion::Path { waypoints, speed, repeat } => {
                let lens: Vec<f64> = waypoints.windows(2).map(|w| (w[1] - w[0]).norm()).collect();
                let total: f64 = lens.iter().sum();
                if total <= 0.0 {
                    return Vec2::zeros();
                }
                let d = speed * t.max(0.0);
                let s = match repeat {
                    Repeat::Stop => d.min(total),
                    Repeat::Loop => d.rem_euclid(total),
                    Repeat::PingPong => {
                        let m = d.rem_euclid(2.0 * total);
                        if m <= total {
                            m
                        } else {
                            2.0 * total - m
                        }
                    }
                };
                let mut acc = 0.0;
                for (i, l) in lens.iter().enumerate() {
                    if s <= acc + l || i + 1 == lens.len() {
                        let f = if *l > 0.0 { ((s - acc) / l).clamp(0.0, 1.0) } else { 0.0 };
                        return waypoints[i] + (waypoints[i + 1] - waypoints[i]) * f - waypoints[0];
                    }
                    acc += l;
                }
                Vec2::zeros()
            }
        }
    }
}

/// An obstacle where it is at one instant.
#[derive(Debug, Clone, PartialEq)]
pub struct ObstacleView {
    /// Index into [`World::obstacles`] (the simulation's ground-truth track id).
    pub index: usize,
    /// Polygon (m).
    pub polygon: Vec<Vec2>,
    /// Height (m).
    pub height: f64,
    /// Centre of the bounding circle.
    pub center: Vec2,
    /// Radius of the bounding circle.
    pub radius: f64,
}

/// The goal of the mission.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Goal {
    /// Position (m).
    pub position: Vec2,
    /// Reached within this distance (m).
    pub tolerance: f64,
    /// Orientation wanted at the goal, if any (rad).
    pub heading: Option<f64>,
}

/// What the road ahead of a pose looks like: the ground truth behind RFCCD.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum RoadAhead {
    /// On a road that runs straight ahead.
    Straight,
    /// On or just before a turn.
    Turn {
        /// |curvature| of the turn (1/m).
        curvature: f64,
        /// True when the road turns left.
        left: bool,
    },
    /// A junction of three roads or more ahead.
    Branch {
        /// Distance along the road to the junction (m).
        distance: f64,
    },
    /// Not on a road.
    None,
}

/// How far ahead [`World::road_ahead`] looks.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RoadLookahead {
    /// A junction within this distance is a branch (m).
    pub branch: f64,
    /// An arc starting within this distance is a turn (m).
    pub turn: f64,
    /// Arcs gentler than this curvature count as straight (1/m).
    pub min_curvature: f64,
}

impl Default for RoadLookahead {
    fn default() -> Self {
        RoadLookahead { branch: 30.0, turn: 15.0, min_curvature: 0.002 }
    }
}

/// An obstacle as seen from a vehicle pose: the geometry behind LADAR and STCCD.
#[derive(Debug, Clone, PartialEq)]
pub struct CorridorHit {
    /// Index into [`World::obstacles`].
    pub index: usize,
    /// Euclidean distance from the sensor to the nearest point of the obstacle (m).
    pub range: f64,
    /// Bearing of that point in the vehicle frame (rad).
    pub bearing: f64,
    /// Distance along the swept corridor to the first point of the obstacle
    /// inside it, if any (m).
    pub corridor: Option<f64>,
    /// Extent of the obstacle across the line of sight (m).
    pub width: f64,
    /// The obstacle's polygon, clipped to nothing: the true polygon (m).
    pub polygon: Vec<Vec2>,
    /// Height (m).
    pub height: f64,
}

/// The swept corridor a sensor tests against: the band of half-width
/// `half_width` around the arc of curvature `curvature` that starts at the
/// sensor, from 0 to `length` metres along it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corridor {
    /// Curvature of the swept arc (1/m, positive left).
    pub curvature: f64,
    /// Half-width of the band (m).
    pub half_width: f64,
    /// Length along the arc (m).
    pub length: f64,
}

impl Corridor {
    /// Arc-length and lateral coordinates of a point given in the sensor
    /// frame (x forward, y left): `(s, l)`.
    pub fn coords(&self, p: Vec2) -> (f64, f64) {
        let k = self.curvature;
        if k.abs() < 1e-6 {
            return (p.x, p.y);
        }
        let r = 1.0 / k;
        // Centre at (0, r); angle swept from the start point.
        let d = v2(p.x, p.y - r);
        let phi = if k > 0.0 { d.x.atan2(-d.y) } else { d.x.atan2(d.y) };
        let s = phi * r.abs();
        let l = r.abs() - d.norm();
        (s, if k > 0.0 { l } else { -l })
    }
}

/// The whole world of one scenario.
#[derive(Debug, Clone)]
pub struct World {
    /// Scenario name.
    pub name: String,
    /// Roads and tracks.
    pub roads: RoadNetwork,
    /// Cross-country areas.
    pub areas: Vec<Area>,
    /// Obstacles.
    pub obstacles: Vec<Obstacle>,
    /// Areas where the GPS has no fix.
    pub gps_outages: Vec<Vec<Vec2>>,
    /// Start pose of the vehicle.
    pub start: Pose,
    /// The goal.
    pub goal: Goal,
    /// The vehicle.
    pub vehicle: VehicleParams,
}

/// Where a point is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Terrain {
    /// On road surface.
    Road,
    /// In a cross-country area (and not on a road).
    CrossCountry,
    /// Neither: off the map.
    Off,
}

impl World {
    /// Whether a point is on road, cross-country, or off the map.
    pub fn terrain(&self, p: Vec2) -> Terrain {
        if self.roads.on_road(p) {
            Terrain::Road
        } else if self.areas.iter().any(|a| contains(&a.polygon, p)) {
            Terrain::CrossCountry
        } else {
            Terrain::Off
        }
    }

    /// The obstacles where they are at time `t`, into `out` (reused).
    pub fn obstacles_at(&self, t: f64, out: &mut Vec<ObstacleView>) {
        out.clear();
        for (index, o) in self.obstacles.iter().enumerate() {
            let off = o.offset_at(t);
            let polygon: Vec<Vec2> = o.polygon.iter().map(|p| p + off).collect();
            let center = crate::geom::vertex_centroid(&polygon);
            let radius = polygon.iter().map(|p| (p - center).norm()).fold(0.0, f64::max);
            out.push(ObstacleView { index, polygon, height: o.height, center, radius });
        }
    }

    /// The road ahead of a pose (see [`RoadAhead`]).
    pub fn road_ahead(&self, pose: &Pose, look: &RoadLookahead) -> RoadAhead {
        let net = &self.roads;
        let p = pose.pos();
        let hw = net.half_width();
        // The road edge under the vehicle: the nearest, ties broken by heading.
        let mut best: Option<(EdgeIndex, crate::geom::Projection, f64)> = None;
        for e in net.graph.edge_references() {
            if e.weight().kind != EdgeKind::Road {
                continue;
            }
            let pr = e.weight().piece.project(p);
            if pr.distance > hw {
                continue;
            }
            let align = wrap_angle(e.weight().piece.heading(pr.s) - pose.theta).cos().abs();
            let score = pr.distance - 0.5 * align;
            if best.as_ref().is_none_or(|b| score < b.2) {
                best = Some((e.id(), pr, score));
            }
        }
        let Some((edge, pr, _)) = best else { return RoadAhead::None };
        let (a, b) = net.graph.edge_endpoints(edge).unwrap_or_default();
        let piece = net.graph[edge].piece;
        let forward = wrap_angle(piece.heading(pr.s) - pose.theta).cos() >= 0.0;
        let (mut node, mut piece_dir, mut travelled) =
            if forward { (b, piece, piece.length() - pr.s) } else { (a, piece.reversed(), pr.s) };
        let mut cur_edge = edge;
        if piece_dir.curvature().abs() >= look.min_curvature {
            let k = piece_dir.curvature();
            return RoadAhead::Turn { curvature: k.abs(), left: k > 0.0 };
        }
        // Walk ahead along the road, node by node.
        for _ in 0..16 {
            let deg = net.road_degree(node);
            if deg >= 3 {
                if travelled <= look.branch {
                    return RoadAhead::Branch { distance: travelled };
                }
                return RoadAhead::Straight;
            }
            if deg < 2 {
                return RoadAhead::Straight;
            }
            let Some(next) =
                net.graph.edges(node).find(|e| e.id() != cur_edge && e.weight().kind == EdgeKind::Road).map(|e| e.id())
            else {
                return RoadAhead::Straight;
            };
            let np = net.oriented(next, node);
            if np.curvature().abs() >= look.min_curvature && travelled <= look.turn {
                let k = np.curvature();
                return RoadAhead::Turn { curvature: k.abs(), left: k > 0.0 };
            }
            travelled += np.length();
            if travelled > look.branch.max(look.turn) {
                return RoadAhead::Straight;
            }
            node = net.other_end(next, node);
            cur_edge = next;
            piece_dir = np;
        }
        let _ = piece_dir;
        RoadAhead::Straight
    }

    /// The obstacles seen from a sensor at `pose` within `range` and a field
    /// of view of `fov` radians centred on the heading, with their distance
    /// along `corridor`. Obstacles are sampled along their boundary every
    /// 0.2 m (their inside counts when the sensor is in it).
    pub fn obstacles_seen(
        &self,
        pose: &Pose,
        views: &[ObstacleView],
        range: f64,
        fov: f64,
        corridor: &Corridor,
        scratch: &mut Vec<Vec2>,
    ) -> Vec<CorridorHit> {
        let mut hits = Vec::new();
        let p0 = pose.pos();
        for o in views {
            if (o.center - p0).norm() - o.radius > range {
                continue;
            }
            densify(&o.polygon, 0.2, scratch);
            let inside = contains(&o.polygon, p0);
            let mut best_range = f64::INFINITY;
            let mut best_bearing = 0.0;
            let mut corr: Option<f64> = if inside { Some(0.0) } else { None };
            let (mut lmin, mut lmax) = (f64::INFINITY, f64::NEG_INFINITY);
            let mut visible = inside;
            for &q in scratch.iter() {
                let loc = pose.to_local(q);
                let r = loc.norm();
                let b = loc.y.atan2(loc.x);
                if r > range || b.abs() > fov / 2.0 {
                    continue;
                }
                visible = true;
                if r < best_range {
                    best_range = r;
                    best_bearing = b;
                }
                lmin = lmin.min(loc.y);
                lmax = lmax.max(loc.y);
                let (s, l) = corridor.coords(loc);
                if s >= 0.0 && s <= corridor.length && l.abs() <= corridor.half_width {
                    corr = Some(corr.map_or(s, |c: f64| c.min(s)));
                }
            }
            if !visible {
                continue;
            }
            if inside {
                best_range = 0.0;
            }
            hits.push(CorridorHit {
                index: o.index,
                range: best_range,
                bearing: best_bearing,
                corridor: corr,
                width: if lmax >= lmin { lmax - lmin } else { 0.0 },
                polygon: o.polygon.clone(),
                height: o.height,
            });
        }
        hits
    }

    /// The first obstacle (higher than the vehicle's clearance) whose polygon
    /// overlaps the vehicle's footprint at `pose`.
    pub fn collision(&self, pose: &Pose, views: &[ObstacleView]) -> Option<usize> {
        let fp = self.vehicle.footprint(pose);
        let c = pose.to_world(v2((self.vehicle.front - self.vehicle.rear) / 2.0, 0.0));
        let rfp = (self.vehicle.front + self.vehicle.rear).hypot(self.vehicle.width) / 2.0;
        views
            .iter()
            .filter(|o| o.height > self.vehicle.clearance && (o.center - c).norm() <= o.radius + rfp)
            .find(|o| polygons_intersect(&fp, &o.polygon))
            .map(|o| o.index)
    }

    /// The smallest distance between the vehicle's footprint and any obstacle
    /// higher than its clearance, and that obstacle's index.
    pub fn closest_obstacle(&self, pose: &Pose, views: &[ObstacleView]) -> Option<(f64, usize)> {
        let fp = self.vehicle.footprint(pose);
        let c = pose.to_world(v2((self.vehicle.front - self.vehicle.rear) / 2.0, 0.0));
        let mut best: Option<(f64, usize)> = None;
        for o in views.iter().filter(|o| o.height > self.vehicle.clearance) {
            // Bounding circles bound the distance from below: skip hopeless ones.
            let lower =
                (o.center - c).norm() - o.radius - (self.vehicle.front + self.vehicle.rear).hypot(self.vehicle.width);
            if best.is_some_and(|(d, _)| lower > d) {
                continue;
            }
            let d = polygon_distance(&fp, &o.polygon);
            if best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, o.index));
            }
        }
        best
    }

    /// Time to collision at the current velocity: how long, driving straight
    /// on at speed `v`, until the footprint touches an obstacle higher than
    /// the clearance (`None` when standing or nothing is in the way within
    /// `horizon` metres).
    pub fn time_to_collision(&self, pose: &Pose, v: f64, views: &[ObstacleView], horizon: f64) -> Option<f64> {
        if v <= 1e-6 {
            return None;
        }
        let corridor = Corridor { curvature: 0.0, half_width: self.vehicle.width / 2.0, length: horizon };
        let mut best: Option<f64> = None;
        let mut scratch = Vec::new();
        for o in views.iter().filter(|o| o.height > self.vehicle.clearance) {
            if (o.center - pose.pos()).norm() - o.radius > horizon + self.vehicle.front {
                continue;
            }
            densify(&o.polygon, 0.1, &mut scratch);
            for &q in &scratch {
                let loc = pose.to_local(q);
                let (s, l) = corridor.coords(loc);
                if l.abs() <= corridor.half_width && s >= -self.vehicle.rear {
                    let gap = (s - self.vehicle.front).max(0.0);
                    if gap <= horizon {
                        best = Some(best.map_or(gap, |b: f64| b.min(gap)));
                    }
                }
            }
        }
        best.map(|d| d / v)
    }

    /// Whether the GPS has a fix at a point.
    pub fn gps_fix(&self, p: Vec2) -> bool {
        !self.gps_outages.iter().any(|poly| contains(poly, p))
    }

    /// The rectangle holding every road, area and obstacle, the start and
    /// the goal: `(min, max)`.
    pub fn bounds(&self) -> (Vec2, Vec2) {
        let mut lo = v2(f64::INFINITY, f64::INFINITY);
        let mut hi = v2(f64::NEG_INFINITY, f64::NEG_INFINITY);
        let mut add = |p: Vec2, m: f64| {
            lo = v2(lo.x.min(p.x - m), lo.y.min(p.y - m));
            hi = v2(hi.x.max(p.x + m), hi.y.max(p.y + m));
        };
        let hw = self.roads.half_width();
        for e in self.roads.graph.edge_weights() {
            for p in e.piece.sample(2.0) {
                add(p, hw);
            }
        }
        for a in &self.areas {
            for &p in &a.polygon {
                add(p, 0.0);
            }
        }
        for o in &self.obstacles {
            for &p in &o.polygon {
                add(p, 0.0);
            }
            if let Motion::Path { waypoints, .. } = &o.motion {
                for w in waypoints {
                    add(w + (o.polygon.first().copied().unwrap_or_default() - waypoints[0]), 1.0);
                }
            }
        }
        add(self.start.pos(), 2.0);
        add(self.goal.position, 2.0);
        (lo, hi)
    }

    /// Distance from a point to the nearest obstacle polygon at time `t`
    /// (metres; infinity when there is none).
    pub fn distance_to_obstacles(&self, p: Vec2, views: &[ObstacleView]) -> f64 {
        views.iter().map(|o| dist_point_polygon(&o.polygon, p)).fold(f64::INFINITY, f64::min)
    }
}

/// A unit vector to the left of heading `theta`.
pub fn left_of(theta: f64) -> Vec2 {
    unit(theta + PI / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{circle_polygon, rect_polygon};

    fn small_world() -> World {
        // A straight road A→B (100 m east), a left turn B→C of radius 30,
        // and at A a junction with two more roads: a branch.
        let mut g = UnGraph::new_undirected();
        let a = g.add_node(RoadNode { id: "A".into(), position: v2(0.0, 0.0) });
        let b = g.add_node(RoadNode { id: "B".into(), position: v2(100.0, 0.0) });
        let c = g.add_node(RoadNode { id: "C".into(), position: v2(130.0, 30.0) });
        let d = g.add_node(RoadNode { id: "D".into(), position: v2(-50.0, 0.0) });
        let e = g.add_node(RoadNode { id: "E".into(), position: v2(0.0, -50.0) });
        g.add_edge(
            a,
            b,
            RoadEdge {
                id: "ab".into(),
                kind: EdgeKind::Road,
                piece: Piece::Line { a: v2(0.0, 0.0), b: v2(100.0, 0.0) },
            },
        );
        let arc = Piece::arc_between(v2(100.0, 0.0), v2(130.0, 30.0), 30.0, true).expect("arc");
        g.add_edge(b, c, RoadEdge { id: "bc".into(), kind: EdgeKind::Road, piece: arc });
        g.add_edge(
            d,
            a,
            RoadEdge {
                id: "da".into(),
                kind: EdgeKind::Road,
                piece: Piece::Line { a: v2(-50.0, 0.0), b: v2(0.0, 0.0) },
            },
        );
        g.add_edge(
            a,
            e,
            RoadEdge {
                id: "ae".into(),
                kind: EdgeKind::Road,
                piece: Piece::Line { a: v2(0.0, 0.0), b: v2(0.0, -50.0) },
            },
        );
        World {
            name: "small".into(),
            roads: RoadNetwork { graph: g, lane_width: 3.5, lanes: 2 },
            areas: vec![Area { id: "field".into(), polygon: rect_polygon(v2(50.0, 50.0), 40.0, 40.0, 0.0) }],
            obstacles: vec![
                Obstacle {
                    id: "box".into(),
                    polygon: rect_polygon(v2(60.0, 0.0), 2.0, 2.0, 0.0),
                    height: 1.0,
                    motion: Motion::Static,
                },
                Obstacle {
                    id: "walker".into(),
                    polygon: circle_polygon(v2(70.0, 10.0), 0.5, 8),
                    height: 1.8,
                    motion: Motion::Path {
                        waypoints: vec![v2(70.0, 10.0), v2(70.0, -10.0)],
                        speed: 1.0,
                        repeat: Repeat::PingPong,
                    },
                },
            ],
            gps_outages: vec![],
            start: Pose::new(-40.0, 0.0, 0.0),
            goal: Goal { position: v2(130.0, 30.0), tolerance: 2.0, heading: None },
            vehicle: VehicleParams::outdoor(),
        }
    }

    #[test]
    fn terrain_queries() {
        let w = small_world();
        assert_eq!(w.terrain(v2(50.0, 1.0)), Terrain::Road);
        assert_eq!(w.terrain(v2(50.0, 50.0)), Terrain::CrossCountry);
        assert_eq!(w.terrain(v2(-200.0, 50.0)), Terrain::Off);
    }

    #[test]
    fn road_ahead_straight_turn_branch_none() {
        let w = small_world();
        let look = RoadLookahead::default();
        assert_eq!(w.road_ahead(&Pose::new(40.0, -1.75, 0.0), &look), RoadAhead::Straight);
        match w.road_ahead(&Pose::new(90.0, -1.75, 0.0), &look) {
            RoadAhead::Turn { curvature, left } => assert!((curvature - 1.0 / 30.0).abs() < 1e-9 && left),
            other => panic!("expected a turn, got {other:?}"),
        }
        // Driving the turn the other way round turns right.
        let pose = Pose::new(130.0, 30.0, -PI / 2.0);
        match w.road_ahead(&pose, &look) {
            RoadAhead::Turn { left, .. } => assert!(!left),
            other => panic!("expected a turn, got {other:?}"),
        }
        match w.road_ahead(&Pose::new(-20.0, -1.75, 0.0), &look) {
            RoadAhead::Branch { distance } => assert!((distance - 20.0).abs() < 0.1, "{distance}"),
            other => panic!("expected a branch, got {other:?}"),
        }
        assert_eq!(w.road_ahead(&Pose::new(50.0, 40.0, 0.0), &look), RoadAhead::None);
    }

    #[test]
    fn obstacles_in_corridor_and_fov() {
        let w = small_world();
        let mut views = Vec::new();
        w.obstacles_at(0.0, &mut views);
        let corr = Corridor { curvature: 0.0, half_width: 1.2, length: 40.0 };
        let mut scratch = Vec::new();
        let hits = w.obstacles_seen(&Pose::new(40.0, 0.0, 0.0), &views, 40.0, PI, &corr, &mut scratch);
        let boxhit = hits.iter().find(|h| h.index == 0).expect("box seen");
        assert!((boxhit.corridor.unwrap_or(f64::NAN) - 19.0).abs() < 1e-9);
        assert!((boxhit.width - 2.0).abs() < 1e-9);
        // The walker at (70, 10) is beside the corridor at t = 0.
        let walker = hits.iter().find(|h| h.index == 1).expect("walker seen");
        assert!(walker.corridor.is_none());
        // Facing away, nothing is in the field of view.
        let back = w.obstacles_seen(&Pose::new(40.0, 0.0, PI), &views, 40.0, PI / 2.0, &corr, &mut scratch);
        assert!(back.is_empty());
        // A curved corridor bending left misses the box.
        let bent = Corridor { curvature: 0.1, half_width: 1.2, length: 40.0 };
        let hits = w.obstacles_seen(&Pose::new(40.0, 0.0, 0.0), &views, 40.0, PI, &bent, &mut scratch);
        assert!(hits.iter().find(|h| h.index == 0).is_some_and(|h| h.corridor.is_none()));
    }

    #[test]
    fn moving_obstacle_and_collision() {
        let w = small_world();
        let mut views = Vec::new();
        w.obstacles_at(10.0, &mut views);
        assert!((views[1].center - v2(70.0, 0.0)).norm() < 1e-9);
        w.obstacles_at(20.0, &mut views);
        assert!((views[1].center - v2(70.0, -10.0)).norm() < 1e-9, "at the end of its path");
        w.obstacles_at(35.0, &mut views);
        assert!((views[1].center - v2(70.0, 5.0)).norm() < 1e-9, "ping-pong: on its way back");
        w.obstacles_at(0.0, &mut views);
        assert_eq!(w.collision(&Pose::new(57.0, 0.0, 0.0), &views), Some(0));
        assert_eq!(w.collision(&Pose::new(50.0, 0.0, 0.0), &views), None);
        let (d, i) = w.closest_obstacle(&Pose::new(50.0, 0.0, 0.0), &views).expect("obstacles");
        assert_eq!(i, 0);
        assert!((d - (59.0 - 53.6)).abs() < 1e-9, "{d}");
        let ttc = w.time_to_collision(&Pose::new(50.0, 0.0, 0.0), 2.0, &views, 50.0).expect("ttc");
        assert!((ttc - (59.0 - 53.6) / 2.0).abs() < 0.06, "{ttc}");
    }

    #[test]
    fn corridor_coordinates_on_an_arc() {
        let c = Corridor { curvature: 0.1, half_width: 1.0, length: 30.0 };
        // A point a quarter turn along the circle of radius 10 centred (0, 10).
        let (s, l) = c.coords(v2(10.0, 10.0));
        assert!((s - 10.0 * PI / 2.0).abs() < 1e-9 && l.abs() < 1e-9);
        let (_, l) = c.coords(v2(0.0, 1.0));
        assert!((l - 1.0).abs() < 1e-9, "inside the turn is left");
        let right = Corridor { curvature: -0.1, half_width: 1.0, length: 30.0 };
        let (s, l) = right.coords(v2(10.0, -10.0));
        assert!((s - 10.0 * PI / 2.0).abs() < 1e-9 && l.abs() < 1e-9);
    }
}
