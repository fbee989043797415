//! `situ-sim`: the reference agent stack of situ, simulated.
//!
//! Plain, deterministic parts (only [`agent`] and [`stack`] use the
//! runtime), each with an API a wrapper calls once per tick:
//! - [`world`]: roads (a petgraph graph with geometry), cross-country areas,
//!   static and moving obstacles, and the queries sensors need;
//! - [`scenario`]: TOML scenarios, validated into a [`world::World`]
//!   (built in: `outdoor-default`, `dafflon-4`, `dla-offices`, `dla-field`);
//! - [`geom`]: points, poses, polygons, road pieces; [`noise`]: seeded noise;
//! - [`vehicle`]: the tricycle model of eq. (1) of Dafflon et al.;
//! - [`sensors`]: RFCCD, STCCD, LADAR and Localization of Zhang & Zhu, each
//!   returning the event of `rules/outdoor.situ` it reports;
//! - [`fusion`], [`gpl`], [`lpl`], [`drive`]: the processing agents
//!   (Fusion, GPL with A*, LPL with the plans of Table 1, Drive);
//! - [`control`]: target reaching, elliptic limit cycles and the single
//!   Lyapunov control law (eqs. 2–15); [`ugv`]: Dafflon's parts (the
//!   LIDAR's ellipses, the action selection, the multi-agent merge of
//!   eqs. 16–19);
//! - [`baseline`]: closed loops of the outdoor stack and the UGV without
//!   the engine, their situation logic hand-copied from `rules/*.situ`
//!   (which stay the truth), and why they exist;
//! - [`agent`]: what every simulated agent shares, whichever its stack: the
//!   events it reports ([`agent::Event`], [`agent::Value`]) and the data it
//!   reads;
//! - [`stack`]: the same parts as runtime agents of `rules/outdoor.situ`,
//!   `rules/ugv.situ` and `rules/ugv-merge.situ`, each a [`stack::Stack`],
//!   run on the **real** rules by the runtime's simulated-time scheduler
//!   (what `situ run` drives). DLA's stack and its building blocks are the
//!   `situ-dla` crate, built on this one;
//! - [`metrics`] and [`plot`]: what a run measured (`metrics.json`,
//!   deterministic to the byte), and its pictures (`trajectory.svg`,
//!   `timeline.svg`).
//!
//! Per tick, a wrapper of the outdoor stack calls, for the agents running
//! in the current state: [`sensors::Rfccd::observe`], [`sensors::Ladar::observe`],
//! [`sensors::Stccd::observe`], [`sensors::Localization::observe`] (each
//! returns its event of `rules/outdoor.situ` and its data);
//! [`gpl::Gpl::plan`] / [`gpl::Gpl::report`]; [`fusion::fuse_road`] or
//! [`fusion::fuse_terrain`]; [`lpl::Lpl::plan`] with the state's
//! [`lpl::PlanKind`]; [`drive::Drive::track`]; and
//! [`vehicle::Vehicle::step`]. [`baseline::outdoor::OutdoorSim::step`] is that sequence
//! with a simple situation logic in place of the Bulletinboard.
#![deny(missing_docs)]

pub mod agent;
pub mod baseline;
pub mod control;
pub mod drive;
pub mod fusion;
pub mod geom;
pub mod gpl;
pub mod lpl;
pub mod metrics;
pub mod noise;
pub mod plot;
pub mod scenario;
pub mod sensors;
pub mod stack;
pub mod ugv;
pub mod vehicle;
pub mod world;
