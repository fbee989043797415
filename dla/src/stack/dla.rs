//! [`Dla`]: DLA's agents as a [`Stack`] that [`situ_sim::stack::StackRun`]
//! runs, with what a run of it shares beyond the physics, and its pictures.

use super::{agents, lock_plans, train, Plans, SharedCases, SharedPlans, AGENTS, NOVELTY, TRAINING_SECONDS};
use situ_compiler::bundle::Content;
use situ_runtime::agent::Agent;
use situ_sim::scenario::Scenario;
use situ_sim::stack::{RunReport, SharedPhysics, Stack};
use situ_sim::world::World;
use std::sync::{Arc, Mutex};

/// Pérez's DLA (`rules/dla.situ`): deliberative and case-based reactive
/// layers. It holds what a run of it shares beyond the physics: the case
/// base (`None`: one trained before each run by the scripted driver,
/// [`train`]), whether the reactive layer learns on line, and the plans
/// the run leaves ([`Dla::plans`], drawn by [`Stack::pictures`]).
pub struct Dla {
    cases: Option<SharedCases>,
    learn: bool,
    plans: SharedPlans,
}

impl Default for Dla {
    fn default() -> Self {
        Dla::new(None, true)
    }
}

impl Dla {
    /// The stack with the case base `cases` (`None`: trained at the start
    /// of each run), learning into it when `learn`.
    pub fn new(cases: Option<SharedCases>, learn: bool) -> Dla {
        Dla { cases, learn, plans: SharedPlans::default() }
    }

    /// The map, route and path of the last run, and its counts.
    pub fn plans(&self) -> &SharedPlans {
        &self.plans
    }
}

/// The name of DLA's stack ([`Stack::name`]).
pub const NAME: &str = "dla";

impl Stack for Dla {
    fn name(&self) -> &'static str {
        NAME
    }
    fn title(&self) -> &'static str {
        "Dla"
    }
    fn agents(&self) -> &'static [&'static str] {
        AGENTS
    }
    fn known_as(&self) -> String {
        format!("of rules/dla.situ ({})", AGENTS.join(", "))
    }
    fn default_scenario(&self) -> &'static str {
        "dla-offices"
    }
    fn goal_state(&self) -> &'static str {
        "Arrived"
    }
    /// The reactive layer's 10 Hz.
    fn sample_every(&self) -> u64 {
        10
    }
    fn default_until(&self) -> f64 {
        300.0
    }
    /// A run starts with no plans.
    fn agents_for(
        &self,
        content: &Arc<Content>,
        physics: &SharedPhysics,
        world: &World,
        seed: u64,
    ) -> Vec<Box<dyn Agent>> {
        let cases = match &self.cases {
            Some(c) => c.clone(),
            None => Arc::new(Mutex::new(train(seed, TRAINING_SECONDS, NOVELTY))),
        };
        *lock_plans(&self.plans) = Plans::default();
        agents(content, physics, world, seed, cases, self.learn, self.plans.clone())
    }
    fn pictures(&self, scenario: &Scenario, report: &RunReport) -> Vec<(&'static str, String)> {
        pictures(&self.plans, scenario, report)
    }
}

/// DLA's pictures: `dla.svg`, the last occupancy grid and the regions of
/// its pyramid, with the last path and the trajectory; `dla-route.svg`, the
/// map the last route was planned on, its regions numbered along the route.
pub fn pictures(plans: &SharedPlans, scenario: &Scenario, report: &RunReport) -> Vec<(&'static str, String)> {
    let p = lock_plans(plans);
    let world = &scenario.world;
    let trajectory: Vec<(f64, f64)> = report.metrics.samples.iter().map(|s| (s.x, s.y)).collect();
    let start = (world.start.x, world.start.y);
    let goal = (world.goal.position.x, world.goal.position.y);
    let mut out = Vec::new();
    if let Some(map) = &p.map {
        let title = format!("{} — {}: the last map, its regions, the last path", scenario.name, report.rules);
        let svg = crate::draw::draw(&map.grid, Some(map.pyramid()), &[], &p.path, &trajectory, start, goal, &title);
        out.push(("dla.svg", svg));
    }
    if let Some(route) = &p.route {
        let title =
            format!("{} — {}: route {} on the map it was planned on", scenario.name, report.rules, route.number);
        let svg = crate::draw::draw(
            &route.map.grid,
            Some(route.map.pyramid()),
            &route.regions,
            &p.path,
            &trajectory,
            start,
            goal,
            &title,
        );
        out.push(("dla-route.svg", svg));
    }
    out
}
