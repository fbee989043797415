//! The wiring of a state as a run saw it (`wiring-STATE.svg` of `situ run
//! --out`): every agent with the mode and function it had when the state
//! first came to rest (FSMs included: what their history made of them),
//! the links of that moment, a title and a legend. Drawn from
//! [`Snapshot::moment`] as DOT by the compiler's wiring writer
//! (`situ_compiler::graph::wiring_moment`) and laid out by the command line with the
//! layout of `situ graph` (Graphviz when installed, else the built-in one),
//! so that the run's pictures and `situ graph`'s are one renderer.
//! Deterministic.

use crate::organise::Organisation;
use situ_bundle::{Mode, Moment};

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

    /// The snapshot as the compiler's wiring writer draws it
    /// (`situ_compiler::graph::wiring_moment`: the styles, title and legend
    /// of `situ graph --view wiring`), captioned with when the run saw it.
    pub fn moment(&self) -> Moment<'_> {
        let caption = format!("as the run first saw it, at {:.3} s", self.time as f64 * 1e-9);
        Moment { state: self.state, agents: &self.agents, links: &self.links, caption }
    }
}
