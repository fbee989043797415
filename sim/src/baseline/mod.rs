//! The reference stacks' situation logic as plain code, without the
//! engine: hand-copied from `rules/outdoor.situ` ([`outdoor::SimpleSituation`],
//! with the rules' states and tables in [`outdoor::State`]) and
//! `rules/ugv.situ` ([`ugv::HardSwitch`]), and the closed loops that run
//! them ([`outdoor::OutdoorSim`], [`ugv::run`]).
//!
//! **`rules/*.situ` are the truth**: what `situ run` drives is the compiled
//! rules ([`crate::stack`]). These copies exist for what the engine must
//! not be part of:
//! - the "sim loop" rows of Dafflon et al.'s comparison (`situ run
//!   --compare`, [`ugv::compare`]): the paper's closed loop, against which
//!   the rules run through the stack are checked (`sim/tests/dafflon.rs`,
//!   `sim/tests/stack.rs`);
//! - the sim's own figures without the runtime (`sim/examples/perf.rs`,
//!   `docs/performance.md`) and the sim's tests of its parts in closed loop
//!   (`sim/tests/outdoor.rs`, `sim/tests/pictures.rs`).
//!
//! A change of the rules' thresholds, run lengths or tables is made in
//! `rules/*.situ` first, then here.

pub mod outdoor;
pub mod ugv;
