//! The building blocks of DLA, the distributed layered architecture of
//! Pérez et al. (2006), as plain deterministic modules:
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

pub mod cases;
pub mod detour;
pub mod draw;
pub mod experience;
pub mod grid;
mod nearest;
pub mod pyramid;
pub mod route;
