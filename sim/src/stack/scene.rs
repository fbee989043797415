//! What a run adds to its MCAP recording besides the runtime's records:
//! the vehicle's pose and the obstacles, on Foxglove's own schemas.

use super::{Physics, NS};
use serde_json::{json, Value as Json};
use situ_runtime::record::mcap::McapRecorder;
use std::sync::{Arc, Mutex};

/// Topics `situ run` adds to a recording.
pub mod topics {
    /// The vehicle's pose, `foxglove.PoseInFrame`.
    pub const POSE: &str = "/pose";
    /// The obstacles, `foxglove.SceneUpdate`.
    pub const OBSTACLES: &str = "/obstacles";
}

fn time_json(t: u64) -> Json {
    json!({ "sec": t / NS, "nsec": t % NS })
}

/// The JSON schema of `foxglove.PoseInFrame`: Foxglove's own, as published
/// (schemas/jsonschema/PoseInFrame.json of github.com/foxglove/foxglove-sdk,
/// MIT), so that Foxglove's panels read the messages and a recording
/// validates against it.
pub fn pose_in_frame_schema() -> String {
    include_str!("schemas/PoseInFrame.json").trim_end().to_string()
}

/// The JSON schema of `foxglove.SceneUpdate`: Foxglove's own, as published
/// (schemas/jsonschema/SceneUpdate.json of github.com/foxglove/foxglove-sdk,
/// MIT), every sub-schema in full (SceneEntity, SceneEntityDeletion, the
/// primitives, Pose, Vector3, Quaternion, Color, time, duration).
pub fn scene_update_schema() -> String {
    include_str!("schemas/SceneUpdate.json").trim_end().to_string()
}

/// The pose and obstacle channels of a recording.
pub(super) struct Scene {
    mcap: Arc<Mutex<McapRecorder>>,
    pose: u16,
    obstacles: u16,
}

impl Scene {
    pub(super) fn new(mcap: Arc<Mutex<McapRecorder>>) -> std::io::Result<Scene> {
        let (pose, obstacles) = {
            let mut m = mcap.lock().unwrap_or_else(|e| e.into_inner());
            let pose = m.add_channel(topics::POSE, "foxglove.PoseInFrame", &pose_in_frame_schema())?;
            let obstacles = m.add_channel(topics::OBSTACLES, "foxglove.SceneUpdate", &scene_update_schema())?;
            (pose, obstacles)
        };
        Ok(Scene { mcap, pose, obstacles })
    }

    pub(super) fn pose(&self, t: u64, ph: &Physics) {
        let p = ph.vehicle.state.pose;
        let (s, c) = (p.theta / 2.0).sin_cos();
        let msg = json!({
            "timestamp": time_json(t), "frame_id": "map",
            "pose": { "position": {"x": p.x, "y": p.y, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": s, "w": c} },
        });
        self.mcap.lock().unwrap_or_else(|e| e.into_inner()).write_message(self.pose, t, &msg);
    }

    pub(super) fn obstacles(&self, t: u64, ph: &Physics) {
        let entities: Vec<Json> = ph
            .views
            .iter()
            .map(|o| {
                let points: Vec<Json> = o.polygon.iter().map(|q| json!({"x": q.x, "y": q.y, "z": 0.0})).collect();
                let tall = o.height > ph.world.vehicle.clearance;
                let color = if tall { json!({"r": 0.85, "g": 0.15, "b": 0.15, "a": 1.0}) } else { json!({"r": 0.6, "g": 0.6, "b": 0.6, "a": 1.0}) };
                json!({
                    "timestamp": time_json(t), "frame_id": "map",
                    "id": format!("obstacle/{}", o.index), "lifetime": {"sec": 0, "nsec": 0}, "frame_locked": false,
                    "metadata": [ {"key": "name", "value": ph.world.obstacles[o.index].id},
                                  {"key": "height", "value": format!("{:.2}", o.height)} ],
                    "arrows": [], "cubes": [], "spheres": [], "cylinders": [],
                    "lines": [{
                        "type": 1,
                        "pose": { "position": {"x": 0.0, "y": 0.0, "z": 0.0}, "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0} },
                        "thickness": 0.15, "scale_invariant": false, "points": points,
                        "color": color, "colors": [], "indices": [],
                    }],
                    "triangles": [], "texts": [], "models": [],
                })
            })
            .collect();
        let msg = json!({ "deletions": [], "entities": entities });
        self.mcap.lock().unwrap_or_else(|e| e.into_inner()).write_message(self.obstacles, t, &msg);
    }
}
