//! The situ runtime: it loads bundles and runs them. It never needs the
//! grammar: a bundle is everything it knows of a program.
//!
//! - [`rete`]: the inference machine, a Rete interpreter over the bundle's
//!   network and a working memory of one state and one fact per agent;
//! - [`organise`]: what each agent does in the current state (tables, FSMs)
//!   and the wiring graph of the moment;
//! - [`bulletinboard`]: the Bulletinboard of Zhang & Zhu (2005) around it:
//!   posting events, the state history, subscriptions, explanations, hot swap;
//! - [`stream`]: seeded random event streams and their text form, for
//!   benchmarks and differential tests.
//!
//! `situ test` (scenario tests and properties) is the `situ-verify` crate.

pub mod agent;
pub mod bench;
pub mod bulletinboard;
pub mod bus;
pub mod demo;
pub mod organise;
pub mod realtime;
pub mod record;
pub mod repl;
pub mod replay;
pub mod rete;
pub mod sched;
pub mod script;
pub mod stack;
pub mod stream;
pub mod summary;
