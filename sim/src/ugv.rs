//! Dafflon et al.'s urban UGV in closed loop: vehicle + LIDAR + action
//! selection + elementary controllers + the single control law, with the two
//! ways of choosing between the controllers: the **hard switch** (the
//! situation rules of `rules/ugv.situ`, mirrored by
//! [`HardSwitch`](crate::baseline::ugv::HardSwitch)) and the **multi-agent
//! merge** of eqs. (16)–(19) ([`Merge`]).
//!
//! Per tick (20 Hz) a wrapper calls [`lidar_scan`] (the Lidar agent),
//! [`select`] (the Selector agent: which obstacle hinders, on which side),
//! then either the hard switch or [`Merge::command`]; and
//! [`crate::vehicle::Vehicle::step`]. The closed loop that does so without
//! the engine, and the table comparing the two, are
//! [`crate::baseline::ugv`].
//!
//! Constants the paper leaves out (CHOICE):
//! - the limit cycle around an obstacle is its enclosing ellipse grown by half
//!   the vehicle's width plus [`UgvConfig::safety_margin`] (0.6 m);
//! - an obstacle *hinders* when the segment vehicle → target cuts that
//!   ellipse (by more than 5% of its level, ahead of the vehicle); the switch
//!   to avoidance happens when the vehicle is within the radius of influence,
//!   [`UgvConfig::influence`] (1.5 m) of the limit-cycle ellipse, and back
//!   to target reaching after 3 selections (0.15 s) with nothing hindering;
//! - the direction: an obstacle left of the vehicle → target line is passed
//!   on its right, counter-clockwise (m = −1), and the other way round;
//! - the merge: 12 particles of unit mass, commands become points by a
//!   horizon τ = 2 s (a command (v, γ) is the point τ·v·(cos γ, sin γ) of the
//!   vehicle frame, so that a point gives back its command: γ = its angle,
//!   v = its length / τ), a circular frustum of 6 m, attraction βg = 4 s⁻²,
//!   agent repulsion α = 0.3, obstacle spots every 0.5 m of the obstacles'
//!   outlines with Δo·mo = 4, viscous damping 4 s⁻¹, 5 sub-steps per
//!   tick (semi-implicit Euler). Particles persist from tick to tick.

use crate::control::{Direction, Ellipse, Gains};
use crate::geom::{cross, densify, unit, v2, Pose, Vec2};
use crate::noise::Noise;
use crate::vehicle::{Command, VehicleParams};
use crate::world::ObstacleView;
use serde::Serialize;

/// The closed loop's settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct UgvConfig {
    /// Control period (s): 20 Hz.
    pub dt: f64,
    /// LIDAR range (m).
    pub lidar_range: f64,
    /// LIDAR field of view (rad).
    pub lidar_fov: f64,
    /// LIDAR noise on the fitted ellipse's centre (m, σ).
    pub lidar_sigma: f64,
    /// Margin added to the enclosing ellipse beyond half the vehicle's width (m).
    pub safety_margin: f64,
    /// Radius of influence beyond the limit-cycle ellipse (m).
    pub influence: f64,
    /// Target reaching: the velocity wanted at the target (m/s).
    pub target_speed: f64,
    /// The run stops after this long (s).
    pub max_time: f64,
    /// Gains of the control law.
    pub gains: Gains,
}

impl Default for UgvConfig {
    fn default() -> Self {
        UgvConfig {
            dt: 0.05,
            lidar_range: 15.0,
            lidar_fov: 270f64.to_radians(),
            lidar_sigma: 0.02,
            safety_margin: 0.3,
            influence: 1.5,
            target_speed: 0.3,
            max_time: 120.0,
            gains: Gains::urban(),
        }
    }
}

/// One obstacle as the LIDAR agent reports it: its enclosing ellipse.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LidarObstacle {
    /// The world's obstacle index (the simulation's track id).
    pub index: usize,
    /// The fitted enclosing ellipse (noisy).
    pub ellipse: Ellipse,
    /// The outline points seen (world frame), for the merge's repulsive spots.
    pub outline: Vec<Vec2>,
    /// Distance from the vehicle to the ellipse (m).
    pub distance: f64,
}

/// The Lidar agent's `scan()`: obstacles in range and field of view, each
/// fitted with an enclosing ellipse (centre noise σ = `lidar_sigma`).
pub fn lidar_scan(pose: &Pose, views: &[ObstacleView], cfg: &UgvConfig, noise: &mut Noise) -> Vec<LidarObstacle> {
    let mut out = Vec::new();
    let mut pts = Vec::new();
    for o in views {
        if (o.center - pose.pos()).norm() - o.radius > cfg.lidar_range {
            continue;
        }
        densify(&o.polygon, 0.5, &mut pts);
        let seen: Vec<Vec2> = pts
            .iter()
            .copied()
            .filter(|p| {
                let l = pose.to_local(*p);
                l.norm() <= cfg.lidar_range && l.y.atan2(l.x).abs() <= cfg.lidar_fov / 2.0
            })
            .collect();
        if seen.is_empty() {
            continue;
        }
        let mut ellipse = Ellipse::enclosing(&o.polygon);
        let shift = v2(noise.normal(cfg.lidar_sigma), noise.normal(cfg.lidar_sigma));
        ellipse.center += shift;
        let distance = ellipse.distance(pose.pos());
        out.push(LidarObstacle {
            index: o.index,
            ellipse,
            outline: seen.iter().map(|p| p + shift).collect(),
            distance,
        });
    }
    out
}

/// The side of the vehicle → target line an obstacle is on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// Left of the line.
    Left,
    /// Right of the line.
    Right,
}

/// An obstacle that hinders the way to the target (the HINDER event).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Hinder {
    /// The world's obstacle index.
    pub index: usize,
    /// Its side of the vehicle → target line.
    pub side: Side,
    /// The limit-cycle ellipse around it.
    pub cycle: Ellipse,
    /// Distance from the vehicle to the limit-cycle ellipse (m).
    pub distance: f64,
}

impl Hinder {
    /// The avoidance direction for this side (the rule `avoid_ccw`/`avoid_cw`).
    pub fn direction(&self) -> Direction {
        match self.side {
            Side::Left => Direction::CounterClockwise,
            Side::Right => Direction::Clockwise,
        }
    }
}

/// The Selector agent's output for one tick.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Selection {
    /// The nearest hindering obstacle, if any (HINDER, else FREE).
    pub hinder: Option<Hinder>,
    /// Distance to the nearest obstacle's enclosing ellipse (the OBS event;
    /// the LIDAR range when none).
    pub nearest: f64,
    /// Radius of influence beyond the limit-cycle ellipse (HINDER's
    /// `influence`, m): avoidance starts when the hindering obstacle's
    /// [`Hinder::distance`] is within it.
    pub influence: f64,
}

/// How deep the segment `p`→`q` goes into an ellipse (1 − the smallest level
/// along it, ≤ 0 when it misses) and where (fraction of the segment).
fn penetration(e: &Ellipse, p: Vec2, q: Vec2) -> (f64, f64) {
    let (a, b, c) = e.coefficients();
    let (p0, d) = (p - e.center, q - p);
    // level(t) = A x² + B y² + C x y along p0 + t d: a quadratic in t.
    let qa = a * d.x * d.x + b * d.y * d.y + c * d.x * d.y;
    let qb = 2.0 * a * p0.x * d.x + 2.0 * b * p0.y * d.y + c * (p0.x * d.y + p0.y * d.x);
    let t = if qa > 0.0 { (-qb / (2.0 * qa)).clamp(0.0, 1.0) } else { 0.0 };
    (1.0 - e.level(p + d * t), t)
}

/// How far the vehicle's outline reaches from its reference point (the
/// rear-axle centre the controllers steer): to a front corner.
pub fn reach(params: &VehicleParams) -> f64 {
    params.front.max(params.rear).hypot(params.width / 2.0)
}

/// The Selector agent's `select()`: which obstacle hinders the movement
/// toward the target, and on which side.
pub fn select(
    pose: &Pose,
    target: &Pose,
    seen: &[LidarObstacle],
    params: &VehicleParams,
    cfg: &UgvConfig,
) -> Selection {
    let p = pose.pos();
    let tp = target.pos();
    let mut best: Option<Hinder> = None;
    let mut nearest = cfg.lidar_range;
    for o in seen {
        nearest = nearest.min(o.distance);
        let cycle = o.ellipse.grown(reach(params) + cfg.safety_margin);
        let (depth, t) = penetration(&cycle, p, tp);
        if depth > 0.05 && t > 0.0 {
            let side = if cross(tp - p, cycle.center - p) > 0.0 { Side::Left } else { Side::Right };
            let h = Hinder { index: o.index, side, cycle, distance: cycle.distance(p) };
            if best.is_none_or(|b| h.distance < b.distance) {
                best = Some(h);
            }
        }
    }
    Selection { hinder: best, nearest, influence: cfg.influence }
}

/// The merge's constants (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MergeParams {
    /// Number of particles.
    pub agents: usize,
    /// Horizon τ turning commands into points (s).
    pub tau: f64,
    /// Radius of the perception frustum (m).
    pub perception: f64,
    /// βg·m: attraction to the target (1/s²).
    pub attraction: f64,
    /// α·mi·mj: repulsion between particles.
    pub repulsion: f64,
    /// Δo·m·mo: repulsion by each obstacle spot.
    pub obstacle: f64,
    /// Spacing of the obstacle spots (m).
    pub spot_spacing: f64,
    /// Viscous damping (1/s).
    pub damping: f64,
    /// Integration sub-steps per tick.
    pub substeps: u32,
}

impl Default for MergeParams {
    fn default() -> Self {
        MergeParams {
            agents: 12,
            tau: 2.0,
            perception: 6.0,
            attraction: 4.0,
            repulsion: 0.3,
            obstacle: 4.0,
            spot_spacing: 0.5,
            damping: 4.0,
            substeps: 5,
        }
    }
}

/// The multi-agent merge of eqs. (16)–(19).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Merge {
    /// Constants.
    pub params: MergeParams,
    /// Particle positions (vehicle frame, m).
    pub pos: Vec<Vec2>,
    /// Particle velocities (m/s).
    pub vel: Vec<Vec2>,
    /// The last blended target T (vehicle frame), for pictures.
    pub last_target: Vec2,
    /// The last f(d).
    pub last_f: f64,
}

/// f of eq. (16): f(x) = 1 / (1 + 0.5 x²).
pub fn blend_weight(d: f64) -> f64 {
    1.0 / (1.0 + 0.5 * d * d)
}

impl Merge {
    /// A swarm on a small circle ahead of the vehicle (deterministic).
    pub fn new(params: MergeParams) -> Self {
        let n = params.agents.max(1);
        let pos = (0..n).map(|i| v2(1.0, 0.0) + unit(std::f64::consts::TAU * i as f64 / n as f64) * 0.5).collect();
        Merge { params, pos, vel: vec![Vec2::zeros(); n], last_target: Vec2::zeros(), last_f: 0.0 }
    }

    fn point(&self, cmd: &Command) -> Vec2 {
        unit(cmd.steer) * (self.params.tau * cmd.v)
    }

    /// One tick: blends the path-following command `follow` (target
    /// reaching) and the avoidance command `avoid` by the distance `d` to the
    /// nearest obstacle (eq. 16), moves the particles in the force field of
    /// the target, each other and the obstacle spots `spots` (vehicle frame;
    /// eqs. 17–19), and reads the command off their centre of mass.
    pub fn command(
        &mut self,
        follow: &Command,
        avoid: &Command,
        d: f64,
        spots: &[Vec2],
        params: &VehicleParams,
        dt: f64,
    ) -> Command {
        let mp = self.params;
        let f = blend_weight(d);
        let mut t = self.point(avoid) * f + self.point(follow) * (1.0 - f);
        // Keep the target on the frustum's border when out of range.
        if t.norm() > mp.perception {
            t = t.normalize() * mp.perception;
        }
        self.last_target = t;
        self.last_f = f;
        let h = dt / mp.substeps.max(1) as f64;
        let n = self.pos.len();
        let mut acc = vec![Vec2::zeros(); n];
        for _ in 0..mp.substeps.max(1) {
            for (i, acc_i) in acc.iter_mut().enumerate() {
                let pi = self.pos[i];
                // Eq. (17): linear attraction to the target.
                let mut a = (t - pi) * mp.attraction;
                // Eq. (18): r⁻² repulsion between particles.
                for j in 0..n {
                    if i != j {
                        let d = pi - self.pos[j];
                        let r = d.norm().max(0.1);
                        a += d * (mp.repulsion / (r * r * r));
                    }
                }
                // Eq. (19): repulsion by the obstacle spots in the frustum.
                for s in spots {
                    let d = pi - s;
                    let r = d.norm().max(0.3);
                    a += d * (mp.obstacle / (r * r * r));
                }
                *acc_i = a - self.vel[i] * mp.damping;
            }
            for ((p, v), a) in self.pos.iter_mut().zip(self.vel.iter_mut()).zip(&acc) {
                *v += a * h;
                *p += *v * h;
                if p.norm() > mp.perception {
                    *p = p.normalize() * mp.perception;
                }
            }
        }
        let mean = self.pos.iter().fold(Vec2::zeros(), |a, p| a + p) / n as f64;
        let steer = mean.y.atan2(mean.x).clamp(-params.max_steer, params.max_steer);
        let v = if mean.x > 0.0 { (mean.norm() / mp.tau).clamp(0.0, params.max_speed) } else { 0.0 };
        Command { v, steer }
    }
}

/// How the controllers are chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Strategy {
    /// The hard switch of `rules/ugv.situ`.
    HardSwitch,
    /// The multi-agent merge.
    Merge,
}

impl Strategy {
    /// The name used on the command line (`hard-switch`, `merge`).
    pub fn name(self) -> &'static str {
        match self {
            Strategy::HardSwitch => "hard-switch",
            Strategy::Merge => "merge",
        }
    }

    /// Parses a command-line name.
    pub fn parse(s: &str) -> Option<Strategy> {
        match s {
            "hard-switch" => Some(Strategy::HardSwitch),
            "merge" => Some(Strategy::Merge),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn selection_finds_the_hindering_obstacle_and_its_side() {
        let params = VehicleParams::urban();
        let cfg = UgvConfig::default();
        let mut views = Vec::new();
        let world = crate::scenario::dafflon_4().world;
        world.obstacles_at(0.0, &mut views);
        let mut noise = Noise::new(1, 1);
        let pose = Pose::new(5.0, 0.0, 0.0);
        let seen = lidar_scan(&pose, &views, &cfg, &mut noise);
        assert!(!seen.is_empty());
        let sel = select(&pose, &Pose::new(60.0, 0.0, 0.0), &seen, &params, &cfg);
        let h = sel.hinder.expect("O1 hinders");
        assert_eq!(world.obstacles[h.index].id, "O1");
        assert_eq!(h.side, Side::Left, "O1 is at y = +0.5");
        // Aim beside it: nothing hinders.
        let sel = select(&pose, &Pose::new(12.0, -8.0, 0.0), &seen, &params, &cfg);
        assert!(sel.hinder.is_none());
    }

    #[test]
    fn merge_without_obstacles_gives_the_follow_command() {
        let params = VehicleParams::urban();
        let mut m = Merge::new(MergeParams::default());
        let follow = Command { v: 1.5, steer: 0.2 };
        let mut cmd = Command::default();
        for _ in 0..200 {
            cmd = m.command(&follow, &follow, f64::INFINITY, &[], &params, 0.05);
        }
        assert!((cmd.v - 1.5).abs() < 0.01 && (cmd.steer - 0.2).abs() < 0.01, "{cmd:?}");
        assert!(blend_weight(0.0) == 1.0 && blend_weight(2.0) == 1.0 / 3.0);
    }
}
