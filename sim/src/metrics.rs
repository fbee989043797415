//! What a run measured: Dafflon et al.'s metrics (steering angle and speed
//! over time, physical integrity: the closest distance to the obstacles and
//! the time to collision), collisions, time to goal, the smoothness of the
//! commands, and hooks for the architecture metrics the runtime fills (time
//! in each state, agents running per state, messages per stream).
//!
//! Everything is deterministic: maps are `BTreeMap`s, nothing reads a clock,
//! so the same scenario and seed give the same `metrics.json` to the byte.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// One sample of a run (one per control tick).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sample {
    /// Simulated time (s).
    pub t: f64,
    /// Pose x (m).
    pub x: f64,
    /// Pose y (m).
    pub y: f64,
    /// Heading (rad).
    pub theta: f64,
    /// Actual speed (m/s).
    pub v: f64,
    /// Actual front-wheel angle (rad).
    pub steer: f64,
    /// Commanded speed (m/s).
    pub v_cmd: f64,
    /// Commanded front-wheel angle (rad).
    pub steer_cmd: f64,
    /// Distance from the footprint to the closest obstacle (m).
    pub closest: Option<f64>,
    /// Time to collision at the current velocity (s).
    pub ttc: Option<f64>,
    /// The caller's label: the system state, or the controller in charge.
    pub label: String,
}

/// A collision.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Collision {
    /// When (s).
    pub t: f64,
    /// With which obstacle (its scenario id).
    pub obstacle: String,
}

/// The figures of a run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Summary {
    /// Simulated duration (s).
    pub duration: f64,
    /// Distance driven (m).
    pub distance: f64,
    /// Whether the goal was reached.
    pub goal_reached: bool,
    /// When the goal was reached (s).
    pub time_to_goal: Option<f64>,
    /// Collisions, in time order.
    pub collisions: Vec<Collision>,
    /// The closest distance to any obstacle over the run (m).
    pub closest_distance: Option<f64>,
    /// Which obstacle that was.
    pub closest_obstacle: Option<String>,
    /// The smallest time to collision over the run (s).
    pub min_ttc: Option<f64>,
    /// Highest commanded speed (m/s).
    pub max_speed: f64,
    /// Mean actual speed (m/s).
    pub mean_speed: f64,
    /// Largest |commanded steering angle| (rad).
    pub max_abs_steer: f64,
    /// Largest |rate of the commanded steering angle| (rad/s).
    pub max_steer_rate: f64,
    /// RMS of the rate of the commanded steering angle (rad/s).
    pub rms_steer_rate: f64,
    /// Largest |rate of the commanded speed| (m/s²).
    pub max_speed_rate: f64,
}

/// The architecture's figures, filled by the runtime (the simulation fills
/// `time_in_state` from the samples' labels).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
pub struct Architecture {
    /// Seconds spent in each state (label).
    pub time_in_state: BTreeMap<String, f64>,
    /// Per state, the agents running in it.
    pub agents_running: BTreeMap<String, Vec<String>>,
    /// Messages sent per stream (e.g. `LADAR->Fusion`, `events`, `status`).
    pub messages_per_stream: BTreeMap<String, u64>,
    /// The sequence of states entered, with the time of entry.
    pub transitions: Vec<(f64, String)>,
}

/// Everything one run measured: written as `metrics.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Metrics {
    /// Scenario name.
    pub scenario: String,
    /// Which controller or stack drove.
    pub controller: String,
    /// The noise seed.
    pub seed: u64,
    /// Control period (s).
    pub dt: f64,
    /// The figures.
    pub summary: Summary,
    /// The architecture's figures.
    pub architecture: Architecture,
    /// Every tick.
    pub samples: Vec<Sample>,
}

impl Metrics {
    /// Pretty JSON (deterministic).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }

    /// Writes `metrics.json` content to a path.
    pub fn write_json(&self, path: &Path) -> std::io::Result<()> {
        std::fs::write(path, self.to_json())
    }
}

/// Collects samples and events during a run, and computes the summary.
#[derive(Debug, Clone)]
pub struct Recorder {
    metrics: Metrics,
    prev: Option<Sample>,
    steer_rate_sq: f64,
    rate_count: u64,
    speed_sum: f64,
    count: u64,
}

impl Recorder {
    /// A recorder for a run.
    pub fn new(scenario: &str, controller: &str, seed: u64, dt: f64) -> Self {
        Recorder {
            metrics: Metrics {
                scenario: scenario.into(),
                controller: controller.into(),
                seed,
                dt,
                summary: Summary::default(),
                architecture: Architecture::default(),
                samples: Vec::new(),
            },
            prev: None,
            steer_rate_sq: 0.0,
            rate_count: 0,
            speed_sum: 0.0,
            count: 0,
        }
    }

    /// Records one tick; `closest_obstacle` names the obstacle at `s.closest`.
    pub fn record(&mut self, s: Sample, closest_obstacle: Option<&str>) {
        let dt = self.metrics.dt;
        let sum = &mut self.metrics.summary;
        let arch = &mut self.metrics.architecture;
        if let Some(p) = &self.prev {
            let rate = (s.steer_cmd - p.steer_cmd) / dt;
            sum.max_steer_rate = sum.max_steer_rate.max(rate.abs());
            sum.max_speed_rate = sum.max_speed_rate.max(((s.v_cmd - p.v_cmd) / dt).abs());
            self.steer_rate_sq += rate * rate;
            self.rate_count += 1;
            sum.distance += (s.x - p.x).hypot(s.y - p.y);
        }
        *arch.time_in_state.entry(s.label.clone()).or_insert(0.0) += dt;
        if self.prev.as_ref().is_none_or(|p| p.label != s.label) {
            arch.transitions.push((s.t, s.label.clone()));
        }
        if let Some(c) = s.closest {
            if sum.closest_distance.is_none_or(|b| c < b) {
                sum.closest_distance = Some(c);
                sum.closest_obstacle = closest_obstacle.map(str::to_string);
            }
        }
        if let Some(t) = s.ttc {
            sum.min_ttc = Some(sum.min_ttc.map_or(t, |b: f64| b.min(t)));
        }
        sum.max_speed = sum.max_speed.max(s.v_cmd);
        sum.max_abs_steer = sum.max_abs_steer.max(s.steer_cmd.abs());
        sum.duration = s.t;
        self.speed_sum += s.v;
        self.count += 1;
        self.metrics.samples.push(s.clone());
        self.prev = Some(s);
    }

    /// A collision happened.
    pub fn collision(&mut self, t: f64, obstacle: &str) {
        self.metrics.summary.collisions.push(Collision { t, obstacle: obstacle.into() });
    }

    /// The goal was reached.
    pub fn goal(&mut self, t: f64) {
        if !self.metrics.summary.goal_reached {
            self.metrics.summary.goal_reached = true;
            self.metrics.summary.time_to_goal = Some(t);
        }
    }

    /// Hook for the runtime: the agents running in a state.
    pub fn agents_running(&mut self, state: &str, agents: Vec<String>) {
        self.metrics.architecture.agents_running.insert(state.into(), agents);
    }

    /// Hook for the runtime: one more message (or `n`) on a stream.
    pub fn message(&mut self, stream: &str, n: u64) {
        *self.metrics.architecture.messages_per_stream.entry(stream.into()).or_insert(0) += n;
    }

    /// Drops the samples kept so far (long runs that want the summary
    /// only; the summary keeps counting).
    pub fn forget_samples(&mut self) {
        self.metrics.samples.clear();
    }

    /// The samples so far.
    pub fn samples(&self) -> &[Sample] {
        &self.metrics.samples
    }

    /// The summary so far (RMS and mean are final only after [`Recorder::finish`]).
    pub fn summary(&self) -> &Summary {
        &self.metrics.summary
    }

    /// Ends the run.
    pub fn finish(mut self) -> Metrics {
        let n = self.count;
        if self.rate_count > 0 {
            self.metrics.summary.rms_steer_rate = (self.steer_rate_sq / self.rate_count as f64).sqrt();
        }
        if n > 0 {
            self.metrics.summary.mean_speed = self.speed_sum / n as f64;
        }
        self.metrics
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample(t: f64, steer: f64, label: &str) -> Sample {
        Sample {
            t,
            x: t,
            y: 0.0,
            theta: 0.0,
            v: 1.0,
            steer,
            v_cmd: 1.0,
            steer_cmd: steer,
            closest: Some(10.0 - t),
            ttc: None,
            label: label.into(),
        }
    }

    #[test]
    fn steering_rate_and_states() {
        let mut r = Recorder::new("s", "c", 1, 0.5);
        r.record(sample(0.0, 0.0, "A"), Some("o"));
        r.record(sample(0.5, 0.1, "A"), Some("o"));
        r.record(sample(1.0, 0.1, "B"), Some("p"));
        r.message("LADAR->Fusion", 2);
        let m = r.finish();
        assert!((m.summary.max_steer_rate - 0.2).abs() < 1e-12);
        assert!((m.summary.rms_steer_rate - (0.04f64 / 2.0).sqrt()).abs() < 1e-12);
        assert_eq!(m.summary.closest_obstacle.as_deref(), Some("p"));
        assert_eq!(m.architecture.time_in_state.get("A"), Some(&1.0));
        assert_eq!(m.architecture.transitions.len(), 2);
        assert!((m.summary.distance - 1.0).abs() < 1e-12);
        let again: Metrics = serde_json::from_str(&m.to_json()).expect("round trip");
        assert_eq!(again, m);
    }
}
