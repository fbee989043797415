//! The reference stacks on the **real** rules: every agent of
//! `rules/outdoor.situ` (Zhang & Zhu) and of `rules/ugv.situ` and
//! `rules/ugv-merge.situ` (Dafflon et al.: hard switch, merge) as a runtime
//! [`Agent`] wrapping the sim's parts, run by
//! the runtime's simulated-time scheduler with the compiled rules deciding
//! the state. This is what `situ run` drives.
//!
//! - [`Stack`]: what a reference stack is to the loop (its agents, rates,
//!   goal state, defaults, pictures); [`outdoor::Outdoor`], [`ugv::Ugv`]
//!   and [`merge::UgvMerge`] here, DLA's in `situ-dla`. A [`Registry`]
//!   tells a program's stack by its agents.
//! - [`Physics`]: the ground truth the agents share (world, vehicle, time,
//!   the last command). Sensors read it; the actuator (Drive, Vehicle)
//!   writes its command into it; nothing else touches it. Every other input
//!   of an agent comes through the data stream, along the links of the
//!   moment (Fig. 5: LPL plans from RFCCD in RS, from Fusion in RO).
//! - [`StackRun`]: the loop. The physics integrates at a fixed step `h`
//!   (10 ms); between two steps the runtime runs every agent step and
//!   heartbeat that falls in `[T, T + h)`, all of them seeing the world at
//!   `T` (a zero-order hold, causal). The run ends at a collision, at a
//!   final state once the vehicle stands still, or at `until`.
//! - [`RunReport`]: what `metrics.json` holds: the outcome, the paper's
//!   metrics (time to goal, closest distance, collisions, steering rate,
//!   speed per state), the architecture's figures and the runtime's summary.
//!   Nothing in it reads a clock: the same scenario and seed give the same
//!   bytes.

pub mod merge;
pub mod outdoor;
mod registry;
mod scene;
pub mod ugv;

pub use merge::{compare, CompareError, UgvPrograms};
pub use registry::{NoStack, Registry};
pub use scene::{pose_in_frame_schema, scene_update_schema, topics};

use crate::metrics::{Metrics, Recorder, Sample};
use crate::scenario::Scenario;
use crate::vehicle::{Command, Vehicle};
use crate::world::{ObstacleView, World};
use scene::Scene;
use serde::Serialize;
use situ_compiler::bundle::{Content, Mode};
use situ_runtime::agent::{self, Agent};
use situ_runtime::record::mcap::McapRecorder;
use situ_runtime::record::{DataRecord, EventRecord, Fate, Level, ModeRecord, Sink, Tee};
use situ_runtime::rete::StateChange;
use situ_runtime::sched::{SimConfig, SimRuntime};
use situ_runtime::summary::Summary;
use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Write as _;
use std::sync::{Arc, Mutex, MutexGuard};

/// Nanoseconds per second.
pub const NS: u64 = 1_000_000_000;

/// The ground truth every agent of a simulated stack shares.
#[derive(Debug)]
pub struct Physics {
    /// The world (roads, areas, obstacles).
    pub world: World,
    /// The vehicle (its true state).
    pub vehicle: Vehicle,
    /// Simulated time (s).
    pub t: f64,
    /// The command the actuator gave last, held until the next one.
    pub command: Command,
    /// The obstacles where they are at `t`.
    pub views: Vec<ObstacleView>,
}

/// [`Physics`] behind a lock, for the agents.
pub type SharedPhysics = Arc<Mutex<Physics>>;

/// Locks the physics (a poisoned lock is still the truth).
pub fn lock(p: &SharedPhysics) -> MutexGuard<'_, Physics> {
    p.lock().unwrap_or_else(|e| e.into_inner())
}

/// A reference stack: the agents of one rules file on the sim's parts, and
/// what a run of it needs besides (its goal, its rates, how long, how
/// often to sample, its pictures). [`StackRun`] runs any of them; a
/// [`Registry`] tells which one a program is, by its agents.
///
/// The sim's own are [`outdoor::Outdoor`], [`ugv::Ugv`] and
/// [`merge::UgvMerge`]; DLA's is in the `situ-dla` crate.
pub trait Stack: Send + Sync {
    /// Its name in `metrics.json` (`outdoor`, `ugv`, `ugv_merge`, `dla`).
    fn name(&self) -> &'static str;

    /// Its name in messages (`Outdoor`, `Ugv`, `UgvMerge`, `Dla`).
    fn title(&self) -> &'static str;

    /// The agents a program must declare to run on this stack.
    fn agents(&self) -> &'static [&'static str];

    /// How an error listing the stacks names this one's agents
    /// (`of rules/outdoor.situ (RFCCD, …)`).
    fn known_as(&self) -> String;

    /// The built-in scenario run by default.
    fn default_scenario(&self) -> &'static str;

    /// The state that means "mission done".
    fn goal_state(&self) -> &'static str;

    /// Rates the stack sets over the rules file (none by default).
    fn rates(&self) -> BTreeMap<String, f64> {
        BTreeMap::new()
    }

    /// Physics steps (of 10 ms) per metrics sample.
    fn sample_every(&self) -> u64;

    /// The longest run by default (s of simulated time).
    fn default_until(&self) -> f64;

    /// The agents of a run of `content` on `world`, sharing `physics`,
    /// their noise seeded with `seed`.
    fn agents_for(
        &self,
        content: &Arc<Content>,
        physics: &SharedPhysics,
        world: &World,
        seed: u64,
    ) -> Vec<Box<dyn Agent>>;

    /// The stack's own pictures of a finished run (file name, SVG), beside
    /// the trajectory and the time line every run draws; none by default.
    fn pictures(&self, scenario: &Scenario, report: &RunReport) -> Vec<(&'static str, String)> {
        let _ = (scenario, report);
        Vec::new()
    }
}

/// Why a run could not be set up or finished.
#[derive(Debug, thiserror::Error)]
pub enum StackError {
    /// The program's agents do not bind to the stack's.
    #[error("{0}")]
    Bind(#[from] agent::BindError),
    /// The recording could not be written.
    #[error("recording: {0}")]
    Recording(#[from] std::io::Error),
}

/// How a run is set up.
#[derive(Debug, Clone, PartialEq)]
pub struct StackConfig {
    /// The noise seed.
    pub seed: u64,
    /// The run stops after this long (s of simulated time).
    pub until: f64,
    /// The physics step (ns).
    pub physics_step: u64,
    /// A metrics sample every this many physics steps (0: the stack's own,
    /// [`Stack::sample_every`]).
    pub sample_every: u64,
    /// Keep every sample in the metrics (off: the summary only).
    pub samples: bool,
    /// Rates (Hz) over the rules file and the stack's own ([`Stack::rates`]).
    pub rates: BTreeMap<String, f64>,
}

impl Default for StackConfig {
    fn default() -> Self {
        StackConfig {
            seed: 1,
            until: 600.0,
            physics_step: 10_000_000,
            sample_every: 0,
            samples: true,
            rates: BTreeMap::new(),
        }
    }
}

/// How a run ended.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Outcome {
    /// The goal state, no collision.
    GoalReached {
        /// When the goal state was entered (s).
        time: f64,
    },
    /// The vehicle touched an obstacle (the run stops there, as in the paper).
    Collision {
        /// When (s).
        time: f64,
        /// Which obstacle.
        obstacle: String,
        /// The state then.
        state: String,
    },
    /// A final state other than the goal (a stop), the vehicle at standstill.
    Stopped {
        /// When the vehicle came to rest (s).
        time: f64,
        /// The final state.
        state: String,
    },
    /// The time ran out before a final state.
    Timeout {
        /// The limit (s).
        time: f64,
        /// The state then.
        state: String,
    },
}

impl Outcome {
    /// Whether the mission is done: the goal, no collision.
    pub fn success(&self) -> bool {
        matches!(self, Outcome::GoalReached { .. })
    }

    /// When it ended (s): at the goal, the collision, the rest, or the limit.
    pub fn time(&self) -> f64 {
        match self {
            Outcome::GoalReached { time }
            | Outcome::Collision { time, .. }
            | Outcome::Stopped { time, .. }
            | Outcome::Timeout { time, .. } => *time,
        }
    }

    /// A few words for a table (`goal at 84.0 s`).
    pub fn brief(&self) -> String {
        match self {
            Outcome::GoalReached { time } => format!("goal at {time:.1} s"),
            Outcome::Collision { time, obstacle, .. } => format!("collision with {obstacle} at {time:.1} s"),
            Outcome::Stopped { time, state } => format!("stopped in {state} at {time:.1} s"),
            Outcome::Timeout { time, state } => format!("still in {state} after {time:.0} s"),
        }
    }

    /// One line for a person.
    pub fn describe(&self) -> String {
        match self {
            Outcome::GoalReached { time } => format!("mission done: goal reached at {time:.1} s, no collision"),
            Outcome::Collision { time, obstacle, state } => {
                format!("mission failed: collision with `{obstacle}` at {time:.1} s (state {state})")
            }
            Outcome::Stopped { time, state } => format!("mission failed: stopped in {state} at {time:.1} s"),
            Outcome::Timeout { time, state } => {
                format!("mission failed: no final state after {time:.1} s (still in {state})")
            }
        }
    }
}

/// The figures of one state.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StateFigures {
    /// Time spent in it (s, from the samples).
    pub seconds: f64,
    /// Mean actual speed (m/s).
    pub mean_speed: f64,
    /// Top actual speed (m/s).
    pub max_speed: f64,
    /// Top commanded speed (m/s).
    pub max_speed_cmd: f64,
}

/// Everything a run measured: `metrics.json`.
#[derive(Debug, Clone, Serialize)]
pub struct RunReport {
    /// The rules (the bundle's source name).
    pub rules: String,
    /// Which stack ([`Stack::name`]).
    pub stack: &'static str,
    /// The scenario's name.
    pub scenario: String,
    /// The noise seed.
    pub seed: u64,
    /// How it ended.
    pub outcome: Outcome,
    /// Speed and time per state (the paper: faster in simple states).
    pub per_state: BTreeMap<String, StateFigures>,
    /// The runtime's summary: time and steps per state, rules fired,
    /// messages per stream and what was dropped.
    pub runtime: Summary,
    /// The sim's metrics: summary, architecture (time in each state,
    /// agents running per state, data messages per link), every sample.
    pub metrics: Metrics,
}

impl RunReport {
    /// `trajectory.svg` and `timeline.svg`: the run's path on the world and
    /// its time line (file name, SVG).
    pub fn pictures(&self, scenario: &Scenario) -> Result<Vec<(&'static str, String)>, crate::plot::PlotError> {
        let title = format!("{} — {}", scenario.name, self.rules);
        let samples = &self.metrics.samples;
        Ok(vec![
            ("trajectory.svg", crate::plot::trajectory_svg(&scenario.world, samples, &title)?),
            ("timeline.svg", crate::plot::timeline_svg(samples, &title)?),
        ])
    }

    /// `metrics.json` (pretty, deterministic).
    pub fn to_json(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}"))
    }

    /// The paper's metrics as a table for a person.
    pub fn table(&self) -> String {
        let s = &self.metrics.summary;
        let mut out = String::new();
        let opt = |o: Option<f64>, unit: &str| o.map_or("-".to_string(), |v| format!("{v:.2} {unit}"));
        let _ = writeln!(out, "  scenario          {} (seed {})", self.scenario, self.seed);
        let _ = writeln!(out, "  time to goal      {}", opt(s.time_to_goal, "s"));
        let _ = writeln!(out, "  distance driven   {:.1} m", s.distance);
        let closest = match (&s.closest_distance, &s.closest_obstacle) {
            (Some(d), Some(o)) => format!("{d:.2} m ({o})"),
            (Some(d), None) => format!("{d:.2} m"),
            _ => "-".into(),
        };
        let _ = writeln!(out, "  closest distance  {closest}");
        let _ = writeln!(out, "  min time to coll. {}", opt(s.min_ttc, "s"));
        let collisions: Vec<String> = s.collisions.iter().map(|c| format!("{} at {:.1} s", c.obstacle, c.t)).collect();
        let _ = writeln!(
            out,
            "  collisions        {}",
            if collisions.is_empty() { "none".into() } else { collisions.join(", ") }
        );
        let _ =
            writeln!(out, "  steering rate     max {:.3} rad/s, RMS {:.3} rad/s", s.max_steer_rate, s.rms_steer_rate);
        let _ = writeln!(out, "  speed             top {:.2} m/s, mean {:.2} m/s", s.max_speed, s.mean_speed);
        let w = self.runtime.states.iter().map(|st| st.state.chars().count()).max().unwrap_or(0).max(6);
        let _ = writeln!(out, "\n  {:<w$} {:>9}  mean v (m/s)  top v (m/s)  running", "state", "time (s)");
        for st in &self.runtime.states {
            let Some(f) = self.per_state.get(&st.state) else { continue };
            let running = self.metrics.architecture.agents_running.get(&st.state).map_or(0, Vec::len);
            let _ = writeln!(
                out,
                "  {:<w$} {:>9.1}  {:>12.2}  {:>11.2}  {:>7}",
                st.state, f.seconds, f.mean_speed, f.max_speed, running
            );
        }
        let _ = writeln!(out, "\n  {}", self.outcome.describe());
        out
    }
}

/// A live view of a run, for a progress line.
#[derive(Debug, Clone, PartialEq)]
pub struct Progress {
    /// Simulated time (s).
    pub t: f64,
    /// The state at rest.
    pub state: String,
    /// The vehicle's speed (m/s).
    pub speed: f64,
    /// Agents running now, and all agents.
    pub running: (usize, usize),
}

impl Progress {
    /// The line.
    pub fn line(&self) -> String {
        format!(
            "t {:>7.1} s  state {:<8}  {:>5.2} m/s  agents running {}/{}",
            self.t, self.state, self.speed, self.running.0, self.running.1
        )
    }
}

/// Counts the data messages per link and what was dropped, for the report.
#[derive(Debug, Default)]
struct StreamCounts {
    delivered: BTreeMap<(u32, u32), u64>,
    dropped: BTreeMap<(u32, &'static str), u64>,
}

impl Sink for StreamCounts {
    fn event(&mut self, _rec: &EventRecord) {}
    fn change(&mut self, _change: &StateChange) {}
    fn data(&mut self, rec: &DataRecord) {
        match rec.fate {
            Fate::Delivered => *self.delivered.entry((rec.from, rec.to)).or_default() += 1,
            Fate::Suppressed => *self.dropped.entry((rec.from, "suppressed (waiting sender)")).or_default() += 1,
            Fate::ToSleeping => *self.dropped.entry((rec.from, "to a sleeping agent")).or_default() += 1,
            Fate::Unrouted => *self.dropped.entry((rec.from, "no active link")).or_default() += 1,
        }
    }
    fn mode(&mut self, _rec: &ModeRecord) {}
    fn diagnostic(&mut self, _time: u64, _level: Level, _text: &str) {}
    fn tick(&mut self, _time: u64) {}
    fn flush(&mut self) -> std::io::Result<()> {
        Ok(())
    }
    fn finish(&mut self) -> std::io::Result<()> {
        Ok(())
    }
}

/// Where a run's records go besides the report.
#[derive(Default)]
pub struct Recording {
    /// An MCAP recording; the pose and obstacle channels are added to it.
    pub mcap: Option<Arc<Mutex<McapRecorder>>>,
    /// More sinks (a [`situ_runtime::record::SharedMemory`] for tests, say).
    pub sinks: Vec<Box<dyn Sink>>,
}

/// One run of a stack: the runtime, the physics, the metrics.
pub struct StackRun {
    /// The stack.
    pub stack: Arc<dyn Stack>,
    /// The runtime running the rules and the agents.
    pub rt: SimRuntime,
    /// The ground truth.
    pub physics: SharedPhysics,
    content: Arc<Content>,
    cfg: StackConfig,
    scenario: String,
    recorder: Recorder,
    counts: Arc<Mutex<StreamCounts>>,
    scene: Option<Scene>,
    moving: bool,
    /// Physics steps done.
    k: u64,
    outcome: Option<Outcome>,
    goal_state: Option<u32>,
    last_state: Option<u32>,
    running: BTreeMap<String, BTreeSet<String>>,
    per_state: BTreeMap<String, (f64, f64, f64, f64, u64)>,
    final_since: Option<u64>,
}

impl StackRun {
    /// Sets up a run of `content` (on `stack`) on `world`, its records
    /// going to `recording` too.
    pub fn new(
        content: Arc<Content>,
        stack: Arc<dyn Stack>,
        world: &World,
        cfg: StackConfig,
        recording: Recording,
    ) -> Result<StackRun, StackError> {
        let mut views = Vec::new();
        world.obstacles_at(0.0, &mut views);
        let physics = Arc::new(Mutex::new(Physics {
            world: world.clone(),
            vehicle: Vehicle::new(world.vehicle, world.start),
            t: 0.0,
            command: Command::default(),
            views,
        }));
        let agents = stack.agents_for(&content, &physics, world, cfg.seed);
        let bound = agent::bind(&content, agents, true)?;
        let counts = Arc::new(Mutex::new(StreamCounts::default()));
        let mut sinks: Vec<Box<dyn Sink>> = vec![Box::new(counts.clone())];
        sinks.extend(recording.sinks);
        let scene = match recording.mcap {
            Some(m) => {
                sinks.push(Box::new(m.clone()));
                Some(Scene::new(m)?)
            }
            None => None,
        };
        let mut cfg = cfg;
        if cfg.sample_every == 0 {
            cfg.sample_every = stack.sample_every();
        }
        let mut rates = stack.rates();
        rates.extend(cfg.rates.clone());
        let config = SimConfig { rates, stop_on_final: false, ..SimConfig::default() };
        let rt = SimRuntime::new(content.clone(), bound, Some(Box::new(Tee(sinks))), config);
        let dt = cfg.physics_step as f64 * cfg.sample_every as f64 / NS as f64;
        let controller = format!("situ run {} (the rules decide the state)", content.source);
        let moving = world.obstacles.iter().any(|o| o.motion != crate::world::Motion::Static);
        Ok(StackRun {
            rt,
            physics,
            goal_state: content.state_id(stack.goal_state()),
            stack,
            content,
            scenario: world.name.clone(),
            recorder: Recorder::new(&world.name, &controller, cfg.seed, dt),
            cfg,
            counts,
            scene,
            moving,
            k: 0,
            outcome: None,
            last_state: None,
            running: BTreeMap::new(),
            per_state: BTreeMap::new(),
            final_since: None,
        })
    }

    /// Simulated time (s).
    pub fn t(&self) -> f64 {
        (self.k * self.cfg.physics_step) as f64 / NS as f64
    }

    /// The state at rest, by name.
    pub fn state(&self) -> &str {
        &self.content.states[self.rt.state() as usize].name
    }

    /// How the run ended, once it has.
    pub fn outcome(&self) -> Option<&Outcome> {
        self.outcome.as_ref()
    }

    /// The live view.
    pub fn progress(&self) -> Progress {
        let org = self.rt.shared.org();
        let n = self.content.agents.len();
        let running = (0..n as u32).filter(|&a| org.mode(a) == Mode::Running).count();
        Progress {
            t: self.t(),
            state: self.state().to_string(),
            speed: lock(&self.physics).vehicle.state.v,
            running: (running, n),
        }
    }

    fn note_running(&mut self, state: u32) {
        let org = self.rt.shared.org();
        let set = self.running.entry(self.content.states[state as usize].name.clone()).or_default();
        for (a, def) in self.content.agents.iter().enumerate() {
            if org.mode(a as u32) == Mode::Running {
                set.insert(def.name.clone());
            }
        }
    }

    /// One physics step: the agents' steps of `[T, T + h)`, then the world
    /// moves to `T + h`. Returns whether the run goes on.
    pub fn step(&mut self) -> bool {
        if self.outcome.is_some() {
            return false;
        }
        let h = self.cfg.physics_step;
        let t0 = self.k * h;
        let ts = t0 as f64 / NS as f64;
        self.rt.run_until(t0 + h - 1, &mut |_| {});
        let state = self.rt.state();
        if self.last_state != Some(state) {
            self.last_state = Some(state);
            self.note_running(state);
            if Some(state) == self.goal_state {
                self.recorder.goal(ts);
            }
        }
        let content = self.content.clone();
        let def = &content.states[state as usize];
        let physics = self.physics.clone();
        let mut guard = lock(&physics);
        let ph = &mut *guard;
        if self.k.is_multiple_of(self.cfg.sample_every) {
            self.sample(ts, &def.name, ph);
        }
        if let Some(scene) = &self.scene {
            if self.k.is_multiple_of((50_000_000 / h).max(1)) {
                scene.pose(t0, ph);
            }
            if self.k.is_multiple_of((NS / h).max(1)) {
                scene.obstacles(t0, ph);
            }
        }
        let name = def.name.clone();
        if let Some(i) = ph.world.collision(&ph.vehicle.state.pose, &ph.views) {
            let obstacle = ph.world.obstacles[i].id.clone();
            self.recorder.collision(ts, &obstacle);
            self.outcome = Some(Outcome::Collision { time: ts, obstacle, state: name });
            return false;
        }
        if def.is_final {
            let since = *self.final_since.get_or_insert(t0);
            // Wait for the vehicle to stand still (10 s at most).
            if ph.vehicle.state.v <= 1e-3 || t0 - since >= 10 * NS {
                self.outcome = Some(if Some(state) == self.goal_state {
                    Outcome::GoalReached { time: since as f64 / NS as f64 }
                } else {
                    Outcome::Stopped { time: ts, state: name }
                });
                return false;
            }
        }
        if ts >= self.cfg.until {
            self.outcome = Some(Outcome::Timeout { time: ts, state: name });
            return false;
        }
        let dt = h as f64 / NS as f64;
        let cmd = ph.command;
        ph.vehicle.step(cmd, dt);
        self.k += 1;
        ph.t = (self.k * h) as f64 / NS as f64;
        if self.moving {
            ph.world.obstacles_at(ph.t, &mut ph.views);
        }
        true
    }

    fn sample(&mut self, t: f64, label: &str, ph: &Physics) {
        let st = ph.vehicle.state;
        let closest = ph.world.closest_obstacle(&st.pose, &ph.views);
        let ttc = ph.world.time_to_collision(&st.pose, st.v, &ph.views, 60.0);
        let s = Sample {
            t,
            x: st.pose.x,
            y: st.pose.y,
            theta: st.pose.theta,
            v: st.v,
            steer: st.steer,
            v_cmd: ph.command.v,
            steer_cmd: ph.command.steer,
            closest: closest.map(|c| c.0),
            ttc,
            label: label.to_string(),
        };
        let dt = self.recorder_dt();
        let e = self.per_state.entry(label.to_string()).or_default();
        e.0 += dt;
        e.1 += st.v;
        e.2 = e.2.max(st.v);
        e.3 = e.3.max(ph.command.v);
        e.4 += 1;
        let name = closest.map(|(_, i)| ph.world.obstacles[i].id.as_str());
        if self.cfg.samples {
            self.recorder.record(s, name);
        } else {
            // The summary without keeping the samples: record, then forget.
            self.recorder.record(s.clone(), name);
            self.recorder.forget_samples();
        }
    }

    fn recorder_dt(&self) -> f64 {
        self.cfg.physics_step as f64 * self.cfg.sample_every as f64 / NS as f64
    }

    /// Runs to the end; `progress` is called every simulated second.
    pub fn run(&mut self, progress: &mut dyn FnMut(&StackRun)) {
        let per_second = (NS / self.cfg.physics_step).max(1);
        while self.step() {
            if self.k.is_multiple_of(per_second) {
                progress(self);
            }
        }
    }

    /// Runs to the end in real time, a simulated second a wall second (for
    /// people watching it live); `progress` is called every simulated
    /// second. The run itself is the same as [`StackRun::run`]'s.
    pub fn run_in_real_time(&mut self, progress: &mut dyn FnMut(&StackRun)) {
        let start = std::time::Instant::now();
        let per_second = (NS / self.cfg.physics_step).max(1);
        while self.step() {
            let t = lock(&self.physics).t;
            let ahead = std::time::Duration::from_secs_f64(t.max(0.0)).saturating_sub(start.elapsed());
            if !ahead.is_zero() {
                std::thread::sleep(ahead);
            }
            if self.k.is_multiple_of(per_second) {
                progress(self);
            }
        }
    }

    /// Ends the run (and the recording) and gathers the report.
    pub fn finish(mut self) -> Result<RunReport, StackError> {
        while self.outcome.is_none() {
            self.step();
        }
        let recording = self.rt.finish_recording();
        let runtime = self.rt.summary();
        let c = self.content.clone();
        let name = |a: u32| c.agents.get(a as usize).map_or("?", |x| x.name.as_str()).to_string();
        for (state, agents) in std::mem::take(&mut self.running) {
            self.recorder.agents_running(&state, agents.into_iter().collect());
        }
        {
            let counts = self.counts.lock().unwrap_or_else(|e| e.into_inner());
            for (&(from, to), &n) in &counts.delivered {
                self.recorder.message(&format!("{}->{}", name(from), name(to)), n);
            }
            for (&(from, why), &n) in &counts.dropped {
                self.recorder.message(&format!("{} dropped: {why}", name(from)), n);
            }
        }
        self.recorder.message("events accepted", runtime.board.accepted);
        self.recorder.message("status broadcasts", runtime.board.status_sent);
        let per_state = self
            .per_state
            .iter()
            .map(|(k, &(secs, vsum, vmax, vcmd, n))| {
                (
                    k.clone(),
                    StateFigures {
                        seconds: secs,
                        mean_speed: vsum / n.max(1) as f64,
                        max_speed: vmax,
                        max_speed_cmd: vcmd,
                    },
                )
            })
            .collect();
        let outcome = self.outcome.clone().unwrap_or(Outcome::Timeout { time: self.t(), state: self.state().into() });
        let report = RunReport {
            rules: c.source.clone(),
            stack: self.stack.name(),
            scenario: self.scenario.clone(),
            seed: self.cfg.seed,
            outcome,
            per_state,
            runtime,
            metrics: self.recorder.finish(),
        };
        recording?;
        Ok(report)
    }
}
