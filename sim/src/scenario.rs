//! Scenarios: TOML files parsed with serde into a [`World`], and validated.
//!
//! ```toml
//! name = "example"
//! vehicle = "outdoor"            # or "urban" (Dafflon et al.'s UGV), "indoor" (DLA's robot)
//!
//! [road]
//! lane_width = 3.5
//! lanes = 2
//! nodes = [{ id = "A", x = 0.0, y = 0.0 }, { id = "B", x = 100.0, y = 0.0 }]
//! edges = [
//!   { id = "ab", from = "A", to = "B", kind = "straight" },
//!   # kind = "arc" needs `radius` and `turn = "left" | "right"` (travelling from → to);
//!   # kind = "cross_country" is a track of the global map across an area.
//! ]
//!
//! [[areas]]                      # cross-country areas
//! id = "field"
//! polygon = [[0.0, 10.0], [50.0, 10.0], [50.0, 60.0], [0.0, 60.0]]
//!
//! [[obstacles]]                  # exactly one of polygon, circle, rect
//! id = "rock"
//! height = 0.8
//! circle = { x = 30.0, y = 40.0, radius = 1.5 }
//! # rect = { x = .., y = .., length = .., width = .., heading_deg = .. }
//! # motion = { path = [[x, y], ...], speed = 1.0, repeat = "ping_pong" }  # moving
//!
//! [[gps_outages]]               # optional: Localization reports LOLOST inside
//! id = "tunnel"
//! polygon = [[40.0, -5.0], [60.0, -5.0], [60.0, 5.0], [40.0, 5.0]]
//!
//! [start]
//! x = 5.0
//! y = -1.75
//! heading_deg = 0.0
//!
//! [goal]
//! x = 95.0
//! y = -1.75
//! tolerance = 2.0
//! ```
//!
//! Every error is a [`ScenarioError`] that names the field or the place;
//! nothing read from a file is unwrapped.

use crate::geom::{
    circle_polygon, contains, polygons_intersect, rect_polygon, signed_area, v2, wrap_angle, Piece, Pose, Vec2,
};
use crate::vehicle::VehicleParams;
use crate::world::{Area, EdgeKind, Goal, Motion, Obstacle, Repeat, RoadEdge, RoadNetwork, RoadNode, World};
use petgraph::graph::{NodeIndex, UnGraph};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

/// The built-in outdoor mission (`sim/scenarios/outdoor-default.toml`).
pub const OUTDOOR_DEFAULT: &str = include_str!("../scenarios/outdoor-default.toml");
/// Dafflon et al.'s four-obstacle scene (`sim/scenarios/dafflon-4.toml`).
pub const DAFFLON_4: &str = include_str!("../scenarios/dafflon-4.toml");
/// DLA's offices: rooms the robot has not seen, a dead end on the straight
/// line to the goal, a person walking (`sim/scenarios/dla-offices.toml`).
pub const DLA_OFFICES: &str = include_str!("../scenarios/dla-offices.toml");
/// DLA's unseen obstacle field for the reactive layer alone (`sim/scenarios/dla-field.toml`).
pub const DLA_FIELD: &str = include_str!("../scenarios/dla-field.toml");

/// Why a scenario was refused. Each variant names the field or the place.
#[derive(Debug, Clone, PartialEq)]
pub enum ScenarioError {
    /// The file could not be read.
    Io {
        /// The path.
        path: String,
        /// The system's message.
        message: String,
    },
    /// Not valid TOML, or a field missing, unknown or of the wrong type (the
    /// message names the field and gives the line and column).
    Syntax {
        /// toml's message, with the place.
        message: String,
    },
    /// Two items of one list share an id.
    Duplicate {
        /// Where the second one is, e.g. `road.nodes[3]`.
        place: String,
        /// The id.
        id: String,
    },
    /// A road edge names a node that does not exist.
    UnknownNode {
        /// The edge, e.g. `road.edges[2] ("t1")`.
        place: String,
        /// `from` or `to`.
        field: &'static str,
        /// The node named.
        node: String,
    },
    /// A value or a shape is impossible (a bad radius, a flat polygon, …).
    Invalid {
        /// The field, e.g. `obstacles[1] ("rock").circle.radius`.
        place: String,
        /// What is wrong.
        message: String,
    },
    /// A road does not connect to the rest of the network, or two roads meet
    /// at a kink.
    NotConnected {
        /// The road, e.g. `road.edges[4] ("spur")`.
        place: String,
        /// What is wrong.
        message: String,
    },
    /// An obstacle overlaps the vehicle at its start pose.
    ObstacleOnStart {
        /// The obstacle, e.g. `obstacles[0] ("rock")`.
        place: String,
    },
    /// The start or the goal is neither on a road nor in a cross-country area.
    OffMap {
        /// `start` or `goal`.
        place: &'static str,
        /// Its position.
        x: f64,
        /// Its position.
        y: f64,
        /// What is nearest, for the reader.
        message: String,
    },
    /// The goal cannot be reached from the start along roads and tracks.
    Unreachable {
        /// Why.
        message: String,
    },
}

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ScenarioError::Io { path, message } => write!(f, "cannot read scenario {path}: {message}"),
            ScenarioError::Syntax { message } => write!(f, "scenario: {}", message.trim_end()),
            ScenarioError::Duplicate { place, id } => write!(f, "{place}: id \"{id}\" is used twice"),
            ScenarioError::UnknownNode { place, field, node } => {
                write!(f, "{place}: `{field}` names node \"{node}\", which is not in road.nodes")
            }
            ScenarioError::Invalid { place, message } => write!(f, "{place}: {message}"),
            ScenarioError::NotConnected { place, message } => write!(f, "{place}: {message}"),
            ScenarioError::ObstacleOnStart { place } => {
                write!(f, "{place}: the obstacle covers the start: the vehicle would collide before it moves")
            }
            ScenarioError::OffMap { place, x, y, message } => {
                write!(f, "{place} ({x}, {y}) is off the map: {message}")
            }
            ScenarioError::Unreachable { message } => write!(f, "goal: {message}"),
        }
    }
}

impl std::error::Error for ScenarioError {}

/// The file's top level.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ScenarioFile {
    name: String,
    #[serde(default)]
    description: String,
    #[serde(default)]
    vehicle: VehicleKind,
    road: RoadFile,
    #[serde(default)]
    areas: Vec<AreaFile>,
    #[serde(default)]
    obstacles: Vec<ObstacleFile>,
    #[serde(default)]
    gps_outages: Vec<AreaFile>,
    start: StartFile,
    goal: GoalFile,
}

#[derive(Debug, Deserialize, Default, Clone, Copy)]
#[serde(rename_all = "snake_case")]
enum VehicleKind {
    #[default]
    Outdoor,
    Urban,
    Indoor,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RoadFile {
    lane_width: f64,
    #[serde(default = "two")]
    lanes: u32,
    #[serde(default)]
    nodes: Vec<NodeFile>,
    #[serde(default)]
    edges: Vec<EdgeFile>,
}

fn two() -> u32 {
    2
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct NodeFile {
    id: String,
    x: f64,
    y: f64,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
enum EdgeKindFile {
    Straight,
    Arc,
    CrossCountry,
}

#[derive(Debug, Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "snake_case")]
enum TurnFile {
    Left,
    Right,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct EdgeFile {
    id: String,
    from: String,
    to: String,
    kind: EdgeKindFile,
    radius: Option<f64>,
    turn: Option<TurnFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct AreaFile {
    id: String,
    polygon: Vec<[f64; 2]>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct CircleFile {
    x: f64,
    y: f64,
    radius: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RectFile {
    x: f64,
    y: f64,
    length: f64,
    width: f64,
    #[serde(default)]
    heading_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct MotionFile {
    path: Vec<[f64; 2]>,
    speed: f64,
    #[serde(default = "ping_pong")]
    repeat: Repeat,
}

fn ping_pong() -> Repeat {
    Repeat::PingPong
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ObstacleFile {
    id: String,
    height: f64,
    polygon: Option<Vec<[f64; 2]>>,
    circle: Option<CircleFile>,
    rect: Option<RectFile>,
    motion: Option<MotionFile>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct StartFile {
    x: f64,
    y: f64,
    heading_deg: f64,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct GoalFile {
    x: f64,
    y: f64,
    #[serde(default = "default_tolerance")]
    tolerance: f64,
    heading_deg: Option<f64>,
}

fn default_tolerance() -> f64 {
    2.0
}

/// A parsed and validated scenario.
#[derive(Debug, Clone)]
pub struct Scenario {
    /// Name.
    pub name: String,
    /// What it is for.
    pub description: String,
    /// The world built from it.
    pub world: World,
}

/// Reads and validates a scenario file.
pub fn load(path: &Path) -> Result<Scenario, ScenarioError> {
    use situ_compiler::loader::{read_bounded, MAX_FILE_BYTES};
    let io = |message: String| ScenarioError::Io { path: path.display().to_string(), message };
    let bytes = read_bounded(path, MAX_FILE_BYTES, "a scenario file").map_err(|e| io(e.to_string()))?;
    let text = String::from_utf8(bytes).map_err(|_| io("not UTF-8 text".into()))?;
    parse(&text)
}

/// A built-in scenario by name: `outdoor-default`, `dafflon-4`, `dla-offices` or `dla-field`.
pub fn builtin(name: &str) -> Option<Scenario> {
    let text = match name {
        "outdoor-default" => OUTDOOR_DEFAULT,
        "dafflon-4" => DAFFLON_4,
        "dla-offices" => DLA_OFFICES,
        "dla-field" => DLA_FIELD,
        _ => return None,
    };
    parse(text).ok()
}

/// A scenario given by name that cannot be had.
#[derive(Debug, thiserror::Error)]
pub enum NamedError {
    /// Neither a built-in scenario nor a file.
    #[error("no built-in scenario `{0}` (outdoor-default, dafflon-4, dla-offices, dla-field) and no such file")]
    Unknown(String),
    /// The file is not a valid scenario.
    #[error("scenario `{name}`: {error}")]
    Bad {
        /// The name given.
        name: String,
        /// What is wrong.
        #[source]
        error: ScenarioError,
    },
}

/// A built-in scenario by name ([`builtin`]), or a TOML file ([`load`]); the
/// error names the field or the place.
pub fn named(name: &str) -> Result<Scenario, NamedError> {
    if let Some(s) = builtin(name) {
        return Ok(s);
    }
    let path = Path::new(name);
    if !path.exists() && !name.ends_with(".toml") {
        return Err(NamedError::Unknown(name.to_string()));
    }
    load(path).map_err(|error| NamedError::Bad { name: name.to_string(), error })
}

/// The built-in outdoor mission.
pub fn outdoor_default() -> Scenario {
    // The embedded file is checked by this crate's tests; an error here is a bug.
    parse(OUTDOOR_DEFAULT).unwrap_or_else(|e| panic!("built-in outdoor-default.toml: {e}"))
}

/// Dafflon et al.'s four-obstacle scene.
pub fn dafflon_4() -> Scenario {
    parse(DAFFLON_4).unwrap_or_else(|e| panic!("built-in dafflon-4.toml: {e}"))
}

/// Parses and validates a scenario from TOML text.
pub fn parse(text: &str) -> Result<Scenario, ScenarioError> {
    let file: ScenarioFile = toml::from_str(text).map_err(|e| ScenarioError::Syntax { message: e.to_string() })?;
    build(file)
}

/// The extent of a scenario's world: coordinates (m) and angles (degrees)
/// within ±100 km of the origin. A road sampled metre by metre across a
/// larger world would ask for more memory than a mission can justify.
pub const MAX_COORDINATE: f64 = 100_000.0;

fn finite(place: &str, v: f64) -> Result<f64, ScenarioError> {
    if !v.is_finite() {
        Err(ScenarioError::Invalid { place: place.into(), message: format!("{v} is not a finite number") })
    } else if v.abs() > MAX_COORDINATE {
        Err(ScenarioError::Invalid {
            place: place.into(),
            message: format!("{v} is out of the world: coordinates and angles lie within ±{MAX_COORDINATE}"),
        })
    } else {
        Ok(v)
    }
}

fn positive(place: &str, v: f64) -> Result<f64, ScenarioError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ScenarioError::Invalid { place: place.into(), message: format!("must be a positive number, not {v}") })
    }
}

fn polygon(place: &str, pts: &[[f64; 2]]) -> Result<Vec<Vec2>, ScenarioError> {
    if pts.len() < 3 {
        return Err(ScenarioError::Invalid {
            place: place.into(),
            message: format!("a polygon needs at least 3 points, it has {}", pts.len()),
        });
    }
    let mut out = Vec::with_capacity(pts.len());
    for (i, p) in pts.iter().enumerate() {
        out.push(v2(finite(&format!("{place}[{i}]"), p[0])?, finite(&format!("{place}[{i}]"), p[1])?));
    }
    if signed_area(&out).abs() < 1e-6 {
        return Err(ScenarioError::Invalid { place: place.into(), message: "the polygon is flat (zero area)".into() });
    }
    Ok(out)
}

fn check_unique<'a>(list: &'static str, ids: impl Iterator<Item = &'a str>) -> Result<(), ScenarioError> {
    let mut seen = BTreeMap::new();
    for (i, id) in ids.enumerate() {
        if seen.insert(id.to_string(), i).is_some() {
            return Err(ScenarioError::Duplicate { place: format!("{list}[{i}]"), id: id.into() });
        }
    }
    Ok(())
}

/// Largest angle at which two roads may meet at a node that only they share
/// (a pass-through node): more is a kink, not a road.
const MAX_KINK_DEG: f64 = 10.0;

fn build(f: ScenarioFile) -> Result<Scenario, ScenarioError> {
    let vehicle = match f.vehicle {
        VehicleKind::Outdoor => VehicleParams::outdoor(),
        VehicleKind::Urban => VehicleParams::urban(),
        VehicleKind::Indoor => VehicleParams::indoor(),
    };
    positive("road.lane_width", f.road.lane_width)?;
    if f.road.lanes == 0 {
        return Err(ScenarioError::Invalid {
            place: "road.lanes".into(),
            message: "a road needs at least one lane".into(),
        });
    }
    check_unique("road.nodes", f.road.nodes.iter().map(|n| n.id.as_str()))?;
    check_unique("road.edges", f.road.edges.iter().map(|e| e.id.as_str()))?;
    check_unique("areas", f.areas.iter().map(|a| a.id.as_str()))?;
    check_unique("obstacles", f.obstacles.iter().map(|o| o.id.as_str()))?;

    let mut graph = UnGraph::new_undirected();
    let mut by_id: BTreeMap<&str, NodeIndex> = BTreeMap::new();
    for (i, n) in f.road.nodes.iter().enumerate() {
        let place = format!("road.nodes[{i}] (\"{}\")", n.id);
        let p = v2(finite(&format!("{place}.x"), n.x)?, finite(&format!("{place}.y"), n.y)?);
        by_id.insert(&n.id, graph.add_node(RoadNode { id: n.id.clone(), position: p }));
    }
    let mut areas = Vec::new();
    for (i, a) in f.areas.iter().enumerate() {
        areas.push(Area {
            id: a.id.clone(),
            polygon: polygon(&format!("areas[{i}] (\"{}\").polygon", a.id), &a.polygon)?,
        });
    }
    let mut edge_places = Vec::new();
    for (i, e) in f.road.edges.iter().enumerate() {
        let place = format!("road.edges[{i}] (\"{}\")", e.id);
        let a = *by_id.get(e.from.as_str()).ok_or_else(|| ScenarioError::UnknownNode {
            place: place.clone(),
            field: "from",
            node: e.from.clone(),
        })?;
        let b = *by_id.get(e.to.as_str()).ok_or_else(|| ScenarioError::UnknownNode {
            place: place.clone(),
            field: "to",
            node: e.to.clone(),
        })?;
        if a == b {
            return Err(ScenarioError::Invalid { place, message: "`from` and `to` are the same node".into() });
        }
        let (pa, pb) = (graph[a].position, graph[b].position);
        let (kind, piece) = match e.kind {
            EdgeKindFile::Straight | EdgeKindFile::CrossCountry => {
                if e.radius.is_some() || e.turn.is_some() {
                    return Err(ScenarioError::Invalid {
                        place,
                        message: "`radius` and `turn` belong to kind = \"arc\" only".into(),
                    });
                }
                let k = if e.kind == EdgeKindFile::Straight { EdgeKind::Road } else { EdgeKind::CrossCountry };
                (k, Piece::Line { a: pa, b: pb })
            }
            EdgeKindFile::Arc => {
                let r = e.radius.ok_or_else(|| ScenarioError::Invalid {
                    place: format!("{place}.radius"),
                    message: "missing: an arc needs `radius`".into(),
                })?;
                let r = positive(&format!("{place}.radius"), r)?;
                let turn = e.turn.ok_or_else(|| ScenarioError::Invalid {
                    place: format!("{place}.turn"),
                    message: "missing: an arc needs `turn = \"left\"` or `\"right\"`".into(),
                })?;
                let piece =
                    Piece::arc_between(pa, pb, r, turn == TurnFile::Left).ok_or_else(|| ScenarioError::Invalid {
                        place: format!("{place}.radius"),
                        message: format!(
                            "radius {r} m is shorter than half the distance between {} and {} ({:.2} m)",
                            e.from,
                            e.to,
                            (pb - pa).norm() / 2.0
                        ),
                    })?;
                (EdgeKind::Road, piece)
            }
        };
        if kind == EdgeKind::CrossCountry {
            // A track must stay in the cross-country areas (or on a road near its ends).
            for p in piece.sample(1.0) {
                let near_end = (p - pa).norm() <= f.road.lane_width * f.road.lanes as f64
                    || (p - pb).norm() <= f.road.lane_width * f.road.lanes as f64;
                if !near_end && !areas.iter().any(|ar| contains(&ar.polygon, p)) {
                    return Err(ScenarioError::NotConnected {
                        place,
                        message: format!(
                            "the cross-country track leaves the cross-country areas at ({:.1}, {:.1})",
                            p.x, p.y
                        ),
                    });
                }
            }
        }
        graph.add_edge(a, b, RoadEdge { id: e.id.clone(), kind, piece });
        edge_places.push(place);
    }
    let roads = RoadNetwork { graph, lane_width: f.road.lane_width, lanes: f.road.lanes };

    // Pass-through nodes must join their two roads smoothly.
    for n in roads.graph.node_indices() {
        let mut es: Vec<_> = roads.graph.edges(n).map(|e| petgraph::visit::EdgeRef::id(&e)).collect();
        es.sort();
        if es.len() != 2 || es.iter().any(|e| roads.graph[*e].kind != EdgeKind::Road) {
            continue;
        }
        let h_in = roads.oriented(es[0], n).reversed();
        let h_out = roads.oriented(es[1], n);
        let kink = wrap_angle(h_out.heading(0.0) - h_in.heading(h_in.length())).abs().to_degrees();
        if kink > MAX_KINK_DEG {
            return Err(ScenarioError::NotConnected {
                place: edge_places[es[1].index()].clone(),
                message: format!(
                    "meets road \"{}\" at node \"{}\" with a kink of {kink:.0}° (at most {MAX_KINK_DEG}°): \
                     the roads do not connect smoothly",
                    roads.graph[es[0]].id, roads.graph[n].id
                ),
            });
        }
    }

    let mut obstacles = Vec::new();
    for (i, o) in f.obstacles.iter().enumerate() {
        let place = format!("obstacles[{i}] (\"{}\")", o.id);
        let height = positive(&format!("{place}.height"), o.height)?;
        let shapes = o.polygon.is_some() as u8 + o.circle.is_some() as u8 + o.rect.is_some() as u8;
        if shapes != 1 {
            return Err(ScenarioError::Invalid {
                place,
                message: format!("give exactly one of `polygon`, `circle`, `rect` (found {shapes})"),
            });
        }
        let poly = if let Some(p) = &o.polygon {
            polygon(&format!("{place}.polygon"), p)?
        } else if let Some(c) = &o.circle {
            let r = positive(&format!("{place}.circle.radius"), c.radius)?;
            circle_polygon(v2(finite(&place, c.x)?, finite(&place, c.y)?), r, 16)
        } else if let Some(r) = &o.rect {
            let l = positive(&format!("{place}.rect.length"), r.length)?;
            let w = positive(&format!("{place}.rect.width"), r.width)?;
            rect_polygon(
                v2(finite(&place, r.x)?, finite(&place, r.y)?),
                l,
                w,
                finite(&place, r.heading_deg)?.to_radians(),
            )
        } else {
            unreachable!("exactly one shape was checked above")
        };
        let motion = match &o.motion {
            None => Motion::Static,
            Some(m) => {
                if m.path.len() < 2 {
                    return Err(ScenarioError::Invalid {
                        place: format!("{place}.motion.path"),
                        message: format!("a path needs at least 2 points, it has {}", m.path.len()),
                    });
                }
                let speed = positive(&format!("{place}.motion.speed"), m.speed)?;
                let mut wps = Vec::new();
                for p in &m.path {
                    wps.push(v2(
                        finite(&format!("{place}.motion.path"), p[0])?,
                        finite(&format!("{place}.motion.path"), p[1])?,
                    ));
                }
                // The polygon is given where the obstacle is at the first waypoint.
                Motion::Path { waypoints: wps, speed, repeat: m.repeat }
            }
        };
        obstacles.push(Obstacle { id: o.id.clone(), polygon: poly, height, motion });
    }
    let mut gps_outages = Vec::new();
    for (i, a) in f.gps_outages.iter().enumerate() {
        gps_outages.push(polygon(&format!("gps_outages[{i}] (\"{}\").polygon", a.id), &a.polygon)?);
    }

    let start = Pose::new(
        finite("start.x", f.start.x)?,
        finite("start.y", f.start.y)?,
        wrap_angle(finite("start.heading_deg", f.start.heading_deg)?.to_radians()),
    );
    let goal = Goal {
        position: v2(finite("goal.x", f.goal.x)?, finite("goal.y", f.goal.y)?),
        tolerance: positive("goal.tolerance", f.goal.tolerance)?,
        heading: match f.goal.heading_deg {
            Some(h) => Some(wrap_angle(finite("goal.heading_deg", h)?.to_radians())),
            None => None,
        },
    };
    let world = World { name: f.name.clone(), roads, areas, obstacles, gps_outages, start, goal, vehicle };

    // Start and goal must be on the map, and on or near a road or track.
    let on_map = |p: Vec2, what: &'static str| -> Result<petgraph::graph::EdgeIndex, ScenarioError> {
        let near = world.roads.nearest_edge(p, None);
        let terrain = world.terrain(p);
        let hw = world.roads.half_width();
        match near {
            Some((e, pr)) if terrain != crate::world::Terrain::Off && pr.distance <= hw.max(5.0) => Ok(e),
            Some((e, pr)) if terrain != crate::world::Terrain::Off => Err(ScenarioError::OffMap {
                place: what,
                x: p.x,
                y: p.y,
                message: format!(
                    "it is {:.1} m from the nearest road or track (\"{}\"); put it within {:.1} m of one",
                    pr.distance,
                    world.roads.graph[e].id,
                    hw.max(5.0)
                ),
            }),
            Some((e, pr)) => Err(ScenarioError::OffMap {
                place: what,
                x: p.x,
                y: p.y,
                message: format!(
                    "neither on a road nor in a cross-country area (the nearest road or track, \"{}\", is {:.1} m away)",
                    world.roads.graph[e].id, pr.distance
                ),
            }),
            None => Err(ScenarioError::OffMap {
                place: what,
                x: p.x,
                y: p.y,
                message: "the scenario has no road or track at all (road.edges is empty)".into(),
            }),
        }
    };
    let start_edge = on_map(start.pos(), "start")?;
    let goal_edge = on_map(goal.position, "goal")?;

    // Every road must connect to the one the start is on.
    let (sa, _) = world.roads.graph.edge_endpoints(start_edge).unwrap_or_default();
    let reach = reachable(&world.roads.graph, sa);
    for e in world.roads.graph.edge_indices() {
        let (a, _) = world.roads.graph.edge_endpoints(e).unwrap_or_default();
        if !reach.contains(&a) {
            return Err(ScenarioError::NotConnected {
                place: edge_places[e.index()].clone(),
                message: format!(
                    "this road does not connect to the road network of the start (road \"{}\")",
                    world.roads.graph[start_edge].id
                ),
            });
        }
    }
    let (ga, _) = world.roads.graph.edge_endpoints(goal_edge).unwrap_or_default();
    if !reach.contains(&ga) {
        return Err(ScenarioError::Unreachable {
            message: format!(
                "no road or track leads from the start to the goal's road \"{}\"",
                world.roads.graph[goal_edge].id
            ),
        });
    }

    // No obstacle on the start.
    let fp = world.vehicle.footprint(&start);
    for (i, o) in world.obstacles.iter().enumerate() {
        if polygons_intersect(&fp, &o.polygon) {
            return Err(ScenarioError::ObstacleOnStart { place: format!("obstacles[{i}] (\"{}\")", o.id) });
        }
    }
    Ok(Scenario { name: f.name, description: f.description, world })
}

fn reachable(g: &UnGraph<RoadNode, RoadEdge>, from: NodeIndex) -> std::collections::BTreeSet<NodeIndex> {
    let mut seen = std::collections::BTreeSet::new();
    let mut stack = vec![from];
    while let Some(n) = stack.pop() {
        if seen.insert(n) {
            stack.extend(g.neighbors(n));
        }
    }
    seen
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn moving_obstacles_and_outages_parse() {
        let text = r#"
name = "walker"
[road]
lane_width = 3.5
nodes = [{ id = "A", x = 0.0, y = 0.0 }, { id = "B", x = 100.0, y = 0.0 }]
edges = [{ id = "ab", from = "A", to = "B", kind = "straight" }]
[[obstacles]]
id = "walker"
height = 1.8
circle = { x = 50.0, y = 8.0, radius = 0.4 }
motion = { path = [[50.0, 8.0], [50.0, -8.0]], speed = 1.2, repeat = "loop" }
[[gps_outages]]
id = "tunnel"
polygon = [[70.0, -5.0], [80.0, -5.0], [80.0, 5.0], [70.0, 5.0]]
[start]
x = 5.0
y = -1.75
heading_deg = 0.0
[goal]
x = 95.0
y = -1.75
"#;
        let s = parse(text).expect("valid");
        let o = &s.world.obstacles[0];
        assert!((o.offset_at(10.0) - v2(0.0, -12.0)).norm() < 1e-9);
        assert!((o.offset_at(15.0) - v2(0.0, -2.0)).norm() < 1e-9, "18 m along a 16 m path: looped");
        assert!(!s.world.gps_fix(v2(75.0, 0.0)) && s.world.gps_fix(v2(60.0, 0.0)));
        let bad = text.replace("speed = 1.2", "speed = -1.0");
        let e = parse(&bad).expect_err("negative speed");
        assert_eq!(e.to_string(), "obstacles[0] (\"walker\").motion.speed: must be a positive number, not -1");
    }

    #[test]
    fn a_coordinate_out_of_the_world_is_refused_not_sampled() {
        // Found by the `scenario` fuzz target: a node at 7e26 m made the
        // cross-country check sample the track metre by metre (capacity overflow).
        let text = include_str!("../tests/fuzz/scenario-huge-coordinate.toml");
        let e = parse(text).unwrap_err().to_string();
        assert!(e.contains("out of the world"), "{e}");
        let fixed = text.replace("704444444444444444444444441.0", "704.0");
        if let Err(e) = parse(&fixed) {
            assert!(!e.to_string().contains("out of the world"), "{e}");
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_device_is_refused_not_read() {
        let err = load(Path::new("/dev/zero")).unwrap_err().to_string();
        assert!(err.contains("/dev/zero") && err.contains("is a character device, not a regular file"), "{err}");
    }

    #[test]
    fn builtins_parse() {
        let s = outdoor_default();
        assert!(s.world.roads.graph.edge_count() >= 5);
        let d = dafflon_4();
        assert_eq!(d.world.obstacles.len(), 4);
        assert!(builtin("outdoor-default").is_some() && builtin("nope").is_none());
    }
}
