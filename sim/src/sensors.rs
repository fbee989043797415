//! The sensory agents of Zhang & Zhu (2005), simulated with seeded noise.
//! Each sensor's reading carries the event of `rules/outdoor.situ` it
//! reports, one-to-one:
//!
//! | sensor | call | events |
//! |---|---|---|
//! | RFCCD | [`Rfccd::observe`] | `RFRS`, `RFRT{curvature, side}`, `RFRB{distance}`, `RFRN` |
//! | STCCD | [`Stccd::observe`] | `STOBS{distance, width}`, `STOBN` |
//! | LADAR | [`Ladar::observe`] | `LAOBS{distance, height}`, `LAOBN` |
//! | Localization | [`Localization::observe`] | `LOFIX{error}`, `LOLOST` |
//!
//! [`Event::name`] and [`Event::fields`] give a wrapper the event's name and
//! payload as the rules file spells them.
//!
//! The obstacle sensors are mounted at the front bumper, centred; their
//! `distance` is measured along the vehicle's swept corridor (the arc of its
//! current curvature, as wide as the vehicle plus 0.3 m each side), so an
//! obstacle beside the lane being passed is not "ahead". Noise (σ): LADAR
//! 0.05 m on positions and distances, 0.02 m on heights; STCCD 0.15 m and
//! 0.03 m.

use crate::geom::{convex_hull, v2, Pose, Vec2};
use crate::noise::Noise;
use crate::vehicle::VehicleState;
use crate::world::{Corridor, CorridorHit, ObstacleView, RoadAhead, RoadLookahead, World};
use serde::Serialize;

use crate::agent::{Event, Value};

/// RFCCD's events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum RfccdEvent {
    /// `RFRS`: road straight.
    Straight,
    /// `RFRT{curvature, side}`: road turn.
    Turn {
        /// |curvature| (1/m).
        curvature: f64,
        /// `left` or `right`.
        left: bool,
    },
    /// `RFRB{distance}`: road branch ahead.
    Branch {
        /// Distance to the junction (m).
        distance: f64,
    },
    /// `RFRN`: no road found.
    None,
}

impl Event for RfccdEvent {
    fn name(&self) -> &'static str {
        match self {
            RfccdEvent::Straight => "RFRS",
            RfccdEvent::Turn { .. } => "RFRT",
            RfccdEvent::Branch { .. } => "RFRB",
            RfccdEvent::None => "RFRN",
        }
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        match *self {
            RfccdEvent::Turn { curvature, left } => {
                vec![("curvature", Value::F64(curvature)), ("side", Value::Symbol(if left { "left" } else { "right" }))]
            }
            RfccdEvent::Branch { distance } => vec![("distance", Value::F64(distance))],
            _ => vec![],
        }
    }
}

/// LADAR's events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum LadarEvent {
    /// `LAOBS{distance, height}`.
    Obstacle {
        /// Distance along the corridor (m).
        distance: f64,
        /// Height (m).
        height: f64,
    },
    /// `LAOBN`.
    None,
}

impl Event for LadarEvent {
    fn name(&self) -> &'static str {
        match self {
            LadarEvent::Obstacle { .. } => "LAOBS",
            LadarEvent::None => "LAOBN",
        }
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        match *self {
            LadarEvent::Obstacle { distance, height } => {
                vec![("distance", Value::F64(distance)), ("height", Value::F64(height))]
            }
            LadarEvent::None => vec![],
        }
    }
}

/// STCCD's events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum StccdEvent {
    /// `STOBS{distance, width}`.
    Obstacle {
        /// Distance along the corridor (m).
        distance: f64,
        /// Width across the line of sight (m).
        width: f64,
    },
    /// `STOBN`.
    None,
}

impl Event for StccdEvent {
    fn name(&self) -> &'static str {
        match self {
            StccdEvent::Obstacle { .. } => "STOBS",
            StccdEvent::None => "STOBN",
        }
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        match *self {
            StccdEvent::Obstacle { distance, width } => {
                vec![("distance", Value::F64(distance)), ("width", Value::F64(width))]
            }
            StccdEvent::None => vec![],
        }
    }
}

/// Localization's events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum LocalizationEvent {
    /// `LOFIX{error}`.
    Fix {
        /// Estimated horizontal error (m).
        error: f64,
    },
    /// `LOLOST`.
    Lost,
}

impl Event for LocalizationEvent {
    fn name(&self) -> &'static str {
        match self {
            LocalizationEvent::Fix { .. } => "LOFIX",
            LocalizationEvent::Lost => "LOLOST",
        }
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        match *self {
            LocalizationEvent::Fix { error } => vec![("error", Value::F64(error))],
            LocalizationEvent::Lost => vec![],
        }
    }
}

/// One obstacle as an obstacle sensor describes it (the data it sends to
/// Fusion or LPL).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Detection {
    /// The simulation's ground-truth track id (the world's obstacle index):
    /// data association is assumed perfect.
    pub track: usize,
    /// Distance along the swept corridor, if the obstacle is in it (m).
    pub distance: Option<f64>,
    /// Distance from the sensor (m).
    pub range: f64,
    /// The circumscribed polygon (convex hull), world frame, noisy (m).
    pub polygon: Vec<Vec2>,
    /// Height (m); STCCD reports its stereo estimate too.
    pub height: f64,
    /// Width across the line of sight (m).
    pub width: f64,
}

/// What an obstacle sensor returns each scan.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObstacleScan<E> {
    /// The event it reports.
    pub event: E,
    /// Every obstacle seen (in the field of view and range).
    pub detections: Vec<Detection>,
}

/// The pose of a sensor mounted at the front bumper.
pub fn front_mount(state: &VehicleState, front: f64) -> Pose {
    let p = state.pose.to_world(v2(front, 0.0));
    Pose::new(p.x, p.y, state.pose.theta)
}

fn detections(hits: Vec<CorridorHit>, sigma: f64, height_sigma: f64, noise: &mut Noise) -> Vec<Detection> {
    hits.into_iter()
        .map(|h| {
            let shift = v2(noise.normal(sigma), noise.normal(sigma));
            let d_noise = noise.normal(sigma);
            Detection {
                track: h.index,
                distance: h.corridor.map(|d| (d + d_noise).max(0.0)),
                range: (h.range + d_noise).max(0.0),
                polygon: convex_hull(&h.polygon.iter().map(|p| p + shift).collect::<Vec<_>>()),
                height: (h.height + noise.normal(height_sigma)).max(0.0),
                width: (h.width + noise.normal(sigma)).max(0.0),
            }
        })
        .collect()
}

/// RFCCD: road following with the long- and short-range cameras.
#[derive(Debug)]
pub struct Rfccd {
    /// How far ahead it sees turns and branches.
    pub lookahead: RoadLookahead,
    /// Relative noise on the curvature (σ, fraction).
    pub curvature_sigma: f64,
    /// Noise on the branch distance (σ, m).
    pub distance_sigma: f64,
    noise: Noise,
}

impl Rfccd {
    /// The camera with its default figures and a seed.
    pub fn new(seed: u64) -> Self {
        Rfccd {
            lookahead: RoadLookahead::default(),
            curvature_sigma: 0.05,
            distance_sigma: 0.5,
            noise: Noise::new(seed, 11),
        }
    }

    /// One frame (`lines_far()` / `lines_near()`): the road ahead of the vehicle.
    pub fn observe(&mut self, world: &World, state: &VehicleState) -> RfccdEvent {
        match world.road_ahead(&state.pose, &self.lookahead) {
            RoadAhead::Straight => RfccdEvent::Straight,
            RoadAhead::Turn { curvature, left } => RfccdEvent::Turn {
                curvature: (curvature * (1.0 + self.noise.normal(self.curvature_sigma))).max(0.0),
                left,
            },
            RoadAhead::Branch { distance } => {
                RfccdEvent::Branch { distance: (distance + self.noise.normal(self.distance_sigma)).max(0.0) }
            }
            RoadAhead::None => RfccdEvent::None,
        }
    }
}

/// The corridor the obstacle sensors test: the vehicle's current arc, as
/// wide as the vehicle plus `margin` each side.
pub fn swept_corridor(world: &World, state: &VehicleState, length: f64, margin: f64) -> Corridor {
    Corridor { curvature: state.curvature(&world.vehicle), half_width: world.vehicle.width / 2.0 + margin, length }
}

/// LADAR: positive obstacles, their circumscribed polygon and height.
#[derive(Debug)]
pub struct Ladar {
    /// Range (m).
    pub range: f64,
    /// Field of view (rad).
    pub fov: f64,
    /// Corridor margin each side of the vehicle (m).
    pub margin: f64,
    /// Range noise (σ, m).
    pub sigma: f64,
    noise: Noise,
    scratch: Vec<Vec2>,
}

impl Ladar {
    /// The LADAR with its default figures (40 m, 180°) and a seed.
    pub fn new(seed: u64) -> Self {
        Ladar {
            range: 40.0,
            fov: std::f64::consts::PI,
            margin: 0.3,
            sigma: 0.05,
            noise: Noise::new(seed, 12),
            scratch: Vec::new(),
        }
    }

    /// One scan (`detect()`). The event is LAOBS for the nearest obstacle in
    /// the corridor that is higher than the vehicle's clearance, else for the
    /// nearest lower one, else LAOBN.
    pub fn observe(&mut self, world: &World, state: &VehicleState, views: &[ObstacleView]) -> ObstacleScan<LadarEvent> {
        let pose = front_mount(state, world.vehicle.front);
        let corridor = swept_corridor(world, state, self.range, self.margin);
        let hits = world.obstacles_seen(&pose, views, self.range, self.fov, &corridor, &mut self.scratch);
        let detections = detections(hits, self.sigma, 0.02, &mut self.noise);
        let clearance = world.vehicle.clearance;
        let pick = |tall: bool| {
            detections
                .iter()
                .filter(|d| d.distance.is_some() && (d.height > clearance) == tall)
                .min_by(|a, b| a.distance.unwrap_or(f64::INFINITY).total_cmp(&b.distance.unwrap_or(f64::INFINITY)))
        };
        let event = match pick(true).or_else(|| pick(false)) {
            Some(d) => LadarEvent::Obstacle { distance: d.distance.unwrap_or(0.0), height: d.height },
            None => LadarEvent::None,
        };
        ObstacleScan { event, detections }
    }
}

/// STCCD: the stereo pair, obstacles on road and intraversable areas off-road.
#[derive(Debug)]
pub struct Stccd {
    /// Range (m).
    pub range: f64,
    /// Field of view (rad).
    pub fov: f64,
    /// Corridor margin each side of the vehicle (m).
    pub margin: f64,
    /// Lowest obstacle it separates from the ground (m).
    pub min_height: f64,
    /// Noise (σ, m).
    pub sigma: f64,
    noise: Noise,
    scratch: Vec<Vec2>,
}

impl Stccd {
    /// The stereo pair with its default figures (25 m, 60°, 0.2 m) and a seed.
    pub fn new(seed: u64) -> Self {
        Stccd {
            range: 25.0,
            fov: 60f64.to_radians(),
            margin: 0.3,
            min_height: 0.2,
            sigma: 0.15,
            noise: Noise::new(seed, 13),
            scratch: Vec::new(),
        }
    }

    /// One stereo frame (`stereo()`): STOBS for the nearest obstacle in the
    /// corridor at least `min_height` high, else STOBN.
    pub fn observe(&mut self, world: &World, state: &VehicleState, views: &[ObstacleView]) -> ObstacleScan<StccdEvent> {
        let pose = front_mount(state, world.vehicle.front);
        let corridor = swept_corridor(world, state, self.range, self.margin);
        let hits = world.obstacles_seen(&pose, views, self.range, self.fov, &corridor, &mut self.scratch);
        let min_h = self.min_height;
        let detections: Vec<Detection> =
            detections(hits, self.sigma, 0.03, &mut self.noise).into_iter().filter(|d| d.height >= min_h).collect();
        let event = detections
            .iter()
            .filter(|d| d.distance.is_some())
            .min_by(|a, b| a.distance.unwrap_or(f64::INFINITY).total_cmp(&b.distance.unwrap_or(f64::INFINITY)))
            .map_or(StccdEvent::None, |d| StccdEvent::Obstacle { distance: d.distance.unwrap_or(0.0), width: d.width });
        ObstacleScan { event, detections }
    }
}

/// Localization: GPS/INS and odometer.
#[derive(Debug)]
pub struct Localization {
    /// Position noise (σ, m).
    pub position_sigma: f64,
    /// Heading noise (σ, rad).
    pub heading_sigma: f64,
    /// Correlation of the error from one solution to the next, in [0, 1):
    /// 0 is white noise; a GPS/INS filter's error wanders slowly (a
    /// first-order Gauss–Markov process keeping σ), see [`Localization::correlated`].
    pub correlation: f64,
    error: (f64, f64, f64),
    noise: Noise,
}

/// Localization's output: the event and the pose estimate (none when lost).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fix {
    /// LOFIX or LOLOST.
    pub event: LocalizationEvent,
    /// The estimated pose.
    pub pose: Option<Pose>,
    /// The estimated speed (m/s).
    pub speed: f64,
}

impl Localization {
    /// GPS/INS with 0.1 m and 0.005 rad noise, and a seed.
    pub fn new(seed: u64) -> Self {
        Localization {
            position_sigma: 0.1,
            heading_sigma: 0.005,
            correlation: 0.0,
            error: (0.0, 0.0, 0.0),
            noise: Noise::new(seed, 14),
        }
    }

    /// The same with an error that wanders with correlation time `tau` (s)
    /// for solutions every `period` (s): what a GPS/INS filter gives, rather
    /// than a fresh error at every solution.
    pub fn correlated(seed: u64, period: f64, tau: f64) -> Self {
        Localization { correlation: (-period / tau.max(1e-9)).exp(), ..Localization::new(seed) }
    }

    /// One solution (`gpsins()`): LOLOST inside the scenario's GPS outages,
    /// else LOFIX with an error estimate of 2σ (±10%).
    pub fn observe(&mut self, world: &World, state: &VehicleState) -> Fix {
        if !world.gps_fix(state.pose.pos()) {
            return Fix { event: LocalizationEvent::Lost, pose: None, speed: state.v };
        }
        let s = self.position_sigma;
        let a = self.correlation;
        let k = (1.0 - a * a).sqrt();
        let (ex, ey, eh) = self.error;
        self.error = (
            a * ex + k * self.noise.normal(s),
            a * ey + k * self.noise.normal(s),
            a * eh + k * self.noise.normal(self.heading_sigma),
        );
        let pose = Pose::new(
            state.pose.x + self.error.0,
            state.pose.y + self.error.1,
            crate::geom::wrap_angle(state.pose.theta + self.error.2),
        );
        let error = 2.0 * s * (1.0 + self.noise.normal(0.1)).max(0.5);
        Fix { event: LocalizationEvent::Fix { error }, pose: Some(pose), speed: state.v }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario;

    fn at(x: f64, y: f64, theta: f64) -> VehicleState {
        VehicleState::at(Pose::new(x, y, theta))
    }

    #[test]
    fn events_map_onto_the_rules_file() {
        let w = scenario::outdoor_default().world;
        let mut views = Vec::new();
        w.obstacles_at(0.0, &mut views);
        let mut rf = Rfccd::new(1);
        assert_eq!(rf.observe(&w, &at(50.0, -1.75, 0.0)).name(), "RFRS");
        let turn = rf.observe(&w, &at(295.0, -1.75, 0.0));
        assert_eq!(turn.name(), "RFRT");
        assert_eq!(turn.fields()[1], ("side", Value::Symbol("left")));
        let branch = rf.observe(&w, &at(341.75, 180.0, std::f64::consts::FRAC_PI_2));
        assert_eq!(branch.name(), "RFRB");
        assert_eq!(rf.observe(&w, &at(560.0, 220.0, 0.0)), RfccdEvent::None);

        let mut la = Ladar::new(1);
        let scan = la.observe(&w, &at(175.0, -1.75, 0.0), &views);
        match scan.event {
            LadarEvent::Obstacle { distance, height } => {
                // The car's rear is at 197.75; the sensor at 175 + 3.6.
                assert!((distance - (197.75 - 178.6)).abs() < 0.3, "{distance}");
                assert!((height - 1.5).abs() < 0.3);
            }
            LadarEvent::None => panic!("the broken-down car is ahead"),
        }
        assert_eq!(scan.event.name(), "LAOBS");
        // In the left lane, passing it: not in the corridor any more.
        assert_eq!(la.observe(&w, &at(194.0, 1.75, 0.0), &views).event, LadarEvent::None);
        // The kerb stone (0.1 m) is reported only when nothing taller is ahead.
        match la.observe(&w, &at(80.0, -1.75, 0.0), &views).event {
            LadarEvent::Obstacle { height, .. } => assert!(height < 0.15 + 0.2),
            LadarEvent::None => panic!("the kerb stone is in the corridor"),
        }

        let mut st = Stccd::new(1);
        match st.observe(&w, &at(180.0, -1.75, 0.0), &views).event {
            StccdEvent::Obstacle { width, .. } => assert!((width - 1.8).abs() < 0.6, "{width}"),
            StccdEvent::None => panic!("stereo sees the car"),
        }
        assert_eq!(st.observe(&w, &at(80.0, -1.75, 0.0), &views).event.name(), "STOBN", "too low for stereo");

        let mut lo = Localization::new(1);
        let fix = lo.observe(&w, &at(10.0, -1.75, 0.0));
        assert_eq!(fix.event.name(), "LOFIX");
        assert!(fix.pose.is_some_and(|p| (p.pos() - v2(10.0, -1.75)).norm() < 0.6));
    }

    #[test]
    fn localization_is_lost_in_an_outage() {
        let mut w = scenario::outdoor_default().world;
        w.gps_outages.push(crate::geom::rect_polygon(v2(50.0, 0.0), 20.0, 20.0, 0.0));
        let mut lo = Localization::new(3);
        assert_eq!(lo.observe(&w, &at(50.0, -1.75, 0.0)).event, LocalizationEvent::Lost);
        assert_eq!(lo.observe(&w, &at(80.0, -1.75, 0.0)).event.name(), "LOFIX");
    }
}
