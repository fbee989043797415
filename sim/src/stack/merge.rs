//! The agents of `rules/ugv-merge.situ` (Dafflon et al. 2013, eqs. 16–19):
//! those of `rules/ugv.situ` ([`super::ugv`]), the two controllers
//! commanding a Merger that alone commands the Vehicle.
//!
//! | agent | reads (data) | does | sends |
//! |---|---|---|---|
//! | Reacher | Gps | target reaching (eqs. 2–5); TARGET{d, etheta} | [`ControlInput`] to the Merger |
//! | Avoider | Lidar, Gps | the limit cycle of its function (eqs. 6–11); ORBIT{turns} | [`AvoidCommand`] to the Merger |
//! | Merger | Reacher, Avoider, Lidar, Gps | `blend()`: [`Merge::command`]; BLEND{steer, speed}; `follow()` (Docking): target reaching alone | the vehicle's [`Command`] |
//! | Vehicle | Merger | `apply()` the Merger's command, or `brake()` | the command (to the vehicle) |
//!
//! The Merger computes what the sim's closed loop ([`crate::ugv::run`])
//! computes in its merge branch, from the latest inputs it holds: follow =
//! the control law on target reaching; avoid = the control law on the limit
//! cycle, or follow when nothing hinders; d = the distance to the nearest
//! limit-cycle ellipse (the enclosing ellipse grown by the vehicle's reach
//! and the safety margin); spots = the obstacles' outline points in the
//! vehicle frame, within the perception frustum.
//!
//! [`compare`] is Dafflon et al.'s table: both programs through the stack.

use super::events::{report, Named};
use super::ugv::{fresh, names, take, GpsFix, LidarScan, FRESH};
use super::{lock, Recording, RunReport, SharedPhysics, StackConfig, StackKind, StackRun};
use crate::control::{control_law, ControlInput};
use crate::geom::Vec2;
use crate::sensors::Value as SimValue;
use crate::ugv::{reach, Merge, MergeParams, UgvConfig};
use crate::vehicle::{Command, VehicleParams};
use crate::world::World;
use situ_compiler::bundle::Content;
use situ_runtime::agent::{Agent, Body, Context};
use std::sync::Arc;

/// The agents `rules/ugv-merge.situ` declares: those of `rules/ugv.situ`
/// and the Merger.
pub const AGENTS: &[&str] = &["Lidar", "Gps", "Selector", "Reacher", "Avoider", "Merger", "Vehicle"];

/// What the Avoider of `rules/ugv-merge.situ` sends the Merger: the limit
/// cycle's control inputs while an obstacle hinders, `None` once nothing
/// does (the Merger then blends target reaching with itself).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AvoidCommand(pub Option<ControlInput>);

/// Merger: the multi-agent merge.
pub struct Merger {
    cfg: UgvConfig,
    params: VehicleParams,
    merge: Merge,
    follow: Option<(u64, ControlInput)>,
    avoid: Option<(u64, AvoidCommand)>,
    seen: Option<(u64, LidarScan)>,
    pose: Option<(u64, GpsFix)>,
    last_step: Option<u64>,
    content: Arc<Content>,
}

impl Merger {
    /// A Merger with the merge's default constants ([`MergeParams`]).
    pub fn new(cfg: UgvConfig, params: VehicleParams, content: Arc<Content>) -> Merger {
        Merger {
            cfg,
            params,
            merge: Merge::new(MergeParams::default()),
            follow: None,
            avoid: None,
            seen: None,
            pose: None,
            last_step: None,
            content,
        }
    }
}

impl Agent for Merger {
    fn name(&self) -> &str {
        "Merger"
    }
    fn functions(&self) -> Vec<String> {
        names(&["blend", "follow"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        let now = cx.now();
        take(cx.inputs(), &mut self.follow);
        take(cx.inputs(), &mut self.avoid);
        take(cx.inputs(), &mut self.seen);
        take(cx.inputs(), &mut self.pose);
        // The swarm steps by the time since the Merger's last step (its
        // period, 50 ms at 20 Hz); after a sleep, by one period.
        let dt = match self.last_step {
            Some(t) if now.saturating_sub(t) <= FRESH => now.saturating_sub(t) as f64 * 1e-9,
            _ => self.cfg.dt,
        };
        self.last_step = Some(now);
        if cx.function() == Some("follow") {
            // The final approach: the target reaching command alone.
            if let Some(input) = fresh(&self.follow, now) {
                let cmd = control_law(input, &self.cfg.gains, &self.params, self.params.max_speed);
                cx.send(Body::local(cmd));
            }
            return;
        }
        let (Some(follow), Some(seen), Some(fix)) =
            (fresh(&self.follow, now), fresh(&self.seen, now), fresh(&self.pose, now))
        else {
            return;
        };
        if dt <= 0.0 {
            return;
        }
        let (gains, vmax) = (self.cfg.gains, self.params.max_speed);
        let follow = control_law(follow, &gains, &self.params, vmax);
        let avoid = match fresh(&self.avoid, now) {
            Some(AvoidCommand(Some(input))) => control_law(input, &gains, &self.params, vmax),
            _ => follow,
        };
        let pose = fix.pose;
        // d of eq. (16): the distance to the nearest limit-cycle ellipse.
        let grow = reach(&self.params) + self.cfg.safety_margin;
        let d = seen.0.iter().map(|o| o.ellipse.grown(grow).distance(pose.pos())).fold(f64::INFINITY, f64::min);
        let perception = self.merge.params.perception;
        let spots: Vec<Vec2> = seen
            .0
            .iter()
            .flat_map(|o| o.outline.iter())
            .map(|p| pose.to_local(*p))
            .filter(|p| p.norm() <= perception)
            .collect();
        let cmd = self.merge.command(&follow, &avoid, d, &spots, &self.params, dt);
        // How far the blend is from target reaching alone: the rules hand
        // the last metres over when they agree (no jump of the command).
        let gap = Named(
            "BLEND",
            vec![("steer", SimValue::F64(cmd.steer - follow.steer)), ("speed", SimValue::F64(cmd.v - follow.v))],
        );
        report(cx, &self.content, &gap);
        cx.send(Body::local(cmd));
    }
}

/// Vehicle of `rules/ugv-merge.situ`: applies the Merger's command, or brakes.
pub struct VehicleApply {
    command: Option<(u64, Command)>,
    physics: SharedPhysics,
}

impl VehicleApply {
    /// The Vehicle on the shared physics.
    pub fn new(physics: SharedPhysics) -> VehicleApply {
        VehicleApply { command: None, physics }
    }
}

impl Agent for VehicleApply {
    fn name(&self) -> &str {
        "Vehicle"
    }
    fn functions(&self) -> Vec<String> {
        names(&["apply", "brake"])
    }
    fn step(&mut self, cx: &mut Context<'_>) {
        take(cx.inputs(), &mut self.command);
        let mut p = lock(&self.physics);
        let steer = p.vehicle.state.steer;
        p.command = match (cx.function(), fresh(&self.command, cx.now())) {
            (Some("apply"), Some(cmd)) => *cmd,
            _ => Command { v: 0.0, steer },
        };
    }
}

/// The two programs of Dafflon et al.'s comparison: the hard switch
/// (`rules/ugv.situ`) and the merge (`rules/ugv-merge.situ`).
#[derive(Clone, Default)]
pub struct UgvPrograms {
    /// The hard switch's program.
    pub hard_switch: Option<Arc<Content>>,
    /// The merge's program.
    pub merge: Option<Arc<Content>>,
}

/// Dafflon et al.'s comparison of two situ programs: for each strategy, the
/// run of its program through the stack (`hard-switch`: `rules/ugv.situ`,
/// `merge`: `rules/ugv-merge.situ`) and, for reference, the sim's own closed
/// loop ([`crate::ugv::run`]). A strategy whose program is not given runs in
/// the sim loop only. Returns the table and the stack runs' reports, in the
/// order of the strategies.
pub fn compare(
    programs: &UgvPrograms,
    world: &World,
    strategies: &[crate::ugv::Strategy],
    seed: u64,
) -> Result<(crate::ugv::Comparison, Vec<RunReport>), String> {
    use crate::ugv::{self, ComparisonRow, Strategy, UgvConfig};
    let cfg = UgvConfig::default();
    let mut rows = Vec::new();
    let mut runs = Vec::new();
    let mut reports = Vec::new();
    for &s in strategies {
        let (program, want) = match s {
            Strategy::HardSwitch => (&programs.hard_switch, StackKind::Ugv),
            Strategy::Merge => (&programs.merge, StackKind::UgvMerge),
        };
        if let Some(content) = program {
            let kind = StackKind::of(content)?;
            if kind != want {
                return Err(format!(
                    "--compare: `{}` is not the {} program (its agents are those of another stack)",
                    content.source,
                    s.name()
                ));
            }
            let stack_cfg = StackConfig { seed, until: cfg.max_time, ..StackConfig::default() };
            let mut run = StackRun::new(content.clone(), kind, world, stack_cfg, Recording::default())?;
            run.run(&mut |_| {});
            let report = run.finish()?;
            rows.push(ComparisonRow::from_metrics(
                &format!("{} ({}, stack)", s.name(), content.source),
                &report.metrics,
            ));
            runs.push(report.metrics.clone());
            reports.push(report);
        }
        let m = ugv::run(world, s, seed, &cfg);
        rows.push(ComparisonRow::from_metrics(&format!("{} (sim loop)", s.name()), &m));
        runs.push(m);
    }
    Ok((ugv::Comparison { scenario: world.name.clone(), seed, rows, runs }, reports))
}
