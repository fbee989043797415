//! Dafflon et al.'s UGV in closed loop without the engine: the hard switch
//! ([`HardSwitch`], the rules `avoid_ccw`, `avoid_cw` and `way_free` of
//! `rules/ugv.situ` as plain code) or the multi-agent merge
//! ([`crate::ugv::Merge`]) driving the vehicle tick by tick ([`run`]), and
//! the table comparing them ([`compare`], [`Comparison`]): the "sim loop"
//! rows of `situ run --compare`.

use crate::control::{control_law, limit_cycle, target_reaching, Direction, Ellipse, Target};
use crate::geom::{Pose, Vec2};
use crate::metrics::{Metrics, Recorder, Sample};
use crate::noise::Noise;
use crate::plot::{timeline_svg, trajectory_svg, PlotError};
use crate::scenario::Scenario;
use crate::ugv::{lidar_scan, reach, select, Merge, MergeParams, Selection, Strategy, UgvConfig};
use crate::vehicle::{Command, Vehicle, VehicleParams};
use crate::world::World;
use serde::Serialize;
use std::fmt;

/// Which controller drives (the states of `rules/ugv.situ`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Mode {
    /// Target reaching.
    Reaching,
    /// Obstacle avoidance on the limit cycle of an obstacle.
    Avoid {
        /// Clockwise or counter-clockwise.
        dir: Direction,
        /// The limit cycle followed.
        cycle: Ellipse,
        /// The world's index of the obstacle orbited.
        index: usize,
    },
}

impl Mode {
    /// The state name of `rules/ugv.situ`.
    pub fn label(&self) -> &'static str {
        match self {
            Mode::Reaching => "Reaching",
            Mode::Avoid { dir: Direction::Clockwise, .. } => "AvoidCW",
            Mode::Avoid { dir: Direction::CounterClockwise, .. } => "AvoidCCW",
        }
    }
}

/// The hard switch: the situation rules `avoid_ccw`, `avoid_cw` and
/// `way_free` of `rules/ugv.situ` as a function of the selections.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HardSwitch {
    /// The controller in charge.
    pub mode: Mode,
    /// FREE selections in a row.
    pub free_run: u32,
}

impl Default for HardSwitch {
    fn default() -> Self {
        HardSwitch { mode: Mode::Reaching, free_run: 0 }
    }
}

impl HardSwitch {
    /// Updates the mode from one selection and returns it. Reaching →
    /// avoidance when a hindering obstacle is within its radius of influence
    /// (direction by its side); avoidance → reaching after 3 FREE in a row;
    /// the direction never flips mid-avoidance, the orbited ellipse follows
    /// the nearest hindering obstacle.
    pub fn step(&mut self, sel: &Selection) -> Mode {
        self.free_run = if sel.hinder.is_none() { self.free_run + 1 } else { 0 };
        self.mode = match (self.mode, sel.hinder) {
            (Mode::Reaching, Some(h)) if h.distance <= sel.influence => {
                Mode::Avoid { dir: h.direction(), cycle: h.cycle, index: h.index }
            }
            (Mode::Avoid { .. }, None) if self.free_run >= 3 => Mode::Reaching,
            (Mode::Avoid { dir, .. }, Some(h)) => Mode::Avoid { dir, cycle: h.cycle, index: h.index },
            (m, _) => m,
        };
        self.mode
    }
}

/// The command of the controller the hard switch selected.
pub fn hard_switch_command(
    mode: &Mode,
    pose: &Pose,
    target: &Target,
    params: &VehicleParams,
    cfg: &UgvConfig,
) -> Command {
    match mode {
        Mode::Reaching => control_law(&target_reaching(pose, target), &cfg.gains, params, params.max_speed),
        Mode::Avoid { dir, cycle, .. } => {
            // vT = vmax / 2 during avoidance (Section 2.2.2).
            let v_t = params.max_speed / 2.0;
            control_law(&limit_cycle(pose, cycle, *dir, v_t), &cfg.gains, params, params.max_speed)
        }
    }
}

/// One closed-loop run of the UGV on a world; stops at the goal, at the
/// first collision (as in the paper), or after `cfg.max_time`.
pub fn run(world: &World, strategy: Strategy, seed: u64, cfg: &UgvConfig) -> Metrics {
    let params = world.vehicle;
    let mut veh = Vehicle::new(params, world.start);
    let goal_heading = world.goal.heading.unwrap_or(0.0);
    let target = Target {
        pose: Pose::new(world.goal.position.x, world.goal.position.y, goal_heading),
        v: cfg.target_speed,
        curvature: 0.0,
    };
    let mut noise = Noise::new(seed, 1);
    let mut rec = Recorder::new(&world.name, strategy.name(), seed, cfg.dt);
    let mut views = Vec::new();
    world.obstacles_at(0.0, &mut views);
    let mut switch = HardSwitch::default();
    let mut merge = Merge::new(MergeParams::default());
    let steps = (cfg.max_time / cfg.dt).round() as u64;
    for k in 0..=steps {
        let t = k as f64 * cfg.dt;
        world.obstacles_at(t, &mut views);
        let pose = veh.state.pose;
        let seen = lidar_scan(&pose, &views, cfg, &mut noise);
        let sel = select(&pose, &target.pose, &seen, &params, cfg);
        let (cmd, label) = match strategy {
            Strategy::HardSwitch => {
                let mode = switch.step(&sel);
                (hard_switch_command(&mode, &pose, &target, &params, cfg), mode.label())
            }
            Strategy::Merge => {
                let follow = control_law(&target_reaching(&pose, &target), &cfg.gains, &params, params.max_speed);
                let avoid = match sel.hinder {
                    Some(h) => control_law(
                        &limit_cycle(&pose, &h.cycle, h.direction(), params.max_speed / 2.0),
                        &cfg.gains,
                        &params,
                        params.max_speed,
                    ),
                    None => follow,
                };
                // d of eq. (16): the distance to the nearest limit-cycle
                // ellipse (it holds the vehicle's reach and the margin).
                let grow = reach(&params) + cfg.safety_margin;
                let d = seen.iter().map(|o| o.ellipse.grown(grow).distance(pose.pos())).fold(f64::INFINITY, f64::min);
                let spots: Vec<Vec2> = seen
                    .iter()
                    .flat_map(|o| o.outline.iter())
                    .map(|p| pose.to_local(*p))
                    .filter(|p| p.norm() <= merge.params.perception)
                    .collect();
                (merge.command(&follow, &avoid, d, &spots, &params, cfg.dt), "Merge")
            }
        };
        let closest = world.closest_obstacle(&pose, &views);
        let ttc = world.time_to_collision(&pose, veh.state.v, &views, 20.0);
        let closest_name = closest.map(|(_, i)| world.obstacles[i].id.as_str());
        rec.record(
            Sample {
                t,
                x: pose.x,
                y: pose.y,
                theta: pose.theta,
                v: veh.state.v,
                steer: veh.state.steer,
                v_cmd: cmd.v,
                steer_cmd: cmd.steer,
                closest: closest.map(|c| c.0),
                ttc,
                label: label.into(),
            },
            closest_name,
        );
        if let Some(i) = world.collision(&pose, &views) {
            rec.collision(t, &world.obstacles[i].id);
            break;
        }
        if (pose.pos() - target.pose.pos()).norm() <= world.goal.tolerance {
            rec.goal(t);
            break;
        }
        veh.step(cmd, cfg.dt);
    }
    rec.finish()
}

/// "Near an obstacle": within this distance of the vehicle's outline (m).
pub const NEAR: f64 = 2.0;

/// One row of the comparison table.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ComparisonRow {
    /// Strategy name.
    pub strategy: String,
    /// Largest |steering rate| of the commands (rad/s).
    pub max_steer_rate: f64,
    /// RMS steering rate of the commands (rad/s).
    pub rms_steer_rate: f64,
    /// Top commanded speed (m/s).
    pub max_speed: f64,
    /// Top commanded speed while an obstacle is within [`NEAR`] of the
    /// vehicle's outline (m/s): "moving near obstacles at a greater speed".
    pub max_speed_near: f64,
    /// Mean speed (m/s).
    pub mean_speed: f64,
    /// Closest distance to an obstacle (m).
    pub closest_distance: f64,
    /// Smallest time to collision (s).
    pub min_ttc: Option<f64>,
    /// Number of collisions.
    pub collisions: usize,
    /// Time to goal (s).
    pub time_to_goal: Option<f64>,
}

impl ComparisonRow {
    /// The row of a run's metrics (its samples give the top speed near obstacles).
    pub fn from_metrics(strategy: &str, m: &Metrics) -> ComparisonRow {
        let sum = &m.summary;
        ComparisonRow {
            strategy: strategy.into(),
            max_steer_rate: sum.max_steer_rate,
            rms_steer_rate: sum.rms_steer_rate,
            max_speed: sum.max_speed,
            max_speed_near: m
                .samples
                .iter()
                .filter(|s| s.closest.is_some_and(|c| c < NEAR))
                .map(|s| s.v_cmd)
                .fold(0.0, f64::max),
            mean_speed: sum.mean_speed,
            closest_distance: sum.closest_distance.unwrap_or(f64::INFINITY),
            min_ttc: sum.min_ttc,
            collisions: sum.collisions.len(),
            time_to_goal: sum.time_to_goal,
        }
    }
}

/// Dafflon et al.'s comparison: one row per strategy.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Comparison {
    /// Scenario name.
    pub scenario: String,
    /// Noise seed.
    pub seed: u64,
    /// The rows, in the order asked.
    pub rows: Vec<ComparisonRow>,
    /// The runs' metrics, in the same order.
    #[serde(skip)]
    pub runs: Vec<Metrics>,
}

impl Comparison {
    /// Each row's path and time line, as `trajectory-ROW.svg` and
    /// `timeline-ROW.svg` (ROW: the row's name in lower case, words joined
    /// by `-`), with their SVG.
    pub fn pictures(&self, scenario: &Scenario) -> Result<Vec<(String, String)>, PlotError> {
        let mut out = Vec::new();
        for (row, metrics) in self.rows.iter().zip(&self.runs) {
            let slug: String = row
                .strategy
                .to_lowercase()
                .split(|c: char| !c.is_ascii_alphanumeric())
                .filter(|w| !w.is_empty())
                .collect::<Vec<_>>()
                .join("-");
            let title = format!("{} — {}", scenario.name, row.strategy);
            out.push((format!("trajectory-{slug}.svg"), trajectory_svg(&scenario.world, &metrics.samples, &title)?));
            out.push((format!("timeline-{slug}.svg"), timeline_svg(&metrics.samples, &title)?));
        }
        Ok(out)
    }

    /// The row of a strategy.
    pub fn row(&self, s: Strategy) -> Option<&ComparisonRow> {
        self.rows.iter().find(|r| r.strategy == s.name())
    }
}

impl fmt::Display for Comparison {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "scenario {} (seed {})", self.scenario, self.seed)?;
        let w = self.rows.iter().map(|r| r.strategy.chars().count()).max().unwrap_or(0).max(12);
        writeln!(
            f,
            "{:<w$} {:>12} {:>10} {:>7} {:>12} {:>7} {:>8} {:>8} {:>10} {:>8}",
            "strategy",
            "max |dγ/dt|",
            "rms dγ/dt",
            "top v",
            "top v near",
            "mean v",
            "closest",
            "min TTC",
            "collisions",
            "goal at"
        )?;
        writeln!(
            f,
            "{:<w$} {:>12} {:>10} {:>7} {:>12} {:>7} {:>8} {:>8} {:>10} {:>8}",
            "", "(rad/s)", "(rad/s)", "(m/s)", "(m/s)", "(m/s)", "(m)", "(s)", "", "(s)"
        )?;
        for r in &self.rows {
            let opt = |o: Option<f64>| o.map_or("-".to_string(), |v| format!("{v:.2}"));
            writeln!(
                f,
                "{:<w$} {:>12.3} {:>10.3} {:>7.2} {:>12.2} {:>7.2} {:>8.2} {:>8} {:>10} {:>8}",
                r.strategy,
                r.max_steer_rate,
                r.rms_steer_rate,
                r.max_speed,
                r.max_speed_near,
                r.mean_speed,
                r.closest_distance,
                opt(r.min_ttc),
                r.collisions,
                opt(r.time_to_goal)
            )?;
        }
        Ok(())
    }
}

/// Runs each strategy on a world with the same seed and tabulates the
/// metrics (`situ run rules/ugv.situ --scenario dafflon-4 --compare hard-switch,merge`).
pub fn compare(world: &World, strategies: &[Strategy], seed: u64, cfg: &UgvConfig) -> Comparison {
    let mut rows = Vec::new();
    let mut runs = Vec::new();
    for &s in strategies {
        let m = run(world, s, seed, cfg);
        rows.push(ComparisonRow::from_metrics(s.name(), &m));
        runs.push(m);
    }
    Comparison { scenario: world.name.clone(), seed, rows, runs }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::v2;
    use crate::ugv::{Hinder, Side};

    fn hinder(side: Side, distance: f64) -> Selection {
        let cycle = Ellipse { center: v2(5.0, 0.0), a: 2.0, b: 2.0, omega: 0.0 };
        Selection { hinder: Some(Hinder { index: 0, side, cycle, distance }), nearest: distance, influence: 1.5 }
    }

    fn free() -> Selection {
        Selection { hinder: None, nearest: 15.0, influence: 1.5 }
    }

    #[test]
    fn hard_switch_mirrors_the_rules() {
        let mut hs = HardSwitch::default();
        assert_eq!(hs.step(&hinder(Side::Left, 4.0)).label(), "Reaching", "waits for the radius of influence");
        assert_eq!(hs.step(&hinder(Side::Left, 1.2)).label(), "AvoidCCW", "left: counter-clockwise");
        assert_eq!(hs.step(&hinder(Side::Right, 1.0)).label(), "AvoidCCW", "no flip mid-avoidance");
        hs.step(&free());
        assert_eq!(hs.step(&free()).label(), "AvoidCCW");
        assert_eq!(hs.step(&free()).label(), "Reaching", "FREE x3");
        assert_eq!(hs.step(&hinder(Side::Right, 1.0)).label(), "AvoidCW", "right: clockwise");
    }
}
