//! Which reference stack a program is, told by its agents: a [`Registry`]
//! of [`Stack`]s, the sim's own ([`Registry::sim`]) and any a crate adds
//! (`situ-dla` adds DLA's).

use super::merge::UgvMerge;
use super::outdoor::Outdoor;
use super::ugv::Ugv;
use super::Stack;
use situ_compiler::bundle::Content;
use std::collections::BTreeSet;
use std::sync::Arc;

/// The stacks a program can run on, in the order an error lists them.
#[derive(Clone)]
pub struct Registry {
    stacks: Vec<Arc<dyn Stack>>,
}

/// No stack of the registry has every agent the program declares.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("no simulated stack for these agents ({}): `situ run` knows the agents {}", .agents.join(", "), list(.known))]
pub struct NoStack {
    /// The program's agents, sorted.
    pub agents: Vec<String>,
    /// Each stack of the registry, as [`Stack::known_as`] names it.
    pub known: Vec<String>,
}

/// `a, b and c`.
fn list(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

impl Registry {
    /// A registry of `stacks`, in the order an error lists them.
    pub fn new(stacks: Vec<Arc<dyn Stack>>) -> Registry {
        Registry { stacks }
    }

    /// The sim's stacks: outdoor, the UGV's hard switch and its merge.
    pub fn sim() -> Registry {
        Registry { stacks: vec![Arc::new(Outdoor), Arc::new(Ugv), Arc::new(UgvMerge)] }
    }

    /// This registry and `stack`.
    pub fn with(mut self, stack: Arc<dyn Stack>) -> Registry {
        self.stacks.push(stack);
        self
    }

    /// The stacks, in order.
    pub fn stacks(&self) -> &[Arc<dyn Stack>] {
        &self.stacks
    }

    /// The stack named `name` ([`Stack::name`]).
    pub fn by_name(&self, name: &str) -> Option<Arc<dyn Stack>> {
        self.stacks.iter().find(|s| s.name() == name).cloned()
    }

    /// The stack whose agents the program declares. When several fit, the
    /// one whose agents include the others' (the merge's include the hard
    /// switch's), else the first.
    pub fn of(&self, content: &Content) -> Result<Arc<dyn Stack>, NoStack> {
        let names: BTreeSet<&str> = content.agents.iter().map(|a| a.name.as_str()).collect();
        let mut best: Option<&Arc<dyn Stack>> = None;
        for stack in self.stacks.iter().filter(|s| s.agents().iter().all(|a| names.contains(a))) {
            let wider = |b: &Arc<dyn Stack>| {
                stack.agents().len() > b.agents().len() && b.agents().iter().all(|a| stack.agents().contains(a))
            };
            if best.is_none_or(wider) {
                best = Some(stack);
            }
        }
        best.cloned().ok_or_else(|| NoStack {
            agents: names.into_iter().map(str::to_string).collect(),
            known: self.stacks.iter().map(|s| s.known_as()).collect(),
        })
    }
}
