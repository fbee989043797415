//! The state of the verdicts ([`crate::verdicts`]) as the documents'
//! [`crate::world::World`] keeps it: the budget, the runs asked for, running
//! and done, and what each found. Data only: the runs are started and read
//! by [`crate::verdicts`].

use crate::data::{Finding, TextEdit};
use lsp_types::Range;
use situ_verify::explore::Limits;
use situ_verify::property::{self, Engines};
use situ_verify::random::Search;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The editor's budget, a fraction of `situ test`'s
/// ([`property::DEFAULT_OPTIONS`]): both checkers, 64 random runs of 60
/// events, exploration to 8 events or 5,000 states, IC3 on 5,000,000
/// propagations per property, under a 120 s wall-clock guard. What it does
/// not decide is *undecided*, never passed.
pub const EDITOR_OPTIONS: property::Options = property::Options {
    engines: Engines::Both,
    search: Search { seed: 1, cases: 64, length: 60 },
    limits: Limits { depth: 8, max_states: 5_000 },
    effort: 5_000_000,
    timeout: Some(Duration::from_secs(120)),
};

/// Whether the verdicts run, and on what budget (the client's
/// `initializationOptions.verdicts`, or the setting `situ.verdicts`).
#[derive(Debug, Clone, Copy)]
pub struct Settings {
    pub enabled: bool,
    pub options: property::Options,
}

impl Default for Settings {
    fn default() -> Settings {
        Settings { enabled: true, options: EDITOR_OPTIONS }
    }
}

/// A line above a property or a test: its verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct Lens {
    pub range: Range,
    pub title: String,
    /// For a violated property: the counterexample as a `test` block.
    pub insert: Option<Insert>,
}

/// An edit of one version of a document: the counterexample of a violated
/// property appended as a `test` block.
#[derive(Debug, Clone, PartialEq)]
pub struct Insert {
    pub uri: String,
    /// The version of the document it was made for (`None`: not open).
    pub version: Option<i32>,
    pub edit: TextEdit,
    /// The finding it answers (for the code action).
    pub finding: Finding,
}

/// What a run found, by URI.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Outcome {
    pub findings: BTreeMap<String, Vec<Finding>>,
    pub lenses: BTreeMap<String, Vec<Lens>>,
}

/// The runs asked for, running and done.
#[derive(Debug, Default)]
pub struct Board {
    pub settings: Settings,
    /// Per root: the generation of its last run, and its outcome once done.
    pub(crate) runs: BTreeMap<PathBuf, (u64, Option<Outcome>)>,
    /// Documents opened or saved since the runs were last started.
    pub(crate) wanted: BTreeSet<PathBuf>,
}

impl Board {
    /// `path` was opened or saved: its compilation is to run.
    pub fn want(&mut self, path: PathBuf) {
        self.wanted.insert(path);
    }

    pub fn forget(&mut self, root: &Path) {
        self.runs.remove(root);
        self.wanted.remove(root);
    }

    /// A run is done: kept if it is of the root's current generation and
    /// the run awaited (a newer run, or an edit, supersedes it).
    pub fn accept(&mut self, root: &Path, generation: u64, current: u64, outcome: Outcome) -> bool {
        match self.runs.get_mut(root) {
            Some((g, slot)) if *g == generation && generation == current => {
                *slot = Some(outcome);
                true
            }
            _ => false,
        }
    }

    /// The state of the verdicts of `root` at its current `generation`:
    /// `None` when there are none (or they are stale), `Some(None)` while
    /// they run.
    pub fn current(&self, root: &Path, generation: u64) -> Option<Option<&Outcome>> {
        let (g, outcome) = self.runs.get(root)?;
        (*g == generation).then_some(outcome.as_ref())
    }

    /// The findings of the verdicts of `root` at its current `generation`
    /// in the file `uri`.
    pub fn found(&self, root: &Path, generation: u64, uri: &str) -> &[Finding] {
        match self.current(root, generation) {
            Some(Some(o)) => o.findings.get(uri).map_or(&[], Vec::as_slice),
            _ => &[],
        }
    }
}
