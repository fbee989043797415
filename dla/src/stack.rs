//! The agents of `rules/dla.situ` (Pérez 2006, DLA) on the runtime: the
//! deliberative layer of Poncela et al. (2002) and the case-based reactive
//! layer of Urdiales et al. (2006), on the building blocks of this crate;
//! [`Dla`] is the [`Stack`](situ_sim::stack::Stack) that runs them.
//!
//! | agent | reads (data) | does | sends |
//! |---|---|---|---|
//! | Laser | the world | 72 beams over 360°, 8 m; SCAN{nearest} | [`Scan`] |
//! | Localization | the world | the pose; POSE{remaining} | [`PoseFix`] |
//! | Mapper | Laser, Localization | fuses the scans into the occupancy grid; rebuilds the pyramid when the grid changed | [`MapSnapshot`] |
//! | RoutePlanner | Mapper, Localization | while running: A* over the regions (unexplored ones at a cost), after its computing time; ROUTE{number, regions} / NO_ROUTE{explored} | [`RouteMsg`] |
//! | PathPlanner | Mapper, Localization (RoutePlanner while it waits) | the route's path by potential fields; checks it on the latest grid; PATH_BLOCKED{route} | [`Subgoal`] |
//! | Reactive | Laser, Localization, PathPlanner | the nearest case's command towards the subgoal (the goal without one); learns novel situations | [`DriveCommand`] |
//! | Base | Reactive | turns (speed, turn rate) into the tricycle's command; nothing fresh: stop | the command |
//!
//! The route planner takes [`PLAN_TIME`] of simulated time to compute a
//! route (a stand-in for the computing time the paper's claim is about:
//! the robot must not stop meanwhile), so re-planning is visible in a run.

use crate::cases::{self, Case, CaseBase, Command as CaseCommand, DriverParams, Situation};
use crate::detour::Detour;
use crate::grid::{Beam, CellClass, GridParams, OccupancyGrid};
use crate::pyramid::{Pyramid, PyramidParams, RegionClass};
use crate::route::{plan_path, plan_route, PathParams, RouteParams};
use situ_compiler::bundle::{Content, Mode};
use situ_runtime::agent::{Agent, Body, Context};
use situ_sim::agent::{fresh, names, report, take, Named, Value as SimValue};
use situ_sim::geom::{edges, unit, v2, wrap_angle, Pose, Vec2};
use situ_sim::noise::Noise;
use situ_sim::stack::{lock, SharedPhysics};
use situ_sim::vehicle::{Command, VehicleParams};
use situ_sim::world::{ObstacleView, World};
use std::sync::{Arc, Mutex, OnceLock};

mod dla;
mod reflexes;

pub use dla::{pictures, Dla, NAME};

use reflexes::{reflexes, scan_points, standstill};
pub use reflexes::{CRAWL, CREEP, STILL_TURN, SWEEP_MARGIN, SWEEP_TIME, TURN_RADIUS, TURN_SWEEP, TURN_TIGHT};

/// The agents `rules/dla.situ` declares.
pub const AGENTS: &[&str] = &["Laser", "Localization", "Mapper", "RoutePlanner", "PathPlanner", "Reactive", "Base"];

/// Range sectors of a case.
pub const SECTORS: usize = 8;
/// A case's key: the sectors and the goal direction (cos, sin).
pub const KEY: usize = SECTORS + 2;
/// The case base of the reactive layer.
pub type Cases = CaseBase<KEY>;
/// The case base the Reactive agent shares with whoever runs the stack
/// (read before the run, written after it with what was learnt).
pub type SharedCases = Arc<Mutex<Cases>>;

/// How long the supervised training drives (s of its own simulated time).
pub const TRAINING_SECONDS: f64 = 300.0;
/// A situation farther than this from every case is learnt.
pub const NOVELTY: f64 = 0.2;

/// Beams of a scan, over 360°.
pub const BEAMS: usize = 72;
/// The laser's range (m).
pub const MAX_RANGE: f64 = 8.0;
/// The reactive layer's horizon (m): in a case, a sector farther than this
/// is clear, so that the cases tell apart what is near, where reacting matters.
pub const REACTIVE_RANGE: f64 = 2.0;
/// Grid cells (m).
pub const CELL: f64 = 0.1;
/// The route planner's computing time (ns of simulated time).
pub const PLAN_TIME: u64 = 800_000_000;
/// How far along the path the reactive layer is sent (m).
pub const LOOKAHEAD: f64 = 0.8;
/// A path cell closer than this to an occupied cell blocks the path (m).
pub const CLEARANCE: f64 = 0.2;
/// How far ahead on the path blocking is checked (m).
pub const CHECK_AHEAD: f64 = 3.0;

/// A scan: the pose it was taken at and its beams.
#[derive(Debug, Clone)]
pub struct Scan {
    /// Where the robot was.
    pub pose: Pose,
    /// The readings.
    pub beams: Arc<Vec<Beam>>,
}

/// The robot's pose.
#[derive(Debug, Clone, Copy)]
pub struct PoseFix(pub Pose);

/// The Mapper's map: the grid and its pyramid, numbered.
///
/// The pyramid is built from the grid the first time someone asks for it
/// (the route planner when it computes a route, the pictures at the end)
/// and then shared by every copy of the snapshot: a map the robot only
/// follows a route on costs a grid copy, not a pyramid.
#[derive(Debug, Clone)]
pub struct MapSnapshot {
    /// Incremented when a cell changes class.
    pub version: u64,
    /// The occupancy grid.
    pub grid: Arc<OccupancyGrid>,
    params: PyramidParams,
    pyramid: Arc<OnceLock<Pyramid>>,
}

impl MapSnapshot {
    /// A snapshot of `grid`, its pyramid to be built with `params`.
    pub fn new(version: u64, grid: Arc<OccupancyGrid>, params: PyramidParams) -> MapSnapshot {
        MapSnapshot { version, grid, params, pyramid: Arc::new(OnceLock::new()) }
    }
    /// Its pyramid: the regions of the topological map (built on first use).
    pub fn pyramid(&self) -> &Pyramid {
        self.pyramid.get_or_init(|| Pyramid::build(&self.grid, &self.params))
    }
}

/// A route and the map it was planned on.
#[derive(Debug, Clone)]
pub struct RouteMsg {
    /// Routes are numbered from 1.
    pub number: i64,
    /// The regions from the robot's to the goal's.
    pub regions: Arc<Vec<usize>>,
    /// The map the regions are of.
    pub map: MapSnapshot,
}

/// Where the reactive layer heads.
#[derive(Debug, Clone, Copy)]
pub struct Subgoal(pub Vec2);

/// The reactive layer's command.
#[derive(Debug, Clone, Copy)]
pub struct DriveCommand(pub CaseCommand);

/// What the stack draws and reports: the last map, route and path.
#[derive(Debug, Default)]
pub struct Plans {
    /// The latest map.
    pub map: Option<MapSnapshot>,
    /// The latest route.
    pub route: Option<RouteMsg>,
    /// The latest path (m).
    pub path: Vec<Vec2>,
    /// Routes computed.
    pub routes: u64,
    /// Routes computed after the first (after a blocked path).
    pub replans: u64,
    /// Cases learnt on line during the run.
    pub learnt: u64,
    /// The explored share of the map when no route was found, if none was.
    pub no_route: Option<f64>,
}

/// [`Plans`], shared.
pub type SharedPlans = Arc<Mutex<Plans>>;

/// The distance from `o` along `dir` (a unit vector) to the nearest edge of
/// the obstacles, if within `max`.
fn ray(o: Vec2, dir: Vec2, views: &[ObstacleView], max: f64) -> f64 {
    let mut best = max;
    for v in views {
        if (v.center - o).norm() - v.radius > best {
            continue;
        }
        for (a, b) in edges(&v.polygon) {
            let e = b - a;
            let den = dir.x * e.y - dir.y * e.x;
            if den.abs() < 1e-12 {
                continue;
            }
            let w = a - o;
            let t = (w.x * e.y - w.y * e.x) / den;
            let u = (w.x * dir.y - w.y * dir.x) / den;
            if t >= 0.0 && (0.0..=1.0).contains(&u) && t < best {
                best = t;
            }
        }
    }
    best
}

/// A scan of the world from `pose`.
pub fn scan(pose: &Pose, views: &[ObstacleView], noise: Option<&mut Noise>) -> Vec<Beam> {
    let mut noise = noise;
    (0..BEAMS)
        .map(|i| {
            let angle = -std::f64::consts::PI + (i as f64 + 0.5) * std::f64::consts::TAU / BEAMS as f64;
            let mut range = ray(pose.pos(), unit(pose.theta + angle), views, MAX_RANGE);
            if range < MAX_RANGE {
                if let Some(n) = noise.as_deref_mut() {
                    range = (range + n.normal(0.01)).clamp(0.0, MAX_RANGE - 1e-6);
                }
            }
            Beam { angle, range, max_range: MAX_RANGE }
        })
        .collect()
}

/// The situation of a scan, with the goal at `target` (world frame).
pub fn situation(pose: &Pose, beams: &[Beam], target: Vec2) -> Situation {
    let to = target - pose.pos();
    let goal_angle = wrap_angle(to.y.atan2(to.x) - pose.theta);
    Situation::from_scan(beams, SECTORS, MAX_RANGE, goal_angle)
}

/// The driver of the supervised training and of on-line learning.
/// CHOICE: the robot is 0.4 m square, its laser at its centre, its corners
/// 0.27 m from it, and it turns "in place" on a 0.08 m circle: it keeps
/// 0.38 m from what is ahead and slows from 1 m.
pub fn driver() -> DriverParams {
    DriverParams { max_speed: 0.5, safety: 0.38, slow_distance: 1.0, ..DriverParams::default() }
}

/// A case base learnt in a supervised run: the scripted driver guides the
/// robot through an obstacle field of its own (seeded), and every situation
/// far enough from the cases so far is kept with the driver's command.
pub fn train(seed: u64, seconds: f64, novelty: f64) -> Cases {
    let mut cases = Cases::new(REACTIVE_RANGE, novelty);
    let mut noise = Noise::new(seed, 41);
    // A 20 m square, walled, with 40 boxes.
    let mut views = Vec::new();
    let wall = |x0: f64, y0: f64, x1: f64, y1: f64| vec![v2(x0, y0), v2(x1, y0), v2(x1, y1), v2(x0, y1)];
    let mut polys = vec![
        wall(-0.2, -0.2, 20.2, 0.0),
        wall(-0.2, 20.0, 20.2, 20.2),
        wall(-0.2, 0.0, 0.0, 20.0),
        wall(20.0, 0.0, 20.2, 20.0),
    ];
    for _ in 0..40 {
        let (x, y) = (1.5 + 17.0 * noise.uniform(), 1.5 + 17.0 * noise.uniform());
        let (w, h) = (0.3 + 0.9 * noise.uniform(), 0.3 + 0.9 * noise.uniform());
        polys.push(wall(x, y, x + w, y + h));
    }
    for (index, polygon) in polys.into_iter().enumerate() {
        let center = polygon.iter().fold(v2(0.0, 0.0), |a, p| a + p) / polygon.len() as f64;
        let radius = polygon.iter().map(|p| (p - center).norm()).fold(0.0, f64::max);
        views.push(ObstacleView { index, polygon, height: 1.0, center, radius });
    }
    let free = |p: Vec2, views: &[ObstacleView]| {
        views.iter().all(|v| {
            !situ_sim::geom::contains(&v.polygon, p) && situ_sim::geom::dist_point_polygon(&v.polygon, p) > 0.4
        })
    };
    let pick = |noise: &mut Noise| loop {
        let p = v2(1.0 + 18.0 * noise.uniform(), 1.0 + 18.0 * noise.uniform());
        if free(p, &views) {
            return p;
        }
    };
    let mut pose = {
        let p = pick(&mut noise);
        Pose::new(p.x, p.y, noise.uniform() * std::f64::consts::TAU)
    };
    let mut goal = pick(&mut noise);
    let dt = 0.1;
    let params = driver();
    let mut t = 0.0;
    // Where the robot was 5 s ago: a robot that has not moved since is stuck.
    let mut mark = (pose.pos(), 0.0);
    while t < seconds {
        let beams = scan(&pose, &views, Some(&mut noise));
        let s = situation(&pose, &beams, goal);
        let cmd = cases::drive(&s, MAX_RANGE, &params);
        let _ = cases.learn(Case { situation: s, command: cmd });
        let next = Pose::new(
            pose.x + cmd.speed * pose.theta.cos() * dt,
            pose.y + cmd.speed * pose.theta.sin() * dt,
            wrap_angle(pose.theta + cmd.turn_rate * dt),
        );
        let mut stuck = !free(next.pos(), &views);
        if t - mark.1 >= 5.0 {
            stuck |= (pose.pos() - mark.0).norm() < 0.2;
            mark = (pose.pos(), t);
        }
        if (goal - pose.pos()).norm() < 0.5 || stuck {
            // A new leg: from where it is (or a fresh free spot when stuck).
            if stuck {
                let p = pick(&mut noise);
                pose = Pose::new(p.x, p.y, noise.uniform() * std::f64::consts::TAU);
            }
            goal = pick(&mut noise);
        } else {
            pose = next;
        }
        t += dt;
    }
    cases
}

struct Laser {
    noise: Noise,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Laser {
    fn name(&self) -> &str {
        "Laser"
    }
    fn functions(&self) -> Vec<String> {
        names(&["scan"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let (pose, beams) = {
            let p = lock(&self.physics);
            let pose = p.vehicle.state.pose;
            (pose, scan(&pose, &p.views, Some(&mut self.noise)))
        };
        let nearest = beams.iter().map(|b| b.range).fold(MAX_RANGE, f64::min);
        report(cx, &self.content, &Named("SCAN", vec![("nearest", SimValue::F64(nearest))]));
        cx.send(Body::local(Scan { pose, beams: Arc::new(beams) }));
    }
}

struct Localization {
    goal: Vec2,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Localization {
    fn name(&self) -> &str {
        "Localization"
    }
    fn functions(&self) -> Vec<String> {
        names(&["locate"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let pose = lock(&self.physics).vehicle.state.pose;
        let remaining = (self.goal - pose.pos()).norm();
        report(cx, &self.content, &Named("POSE", vec![("remaining", SimValue::F64(remaining))]));
        cx.send(Body::local(PoseFix(pose)));
    }
}

struct Mapper {
    grid: OccupancyGrid,
    pyramid: PyramidParams,
    version: u64,
    /// The latest snapshot, replaced when a cell changes class.
    last: Option<MapSnapshot>,
    last_scan: u64,
    plans: SharedPlans,
}

impl Mapper {
    fn new(world: &World, plans: SharedPlans) -> Mapper {
        let (lo, hi) = world.bounds();
        let origin = v2(lo.x - 1.0, lo.y - 1.0);
        let w = ((hi.x - lo.x + 2.0) / CELL).ceil() as usize;
        let h = ((hi.y - lo.y + 2.0) / CELL).ceil() as usize;
        let grid = OccupancyGrid::new(w.clamp(8, 1024), h.clamp(8, 1024), CELL, origin, GridParams::default());
        Mapper {
            grid,
            pyramid: PyramidParams { max_extent: 24, ..PyramidParams::default() },
            version: 0,
            last: None,
            last_scan: 0,
            plans,
        }
    }
}

impl Agent for Mapper {
    fn name(&self) -> &str {
        "Mapper"
    }
    fn functions(&self) -> Vec<String> {
        names(&["map"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let mut changed = 0;
        for d in cx.inputs() {
            if let Some(s) = d.body.get::<Scan>() {
                if d.time > self.last_scan {
                    self.last_scan = d.time;
                    changed += self.grid.update(&s.pose, &s.beams);
                }
            }
        }
        // A new snapshot when a cell changed class since the last one.
        if changed > 0 || self.last.is_none() {
            self.version += 1;
            let snap = MapSnapshot::new(self.version, Arc::new(self.grid.clone()), self.pyramid);
            lock_plans(&self.plans).map = Some(snap.clone());
            self.last = Some(snap);
        }
        if let Some(snap) = &self.last {
            cx.send(Body::local(snap.clone()));
        }
    }
}

/// Locks the plans (a poisoned lock is still the truth).
pub fn lock_plans(p: &SharedPlans) -> std::sync::MutexGuard<'_, Plans> {
    p.lock().unwrap_or_else(|e| e.into_inner())
}

struct RoutePlanner {
    goal: Vec2,
    map: Option<(u64, MapSnapshot)>,
    pose: Option<(u64, PoseFix)>,
    /// When the present computation started (a new one each time the
    /// planner is woken).
    started: Option<u64>,
    number: i64,
    plans: SharedPlans,
    content: Arc<Content>,
}

impl Agent for RoutePlanner {
    fn name(&self) -> &str {
        "RoutePlanner"
    }
    fn functions(&self) -> Vec<String> {
        names(&["route"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        take(cx.inputs(), &mut self.map);
        take(cx.inputs(), &mut self.pose);
        let now = cx.now();
        if cx.mode() != Mode::Running {
            self.started = None;
            return;
        }
        let started = *self.started.get_or_insert(now);
        if now < started + PLAN_TIME {
            return;
        }
        let (Some((_, map)), Some(fix)) = (&self.map, fresh(&self.pose, now)) else { return };
        let params = RouteParams { allow_unexplored: true, unexplored_cost: 3.0 };
        match plan_route(map.pyramid(), &map.grid, fix.0.pos(), self.goal, &params) {
            Some(regions) => {
                self.number += 1;
                let n = regions.len() as i64;
                let msg = RouteMsg { number: self.number, regions: Arc::new(regions), map: map.clone() };
                {
                    let mut p = lock_plans(&self.plans);
                    p.routes += 1;
                    if self.number > 1 {
                        p.replans += 1;
                    }
                    p.route = Some(msg.clone());
                }
                cx.send(Body::local(msg));
                let ev = Named("ROUTE", vec![("number", SimValue::I64(self.number)), ("regions", SimValue::I64(n))]);
                report(cx, &self.content, &ev);
            }
            None => {
                let known = (0..map.grid.len()).filter(|&i| map.grid.class_index(i) != CellClass::Unknown).count();
                let explored = known as f64 / map.grid.len().max(1) as f64;
                lock_plans(&self.plans).no_route = Some(explored);
                report(cx, &self.content, &Named("NO_ROUTE", vec![("explored", SimValue::F64(explored))]));
            }
        }
        // One route per waking: the next computation starts when woken again.
        self.started = Some(u64::MAX - PLAN_TIME);
    }
}

struct PathPlanner {
    goal: Vec2,
    route: Option<(u64, RouteMsg)>,
    map: Option<(u64, MapSnapshot)>,
    pose: Option<(u64, PoseFix)>,
    path: Option<(i64, Vec<Vec2>)>,
    /// The path point the robot has got to.
    progress: usize,
    reported: Option<i64>,
    plans: SharedPlans,
    content: Arc<Content>,
}

impl PathPlanner {
    /// Whether a cell near the path ahead (from the point closest to the
    /// robot) is occupied on the latest grid.
    fn blocked(path: &[Vec2], from: usize, grid: &OccupancyGrid) -> bool {
        let r = (CLEARANCE / grid.cell_size()).ceil() as i64;
        let mut walked = 0.0;
        for k in from..path.len() {
            if k > from {
                walked += (path[k] - path[k - 1]).norm();
            }
            if walked > CHECK_AHEAD {
                break;
            }
            let Some((cx, cy)) = grid.cell_of(path[k]) else { continue };
            for dy in -r..=r {
                for dx in -r..=r {
                    let (x, y) = (cx as i64 + dx, cy as i64 + dy);
                    if x >= 0
                        && y >= 0
                        && (x as usize) < grid.width()
                        && (y as usize) < grid.height()
                        && grid.is_occupied(x as usize, y as usize)
                    {
                        return true;
                    }
                }
            }
        }
        false
    }
}

impl Agent for PathPlanner {
    fn name(&self) -> &str {
        "PathPlanner"
    }
    fn functions(&self) -> Vec<String> {
        names(&["path"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        take(cx.inputs(), &mut self.route);
        take(cx.inputs(), &mut self.map);
        take(cx.inputs(), &mut self.pose);
        let now = cx.now();
        if cx.mode() != Mode::Running {
            return;
        }
        let (Some((_, route)), Some(fix)) = (&self.route, fresh(&self.pose, now)) else { return };
        let number = route.number;
        if self.path.as_ref().is_none_or(|(n, _)| *n != number) {
            let path = plan_path(
                &route.map.grid,
                route.map.pyramid(),
                &route.regions,
                fix.0.pos(),
                self.goal,
                &PathParams::default(),
            );
            match path {
                Some(p) => {
                    lock_plans(&self.plans).path = p.clone();
                    self.path = Some((number, p));
                    self.progress = 0;
                }
                None => {
                    if self.reported != Some(number) {
                        self.reported = Some(number);
                        report(cx, &self.content, &Named("PATH_BLOCKED", vec![("route", SimValue::I64(number))]));
                    }
                    return;
                }
            }
        }
        let Some((_, path)) = &self.path else { return };
        let here = fix.0.pos();
        // Progress along the path only goes forward (a window of 3 m ahead
        // is searched), so a path that passes near itself is not followed
        // back to its earlier part.
        let window = self.progress..path.len().min(self.progress + 30);
        let closest = window
            .min_by(|&a, &b| (path[a] - here).norm().total_cmp(&(path[b] - here).norm()))
            .unwrap_or(self.progress);
        self.progress = closest;
        let grid = self.map.as_ref().map(|(_, m)| m.grid.clone()).unwrap_or_else(|| route.map.grid.clone());
        if Self::blocked(path, closest, &grid) {
            if self.reported != Some(number) {
                self.reported = Some(number);
                report(cx, &self.content, &Named("PATH_BLOCKED", vec![("route", SimValue::I64(number))]));
            }
            return;
        }
        let mut walked = 0.0;
        let mut target = *path.last().unwrap_or(&self.goal);
        for k in closest + 1..path.len() {
            walked += (path[k] - path[k - 1]).norm();
            if walked >= LOOKAHEAD {
                target = path[k];
                break;
            }
        }
        cx.send(Body::local(Subgoal(target)));
    }
}

struct Reactive {
    goal: Vec2,
    vehicle: VehicleParams,
    cases: SharedCases,
    learn: bool,
    scan: Option<(u64, Scan)>,
    pose: Option<(u64, PoseFix)>,
    subgoal: Option<(u64, Subgoal)>,
    plans: SharedPlans,
    detour: Detour,
}

impl Agent for Reactive {
    fn name(&self) -> &str {
        "Reactive"
    }
    fn functions(&self) -> Vec<String> {
        names(&["cases"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        take(cx.inputs(), &mut self.scan);
        take(cx.inputs(), &mut self.pose);
        take(cx.inputs(), &mut self.subgoal);
        let now = cx.now();
        let (Some(scan), Some(_)) = (fresh(&self.scan, now), fresh(&self.pose, now)) else { return };
        // Following: the path's subgoal; otherwise (or a stale one) the goal.
        let target = match (cx.state(), fresh(&self.subgoal, now)) {
            ("Following", Some(s)) => s.0,
            _ => self.goal,
        };
        let mut s = situation(&scan.pose, &scan.beams, target);
        // Towards the goal (no path to follow), a detour out of a local
        // minimum when the robot is caught in one.
        if cx.state() == "Following" {
            self.detour.reset();
        } else {
            let aim = self.detour.aim(now as f64 * 1e-9, &scan.pose, target, &s.ranges);
            s = Situation::new(s.ranges, aim);
        }
        let mut cases = self.cases.lock().unwrap_or_else(|e| e.into_inner());
        let nearest = cases.nearest(&s).ok().flatten();
        let novel = nearest.is_none_or(|(_, d)| d > cases.novelty());
        // A case that would drive on towards something closer than the
        // driver's safety distance is wrong here: the driver corrects it,
        // and the correction is learnt (learning from the robot's own trouble).
        let nearest_all = s.ranges.iter().copied().fold(f64::INFINITY, f64::min);
        let ahead = (0..SECTORS)
            .filter(|&i| Situation::sector_angle(i, SECTORS).abs() <= std::f64::consts::FRAC_PI_4 + 1e-9)
            .map(|i| s.ranges[i])
            .fold(f64::INFINITY, f64::min);
        // So is a case that leaves the robot standing where it could move.
        let wrong = |c: &CaseCommand| (c.speed > 0.0 && ahead < driver().safety) || standstill(c);
        let command = match nearest {
            Some((i, _)) if !(self.learn && (novel || wrong(&cases.cases()[i].command))) => cases.cases()[i].command,
            _ => {
                let c = cases::drive(&s, MAX_RANGE, &driver());
                let case = Case { situation: s, command: c };
                let added = if novel { cases.learn(case) } else { cases.insert(case) };
                if self.learn && added.unwrap_or(false) {
                    lock_plans(&self.plans).learnt += 1;
                }
                c
            }
        };
        drop(cases);
        let points: Vec<Vec2> = scan_points(&scan.beams).collect();
        let command = reflexes(command, &points, nearest_all, &self.vehicle);
        cx.send(Body::local(DriveCommand(command)));
    }
}

struct Base {
    params: VehicleParams,
    input: Option<(u64, DriveCommand)>,
    physics: SharedPhysics,
}

impl Agent for Base {
    fn name(&self) -> &str {
        "Base"
    }
    fn functions(&self) -> Vec<String> {
        names(&["drive", "stop"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        take(cx.inputs(), &mut self.input);
        let mut p = lock(&self.physics);
        let steer = p.vehicle.state.steer;
        p.command = match fresh(&self.input, cx.now()) {
            Some(DriveCommand(c)) if cx.mode() == Mode::Running && cx.function() == Some("drive") => {
                if standstill(c) {
                    Command { v: 0.0, steer }
                } else {
                    // A tricycle turns only while it rolls: "turn in place" is a crawl on full lock.
                    let v = c.speed.clamp(CRAWL, self.params.max_speed);
                    let max = self.params.max_steer;
                    Command { v, steer: (c.turn_rate * self.params.wheelbase / v).atan().clamp(-max, max) }
                }
            }
            _ => Command { v: 0.0, steer },
        };
    }
}

/// The DLA stack's agents; `cases` is the reactive layer's case base (it
/// learns into it when `learn`), `plans` what the stack draws.
pub fn agents(
    content: &Arc<Content>,
    physics: &SharedPhysics,
    world: &World,
    seed: u64,
    cases: SharedCases,
    learn: bool,
    plans: SharedPlans,
) -> Vec<Box<dyn Agent>> {
    let goal = world.goal.position;
    let c = || content.clone();
    vec![
        Box::new(Laser { noise: Noise::new(seed, 31), physics: physics.clone(), content: c() }),
        Box::new(Localization { goal, physics: physics.clone(), content: c() }),
        Box::new(Mapper::new(world, plans.clone())),
        Box::new(RoutePlanner {
            goal,
            map: None,
            pose: None,
            started: None,
            number: 0,
            plans: plans.clone(),
            content: c(),
        }),
        Box::new(PathPlanner {
            goal,
            route: None,
            map: None,
            pose: None,
            path: None,
            progress: 0,
            reported: None,
            plans: plans.clone(),
            content: c(),
        }),
        Box::new(Reactive {
            goal,
            vehicle: world.vehicle,
            cases,
            learn,
            scan: None,
            pose: None,
            subgoal: None,
            plans,
            detour: Detour::default(),
        }),
        Box::new(Base { params: world.vehicle, input: None, physics: physics.clone() }),
    ]
}

/// Region classes, for reports.
pub fn region_counts(p: &Pyramid) -> (usize, usize, usize) {
    let count = |c: RegionClass| p.regions().iter().filter(|r| r.class == c).count();
    (count(RegionClass::Free), count(RegionClass::Occupied), count(RegionClass::Unexplored))
}
