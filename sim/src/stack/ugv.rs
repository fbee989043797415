//! The agents of `rules/ugv.situ` (Dafflon et al. 2013) on the runtime:
//! the hard switch between the two elementary controllers is the rules'
//! (`avoid_ccw`, `avoid_cw`, `way_free`) and the tables' links (only the
//! controller the state selects is linked to the Vehicle).
//!
//! | agent | reads (data) | does | sends |
//! |---|---|---|---|
//! | Lidar | the world | [`crate::ugv::lidar_scan`]: enclosing ellipses; OBS{distance} | the ellipses |
//! | Gps | the world | RTK posture (σ 2 cm, 5 mrad); FIX{error}/NOFIX | [`GpsFix`] |
//! | Selector | Lidar, Gps | [`crate::ugv::select`]: HINDER{side, influence}/FREE | — |
//! | Reacher | Gps | target reaching (eqs. 2–5); TARGET{d, etheta} | [`ControlInput`] |
//! | Avoider | Lidar, Gps | the limit cycle of its function (eqs. 6–11); ORBIT{turns} | [`ControlInput`] |
//! | Vehicle | Reacher or Avoider | the single control law (eqs. 12–15), or brakes | the command (to the vehicle) |
//!
//! The multi-agent merge ([`crate::ugv::Merge`]) is `rules/ugv-merge.situ`:
//! the same agents, the controllers commanding a Merger that alone commands
//! the Vehicle ([`super::merge`], built on this module; this module knows
//! nothing of it).

use super::{lock, SharedPhysics, Stack};
use crate::agent::{fresh, names, report, take, Named, Plain, Value as SimValue, FRESH};
use crate::control::{control_law, limit_cycle, target_reaching, ControlInput, Direction, Ellipse, Gains, Target};
use crate::geom::{wrap_angle, Pose};
use crate::noise::Noise;
use crate::ugv::{lidar_scan, reach, select, LidarObstacle, Side, UgvConfig};
use crate::vehicle::{Command, VehicleParams};
use crate::world::World;
use situ_compiler::bundle::Content;
use situ_runtime::agent::{Agent, Body, Context};
use std::sync::Arc;

/// The agents `rules/ugv.situ` declares.
pub const AGENTS: &[&str] = &["Lidar", "Gps", "Selector", "Reacher", "Avoider", "Vehicle"];

/// Correlation time of the RTK error (s).
pub const GPS_TAU: f64 = 2.0;

/// The Gps agent's posture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GpsFix {
    /// The posture (x, y, θ).
    pub pose: Pose,
}

/// The Lidar agent's scan: the obstacles' enclosing ellipses.
#[derive(Debug, Clone, PartialEq)]
pub struct LidarScan(pub Vec<LidarObstacle>);

/// What the Avoider of `rules/ugv-merge.situ` sends the Merger: the limit
/// cycle's control inputs while an obstacle hinders, `None` once nothing
/// does (the Merger then blends target reaching with itself).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AvoidCommand(pub Option<ControlInput>);

/// Lidar.
pub struct Lidar {
    cfg: UgvConfig,
    noise: Noise,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Lidar {
    fn name(&self) -> &str {
        "Lidar"
    }
    fn functions(&self) -> Vec<String> {
        names(&["scan"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let seen = {
            let p = lock(&self.physics);
            lidar_scan(&p.vehicle.state.pose, &p.views, &self.cfg, &mut self.noise)
        };
        let nearest = seen.iter().map(|o| o.distance).fold(self.cfg.lidar_range, f64::min);
        report(cx, &self.content, &Named("OBS", vec![("distance", SimValue::F64(nearest))]));
        cx.send(Body::local(LidarScan(seen)));
    }
}

/// Gps: the RTK posture.
pub struct Gps {
    noise: Noise,
    error: (f64, f64, f64),
    last: u64,
    started: bool,
    sigma: f64,
    heading_sigma: f64,
    physics: SharedPhysics,
    content: Arc<Content>,
}

impl Agent for Gps {
    fn name(&self) -> &str {
        "Gps"
    }
    fn functions(&self) -> Vec<String> {
        names(&["rtk"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let (pose, fix) = {
            let p = lock(&self.physics);
            (p.vehicle.state.pose, p.world.gps_fix(p.vehicle.state.pose.pos()))
        };
        if !fix {
            report(cx, &self.content, &Plain("NOFIX"));
            return;
        }
        // The error of an RTK solution wanders (a first-order Gauss–Markov
        // process, correlation time TAU) rather than jumping at every fix.
        let dt = cx.now().saturating_sub(self.last) as f64 * 1e-9;
        self.last = cx.now();
        let a = if self.started { (-dt / GPS_TAU).exp() } else { 0.0 };
        self.started = true;
        let k = (1.0 - a * a).sqrt();
        let (ex, ey, eh) = self.error;
        self.error = (
            a * ex + k * self.noise.normal(self.sigma),
            a * ey + k * self.noise.normal(self.sigma),
            a * eh + k * self.noise.normal(self.heading_sigma),
        );
        let pose = Pose::new(pose.x + self.error.0, pose.y + self.error.1, wrap_angle(pose.theta + self.error.2));
        report(cx, &self.content, &Named("FIX", vec![("error", SimValue::F64(self.sigma))]));
        cx.send(Body::local(GpsFix { pose }));
    }
}

/// Selector: the hierarchical action selection.
pub struct Selector {
    cfg: UgvConfig,
    params: VehicleParams,
    target: Pose,
    seen: Option<(u64, LidarScan)>,
    pose: Option<(u64, GpsFix)>,
    content: Arc<Content>,
}

impl Agent for Selector {
    fn name(&self) -> &str {
        "Selector"
    }
    fn functions(&self) -> Vec<String> {
        names(&["select"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let now = cx.now();
        take(cx.inputs(), &mut self.seen);
        take(cx.inputs(), &mut self.pose);
        let (Some(seen), Some(fix)) = (fresh(&self.seen, now), fresh(&self.pose, now)) else { return };
        let sel = select(&fix.pose, &self.target, &seen.0, &self.params, &self.cfg);
        match sel.hinder {
            Some(h) => {
                // OBS measures to the enclosing ellipse; the radius of
                // influence is taken beyond the limit cycle, which is that
                // ellipse grown by the vehicle's reach and the margin.
                let influence = reach(&self.params) + self.cfg.safety_margin + sel.influence;
                let side = match h.side {
                    Side::Left => "left",
                    Side::Right => "right",
                };
                let ev =
                    Named("HINDER", vec![("side", SimValue::Symbol(side)), ("influence", SimValue::F64(influence))]);
                report(cx, &self.content, &ev);
            }
            None => {
                report(cx, &self.content, &Plain("FREE"));
            }
        }
    }
}

/// Reacher: the target-reaching controller.
pub struct Reacher {
    target: Target,
    pose: Option<(u64, GpsFix)>,
    content: Arc<Content>,
}

impl Agent for Reacher {
    fn name(&self) -> &str {
        "Reacher"
    }
    fn functions(&self) -> Vec<String> {
        names(&["attract"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        take(cx.inputs(), &mut self.pose);
        let Some(fix) = fresh(&self.pose, cx.now()) else { return };
        let input = target_reaching(&fix.pose, &self.target);
        let ev =
            Named("TARGET", vec![("d", SimValue::F64(input.errors.d)), ("etheta", SimValue::F64(input.errors.etheta))]);
        report(cx, &self.content, &ev);
        cx.send(Body::local(input));
    }
}

/// Avoider: the elliptic limit cycles.
pub struct Avoider {
    /// For the Merger (`rules/ugv-merge.situ`): sends an
    /// [`AvoidCommand`], empty when nothing hinders now.
    merge: bool,
    cfg: UgvConfig,
    params: VehicleParams,
    target: Pose,
    seen: Option<(u64, LidarScan)>,
    pose: Option<(u64, GpsFix)>,
    /// The obstacle orbited and its limit cycle.
    cycle: Option<(usize, Ellipse)>,
    dir: Option<Direction>,
    last_step: u64,
    last_angle: Option<f64>,
    turns: f64,
    content: Arc<Content>,
}

impl Agent for Avoider {
    fn name(&self) -> &str {
        "Avoider"
    }
    fn functions(&self) -> Vec<String> {
        names(&["cycle_cw", "cycle_ccw"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let now = cx.now();
        take(cx.inputs(), &mut self.seen);
        take(cx.inputs(), &mut self.pose);
        let dir = match cx.function() {
            Some("cycle_cw") => Direction::Clockwise,
            Some("cycle_ccw") => Direction::CounterClockwise,
            _ => return,
        };
        // A new avoidance (it slept in between, or the direction changed).
        if self.dir != Some(dir) || now.saturating_sub(self.last_step) > FRESH {
            self.cycle = None;
            self.last_angle = None;
            self.turns = 0.0;
        }
        self.dir = Some(dir);
        self.last_step = now;
        let (Some(seen), Some(fix)) = (fresh(&self.seen, now), fresh(&self.pose, now)) else { return };
        let pose = fix.pose;
        // The limit cycle follows the nearest hindering obstacle (the
        // direction is the function's: it never flips mid-avoidance).
        let hinder = select(&pose, &self.target, &seen.0, &self.params, &self.cfg).hinder;
        if let Some(h) = hinder {
            if self.cycle.is_none_or(|(i, _)| i != h.index) {
                self.last_angle = None;
                self.turns = 0.0;
            }
            self.cycle = Some((h.index, h.cycle));
        }
        let Some((_, cycle)) = self.cycle else {
            if self.merge {
                cx.send(Body::local(AvoidCommand(None)));
            }
            return;
        };
        let angle = (pose.y - cycle.center.y).atan2(pose.x - cycle.center.x);
        if let Some(a) = self.last_angle {
            self.turns += wrap_angle(angle - a).abs() / std::f64::consts::TAU;
        }
        self.last_angle = Some(angle);
        report(cx, &self.content, &Named("ORBIT", vec![("turns", SimValue::F64(self.turns))]));
        let input = limit_cycle(&pose, &cycle, dir, self.params.max_speed / 2.0);
        if self.merge {
            // The merge blends the limit cycle only while an obstacle
            // hinders (else the target reaching command with itself).
            cx.send(Body::local(AvoidCommand(hinder.map(|_| input))));
        } else {
            cx.send(Body::local(input));
        }
    }
}

/// Vehicle: the single control law, or the brake.
pub struct VehicleAgent {
    gains: Gains,
    params: VehicleParams,
    input: Option<(u64, ControlInput)>,
    physics: SharedPhysics,
}

impl Agent for VehicleAgent {
    fn name(&self) -> &str {
        "Vehicle"
    }
    fn functions(&self) -> Vec<String> {
        names(&["control", "brake"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        take(cx.inputs(), &mut self.input);
        let mut p = lock(&self.physics);
        let steer = p.vehicle.state.steer;
        let brake = Command { v: 0.0, steer };
        p.command = match (cx.function(), fresh(&self.input, cx.now())) {
            (Some("control"), Some(input)) => control_law(input, &self.gains, &self.params, self.params.max_speed),
            _ => brake,
        };
    }
}

/// Dafflon et al.'s urban UGV with the hard switch (`rules/ugv.situ`).
#[derive(Debug, Clone, Copy, Default)]
pub struct Ugv;

/// What the UGV's stacks (the hard switch and the merge) share.
pub(super) mod common {
    /// The built-in scenario run by default.
    pub const SCENARIO: &str = "dafflon-4";
    /// The state that means "mission done".
    pub const GOAL: &str = "Reached";
    /// 20 Hz, the control period of Dafflon et al.'s closed loop
    /// ([`crate::baseline::ugv::run`]), so that the stacks' figures compare with it.
    pub const SAMPLE_EVERY: u64 = 5;
    /// The longest run by default (s).
    pub const UNTIL: f64 = 120.0;
}

impl Stack for Ugv {
    fn name(&self) -> &'static str {
        "ugv"
    }
    fn title(&self) -> &'static str {
        "Ugv"
    }
    fn agents(&self) -> &'static [&'static str] {
        AGENTS
    }
    fn known_as(&self) -> String {
        format!("of rules/ugv.situ ({})", AGENTS.join(", "))
    }
    fn default_scenario(&self) -> &'static str {
        common::SCENARIO
    }
    fn goal_state(&self) -> &'static str {
        common::GOAL
    }
    fn sample_every(&self) -> u64 {
        common::SAMPLE_EVERY
    }
    fn default_until(&self) -> f64 {
        common::UNTIL
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

/// Every agent of `rules/ugv.situ` on a world, with a seed. The target is
/// the world's goal, with its heading.
pub fn agents(content: &Arc<Content>, physics: &SharedPhysics, world: &World, seed: u64) -> Vec<Box<dyn Agent>> {
    build(content, physics, world, seed, false)
}

/// The agents of `rules/ugv.situ`, or (`merge`) those the merge shares
/// with it: the Avoider then sends [`AvoidCommand`]s, and the Vehicle is
/// left to [`super::merge`] (with the Merger).
pub(super) fn build(
    content: &Arc<Content>,
    physics: &SharedPhysics,
    world: &World,
    seed: u64,
    merge: bool,
) -> Vec<Box<dyn Agent>> {
    let cfg = UgvConfig::default();
    let params = world.vehicle;
    let goal = Pose::new(world.goal.position.x, world.goal.position.y, world.goal.heading.unwrap_or(0.0));
    let target = Target { pose: goal, v: cfg.target_speed, curvature: 0.0 };
    let c = || content.clone();
    let ph = || physics.clone();
    let mut agents: Vec<Box<dyn Agent>> = vec![
        Box::new(Lidar { cfg, noise: Noise::new(seed, 1), physics: ph(), content: c() }),
        Box::new(Gps {
            noise: Noise::new(seed, 2),
            error: (0.0, 0.0, 0.0),
            last: 0,
            started: false,
            sigma: 0.02,
            heading_sigma: 0.005,
            physics: ph(),
            content: c(),
        }),
        Box::new(Selector { cfg, params, target: goal, seen: None, pose: None, content: c() }),
        Box::new(Reacher { target, pose: None, content: c() }),
        Box::new(Avoider {
            merge,
            cfg,
            params,
            target: goal,
            seen: None,
            pose: None,
            cycle: None,
            dir: None,
            last_step: 0,
            last_angle: None,
            turns: 0.0,
            content: c(),
        }),
    ];
    if !merge {
        agents.push(Box::new(VehicleAgent { gains: cfg.gains, params, input: None, physics: ph() }));
    }
    agents
}
