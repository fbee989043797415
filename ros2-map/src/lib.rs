//! The ROS 2 map of situ (issue 17): the file that says which ROS 2 topic
//! and message each event comes from, its static check against the rules
//! (`situ check FILE --ros2-map MAP`), and the decoding of messages from
//! their CDR bytes into the map's events. No DDS here; the bridge process
//! will reuse this crate.
//!
//! - [`map`]: the map file (TOML), parsed with the place of every value.
//! - [`msgs`]: the message definitions, as data: the `.msg`/`.srv`/`.action`
//!   parser, the search path, the [`msgs::Registry`] everything shares.
//! - [`load`]: the search path and registry of a map, and its whole check.
//! - [`expr`]: the expressions of `when` and of payload fields.
//! - [`types`]: the types of expressions against a message.
//! - [`expr_check`]: the checks of expressions beyond fields and types (E0419, E0420).
//! - [`check`]: the checks, one function each; [`check_map`] runs them all.
//! - [`check_names`]: the checks of topic and node names, repeated entries and the bridge's own topics.
//! - [`cdr`]: decoding of messages from their CDR bytes.
//! - [`eval`]: expressions on a decoded message; the [`Translator`] of messages to events.
//! - [`lifecycle`]: the next `change_state` request the tables ask of the lifecycle nodes.
//! - [`skeleton`]: the part of a model a map needs, from a bundle.

pub mod cdr;
pub mod check;
pub mod check_names;
pub mod eval;
pub mod expr;
pub mod expr_check;
pub mod lifecycle;
pub mod load;
pub mod map;
pub mod msgs;
pub mod skeleton;
pub mod types;

pub use check::{check_map, check_parsed};
pub use eval::Translator;
pub use msgs::Registry;
