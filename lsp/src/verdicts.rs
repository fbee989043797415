//! The verdicts of a file's properties and `test` blocks, in the editor.
//!
//! When a document is opened or saved, the compilation that answers for it
//! (its includer's, if an open file includes it) is run through `situ
//! test`'s own policy ([`situ_verify::suite::run_checked`]) on a worker
//! thread, on a budget suited to an editor ([`EDITOR_OPTIONS`]: work, not
//! seconds, so the same text gives the same verdicts on any machine). The
//! run belongs to one generation of the documents: an edit makes it stale,
//! and a stale run's results are dropped.
//!
//! What comes back is data: findings with the codes `situ test` gives in
//! SARIF (E0503 violated, E0502 undecided, W0501 vacuous, E0504 a failed
//! test), merged by [`crate::diagnostics`] with the compiler's; a lens
//! above each property and test (`proved (IC3)`, `violated: 5 events`,
//! `undecided: …`, `passed`, `running…`); and, for a violated property, the
//! edit that appends its counterexample to the file as a `test` block.

use crate::data::{CodeAction, Finding, TextEdit, WorkspaceEdit};
use crate::diagnostics;
pub use crate::runs::{Board, Insert, Lens, Outcome, Settings, EDITOR_OPTIONS};
use crate::world::{Analysis, Doc, World};
use lsp_types::Range;
use situ_compiler::codes;
use situ_grammar::ast::{self, Span};
use situ_grammar::diag::FileId;
use situ_verify::ic3::Stop;
use situ_verify::property::{self, Conclusion, Premise, Report};
use situ_verify::suite::{self, FileReport, PropertyResult};
use situ_verify::Verdict;
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The command of a lens that appends a counterexample to its file.
pub const INSERT_COMMAND: &str = "situ.insertCounterexample";

/// One run to do away from the server loop: a root, the generation of its
/// documents, a copy of them, and the budget.
#[derive(Debug)]
pub struct Run {
    pub root: PathBuf,
    pub generation: u64,
    pub docs: BTreeMap<PathBuf, Doc>,
    pub options: property::Options,
}

impl Run {
    /// Checks the root (with the static checks, as `situ test` does) and,
    /// without errors, runs its tests and properties: nothing with errors.
    pub fn run(&self) -> Outcome {
        let Some(a) = Analysis::new(&self.root, &self.docs, true) else { return Outcome::default() };
        if a.checked.errors() > 0 {
            return Outcome::default();
        }
        let opts = suite::Options { filter: None, properties: self.options, allow_undecided: false };
        outcome(&a, &suite::run_checked(&a.checked, &opts), &self.docs)
    }
}

/// The runs to start now (each recorded as running): one per compilation
/// that answers for a document opened or saved, if it has tests or
/// properties and no errors so far.
pub fn start(world: &mut World) -> Vec<Run> {
    let wanted = std::mem::take(&mut world.verdicts.wanted);
    let mut runs = Vec::new();
    if !world.verdicts.settings.enabled {
        return runs;
    }
    let mut roots = BTreeSet::new();
    for path in wanted {
        if let Some((a, _)) = world.primary(&path) {
            roots.insert(a.root.clone());
        }
    }
    for root in roots {
        let Some(a) = world.analyses.get(&root) else { continue };
        let errors = a.checked.errors() > 0;
        if errors || !a.asts.iter().flat_map(|f| &f.items).any(|i| verdict_item(i).is_some()) {
            world.verdicts.runs.remove(&root);
            continue;
        }
        let generation = world.generation(&root);
        world.verdicts.runs.insert(root.clone(), (generation, None));
        let options = world.verdicts.settings.options;
        runs.push(Run { root, generation, docs: world.docs.clone(), options });
    }
    runs
}

/// The state of the verdicts of `root` for its current documents: `None`
/// when there are none (or they are stale), `Some(None)` while they run.
fn current<'w>(world: &'w World, root: &Path) -> Option<Option<&'w Outcome>> {
    world.verdicts.current(root, world.generation(root))
}

/// The verdicts' findings in the file `uri` of the analysis `a`.
pub fn findings<'w>(world: &'w World, a: &Analysis, uri: &str) -> &'w [Finding] {
    world.verdicts.found(&a.root, world.generation(&a.root), uri)
}

/// The lenses of a document: the verdicts, or `running…` above each
/// property and test while they run.
pub fn lenses(world: &World, path: &Path) -> Vec<Lens> {
    let Some((a, file)) = world.primary(path) else { return Vec::new() };
    match current(world, &a.root) {
        Some(Some(o)) => o.lenses.get(&a.uri(file)).cloned().unwrap_or_default(),
        Some(None) => a.asts[file.0 as usize]
            .items
            .iter()
            .filter_map(verdict_item)
            .map(|span| Lens { range: a.range(file, span), title: "running…".into(), insert: None })
            .collect(),
        None => Vec::new(),
    }
}

/// The code actions of the verdicts whose property touches `range` of the
/// document: append the counterexample as a `test` block.
pub fn code_actions(world: &World, path: &Path, range: Range) -> Vec<CodeAction> {
    lenses(world, path)
        .into_iter()
        .filter(|l| l.range.start <= range.end && range.start <= l.range.end)
        .filter_map(|l| l.insert)
        .map(|i| CodeAction {
            title: "append the counterexample as a `test` block".into(),
            finding: i.finding,
            preferred: false,
            edit: WorkspaceEdit::from([(i.uri, vec![i.edit])]),
        })
        .collect()
}

/// The place of a property or a test: its name (where `situ test` puts its
/// findings).
fn verdict_item(item: &ast::Item) -> Option<Span> {
    match item {
        ast::Item::Test(t) => Some(t.name.span),
        ast::Item::Property(p) => Some(p.name.span),
        _ => None,
    }
}

/// The findings and lenses of a suite's report on the analysis `a`.
fn outcome(a: &Analysis, r: &FileReport, docs: &BTreeMap<PathBuf, Doc>) -> Outcome {
    let mut out = Outcome::default();
    for d in r.findings() {
        let mut f = diagnostics::finding(a, &d);
        // The editor's budget is not `situ test`'s: undecided here is a warning.
        f.error &= d.code != codes::UNDECIDED_PROPERTY;
        if d.code == codes::VIOLATED_PROPERTY {
            let origin =
                |p: &&PropertyResult| (p.spec.origin.file, p.spec.origin.span) == (d.primary.file, d.primary.span);
            let run = r.properties.iter().find(origin);
            if let Some(Conclusion::Violated { by, how, counterexample }) = run.map(|p| &p.report.conclusion) {
                let text = format!("the run ({}, {how}):\n{}", by.name(), counterexample.describe(&r.content));
                f.related.insert(0, (a.location(d.primary.file, d.primary.span), text));
            }
        }
        out.findings.entry(a.uri(d.primary.file)).or_default().push(f);
    }
    let mut lens = |file: FileId, span: Span, title: String, insert: Option<Insert>| {
        out.lenses.entry(a.uri(file)).or_default().push(Lens { range: a.range(file, span), title, insert });
    };
    for t in &r.tests {
        let title = match t.outcome.failures.first() {
            None => "passed".to_string(),
            Some(f) => format!("failed: {}", f.message),
        };
        lens(t.spec.origin.file, t.spec.origin.span, title, None);
    }
    for p in &r.properties {
        let (file, span) = (p.spec.origin.file, p.spec.origin.span);
        let insert = match &p.report.conclusion {
            Conclusion::Violated { counterexample, .. } => {
                let block = counterexample.as_test(&r.content, &p.spec.name);
                let finding = out.findings.get(&a.uri(file)).and_then(|fs| {
                    fs.iter().find(|f| f.code == codes::VIOLATED_PROPERTY && f.range == a.range(file, span)).cloned()
                });
                finding.map(|finding| appended(a, file, &block, docs, finding))
            }
            _ => None,
        };
        lens(file, span, title(&p.report), insert);
    }
    for lenses in out.lenses.values_mut() {
        lenses.sort_by_key(|l| (l.range.start.line, l.range.start.character));
    }
    out
}

/// `block` appended to the file, after a blank line.
fn appended(a: &Analysis, file: FileId, block: &str, docs: &BTreeMap<PathBuf, Doc>, finding: Finding) -> Insert {
    let text = a.text(file);
    let end = a.range(file, Span { start: text.len(), end: text.len() }).end;
    let before = if text.is_empty() || text.ends_with("\n\n") {
        ""
    } else if text.ends_with('\n') {
        "\n"
    } else {
        "\n\n"
    };
    Insert {
        uri: a.uri(file),
        version: docs.get(&a.paths[file.0 as usize]).map(|d| d.version),
        edit: TextEdit { range: Range { start: end, end }, new_text: format!("{before}{block}") },
        finding,
    }
}

/// A property's lens: its verdict in a few words.
fn title(r: &Report) -> String {
    let vacuous = matches!(r.premise, Some(Premise::Vacuous { .. }));
    match &r.conclusion {
        Conclusion::Proved { by, .. } if vacuous => format!("proved ({}), vacuous: the premise never holds", by.name()),
        Conclusion::Proved { by, .. } => format!("proved ({})", by.name()),
        Conclusion::Violated { by, counterexample: cex, .. } => {
            format!("violated: {} ({}): append as a test", events(cex.steps.len()), by.name())
        }
        Conclusion::Undecided { .. } => {
            let mut reached = Vec::new();
            match &r.exhaustive {
                Some(Verdict::Bounded { depth, .. }) => reached.push(format!("explored {}", events(*depth))),
                Some(Verdict::Exhausted { .. }) => reached.push("explored a sampled abstraction".into()),
                _ => {}
            }
            match &r.symbolic {
                Some(Verdict::GaveUp { depth, stop, .. }) => {
                    let why = match stop {
                        Stop::Frames => "frames",
                        Stop::Work => "work budget",
                        Stop::Deadline => "clock",
                    };
                    reached.push(format!("IC3 stopped at {} ({why})", events(*depth)));
                }
                Some(Verdict::Inductive { sampled: Some(_), .. }) => {
                    reached.push("IC3 on a sampled abstraction".into())
                }
                None if r.symbolic_note.is_some() => reached.push("IC3 not run".into()),
                _ => {}
            }
            if let Some(Verdict::NotFound { runs, .. }) = &r.random {
                reached.push(format!("{runs} random runs"));
            }
            if reached.is_empty() {
                "undecided".into()
            } else {
                format!("undecided: {}", reached.join(", "))
            }
        }
        Conclusion::Disagree { events: n } => format!("error: IC3's run of {} does not replay", events(*n)),
    }
}

/// `1 event`, `5 events`.
fn events(n: usize) -> String {
    if n == 1 {
        "1 event".into()
    } else {
        format!("{n} events")
    }
}

#[cfg(test)]
mod tests;
