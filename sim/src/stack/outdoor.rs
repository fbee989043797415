//! The agents of `rules/outdoor.situ` (Zhang & Zhu 2005) on the runtime.
//!
//! | agent | reads (data) | does | sends |
//! |---|---|---|---|
//! | RFCCD | the world | [`sensors::Rfccd::observe`]; RFRS/RFRT/RFRB/RFRN | the road ([`RfccdEvent`]) |
//! | STCCD | the world | [`sensors::Stccd::observe`]; STOBS/STOBN | its scan |
//! | LADAR | the world | [`sensors::Ladar::observe`]; LAOBS/LAOBN | its scan |
//! | Localization | the world | [`sensors::Localization::observe`]; LOFIX/LOLOST | the [`Fix`] |
//! | Fusion | RFCCD, LADAR, STCCD | `fuse_road()` / `fuse_terrain()`; FU.. | [`FusionOutput`] |
//! | GPL | Supervisor (the goal), Mapper (the map), Localization | A*, re-plans on blocked roads; GP.. | [`GplData`] |
//! | LPL | RFCCD, Fusion or STCCD, GPL, Localization | the plan of Table 1 the table chooses; PL.. | [`LocalPlan`] |
//! | Drive | LPL, Localization | `track()`, `halt()`, `estop()`; DRSTOP at standstill | the command (to the vehicle) |
//! | Supervisor | Localization | its FSM: `mission()` sends the goal, then SVRDY | [`Mission`] |
//! | TeleControl | — | the safety radio: TCHB | — |
//! | Mapper | Fusion, Localization | `load()`, `update()`: roads found blocked | [`MapUpdate`] |
//! | Recorder | Localization, Fusion, LPL | counts what it records | — |
//!
//! Only the sensors read the ground truth and only Drive writes to it (its
//! command); every other input comes through the data stream, so an agent
//! that is not linked to a source in the current state does not see it
//! (LPL gets no obstacles in RS: LADAR waits and Fusion sleeps there).
//! Data older than [`FRESH`](crate::agent::FRESH) is not used.

use super::{lock, SharedPhysics, Stack};
use crate::agent::{held, hold, names, report, Event, Held, Plain};
use crate::drive;
use crate::fusion::{self, FusedObstacle, FusionConfig, FusionOutput};
use crate::geom::Pose;
use crate::gpl::{self, GlobalPath};
use crate::lpl::{self, FailReason, LocalPlan, PlanEvent, PlanInput, PlanKind};
use crate::sensors::{self, Fix, LadarEvent, ObstacleScan, RfccdEvent, StccdEvent};
use crate::world::{EdgeKind, Goal, World};
use petgraph::graph::EdgeIndex;
use situ_compiler::bundle::Content;
use situ_runtime::agent::{Agent, Body, Context};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

/// The agents `rules/outdoor.situ` declares.
pub const AGENTS: &[&str] = &[
    "RFCCD",
    "STCCD",
    "LADAR",
    "Localization",
    "Fusion",
    "GPL",
    "LPL",
    "Mapper",
    "Drive",
    "Supervisor",
    "TeleControl",
    "Recorder",
];

/// LPL plans a stop before a road it finds blocked, and fails (PLF) when
/// no new path comes within this time (ns).
pub const BLOCKED_PATIENCE: u64 = 5_000_000_000;

/// The mission the Supervisor loads and sends to GPL.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mission {
    /// The goal.
    pub goal: Goal,
}

/// The Mapper's map: the roads found blocked.
#[derive(Debug, Clone, PartialEq)]
pub struct MapUpdate {
    /// Blocked road edges.
    pub blocked: Vec<EdgeIndex>,
}

/// GPL's data for LPL.
#[derive(Debug, Clone)]
pub enum GplData {
    /// The global path; the version changes with every (re-)plan.
    Path(u32, Arc<GlobalPath>),
    /// No path to the goal.
    NoPath,
}

/// The a priori map: the world without its obstacles (nobody knows those
/// beforehand).
pub fn a_priori(world: &World) -> World {
    let mut map = world.clone();
    map.obstacles.clear();
    map
}

/// RFCCD: road following with the cameras.
pub struct Rfccd {
    cam: sensors::Rfccd,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Rfccd {
    fn name(&self) -> &str {
        "RFCCD"
    }
    fn functions(&self) -> Vec<String> {
        names(&["lines_far", "lines_near"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let ev = {
            let p = lock(&self.physics);
            self.cam.observe(&p.world, &p.vehicle.state)
        };
        report(cx, &self.content, &ev);
        cx.send(Body::local(ev));
    }
}

/// STCCD: the stereo pair.
pub struct Stccd {
    cam: sensors::Stccd,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Stccd {
    fn name(&self) -> &str {
        "STCCD"
    }
    fn functions(&self) -> Vec<String> {
        names(&["stereo"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let scan = {
            let p = lock(&self.physics);
            self.cam.observe(&p.world, &p.vehicle.state, &p.views)
        };
        report(cx, &self.content, &scan.event);
        cx.send(Body::local(scan));
    }
}

/// LADAR.
pub struct Ladar {
    ladar: sensors::Ladar,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Ladar {
    fn name(&self) -> &str {
        "LADAR"
    }
    fn functions(&self) -> Vec<String> {
        names(&["detect"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let scan = {
            let p = lock(&self.physics);
            self.ladar.observe(&p.world, &p.vehicle.state, &p.views)
        };
        report(cx, &self.content, &scan.event);
        cx.send(Body::local(scan));
    }
}

/// Localization: GPS/INS and odometer.
pub struct Localization {
    loc: sensors::Localization,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Localization {
    fn name(&self) -> &str {
        "Localization"
    }
    fn functions(&self) -> Vec<String> {
        names(&["gpsins"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let fix = {
            let p = lock(&self.physics);
            self.loc.observe(&p.world, &p.vehicle.state)
        };
        report(cx, &self.content, &fix.event);
        cx.send(Body::local(fix));
    }
}

/// Fusion: one description of the environment from the obstacle sensors
/// and the road camera.
pub struct Fusion {
    cfg: FusionConfig,
    road: Option<Held>,
    ladar: Option<Held>,
    stereo: Option<Held>,
    content: Arc<Content>,
}

impl Agent for Fusion {
    fn name(&self) -> &str {
        "Fusion"
    }
    fn functions(&self) -> Vec<String> {
        names(&["fuse_road", "fuse_terrain"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let now = cx.now();
        hold::<RfccdEvent>(cx.inputs(), &mut self.road);
        hold::<ObstacleScan<LadarEvent>>(cx.inputs(), &mut self.ladar);
        hold::<ObstacleScan<StccdEvent>>(cx.inputs(), &mut self.stereo);
        let ladar = held::<ObstacleScan<LadarEvent>>(&self.ladar, now);
        let stereo = held::<ObstacleScan<StccdEvent>>(&self.stereo, now);
        let out: FusionOutput = match cx.function() {
            Some("fuse_road") => {
                let (Some(road), Some(ladar)) = (held::<RfccdEvent>(&self.road, now), ladar) else { return };
                fusion::fuse_road(road, &ladar.detections, &self.cfg)
            }
            Some("fuse_terrain") => {
                if ladar.is_none() && stereo.is_none() {
                    return;
                }
                let l = ladar.map_or(&[][..], |s| &s.detections[..]);
                let s = stereo.map_or(&[][..], |s| &s.detections[..]);
                fusion::fuse_terrain(l, s, &self.cfg)
            }
            _ => return,
        };
        report(cx, &self.content, &out.event);
        cx.send(Body::local(out));
    }
}

/// GPL: the global path on the a priori map.
pub struct Gpl {
    planner: gpl::Gpl,
    map: World,
    goal: bool,
    map_loaded: bool,
    pose: Option<Pose>,
    path: Option<Arc<GlobalPath>>,
    version: u32,
    no_path: bool,
    replan: bool,
    content: Arc<Content>,
}

impl Gpl {
    fn plan(&mut self, pose: &Pose) {
        match self.planner.plan(&self.map, pose) {
            Ok(p) => {
                self.path = Some(Arc::new(p.clone()));
                self.version += 1;
                self.no_path = false;
            }
            Err(_) => {
                self.path = None;
                self.no_path = true;
            }
        }
        self.replan = false;
    }
}

impl Agent for Gpl {
    fn name(&self) -> &str {
        "GPL"
    }
    fn functions(&self) -> Vec<String> {
        names(&["plan", "replan"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        for d in cx.inputs() {
            if let Some(m) = d.body.get::<Mission>() {
                self.map.goal = m.goal;
                self.goal = true;
            } else if let Some(m) = d.body.get::<MapUpdate>() {
                self.map_loaded = true;
                for &e in &m.blocked {
                    if self.planner.blocked.insert(e)
                        && self.path.as_ref().is_some_and(|p| p.pieces.iter().any(|x| x.edge == e))
                    {
                        self.replan = true;
                    }
                }
            } else if let Some(f) = d.body.get::<Fix>() {
                if f.pose.is_some() {
                    self.pose = f.pose;
                }
            }
        }
        let Some(pose) = self.pose else { return };
        match cx.function() {
            Some("plan") if self.path.is_none() && !self.no_path && self.goal && self.map_loaded => self.plan(&pose),
            Some("replan") if self.replan => self.plan(&pose),
            _ => {}
        }
        if self.no_path {
            cx.send(Body::local(GplData::NoPath));
            return;
        }
        let Some(path) = self.path.clone() else { return };
        if let Some(r) = self.planner.report(&self.map, &pose) {
            report(cx, &self.content, &r.event);
        }
        cx.send(Body::local(GplData::Path(self.version, path)));
    }
}

/// LPL: the plans of Table 1.
pub struct Lpl {
    planner: lpl::Lpl,
    map: Arc<World>,
    path: Option<(u32, Arc<GlobalPath>)>,
    no_path: bool,
    fix: Option<Fix>,
    road: Option<u64>,
    fusion: Option<Held>,
    stereo: Option<Held>,
    s: f64,
    blocked_since: Option<u64>,
    content: Arc<Content>,
}

impl Agent for Lpl {
    fn name(&self) -> &str {
        "LPL"
    }
    fn functions(&self) -> Vec<String> {
        names(&["plrs", "plrt", "plrb", "plro", "plcn", "plco"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let now = cx.now();
        for d in cx.inputs() {
            if let Some(g) = d.body.get::<GplData>() {
                match g {
                    GplData::Path(v, p) => {
                        if self.path.as_ref().is_none_or(|(w, _)| w != v) {
                            // A new path: the old passes and progress mean nothing on it.
                            self.planner.reset();
                            self.s = 0.0;
                            self.path = Some((*v, p.clone()));
                        }
                        self.no_path = false;
                    }
                    GplData::NoPath => self.no_path = true,
                }
            } else if let Some(f) = d.body.get::<Fix>() {
                self.fix = Some(*f);
            } else if d.body.get::<RfccdEvent>().is_some() {
                self.road = Some(d.time);
            }
        }
        hold::<FusionOutput>(cx.inputs(), &mut self.fusion);
        hold::<ObstacleScan<StccdEvent>>(cx.inputs(), &mut self.stereo);
        let kind = match cx.function() {
            Some("plrs") => PlanKind::Straight,
            Some("plrt") => PlanKind::Turn,
            Some("plrb") => PlanKind::Branch,
            Some("plro") => PlanKind::RoadObstacle,
            Some("plcn") => PlanKind::CrossCountry,
            Some("plco") => PlanKind::CrossCountryObstacle,
            _ => return,
        };
        if self.no_path {
            report(cx, &self.content, &PlanEvent::Failed { reason: FailReason::NoPath });
            return;
        }
        let (Some((_, path)), Some(fix)) = (self.path.clone(), self.fix) else { return };
        // Without a position there is no plan (Localization's LOLOST is the
        // rules' business).
        let Some(pose) = fix.pose else { return };
        let (s, _) = path.project(pose.pos(), self.s, 60.0);
        self.s = s;
        let obstacles: Vec<FusedObstacle> = match kind {
            PlanKind::RoadObstacle | PlanKind::CrossCountryObstacle => {
                held::<FusionOutput>(&self.fusion, now).map(|f| f.obstacles.clone()).unwrap_or_default()
            }
            PlanKind::CrossCountry => held::<ObstacleScan<StccdEvent>>(&self.stereo, now)
                .map(|s| fusion::merge(&[], &s.detections))
                .unwrap_or_default(),
            _ => Vec::new(),
        };
        let input = PlanInput { world: &self.map, pose, speed: fix.speed, path: &path, s, obstacles: &obstacles };
        let mut plan = self.planner.plan(kind, &input);
        // On a road plan the camera must see the road: without a road
        // description for a second, slow to the cross-country speed.
        let road_plan = matches!(kind, PlanKind::Straight | PlanKind::Turn | PlanKind::Branch);
        if road_plan && self.road.is_none_or(|t| now.saturating_sub(t) > 1_000_000_000) {
            let cap = self.planner.cfg.speeds[4];
            plan.speed = plan.speed.min(cap);
            plan.target.v = plan.target.v.min(cap);
        }
        if plan.blocked.is_some() {
            // No pass: stop before it while the Mapper and GPL find another way.
            let since = *self.blocked_since.get_or_insert(now);
            if now - since > BLOCKED_PATIENCE {
                report(cx, &self.content, &PlanEvent::Failed { reason: FailReason::Blocked });
                return;
            }
            plan.speed = 0.0;
            plan.target.v = 0.0;
            plan.event =
                if path.kind(s) == EdgeKind::Road { PlanEvent::RoadObstacle } else { PlanEvent::CrossCountryObstacle };
        } else {
            self.blocked_since = None;
        }
        report(cx, &self.content, &plan.event);
        cx.send(Body::local(plan));
    }
}

/// Drive: the actuator.
pub struct Drive {
    drive: drive::Drive,
    physics: SharedPhysics,
    plan: Option<Held>,
    fix: Option<Fix>,
    content: Arc<Content>,
}

impl Agent for Drive {
    fn name(&self) -> &str {
        "Drive"
    }
    fn functions(&self) -> Vec<String> {
        names(&["track", "halt", "estop"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let now = cx.now();
        hold::<LocalPlan>(cx.inputs(), &mut self.plan);
        for d in cx.inputs() {
            if let Some(f) = d.body.get::<Fix>() {
                self.fix = Some(*f);
            }
        }
        let mut p = lock(&self.physics);
        let steer = p.vehicle.state.steer;
        let cmd = match cx.function() {
            Some("track") => match (held::<LocalPlan>(&self.plan, now), self.fix.and_then(|f| f.pose)) {
                (Some(plan), Some(pose)) => self.drive.track(&pose, plan),
                _ => self.drive.halt(steer),
            },
            Some("estop") => self.drive.estop(),
            _ => self.drive.halt(steer),
        };
        p.command = cmd;
        let standing = p.vehicle.state.v <= 1e-3;
        drop(p);
        if standing {
            report(cx, &self.content, &Plain("DRSTOP"));
        }
    }
}

/// Supervisor: loads the mission, then watches.
pub struct Supervisor {
    goal: Goal,
    steps: u32,
    pose: Option<Pose>,
    content: Arc<Content>,
}

impl Agent for Supervisor {
    fn name(&self) -> &str {
        "Supervisor"
    }
    fn functions(&self) -> Vec<String> {
        names(&["mission", "monitor", "alarm"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        for d in cx.inputs() {
            if let Some(f) = d.body.get::<Fix>() {
                self.pose = f.pose.or(self.pose);
            }
        }
        if cx.function() == Some("mission") {
            // The goal goes to GPL (which reads from the Supervisor while
            // initializing); the process table is the bound agents, all of
            // them present: ready from the second step on.
            self.steps += 1;
            cx.send(Body::local(Mission { goal: self.goal }));
            if self.steps >= 2 {
                report(cx, &self.content, &Plain("SVRDY"));
            }
        }
    }
}

/// TeleControl: the operator station's heartbeat.
pub struct TeleControl {
    content: Arc<Content>,
}

impl Agent for TeleControl {
    fn name(&self) -> &str {
        "TeleControl"
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        report(cx, &self.content, &Plain("TCHB"));
    }
}

/// Mapper: the global map, with what Fusion perceived.
pub struct Mapper {
    map: Arc<World>,
    margin: f64,
    blocked: BTreeSet<EdgeIndex>,
}

impl Agent for Mapper {
    fn name(&self) -> &str {
        "Mapper"
    }
    fn functions(&self) -> Vec<String> {
        names(&["load", "update"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        if cx.function() == Some("update") {
            for d in cx.inputs() {
                if let Some(f) = d.body.get::<FusionOutput>() {
                    for o in &f.obstacles {
                        if let Some(e) = lpl::blocked_road(&self.map, &o.polygon, o.height, self.margin) {
                            self.blocked.insert(e);
                        }
                    }
                }
            }
        }
        if matches!(cx.function(), Some("load") | Some("update")) {
            cx.send(Body::local(MapUpdate { blocked: self.blocked.iter().copied().collect() }));
        }
    }
}

/// Recorder: the operating data, counted per source.
pub struct Recorder {
    /// Data received per source agent.
    pub received: BTreeMap<String, u64>,
}

impl Agent for Recorder {
    fn name(&self) -> &str {
        "Recorder"
    }
    fn functions(&self) -> Vec<String> {
        names(&["record"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        for d in cx.inputs() {
            let from = cx.agent_name(d.from);
            match self.received.get_mut(from) {
                Some(n) => *n += 1,
                None => {
                    self.received.insert(from.to_string(), 1);
                }
            }
        }
    }
}

/// Zhang & Zhu's outdoor vehicle (`rules/outdoor.situ`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Outdoor;

impl Stack for Outdoor {
    fn name(&self) -> &'static str {
        "outdoor"
    }
    fn title(&self) -> &'static str {
        "Outdoor"
    }
    fn agents(&self) -> &'static [&'static str] {
        AGENTS
    }
    fn known_as(&self) -> String {
        format!("of rules/outdoor.situ ({})", AGENTS.join(", "))
    }
    fn default_scenario(&self) -> &'static str {
        "outdoor-default"
    }
    fn goal_state(&self) -> &'static str {
        "GL"
    }
    /// TeleControl has no `rate` in the rules (it runs in every state with
    /// no function): its heartbeat TCHB comes at 10 Hz, the rate the rules'
    /// `stale after 1s` ("10 heartbeats") assumes.
    fn rates(&self) -> BTreeMap<String, f64> {
        [("TeleControl".to_string(), 10.0)].into()
    }
    /// The Drive's period (50 Hz), so that the steering rate is the rate of
    /// its commands.
    fn sample_every(&self) -> u64 {
        2
    }
    fn default_until(&self) -> f64 {
        600.0
    }
    fn agents_for(
        &self,
        content: &Arc<Content>,
        physics: &SharedPhysics,
        world: &World,
        seed: u64,
    ) -> Vec<Box<dyn Agent>> {
        agents(content, physics, world, seed)
    }
}

/// Every agent of `rules/outdoor.situ` on a world, with a seed.
pub fn agents(content: &Arc<Content>, physics: &SharedPhysics, world: &World, seed: u64) -> Vec<Box<dyn Agent>> {
    let map = Arc::new(a_priori(world));
    let c = || content.clone();
    let ph = || physics.clone();
    vec![
        Box::new(Rfccd { cam: sensors::Rfccd::new(seed), physics: ph(), content: c() }),
        Box::new(Stccd { cam: sensors::Stccd::new(seed), physics: ph(), content: c() }),
        Box::new(Ladar { ladar: sensors::Ladar::new(seed), physics: ph(), content: c() }),
        // A GPS/INS filter's error wanders (correlation time 2 s at the
        // rules' 50 Hz) rather than jumping at every solution.
        Box::new(Localization { loc: sensors::Localization::correlated(seed, 0.02, 2.0), physics: ph(), content: c() }),
        Box::new(Fusion { cfg: FusionConfig::default(), road: None, ladar: None, stereo: None, content: c() }),
        Box::new(Gpl {
            planner: gpl::Gpl::default(),
            map: (*map).clone(),
            goal: false,
            map_loaded: false,
            pose: None,
            path: None,
            version: 0,
            no_path: false,
            replan: false,
            content: c(),
        }),
        Box::new(Lpl {
            planner: lpl::Lpl::default(),
            map: map.clone(),
            path: None,
            no_path: false,
            fix: None,
            road: None,
            fusion: None,
            stereo: None,
            s: 0.0,
            blocked_since: None,
            content: c(),
        }),
        Box::new(Mapper { map: map.clone(), margin: lpl::LplConfig::default().road_margin, blocked: BTreeSet::new() }),
        Box::new(Drive { drive: drive::Drive::new(world.vehicle), physics: ph(), plan: None, fix: None, content: c() }),
        Box::new(Supervisor { goal: world.goal, steps: 0, pose: None, content: c() }),
        Box::new(TeleControl { content: c() }),
        Box::new(Recorder { received: BTreeMap::new() }),
    ]
}

/// Every event the outdoor agents report, one of each kind (for a check
/// that the rules file declares them all).
pub fn sample_events() -> Vec<Box<dyn Event>> {
    use crate::fusion::FusionEvent;
    use crate::gpl::GplEvent;
    use crate::sensors::LocalizationEvent;
    vec![
        Box::new(RfccdEvent::Straight),
        Box::new(RfccdEvent::Turn { curvature: 0.03, left: true }),
        Box::new(RfccdEvent::Branch { distance: 20.0 }),
        Box::new(RfccdEvent::None),
        Box::new(StccdEvent::Obstacle { distance: 10.0, width: 1.0 }),
        Box::new(StccdEvent::None),
        Box::new(LadarEvent::Obstacle { distance: 10.0, height: 1.0 }),
        Box::new(LadarEvent::None),
        Box::new(LocalizationEvent::Fix { error: 0.2 }),
        Box::new(LocalizationEvent::Lost),
        Box::new(FusionEvent::RoadStraight),
        Box::new(FusionEvent::RoadTurn),
        Box::new(FusionEvent::RoadBranch),
        Box::new(FusionEvent::RoadObstacle { distance: 10.0 }),
        Box::new(FusionEvent::CrossCountry),
        Box::new(FusionEvent::CrossCountryObstacle { distance: 10.0 }),
        Box::new(GplEvent::Straight),
        Box::new(GplEvent::Turn),
        Box::new(GplEvent::Branch),
        Box::new(GplEvent::CrossCountry),
        Box::new(GplEvent::Goal { remaining: 1.0 }),
        Box::new(PlanEvent::Straight),
        Box::new(PlanEvent::Turn),
        Box::new(PlanEvent::Branch),
        Box::new(PlanEvent::RoadObstacle),
        Box::new(PlanEvent::CrossCountry),
        Box::new(PlanEvent::CrossCountryObstacle),
        Box::new(PlanEvent::Failed { reason: FailReason::NoPath }),
        Box::new(PlanEvent::Failed { reason: FailReason::Blocked }),
        Box::new(PlanEvent::Failed { reason: FailReason::Timeout }),
        Box::new(Plain("DRSTOP")),
        Box::new(Plain("SVRDY")),
        Box::new(Plain("TCHB")),
    ]
}
