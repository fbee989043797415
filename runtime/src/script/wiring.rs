//! The wiring of a state as a run saw it (`wiring-STATE.svg` of `situ run
//! --out`): every agent with the mode and function it had when the state
//! first came to rest (FSMs included: what their history made of them),
//! the links of that moment, a title and a legend. Written as DOT by the
//! compiler's wiring writer and laid out by the command line with the
//! layout of `situ graph` (Graphviz when installed, else the built-in one),
//! so that the run's pictures and `situ graph`'s are one renderer.
//! Deterministic.

use crate::organise::Organisation;
use situ_compiler::bundle::{Content, Mode};
use situ_compiler::graph::Moment;

/// The organisation at one moment.
#[derive(Debug, Clone, PartialEq)]
pub struct Snapshot {
    /// When (ns).
    pub time: u64,
    pub state: u32,
    /// Per agent: its mode and function.
    pub agents: Vec<(Mode, Option<String>)>,
    /// The links of the moment, `(from, to)`.
    pub links: Vec<(u32, u32)>,
}

impl Snapshot {
    pub fn take(org: &Organisation, time: u64) -> Snapshot {
        let n = org.content().agents.len() as u32;
        Snapshot {
            time,
            state: org.state(),
            agents: (0..n).map(|a| (org.mode(a), org.function(a).map(str::to_string))).collect(),
            links: org.links(),
        }
    }
}

/// The DOT of a snapshot, written by the compiler's wiring writer (the
/// styles, title and legend of `situ graph --view wiring`); the command
/// line lays it out as it lays out `situ graph`'s pictures.
pub fn dot(content: &Content, snap: &Snapshot) -> String {
    let caption = format!("as the run first saw it, at {:.3} s", snap.time as f64 * 1e-9);
    situ_compiler::graph::wiring_moment(
        content,
        &Moment { state: snap.state, agents: &snap.agents, links: &snap.links, caption },
    )
}
