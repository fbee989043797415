//! Fusion: merges the obstacle sensors' descriptions into one, and classifies
//! the scene with the events FURS / FURT / FURB / FURO{distance} / FUCN /
//! FUCO{distance} of `rules/outdoor.situ`.
//!
//! Detections of one obstacle by several sensors are associated by their
//! track id (the simulation's ground truth: association is assumed
//! perfect); the fused polygon is the convex hull of theirs, the height the
//! LADAR's (else the stereo estimate), the corridor distance the smaller.

use crate::agent::{Event, Value};
use crate::geom::{convex_hull, Vec2};
use crate::sensors::{Detection, RfccdEvent};
use serde::Serialize;
use std::collections::BTreeMap;

/// One obstacle in the fused description.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FusedObstacle {
    /// Track id (the world's obstacle index).
    pub track: usize,
    /// Circumscribed polygon, world frame (m).
    pub polygon: Vec<Vec2>,
    /// Height (m).
    pub height: f64,
    /// Width across the line of sight (m).
    pub width: f64,
    /// Distance along the swept corridor, if in it (m).
    pub distance: Option<f64>,
    /// Which sensors saw it: `(ladar, stereo)`.
    pub seen_by: (bool, bool),
}

/// Fusion's events.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum FusionEvent {
    /// `FURS`.
    RoadStraight,
    /// `FURT`.
    RoadTurn,
    /// `FURB`.
    RoadBranch,
    /// `FURO{distance}`.
    RoadObstacle {
        /// Distance to the obstacle (m).
        distance: f64,
    },
    /// `FUCN`.
    CrossCountry,
    /// `FUCO{distance}`.
    CrossCountryObstacle {
        /// Distance to the obstacle (m).
        distance: f64,
    },
}

impl Event for FusionEvent {
    fn name(&self) -> &'static str {
        match self {
            FusionEvent::RoadStraight => "FURS",
            FusionEvent::RoadTurn => "FURT",
            FusionEvent::RoadBranch => "FURB",
            FusionEvent::RoadObstacle { .. } => "FURO",
            FusionEvent::CrossCountry => "FUCN",
            FusionEvent::CrossCountryObstacle { .. } => "FUCO",
        }
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        match *self {
            FusionEvent::RoadObstacle { distance } | FusionEvent::CrossCountryObstacle { distance } => {
                vec![("distance", Value::F64(distance))]
            }
            _ => vec![],
        }
    }
}

/// Fusion's thresholds (those of the rules file: an obstacle matters on
/// road within 30 m and above 0.15 m, off-road within 20 m and above 0.3 m;
/// anything the stereo pair reports matters).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FusionConfig {
    /// Range on road (m).
    pub road_range: f64,
    /// Lowest obstacle that matters on road (m).
    pub road_height: f64,
    /// Range off-road (m).
    pub terrain_range: f64,
    /// Lowest obstacle that matters off-road (m).
    pub terrain_height: f64,
}

impl Default for FusionConfig {
    fn default() -> Self {
        FusionConfig { road_range: 30.0, road_height: 0.15, terrain_range: 20.0, terrain_height: 0.3 }
    }
}

/// The fused description and the event.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FusionOutput {
    /// The event.
    pub event: FusionEvent,
    /// Every obstacle, by track id.
    pub obstacles: Vec<FusedObstacle>,
}

/// Merges detections by track id (deterministic order: by track).
pub fn merge(ladar: &[Detection], stereo: &[Detection]) -> Vec<FusedObstacle> {
    let mut by: BTreeMap<usize, FusedObstacle> = BTreeMap::new();
    for (d, is_ladar) in ladar.iter().map(|d| (d, true)).chain(stereo.iter().map(|d| (d, false))) {
        let e = by.entry(d.track).or_insert_with(|| FusedObstacle {
            track: d.track,
            polygon: Vec::new(),
            height: 0.0,
            width: 0.0,
            distance: None,
            seen_by: (false, false),
        });
        e.polygon.extend(d.polygon.iter().copied());
        if is_ladar {
            e.height = d.height;
            e.seen_by.0 = true;
        } else {
            if !e.seen_by.0 {
                e.height = d.height;
            }
            e.seen_by.1 = true;
        }
        e.width = e.width.max(d.width);
        e.distance = match (e.distance, d.distance) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
    }
    by.into_values()
        .map(|mut o| {
            o.polygon = convex_hull(&o.polygon);
            o
        })
        .collect()
}

/// The nearest obstacle that matters: in the corridor within `range`, and
/// higher than `height` or seen by the stereo pair.
fn nearest(obstacles: &[FusedObstacle], range: f64, height: f64) -> Option<f64> {
    obstacles
        .iter()
        .filter(|o| o.height > height || (o.seen_by.1 && !o.seen_by.0))
        .filter_map(|o| o.distance)
        .filter(|d| *d < range)
        .min_by(f64::total_cmp)
}

/// `fuse_road()`: road edges (RFCCD) with obstacles (LADAR). Without a road
/// in view it falls back to the terrain classification.
pub fn fuse_road(road: &RfccdEvent, ladar: &[Detection], cfg: &FusionConfig) -> FusionOutput {
    fuse(Some(road), ladar, &[], cfg)
}

/// `fuse_terrain()`: obstacles (LADAR) with intraversable areas (STCCD).
pub fn fuse_terrain(ladar: &[Detection], stereo: &[Detection], cfg: &FusionConfig) -> FusionOutput {
    fuse(None, ladar, stereo, cfg)
}

/// The general fusion: the road camera's event if any (`None` or RFRN:
/// cross-country), and both obstacle sensors' detections.
pub fn fuse(road: Option<&RfccdEvent>, ladar: &[Detection], stereo: &[Detection], cfg: &FusionConfig) -> FusionOutput {
    let obstacles = merge(ladar, stereo);
    let on_road = matches!(road, Some(r) if *r != RfccdEvent::None);
    let event = if on_road {
        match nearest(&obstacles, cfg.road_range, cfg.road_height) {
            Some(distance) => FusionEvent::RoadObstacle { distance },
            None => match road {
                Some(RfccdEvent::Turn { .. }) => FusionEvent::RoadTurn,
                Some(RfccdEvent::Branch { .. }) => FusionEvent::RoadBranch,
                _ => FusionEvent::RoadStraight,
            },
        }
    } else {
        match nearest(&obstacles, cfg.terrain_range, cfg.terrain_height) {
            Some(distance) => FusionEvent::CrossCountryObstacle { distance },
            None => FusionEvent::CrossCountry,
        }
    };
    FusionOutput { event, obstacles }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::{rect_polygon, v2};

    fn det(track: usize, distance: Option<f64>, height: f64, x: f64) -> Detection {
        Detection {
            track,
            distance,
            range: distance.unwrap_or(10.0),
            polygon: rect_polygon(v2(x, 0.0), 1.0, 1.0, 0.0),
            height,
            width: 1.0,
        }
    }

    #[test]
    fn merges_by_track_and_classifies() {
        let l = [det(0, Some(12.0), 1.0, 20.0), det(2, None, 2.0, 30.0)];
        let s = [det(0, Some(11.5), 0.8, 20.3), det(1, Some(8.0), 0.25, 15.0)];
        let fused = merge(&l, &s);
        assert_eq!(fused.iter().map(|o| o.track).collect::<Vec<_>>(), [0, 1, 2]);
        assert_eq!(fused[0].distance, Some(11.5));
        assert_eq!(fused[0].height, 1.0, "LADAR's height wins");
        assert!(fused[0].polygon.len() >= 4);
        let road = fuse_road(&RfccdEvent::Straight, &l, &FusionConfig::default());
        assert_eq!(road.event, FusionEvent::RoadObstacle { distance: 12.0 });
        assert_eq!(road.event.name(), "FURO");
        let clear = fuse_road(
            &RfccdEvent::Turn { curvature: 0.03, left: true },
            &[det(0, None, 1.0, 20.0)],
            &FusionConfig::default(),
        );
        assert_eq!(clear.event.name(), "FURT");
        let terrain = fuse_terrain(&l, &s, &FusionConfig::default());
        assert_eq!(
            terrain.event,
            FusionEvent::CrossCountryObstacle { distance: 8.0 },
            "stereo's intraversable area counts"
        );
        assert_eq!(fuse_terrain(&[], &[], &FusionConfig::default()).event.name(), "FUCN");
        let low = fuse_terrain(&[det(0, Some(5.0), 0.2, 10.0)], &[], &FusionConfig::default());
        assert_eq!(low.event.name(), "FUCN", "off-road tyres take 0.2 m");
    }
}
