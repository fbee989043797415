//! The organisation a run saw at one moment, as data: what the runtime
//! records (`situ_runtime::script::wiring::Snapshot::moment`) and the
//! compiler's wiring writer draws (`situ_compiler::graph::wiring_moment`),
//! so that neither crate needs the other.

use crate::Mode;

/// What a run saw at one moment: the state, every agent's mode and
/// function, the links of the moment, and a caption (when, and how).
#[derive(Debug, Clone, PartialEq)]
pub struct Moment<'a> {
    pub state: u32,
    pub agents: &'a [(Mode, Option<String>)],
    pub links: &'a [(u32, u32)],
    pub caption: String,
}
