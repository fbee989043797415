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
//! The Merger computes what the sim's closed loop ([`crate::baseline::ugv::run`])
//! computes in its merge branch, from the latest inputs it holds: follow =
//! the control law on target reaching; avoid = the control law on the limit
//! cycle, or follow when nothing hinders; d = the distance to the nearest
//! limit-cycle ellipse (the enclosing ellipse grown by the vehicle's reach
//! and the safety margin); spots = the obstacles' outline points in the
//! vehicle frame, within the perception frustum.
//!
//! [`compare`] is Dafflon et al.'s table: both programs through the stack;
//! [`UgvPrograms::plan`] tells which program is which and which file
//! beside the rules holds the other.

use super::ugv::{self, AvoidCommand, GpsFix, LidarScan};
use super::{lock, Recording, Registry, RunReport, SharedPhysics, Stack, StackConfig, StackError, StackRun};
use crate::agent::{fresh, names, report, take, Named, Value as SimValue, FRESH};
use crate::control::{control_law, ControlInput};
use crate::geom::Vec2;
use crate::ugv::{reach, Merge, MergeParams, Strategy, UgvConfig};
use crate::vehicle::{Command, VehicleParams};
use crate::world::World;
use situ_compiler::bundle::Content;
use situ_runtime::agent::{Agent, Body, Context};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// The agents `rules/ugv-merge.situ` declares: those of `rules/ugv.situ`
/// and the Merger.
pub const AGENTS: &[&str] = &["Lidar", "Gps", "Selector", "Reacher", "Avoider", "Merger", "Vehicle"];

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

/// Dafflon et al.'s urban UGV with the multi-agent merge
/// (`rules/ugv-merge.situ`): the agents of `rules/ugv.situ` and a Merger.
#[derive(Debug, Clone, Copy, Default)]
pub struct UgvMerge;

impl Stack for UgvMerge {
    fn name(&self) -> &'static str {
        "ugv_merge"
    }
    fn title(&self) -> &'static str {
        "UgvMerge"
    }
    fn agents(&self) -> &'static [&'static str] {
        AGENTS
    }
    fn known_as(&self) -> String {
        "of rules/ugv-merge.situ (those and Merger)".into()
    }
    fn default_scenario(&self) -> &'static str {
        ugv::common::SCENARIO
    }
    fn goal_state(&self) -> &'static str {
        ugv::common::GOAL
    }
    fn sample_every(&self) -> u64 {
        ugv::common::SAMPLE_EVERY
    }
    fn default_until(&self) -> f64 {
        ugv::common::UNTIL
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

/// Every agent of `rules/ugv-merge.situ` on a world, with a seed: those
/// it shares with `rules/ugv.situ` (the Avoider sending [`AvoidCommand`]s),
/// the Merger that blends, the Vehicle that applies its command.
pub fn agents(content: &Arc<Content>, physics: &SharedPhysics, world: &World, seed: u64) -> Vec<Box<dyn Agent>> {
    let mut agents = ugv::build(content, physics, world, seed, true);
    agents.push(Box::new(Merger::new(UgvConfig::default(), world.vehicle, content.clone())));
    agents.push(Box::new(VehicleApply::new(physics.clone())));
    agents
}

/// Why Dafflon et al.'s comparison cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum CompareError {
    /// A strategy that is neither `hard-switch` nor `merge`.
    #[error("--compare: unknown strategy `{0}` (hard-switch, merge)")]
    UnknownStrategy(String),
    /// The rules are not the UGV's.
    #[error(
        "--compare needs the UGV's rules (rules/ugv.situ or rules/ugv-merge.situ): hard-switch and merge are its controllers"
    )]
    NotUgv,
    /// The other program is not beside the rules file.
    #[error("--compare: the {} strategy runs `{name}` through the stack, and there is no `{}` beside `{}`", .strategy.name(), .path.display(), .file.display())]
    NoSibling {
        /// The strategy the missing program is.
        strategy: Strategy,
        /// Its file name.
        name: &'static str,
        /// Where it was looked for.
        path: PathBuf,
        /// The rules file it should be beside.
        file: PathBuf,
    },
    /// A program is not the one of its strategy.
    #[error("--compare: `{source_name}` is not the {} program (its agents are those of another stack)", .strategy.name())]
    WrongProgram {
        /// The program's source name.
        source_name: String,
        /// The strategy it was given for.
        strategy: Strategy,
    },
    /// A program's agents are those of no stack.
    #[error(transparent)]
    NoStack(#[from] super::NoStack),
    /// A stack run failed.
    #[error(transparent)]
    Run(#[from] StackError),
}

/// Parses `--compare`'s list (`hard-switch,merge`).
pub fn strategies(list: &[String]) -> Result<Vec<Strategy>, CompareError> {
    list.iter().map(|s| Strategy::parse(s.trim()).ok_or_else(|| CompareError::UnknownStrategy(s.clone()))).collect()
}

/// The comparison's other program: the strategy it is for and its file.
#[derive(Debug, Clone, PartialEq)]
pub struct Sibling {
    /// The strategy it runs.
    pub strategy: Strategy,
    /// Its file, beside the rules file.
    pub path: PathBuf,
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

impl UgvPrograms {
    /// The programs of a comparison of `strategies` started from `file`
    /// (`content`, on `stack`): `content` in its strategy's place, and the
    /// other program, when a strategy wants it, to be read from beside
    /// `file` (the merge's `ugv-merge.situ` beside the hard switch's
    /// `ugv.situ`, or the other way round). Read from the file, not built
    /// in, so that the table compares the programs as they are on disk,
    /// edits included.
    pub fn plan(
        file: &Path,
        content: Arc<Content>,
        stack: &dyn Stack,
        strategies: &[Strategy],
    ) -> Result<(UgvPrograms, Option<Sibling>), CompareError> {
        let mut programs = UgvPrograms::default();
        let (other, name) = match stack.name() {
            "ugv" => {
                programs.hard_switch = Some(content);
                (Strategy::Merge, "ugv-merge.situ")
            }
            "ugv_merge" => {
                programs.merge = Some(content);
                (Strategy::HardSwitch, "ugv.situ")
            }
            _ => return Err(CompareError::NotUgv),
        };
        if !strategies.contains(&other) {
            return Ok((programs, None));
        }
        let path = file.parent().unwrap_or(Path::new("")).join(name);
        if !path.is_file() {
            return Err(CompareError::NoSibling { strategy: other, name, path, file: file.to_path_buf() });
        }
        Ok((programs, Some(Sibling { strategy: other, path })))
    }

    /// Puts `content` in the place of `strategy`'s program.
    pub fn set(&mut self, strategy: Strategy, content: Arc<Content>) {
        match strategy {
            Strategy::HardSwitch => self.hard_switch = Some(content),
            Strategy::Merge => self.merge = Some(content),
        }
    }
}

/// Dafflon et al.'s comparison of two situ programs: for each strategy, the
/// run of its program through the stack (`hard-switch`: `rules/ugv.situ`,
/// `merge`: `rules/ugv-merge.situ`) and, for reference, the sim's own closed
/// loop ([`crate::baseline::ugv::run`]). A strategy whose program is not given runs in
/// the sim loop only. `stacks` tells each program's stack. Returns the
/// table and the stack runs' reports, in the order of the strategies.
pub fn compare(
    programs: &UgvPrograms,
    stacks: &Registry,
    world: &World,
    strategies: &[Strategy],
    seed: u64,
) -> Result<(crate::baseline::ugv::Comparison, Vec<RunReport>), CompareError> {
    use crate::baseline::ugv::{self, ComparisonRow};
    let cfg = UgvConfig::default();
    let mut rows = Vec::new();
    let mut runs = Vec::new();
    let mut reports = Vec::new();
    for &s in strategies {
        let (program, want) = match s {
            Strategy::HardSwitch => (&programs.hard_switch, "ugv"),
            Strategy::Merge => (&programs.merge, "ugv_merge"),
        };
        if let Some(content) = program {
            let stack = stacks.of(content)?;
            if stack.name() != want {
                return Err(CompareError::WrongProgram { source_name: content.source.clone(), strategy: s });
            }
            let stack_cfg = StackConfig { seed, until: cfg.max_time, ..StackConfig::default() };
            let mut run = StackRun::new(content.clone(), stack, world, stack_cfg, Recording::default())?;
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
