//! `situ-dla`: DLA, the distributed layered architecture of Pérez et al.
//! (2006), on the sim's kernel (`situ-sim`: world, vehicle, physics, the
//! stack runner). The kernel knows nothing of it.
//!
//! Its building blocks, plain deterministic modules:
//! - [`grid`]: the probabilistic occupancy grid, updated from range readings;
//! - [`pyramid`]: the hierarchical pyramid by split and merge over the grid,
//!   whose homogeneous regions are the topological map (Poncela et al. 2002);
//! - [`route`]: the route planner over the regions and the potential-field
//!   path planner between consecutive regions;
//! - [`cases`]: the reactive layer learnt by cases (Urdiales et al. 2006):
//!   a k-d tree case base, on-line learning, its file, a scripted driver;
//! - [`detour`]: the reactive layer's way out of a local minimum;
//! - [`draw`]: an SVG picture of a grid, its regions, a route, a path and a
//!   trajectory;
//! - [`experience`]: successive missions learning on line, their table and
//!   their curve.
//!
//! And on the runtime:
//! - [`stack`]: the agents of `rules/dla.situ`, and [`stack::Dla`], the
//!   [`situ_sim::stack::Stack`] that runs them; [`registry`] is the sim's
//!   stacks and this one, which `situ run` chooses among;
//! - [`missions`]: DLA's experience (`situ run --missions`): missions with
//!   one case base, evaluations on held-out missions, the whole series;
//! - [`missions::load_or_train`]: the case base a run starts from.
#![deny(missing_docs)]

pub mod cases;
pub mod detour;
pub mod draw;
pub mod experience;
pub mod grid;
pub mod missions;
mod nearest;
pub mod pyramid;
pub mod route;
pub mod stack;

use std::sync::Arc;

/// The sim's stacks ([`situ_sim::stack::Registry::sim`]) and DLA's (its
/// case base trained at the start of each run, learning on line).
pub fn registry() -> situ_sim::stack::Registry {
    situ_sim::stack::Registry::sim().with(Arc::new(stack::Dla::default()))
}
