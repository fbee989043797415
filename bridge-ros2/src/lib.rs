//! The ROS 2 bridge of situ (`situ ros2 FILE --map MAP`, docs/ros2.md): a
//! process that is the Bulletinboard of a ROS 2 robot. It reads the map's
//! topics and turns their messages into events, publishes the situation
//! (`/situ/state`, `/situ/agents`, `/diagnostics`), and drives the map's
//! lifecycle nodes from the tables with `change_state` requests.
//!
//! - [`core`]: every decision, without DDS: what arrives in, what to send out;
//! - [`dds`]: the DDS shell (ros2-client on RustDDS): readers of the raw
//!   CDR samples, the publishers, the lifecycle service clients, the loop;
//! - [`bag`]: the recording, a ROS 2 bag (MCAP storage) of what came and went;
//! - [`msgs`]: the ROS 2 messages and services it writes, as serde types;
//! - [`raw`]: a sample's bytes as they came, the reader type of every topic;
//! - [`service`]: its service client (lifecycle requests) on RustDDS;
//! - [`xcdr2`]: XCDR2 samples read into the XCDR1 the map's decoder reads.

pub mod bag;
pub mod core;
pub mod dds;
pub mod msgs;
pub mod raw;
pub mod service;
pub mod xcdr2;
