//! The outdoor stack of Zhang & Zhu in closed loop, with a simple built-in
//! situation logic standing in for the Bulletinboard.
//!
//! [`SimpleSituation`] mirrors the driving rules of `rules/outdoor.situ`
//! (thresholds, run lengths, saliences) over the events of one tick; the
//! real system replaces it with the compiled rules. [`OutdoorSim::step`] is
//! one 20 Hz tick of every agent:
//!
//! 1. sensors: RFCCD, LADAR, STCCD, Localization (every tick);
//! 2. GPL's report (path ahead, remaining distance);
//! 3. the situation: a new state from this tick's sensor events and the
//!    processing agents' latest events (Fusion, LPL: one tick old);
//! 4. Fusion (in RO and CO only, as the rules' tables say), LPL's plan of
//!    the state (Table 1), GPL re-planning when LPL finds the road blocked;
//! 5. Drive: `track()` in the driving states, `halt()` or `estop()` else;
//! 6. the vehicle moves; metrics, collisions, the goal.

use crate::drive::Drive;
use crate::fusion::{fuse_road, fuse_terrain, FusedObstacle, FusionConfig, FusionEvent, FusionOutput};
use crate::gpl::{Gpl, GplEvent, GplReport};
use crate::lpl::{FailReason, LocalPlan, Lpl, PlanEvent, PlanInput, PlanKind};
use crate::metrics::{Metrics, Recorder, Sample};
use crate::sensors::{Ladar, LadarEvent, Localization, LocalizationEvent, Rfccd, RfccdEvent, Stccd, StccdEvent};
use crate::vehicle::{Command, Vehicle};
use crate::world::{ObstacleView, World};
use serde::Serialize;

/// The system states of `rules/outdoor.situ`. (`bench/handwritten` has its
/// own copy, `repr(u8)`: that benchmark depends on nothing.)
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub enum State {
    /// System initializing.
    IT,
    /// System gets ready.
    RD,
    /// Road straight.
    RS,
    /// Road turn.
    RT,
    /// Road branch.
    RB,
    /// Road with obstacle.
    RO,
    /// Cross-country without obstacle.
    CN,
    /// Cross-country with obstacle.
    CO,
    /// Goal achieved.
    GL,
    /// Emergency.
    EM,
    /// Stop.
    SP,
}

impl State {
    /// The state's name in the rules file.
    pub fn name(self) -> &'static str {
        match self {
            State::IT => "IT",
            State::RD => "RD",
            State::RS => "RS",
            State::RT => "RT",
            State::RB => "RB",
            State::RO => "RO",
            State::CN => "CN",
            State::CO => "CO",
            State::GL => "GL",
            State::EM => "EM",
            State::SP => "SP",
        }
    }

    /// A driving state (the vehicle tracks a plan).
    pub fn driving(self) -> bool {
        matches!(self, State::RS | State::RT | State::RB | State::RO | State::CN | State::CO)
    }

    /// The plan LPL runs in this state (Table 1), if any.
    pub fn plan(self) -> Option<PlanKind> {
        Some(match self {
            State::RS => PlanKind::Straight,
            State::RT => PlanKind::Turn,
            State::RB => PlanKind::Branch,
            State::RO => PlanKind::RoadObstacle,
            State::CN => PlanKind::CrossCountry,
            State::CO => PlanKind::CrossCountryObstacle,
            _ => return None,
        })
    }

    /// The agents running in this state per the tables of `rules/outdoor.situ`
    /// (the sensors that only `wait` are left out).
    pub fn agents_running(self) -> Vec<String> {
        let mut a = vec!["Localization", "Drive", "Recorder"];
        match self {
            State::RS | State::RT | State::RB => a.extend(["RFCCD", "GPL", "LPL"]),
            State::RO => a.extend(["RFCCD", "LADAR", "Fusion", "GPL", "LPL", "Mapper"]),
            State::CN => a.extend(["STCCD", "GPL", "LPL"]),
            State::CO => a.extend(["STCCD", "LADAR", "Fusion", "GPL", "LPL", "Mapper"]),
            State::IT => a.extend(["GPL", "Mapper"]),
            State::RD => a.push("GPL"),
            State::EM | State::GL | State::SP => {}
        }
        a.sort_unstable();
        a.into_iter().map(str::to_string).collect()
    }
}

/// One tick's events, as the Bulletinboard would receive them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct TickEvents {
    /// RFCCD.
    pub rfccd: RfccdEvent,
    /// LADAR.
    pub ladar: LadarEvent,
    /// STCCD.
    pub stccd: StccdEvent,
    /// Localization.
    pub localization: LocalizationEvent,
    /// GPL (none before the first plan).
    pub gpl: Option<GplEvent>,
    /// Fusion's latest (it sleeps outside RO and CO).
    pub fusion: Option<FusionEvent>,
    /// LPL's latest.
    pub lpl: Option<PlanEvent>,
}

/// A simple situation logic: the driving rules of `rules/outdoor.situ` as
/// plain code (a stand-in for the Bulletinboard in tests and benchmarks).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimpleSituation {
    /// The current state.
    pub state: State,
    rfrs: u32,
    rfrt: u32,
    rfrn: u32,
    laobn: u32,
    stobn: u32,
    lofix: u32,
}

impl Default for SimpleSituation {
    fn default() -> Self {
        SimpleSituation { state: State::IT, rfrs: 0, rfrt: 0, rfrn: 0, laobn: 0, stobn: 0, lofix: 0 }
    }
}

fn run(c: &mut u32, yes: bool) {
    *c = if yes { *c + 1 } else { 0 };
}

impl SimpleSituation {
    /// Takes one tick's events and returns the new state.
    pub fn step(&mut self, ev: &TickEvents) -> State {
        run(&mut self.rfrs, ev.rfccd == RfccdEvent::Straight);
        run(&mut self.rfrt, matches!(ev.rfccd, RfccdEvent::Turn { curvature, .. } if curvature >= 0.02));
        run(&mut self.rfrn, ev.rfccd == RfccdEvent::None);
        run(&mut self.laobn, ev.ladar == LadarEvent::None);
        run(&mut self.stobn, ev.stccd == StccdEvent::None);
        run(&mut self.lofix, matches!(ev.localization, LocalizationEvent::Fix { error } if error < 0.5));
        use State::*;
        let s = self.state;
        let laobs = |d: f64, h: f64| matches!(ev.ladar, LadarEvent::Obstacle { distance, height } if distance < d && height > h);
        let stobs = |d: f64| matches!(ev.stccd, StccdEvent::Obstacle { distance, .. } if distance < d);
        let gpl = ev.gpl;
        let next = if s.driving()
            && (matches!(ev.lpl, Some(PlanEvent::Failed { .. }))
                || laobs(5.0, 0.15)
                || ev.localization == LocalizationEvent::Lost)
        {
            EM
        } else if s.driving() && matches!(gpl, Some(GplEvent::Goal { remaining }) if remaining < 2.0) {
            GL
        } else if s == RD && ev.localization == LocalizationEvent::Lost {
            IT
        } else if matches!(s, RS | RT | RB) && (laobs(30.0, 0.15) || stobs(30.0)) {
            RO
        } else if s == CN && (laobs(20.0, 0.3) || stobs(20.0)) {
            CO
        } else if s == RO
            && self.laobn >= 3
            && !stobs(30.0)
            && ev.fusion == Some(FusionEvent::RoadStraight)
            && ev.lpl == Some(PlanEvent::Straight)
        {
            RS
        } else if s == RO
            && self.laobn >= 3
            && !stobs(30.0)
            && ev.fusion == Some(FusionEvent::RoadTurn)
            && ev.lpl == Some(PlanEvent::Turn)
        {
            RT
        } else if s == RO
            && self.laobn >= 3
            && !stobs(30.0)
            && ev.fusion == Some(FusionEvent::RoadBranch)
            && ev.lpl == Some(PlanEvent::Branch)
        {
            RB
        } else if s == RO
            && matches!(ev.fusion, Some(FusionEvent::CrossCountryObstacle { .. }))
            && ev.lpl == Some(PlanEvent::CrossCountryObstacle)
        {
            CO
        } else if s == CO
            && ev.fusion == Some(FusionEvent::CrossCountry)
            && ev.lpl == Some(PlanEvent::CrossCountry)
            && self.laobn >= 3
            && self.stobn >= 1
        {
            CN
        } else if s == CO
            && matches!(ev.fusion, Some(FusionEvent::RoadObstacle { .. }))
            && ev.lpl == Some(PlanEvent::RoadObstacle)
        {
            RO
        } else if s == IT && self.lofix >= 10 {
            RD
        } else if s == RD && gpl == Some(GplEvent::Straight) && self.rfrs >= 3 && self.laobn >= 3 && self.stobn >= 1 {
            RS
        } else if s == RD && gpl == Some(GplEvent::Turn) && self.rfrt >= 3 && self.laobn >= 3 && self.stobn >= 1 {
            RT
        } else if s == RD && gpl == Some(GplEvent::CrossCountry) && self.laobn >= 3 && self.stobn >= 3 {
            CN
        } else if matches!(s, RT | RB) && self.rfrs >= 3 {
            RS
        } else if matches!(s, RS | RB) && self.rfrt >= 2 {
            RT
        } else if matches!(s, RS | RT) && matches!(ev.rfccd, RfccdEvent::Branch { .. }) && gpl == Some(GplEvent::Branch)
        {
            RB
        } else if matches!(s, RS | RT | RB) && gpl == Some(GplEvent::CrossCountry) && self.rfrn >= 3 {
            CN
        } else if s == CN && gpl == Some(GplEvent::Straight) && self.rfrs >= 3 {
            RS
        } else {
            s
        };
        self.state = next;
        next
    }
}

/// What one tick did (for a wrapper, a recorder or a test).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TickReport {
    /// Simulated time (s).
    pub t: f64,
    /// The events of the tick.
    pub events: TickEvents,
    /// The state after the tick's events.
    pub state: State,
    /// The command Drive gave.
    pub command: Command,
    /// LPL's plan, in driving states.
    pub plan: Option<LocalPlan>,
}

/// The outdoor stack in closed loop on a world.
#[derive(Debug)]
pub struct OutdoorSim {
    /// The world.
    pub world: World,
    /// The vehicle.
    pub vehicle: Vehicle,
    /// RFCCD.
    pub rfccd: Rfccd,
    /// LADAR.
    pub ladar: Ladar,
    /// STCCD.
    pub stccd: Stccd,
    /// Localization.
    pub localization: Localization,
    /// Fusion's thresholds.
    pub fusion_cfg: FusionConfig,
    /// GPL.
    pub gpl: Gpl,
    /// LPL.
    pub lpl: Lpl,
    /// Drive.
    pub drive: Drive,
    /// The situation logic.
    pub situation: SimpleSituation,
    /// Control period (s).
    pub dt: f64,
    /// Simulated time (s).
    pub t: f64,
    /// Metrics so far.
    pub recorder: Recorder,
    /// Whether the run is over (goal, collision, stop).
    pub done: bool,
    fusion_last: Option<FusionEvent>,
    lpl_last: Option<PlanEvent>,
    views: Vec<ObstacleView>,
    record_samples: bool,
}

impl OutdoorSim {
    /// The stack at the world's start, 20 Hz, noise from `seed`.
    pub fn new(world: World, seed: u64) -> Self {
        let vehicle = Vehicle::new(world.vehicle, world.start);
        let name = world.name.clone();
        let drive = Drive::new(world.vehicle);
        OutdoorSim {
            world,
            vehicle,
            rfccd: Rfccd::new(seed),
            ladar: Ladar::new(seed),
            stccd: Stccd::new(seed),
            localization: Localization::new(seed),
            fusion_cfg: FusionConfig::default(),
            gpl: Gpl::default(),
            lpl: Lpl::default(),
            drive,
            situation: SimpleSituation::default(),
            dt: 0.05,
            t: 0.0,
            recorder: Recorder::new(&name, "outdoor-simple-situation", seed, 0.05),
            done: false,
            fusion_last: None,
            lpl_last: None,
            views: Vec::new(),
            record_samples: true,
        }
    }

    /// Keep only the summary, not every sample (long benchmark runs).
    pub fn without_samples(mut self) -> Self {
        self.record_samples = false;
        self
    }

    /// One 20 Hz tick of every agent (see the module doc).
    pub fn step(&mut self) -> TickReport {
        let t = self.t;
        self.world.obstacles_at(t, &mut self.views);
        let state_now = self.vehicle.state;
        // 1. Sensors.
        let rf = self.rfccd.observe(&self.world, &state_now);
        let la = self.ladar.observe(&self.world, &state_now, &self.views);
        let st = self.stccd.observe(&self.world, &state_now, &self.views);
        let fix = self.localization.observe(&self.world, &state_now);
        let pose = fix.pose.unwrap_or(state_now.pose);
        // 2. GPL: plan at the start, then report.
        if self.gpl.path.is_none() && self.gpl.plan(&self.world, &pose).is_err() {
            self.lpl_last = Some(PlanEvent::Failed { reason: FailReason::NoPath });
        }
        let report: Option<GplReport> = self.gpl.report(&self.world, &pose);
        // 3. The situation.
        let events = TickEvents {
            rfccd: rf,
            ladar: la.event,
            stccd: st.event,
            localization: fix.event,
            gpl: report.map(|r| r.event),
            fusion: self.fusion_last,
            lpl: self.lpl_last,
        };
        let state = self.situation.step(&events);
        // 4. Fusion and LPL.
        let fused: Option<FusionOutput> = match state {
            State::RO => Some(fuse_road(&rf, &la.detections, &self.fusion_cfg)),
            State::CO => Some(fuse_terrain(&la.detections, &st.detections, &self.fusion_cfg)),
            _ => None,
        };
        if let Some(f) = &fused {
            self.fusion_last = Some(f.event);
        }
        let mut plan = None;
        if let (Some(kind), Some(rep), Some(path)) = (state.plan(), report, self.gpl.path.as_ref()) {
            let stereo_only: Vec<FusedObstacle>;
            let obstacles: &[FusedObstacle] = match &fused {
                Some(f) => &f.obstacles,
                None => {
                    stereo_only = crate::fusion::merge(&[], &st.detections);
                    &stereo_only
                }
            };
            let input = PlanInput { world: &self.world, pose, speed: state_now.v, path, s: rep.s, obstacles };
            let p = self.lpl.plan(kind, &input);
            if let Some(edge) = p.blocked {
                // The path is infeasible: GPL re-plans without that edge.
                self.gpl.block(edge);
                match self.gpl.plan(&self.world, &pose) {
                    Ok(_) => {
                        self.lpl.reset();
                        self.lpl_last = Some(PlanEvent::RoadObstacle);
                    }
                    Err(_) => self.lpl_last = Some(PlanEvent::Failed { reason: FailReason::NoPath }),
                }
            } else {
                self.lpl_last = Some(p.event);
            }
            plan = Some(p);
        }
        // 5. Drive.
        let command = match (state, &plan) {
            (s, Some(p)) if s.driving() => self.drive.track(&pose, p),
            (State::EM, _) => self.drive.estop(),
            _ => self.drive.halt(state_now.steer),
        };
        // 6. Metrics, then the vehicle moves.
        let closest = self.world.closest_obstacle(&state_now.pose, &self.views);
        if self.record_samples {
            let ttc = self.world.time_to_collision(&state_now.pose, state_now.v, &self.views, 60.0);
            let name = closest.map(|(_, i)| self.world.obstacles[i].id.as_str());
            self.recorder.record(
                Sample {
                    t,
                    x: state_now.pose.x,
                    y: state_now.pose.y,
                    theta: state_now.pose.theta,
                    v: state_now.v,
                    steer: state_now.steer,
                    v_cmd: command.v,
                    steer_cmd: command.steer,
                    closest: closest.map(|c| c.0),
                    ttc,
                    label: state.name().into(),
                },
                name,
            );
        }
        if let Some(i) = self.world.collision(&state_now.pose, &self.views) {
            self.recorder.collision(t, &self.world.obstacles[i].id);
            self.done = true;
        }
        if state == State::GL {
            self.recorder.goal(t);
        }
        if matches!(state, State::GL | State::SP) && state_now.v == 0.0 {
            self.done = true;
        }
        self.vehicle.step(command, self.dt);
        self.t += self.dt;
        TickReport { t, events, state, command, plan }
    }

    /// Runs until done or `max_time` (s) and returns the metrics.
    pub fn run(mut self, max_time: f64) -> Metrics {
        let mut states = std::collections::BTreeSet::new();
        while !self.done && self.t < max_time {
            let r = self.step();
            states.insert(r.state);
        }
        for s in states {
            self.recorder.agents_running(s.name(), s.agents_running());
        }
        self.recorder.finish()
    }
}

/// The built-in mission, closed loop, with the simple situation logic.
pub fn run_mission(world: World, seed: u64, max_time: f64) -> Metrics {
    OutdoorSim::new(world, seed).run(max_time)
}
