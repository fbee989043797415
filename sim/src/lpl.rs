//! LPL, local path planning: the plans of Table 1 of Zhang & Zhu, each a
//! function producing a local target for Drive, and the events PLRS / PLRT /
//! PLRB / PLRO / PLCN / PLCO / PLF{reason} of `rules/outdoor.situ`.
//!
//! Every plan follows GPL's global path with a lateral offset profile: the
//! centre of the right lane on roads (centre line with one lane), the track
//! itself cross-country, and, around an obstacle in the way (plans `plro`
//! and `plco`), a pass on the side with room, entered and left over a
//! smooth ramp. The local target is the point of that offset path a
//! lookahead ahead of the vehicle, with the path's heading and curvature,
//! at the plan's speed. The speed is capped per plan (the working figures of
//! `rules/outdoor.situ`: 10 m/s on a straight road, 5 with an obstacle,
//! 4 cross-country, 2 with an obstacle there; CHOICE: 6 m/s through a
//! branch), by 2 m/s² of lateral acceleration in turns, and slowed at
//! 2 m/s² before a turn and to a stop at the goal.
//!
//! Obstacles are remembered as *passing windows* (by track id) from the
//! moment an obstacle plan sees them until the vehicle has passed them, so
//! the manoeuvre completes even when the obstacle leaves the sensors' view.
//! While a window is being driven LPL reports PLRO / PLCO; after it, the
//! plain plan of the road ahead (PLRS, PLRT, PLRB, PLCN): the "avoidance
//! manoeuvre is over" witness of the rules `obstacle_passed_*`.

use crate::agent::{Event, Value};
use crate::control::Target;
use crate::fusion::FusedObstacle;
use crate::geom::{contains, unit, wrap_angle, Pose};
use crate::gpl::GlobalPath;
use crate::world::{EdgeKind, World};
use petgraph::graph::EdgeIndex;
use serde::Serialize;
use std::f64::consts::FRAC_PI_2;

/// The plans of Table 1.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum PlanKind {
    /// `plrs()`: straight road plan.
    Straight,
    /// `plrt()`: turn road plan.
    Turn,
    /// `plrb()`: branch road plan.
    Branch,
    /// `plro()`: avoid obstacle plan on road.
    RoadObstacle,
    /// `plcn()`: cross-country plan.
    CrossCountry,
    /// `plco()`: avoiding obstacle plan cross-country.
    CrossCountryObstacle,
}

impl PlanKind {
    /// The function's name in the rules file.
    pub fn function(self) -> &'static str {
        match self {
            PlanKind::Straight => "plrs",
            PlanKind::Turn => "plrt",
            PlanKind::Branch => "plrb",
            PlanKind::RoadObstacle => "plro",
            PlanKind::CrossCountry => "plcn",
            PlanKind::CrossCountryObstacle => "plco",
        }
    }

    /// Whether the plan avoids obstacles.
    pub fn avoids(self) -> bool {
        matches!(self, PlanKind::RoadObstacle | PlanKind::CrossCountryObstacle)
    }
}

/// PLF's reasons.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FailReason {
    /// No global path.
    NoPath,
    /// An obstacle blocks the way: no pass on either side.
    Blocked,
    /// Planning took too long.
    Timeout,
}

/// LPL's events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum PlanEvent {
    /// `PLRS`.
    Straight,
    /// `PLRT`.
    Turn,
    /// `PLRB`.
    Branch,
    /// `PLRO`.
    RoadObstacle,
    /// `PLCN`.
    CrossCountry,
    /// `PLCO`.
    CrossCountryObstacle,
    /// `PLF{reason}`.
    Failed {
        /// Why.
        reason: FailReason,
    },
}

impl Event for PlanEvent {
    fn name(&self) -> &'static str {
        match self {
            PlanEvent::Straight => "PLRS",
            PlanEvent::Turn => "PLRT",
            PlanEvent::Branch => "PLRB",
            PlanEvent::RoadObstacle => "PLRO",
            PlanEvent::CrossCountry => "PLCN",
            PlanEvent::CrossCountryObstacle => "PLCO",
            PlanEvent::Failed { .. } => "PLF",
        }
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        match *self {
            PlanEvent::Failed { reason } => vec![(
                "reason",
                Value::Symbol(match reason {
                    FailReason::NoPath => "no_path",
                    FailReason::Blocked => "blocked",
                    FailReason::Timeout => "timeout",
                }),
            )],
            _ => vec![],
        }
    }
}

/// LPL's figures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LplConfig {
    /// Speed caps of plrs, plrt, plrb, plro, plcn, plco (m/s).
    pub speeds: [f64; 6],
    /// Lateral acceleration allowed in turns (m/s²).
    pub lateral_accel: f64,
    /// Deceleration planned before turns and the goal (m/s²).
    pub decel: f64,
    /// Shortest lookahead (m).
    pub lookahead_min: f64,
    /// Lookahead per m/s of speed (s).
    pub lookahead_time: f64,
    /// Length of the offset ramps (m).
    pub ramp: f64,
    /// Lateral clearance kept from obstacles on road (m).
    pub road_margin: f64,
    /// Lateral clearance kept from obstacles cross-country (m).
    pub terrain_margin: f64,
}

impl Default for LplConfig {
    fn default() -> Self {
        LplConfig {
            speeds: [10.0, 10.0, 6.0, 5.0, 4.0, 2.0],
            lateral_accel: 2.0,
            decel: 2.0,
            lookahead_min: 6.0,
            lookahead_time: 1.0,
            ramp: 15.0,
            road_margin: 0.8,
            terrain_margin: 1.2,
        }
    }
}

/// A remembered obstacle pass: full offset between `s_in` and `s_out`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Window {
    /// The obstacle's track id.
    pub track: usize,
    /// Full offset from this arc length (m).
    pub s_in: f64,
    /// Full offset until this arc length (m).
    pub s_out: f64,
    /// The lateral offset of the pass (m, left positive).
    pub offset: f64,
    /// Length of the ramp into the pass (m): the configured ramp, shortened
    /// when the obstacle was seen late so that the ramp starts ahead of the
    /// target (no jump of the target).
    pub ramp_in: f64,
    /// On road or cross-country.
    pub kind: EdgeKind,
}

/// What LPL reads each tick.
#[derive(Debug, Clone, Copy)]
pub struct PlanInput<'a> {
    /// The world (road widths, areas).
    pub world: &'a World,
    /// The pose from Localization.
    pub pose: Pose,
    /// The speed (m/s).
    pub speed: f64,
    /// GPL's path.
    pub path: &'a GlobalPath,
    /// The vehicle's arc length along it (GPL's report).
    pub s: f64,
    /// Fusion's obstacles (or the obstacle sensor's, in CN).
    pub obstacles: &'a [FusedObstacle],
}

/// LPL's output for Drive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LocalPlan {
    /// The local target.
    pub target: Target,
    /// The speed limit (m/s).
    pub speed: f64,
    /// The lookahead used (m): Drive scales its gains with it.
    pub lookahead: f64,
    /// The event.
    pub event: PlanEvent,
    /// The edge found blocked, for GPL to re-plan.
    #[serde(skip)]
    pub blocked: Option<EdgeIndex>,
}

/// The LPL agent.
#[derive(Debug, Clone, Default)]
pub struct Lpl {
    /// Figures.
    pub cfg: LplConfig,
    /// Passing windows, in the order they were made.
    pub windows: Vec<Window>,
}

fn smoothstep(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

impl Lpl {
    /// An LPL with its figures.
    pub fn new(cfg: LplConfig) -> Self {
        Lpl { cfg, windows: Vec::new() }
    }

    /// Forgets every window (a new path).
    pub fn reset(&mut self) {
        self.windows.clear();
    }

    /// The lane offset of the path at `s`, ramped across road/track changes.
    pub fn base_offset(&self, world: &World, path: &GlobalPath, s: f64) -> f64 {
        let lane = world.roads.lane_offset();
        let value = |k: EdgeKind| if k == EdgeKind::Road { lane } else { 0.0 };
        let r = self.cfg.ramp;
        for &b in &path.kind_changes {
            if (s - b).abs() < r / 2.0 {
                let before = value(path.kind(b - 0.01));
                let after = value(path.kind(b + 0.01));
                return before + (after - before) * smoothstep((s - (b - r / 2.0)) / r);
            }
        }
        value(path.kind(s))
    }

    /// The planned lateral offset at `s` (`lag` m added to the windows' ends,
    /// for a target that leads the vehicle by that much).
    pub fn offset(&self, world: &World, path: &GlobalPath, s: f64, lag: f64) -> f64 {
        let base = self.base_offset(world, path, s);
        let r = self.cfg.ramp;
        let mut best = (0.0, base);
        for w in &self.windows {
            let wgt = if s < w.s_in {
                smoothstep((s - (w.s_in - w.ramp_in)) / w.ramp_in)
            } else if s <= w.s_out + lag {
                1.0
            } else {
                smoothstep(1.0 - (s - w.s_out - lag) / r)
            };
            if wgt > best.0 {
                best = (wgt, base + (w.offset - base) * wgt);
            }
        }
        best.1
    }

    /// Updates the passing windows from the obstacles; `Err` with the edge
    /// when an obstacle leaves no pass.
    fn update_windows(&mut self, input: &PlanInput<'_>, kind: EdgeKind, lookahead: f64) -> Result<(), EdgeIndex> {
        let world = input.world;
        let veh = &world.vehicle;
        let hw = veh.width / 2.0;
        let margin = if kind == EdgeKind::Road { self.cfg.road_margin } else { self.cfg.terrain_margin };
        let road_half = world.roads.half_width();
        for o in input.obstacles {
            if o.height <= veh.clearance || o.polygon.is_empty() {
                continue;
            }
            let (mut smin, mut smax, mut lmin, mut lmax) =
                (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
            for p in &o.polygon {
                let (s, l) = input.path.project(*p, input.s, 80.0);
                smin = smin.min(s);
                smax = smax.max(s);
                lmin = lmin.min(l);
                lmax = lmax.max(l);
            }
            if smax < input.s - veh.rear || smin > input.s + 60.0 {
                continue;
            }
            let existing = self.windows.iter().position(|w| w.track == o.track);
            if existing.is_none() {
                // Is it in the way of the planned path?
                let band = self.offset(world, input.path, smin, 0.0);
                if lmax < band - hw - margin || lmin > band + hw + margin {
                    continue;
                }
            }
            let left = lmax + hw + margin;
            let right = lmin - hw - margin;
            let fits = |l: f64| -> bool {
                if kind == EdgeKind::Road {
                    l.abs() <= road_half - hw + 0.25
                } else {
                    [smin, (smin + smax) / 2.0, smax].iter().all(|&s| {
                        let q = input.path.point(s) + unit(input.path.heading(s) + FRAC_PI_2) * l;
                        world.areas.iter().any(|a| contains(&a.polygon, q))
                    })
                }
            };
            let current = self.offset(world, input.path, input.s, 0.0);
            let centre = (lmin + lmax) / 2.0;
            // A pass once chosen keeps its side, and only widens.
            let choice = match existing.map(|i| self.windows[i].offset) {
                Some(prev) if prev > centre => fits(left.max(prev)).then_some(left.max(prev)),
                Some(prev) => fits(right.min(prev)).then_some(right.min(prev)),
                None => match (fits(left), fits(right)) {
                    (true, true) => Some(if (left - current).abs() <= (right - current).abs() { left } else { right }),
                    (true, false) => Some(left),
                    (false, true) => Some(right),
                    (false, false) => None,
                },
            };
            let Some(offset) = choice else {
                return Err(input.path.piece_at(((smin + smax) / 2.0).clamp(0.0, input.path.length)).edge);
            };
            let s_in = smin - veh.front - 4.0;
            let s_out = smax + veh.rear + 2.0;
            match existing {
                Some(i) => {
                    let w = &mut self.windows[i];
                    w.s_in = w.s_in.min(s_in);
                    w.s_out = w.s_out.max(s_out);
                    w.offset = offset;
                }
                None => {
                    let ramp_in = (s_in - (input.s + lookahead)).clamp(5.0, self.cfg.ramp);
                    self.windows.push(Window { track: o.track, s_in, s_out, offset, ramp_in, kind })
                }
            }
        }
        Ok(())
    }

    /// Runs one of Table 1's plans.
    pub fn plan(&mut self, kind: PlanKind, input: &PlanInput<'_>) -> LocalPlan {
        let cfg = self.cfg;
        let path = input.path;
        let s = input.s;
        let lookahead = cfg.lookahead_min.max(cfg.lookahead_time * input.speed);
        // Forget the windows already passed.
        let r = cfg.ramp;
        self.windows.retain(|w| s < w.s_out + lookahead + r);
        let mut blocked = None;
        if kind.avoids() {
            let terrain = if kind == PlanKind::RoadObstacle { EdgeKind::Road } else { EdgeKind::CrossCountry };
            if let Err(e) = self.update_windows(input, terrain, lookahead) {
                blocked = Some(e);
            }
        }
        let st = s + lookahead;
        let off = self.offset(input.world, path, st, lookahead);
        let d_off = (self.offset(input.world, path, st + 0.5, lookahead)
            - self.offset(input.world, path, st - 0.5, lookahead))
            / 1.0;
        let heading = wrap_angle(path.heading(st) + d_off.atan());
        let pos = path.point(st) + unit(path.heading(st) + FRAC_PI_2) * off;
        // Speed: the plan's cap, turns ahead, the goal.
        let idx = match kind {
            PlanKind::Straight => 0,
            PlanKind::Turn => 1,
            PlanKind::Branch => 2,
            PlanKind::RoadObstacle => 3,
            PlanKind::CrossCountry => 4,
            PlanKind::CrossCountryObstacle => 5,
        };
        let mut v = cfg.speeds[idx];
        let horizon = v * v / (2.0 * cfg.decel) + 10.0;
        let mut k = 0.0;
        while k <= horizon {
            let sk = s + k;
            let kappa = path.curvature(sk).abs();
            let mut limit = if kappa > 1e-6 { (cfg.lateral_accel / kappa).sqrt() } else { f64::INFINITY };
            if path.kind(sk) == EdgeKind::CrossCountry && sk <= path.length {
                limit = limit.min(cfg.speeds[4]);
            }
            v = v.min((limit * limit + 2.0 * cfg.decel * k).sqrt());
            k += 2.0;
        }
        let remaining = (path.length - s).max(0.0);
        v = v.min((2.0 * cfg.decel * (remaining - 0.5).max(0.0)).sqrt());
        let in_window =
            self.windows.iter().any(|w| s + lookahead >= w.s_in - w.ramp_in && s <= w.s_out + lookahead + r);
        let event = if let Some(_e) = blocked {
            PlanEvent::Failed { reason: FailReason::Blocked }
        } else if in_window {
            if path.kind(s) == EdgeKind::Road {
                PlanEvent::RoadObstacle
            } else {
                PlanEvent::CrossCountryObstacle
            }
        } else if path.kind(s) == EdgeKind::CrossCountry {
            PlanEvent::CrossCountry
        } else if path.junctions.iter().any(|&j| j >= s - 5.0 && j - s <= 30.0) {
            PlanEvent::Branch
        } else if (0..=8).any(|i| {
            path.curvature(s + 2.0 * i as f64).abs() >= 0.002 && path.kind(s + 2.0 * i as f64) == EdgeKind::Road
        }) {
            PlanEvent::Turn
        } else {
            PlanEvent::Straight
        };
        // The curvature feed-forward, averaged over a lookahead around the
        // target: roads here have no clothoids, and a step of curvature at
        // an arc's start would be a step of the steering command.
        let curvature = (-2..=2).map(|i| path.curvature(st + lookahead * i as f64 / 4.0)).sum::<f64>() / 5.0;
        let target = Target { pose: Pose::new(pos.x, pos.y, heading), v, curvature };
        LocalPlan { target, speed: v, lookahead, event, blocked }
    }

    /// `plrs()`: straight road plan.
    pub fn plrs(&mut self, input: &PlanInput<'_>) -> LocalPlan {
        self.plan(PlanKind::Straight, input)
    }
    /// `plrt()`: turn road plan.
    pub fn plrt(&mut self, input: &PlanInput<'_>) -> LocalPlan {
        self.plan(PlanKind::Turn, input)
    }
    /// `plrb()`: branch road plan.
    pub fn plrb(&mut self, input: &PlanInput<'_>) -> LocalPlan {
        self.plan(PlanKind::Branch, input)
    }
    /// `plro()`: avoid obstacle plan on road.
    pub fn plro(&mut self, input: &PlanInput<'_>) -> LocalPlan {
        self.plan(PlanKind::RoadObstacle, input)
    }
    /// `plcn()`: cross-country plan.
    pub fn plcn(&mut self, input: &PlanInput<'_>) -> LocalPlan {
        self.plan(PlanKind::CrossCountry, input)
    }
    /// `plco()`: avoiding obstacle plan cross-country.
    pub fn plco(&mut self, input: &PlanInput<'_>) -> LocalPlan {
        self.plan(PlanKind::CrossCountryObstacle, input)
    }
}

/// The road edge an obstacle blocks, if it blocks one: an obstacle on a
/// road (taller than the vehicle's clearance) beside which there is room
/// for the vehicle with `margin` on neither side (the test of the passes of
/// [`Lpl`]). What the Mapper writes into the map, for GPL to re-plan.
pub fn blocked_road(world: &World, polygon: &[crate::geom::Vec2], height: f64, margin: f64) -> Option<EdgeIndex> {
    let veh = &world.vehicle;
    if height <= veh.clearance || polygon.is_empty() {
        return None;
    }
    let centre = crate::geom::vertex_centroid(polygon);
    let (edge, pr) = world.roads.nearest_edge(centre, Some(EdgeKind::Road))?;
    let piece = world.roads.graph[edge].piece;
    let road_half = world.roads.half_width();
    let radius = polygon.iter().map(|p| (p - centre).norm()).fold(0.0, f64::max);
    if pr.distance > road_half + radius {
        return None; // not on that road (beyond its end, or off it)
    }
    let (mut lmin, mut lmax) = (f64::INFINITY, f64::NEG_INFINITY);
    for p in polygon {
        let l = piece.project(*p).lateral;
        lmin = lmin.min(l);
        lmax = lmax.max(l);
    }
    if lmin > road_half || lmax < -road_half {
        return None;
    }
    let hw = veh.width / 2.0;
    let fits = |l: f64| l.abs() <= road_half - hw + 0.25;
    (!fits(lmax + hw + margin) && !fits(lmin - hw - margin)).then_some(edge)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{rect_polygon, v2};
    use crate::gpl::Gpl;
    use crate::scenario;

    fn obstacle(track: usize, x: f64, y: f64, w: f64) -> FusedObstacle {
        FusedObstacle {
            track,
            polygon: rect_polygon(v2(x, y), 4.5, w, 0.0),
            height: 1.5,
            width: w,
            distance: Some(20.0),
            seen_by: (true, false),
        }
    }

    #[test]
    fn straight_plan_keeps_right_lane_at_road_speed() {
        let w = scenario::outdoor_default().world;
        let mut gpl = Gpl::default();
        let path = gpl.plan(&w, &w.start).expect("path").clone();
        let mut lpl = Lpl::default();
        let input = PlanInput {
            world: &w,
            pose: Pose::new(50.0, -1.75, 0.0),
            speed: 10.0,
            path: &path,
            s: 45.0,
            obstacles: &[],
        };
        let p = lpl.plrs(&input);
        assert_eq!(p.event, PlanEvent::Straight);
        assert!((p.target.pose.y + 1.75).abs() < 1e-9, "right lane");
        assert!((p.target.pose.x - 60.0).abs() < 1e-9, "10 m ahead at 10 m/s (the path starts at x = 5)");
        assert_eq!(p.speed, 10.0);
        // Before the turn of radius 40: sqrt(2 × 40) ≈ 8.9 m/s at most there.
        let near = PlanInput { s: 293.0, pose: Pose::new(298.0, -1.75, 0.0), ..input };
        let t = lpl.plrt(&near);
        assert!(t.speed < 9.5 && t.event == PlanEvent::Turn, "{t:?}");
    }

    #[test]
    fn obstacle_plan_passes_in_the_left_lane_and_reports() {
        let w = scenario::outdoor_default().world;
        let mut gpl = Gpl::default();
        let path = gpl.plan(&w, &w.start).expect("path").clone();
        let mut lpl = Lpl::default();
        let obs = [obstacle(0, 200.0, -1.75, 1.8)];
        let input = PlanInput {
            world: &w,
            pose: Pose::new(175.0, -1.75, 0.0),
            speed: 5.0,
            path: &path,
            s: 170.0,
            obstacles: &obs,
        };
        let p = lpl.plro(&input);
        assert_eq!(p.event, PlanEvent::RoadObstacle);
        assert_eq!(lpl.windows.len(), 1);
        assert!(lpl.windows[0].offset > 0.0, "passes on the left: {:?}", lpl.windows[0]);
        assert!(p.speed <= 5.0);
        // Beside the obstacle the planned offset is the pass.
        assert!((lpl.offset(&w, &path, 200.0, 0.0) - lpl.windows[0].offset).abs() < 1e-9);
        // Far past it, the plain plan again.
        let later = PlanInput { pose: Pose::new(260.0, -1.75, 0.0), s: 255.0, obstacles: &[], ..input };
        assert_eq!(lpl.plro(&later).event, PlanEvent::Straight);
        assert!(lpl.windows.is_empty());
    }

    #[test]
    fn the_mapper_sees_which_road_an_obstacle_blocks() {
        let w = scenario::outdoor_default().world;
        let wide = rect_polygon(v2(200.0, 0.0), 4.5, 6.5, 0.0);
        let edge = blocked_road(&w, &wide, 1.5, 0.8).map(|e| w.roads.graph[e].id.as_str());
        assert_eq!(edge, Some("r1"));
        let car = rect_polygon(v2(200.0, -1.75), 4.5, 1.8, 0.0);
        assert_eq!(blocked_road(&w, &car, 1.5, 0.8), None, "the left lane is free");
        assert_eq!(blocked_road(&w, &wide, 0.1, 0.8), None, "driven over");
        let thicket = crate::geom::circle_polygon(v2(600.0, 220.5), 2.0, 16);
        assert_eq!(blocked_road(&w, &thicket, 1.2, 0.8), None, "on the track, beyond the road's end");
    }

    #[test]
    fn a_road_wide_obstacle_blocks() {
        let w = scenario::outdoor_default().world;
        let mut gpl = Gpl::default();
        let path = gpl.plan(&w, &w.start).expect("path").clone();
        let mut lpl = Lpl::default();
        let obs = [obstacle(0, 200.0, 0.0, 6.5)];
        let input = PlanInput {
            world: &w,
            pose: Pose::new(175.0, -1.75, 0.0),
            speed: 5.0,
            path: &path,
            s: 170.0,
            obstacles: &obs,
        };
        let p = lpl.plro(&input);
        assert_eq!(p.event, PlanEvent::Failed { reason: FailReason::Blocked });
        assert_eq!(p.event.fields(), vec![("reason", Value::Symbol("blocked"))]);
        assert_eq!(p.blocked.map(|e| w.roads.graph[e].id.as_str()), Some("r1"));
    }
}
