//! `situ test` as one call: every `test` block run and every `property`
//! checked, in each file given, with the verdicts counted into a summary.
//! The policy lives here (which tests and properties run, which checkers
//! look at them, how the answers combine: [`property`]); the command line
//! only renders a [`SuiteReport`] (human, JSON, SARIF) and maps it to an
//! exit code.
//!
//! A file is checked first: one that cannot be read is an I/O failure
//! ([`FileOutcome::Unreadable`]), one with errors runs nothing and counts
//! as one failure ([`FileOutcome::Errors`]). A test passes or fails; a
//! property is proved (passes), violated or in disagreement (fails), or
//! undecided (fails unless undecided properties are allowed).

use super::findings;
use super::property::{self, Conclusion, Report, Session};
use super::scenario::{self, TestOutcome};
use situ_compiler::bundle::{self, Content};
use situ_compiler::loader::Loader;
use situ_compiler::spec::{self, PropertySpec, TestSpec};
use situ_compiler::{Checked, Diagnostic, RootError};
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What to run, and on what budget; the default is `situ test`'s.
#[derive(Debug, Clone, Default)]
pub struct Options {
    /// Only the tests and properties whose name contains this.
    pub filter: Option<String>,
    /// The checkers of the properties and their budgets.
    pub properties: property::Options,
    /// Undecided properties do not fail the suite.
    pub allow_undecided: bool,
}

/// A test block and how it went.
#[derive(Debug, Clone)]
pub struct TestResult {
    pub spec: TestSpec,
    pub outcome: TestOutcome,
}

/// A property and its checkers' answers.
#[derive(Debug, Clone)]
pub struct PropertyResult {
    pub spec: PropertySpec,
    pub report: Report,
}

/// The tests and properties of one file without errors.
pub struct FileReport {
    /// The program the tests and properties ran on.
    pub content: Arc<Content>,
    /// The tests the filter kept, in the file's order.
    pub tests: Vec<TestResult>,
    /// The properties the filter kept, in the file's order.
    pub properties: Vec<PropertyResult>,
    /// What was built once for the properties (none without properties).
    pub session: Option<Session>,
}

impl FileReport {
    /// The verdicts as findings ([`findings`]): the failed tests, then the
    /// properties violated, undecided or vacuous.
    pub fn findings(&self) -> Vec<Diagnostic> {
        let tests = self.tests.iter().filter(|t| !t.outcome.passed()).map(|t| findings::of_test(&t.spec, &t.outcome));
        let properties = self.properties.iter().flat_map(|p| findings::of_property(&self.content, &p.spec, &p.report));
        tests.chain(properties).collect()
    }
}

/// What became of one file.
pub enum FileOutcome {
    /// It could not be read (an I/O failure of the suite).
    Unreadable(RootError),
    /// It has errors: nothing was run (one failure).
    Errors(Checked),
    /// Its tests and properties ran.
    Ran(Checked, Box<FileReport>),
}

/// One file given, and what became of it.
pub struct FileResult {
    pub path: PathBuf,
    pub outcome: FileOutcome,
}

/// The counts of a suite: what passed, failed and is undecided.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Summary {
    pub passed: usize,
    pub failed: usize,
    pub undecided: usize,
    /// A file could not be read.
    pub io_failed: bool,
}

/// How a suite ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Verdict {
    /// Every test passed and every property was proved (or only undecided
    /// ones are left, and they are allowed).
    Pass,
    /// A test failed, a property was violated, a file had errors, or a
    /// property is undecided and undecided ones are not allowed.
    Fail,
    /// A file could not be read.
    Unreadable,
}

/// Every file's outcome, and the summary.
pub struct SuiteReport {
    pub files: Vec<FileResult>,
    pub summary: Summary,
    pub allow_undecided: bool,
}

impl SuiteReport {
    pub fn verdict(&self) -> Verdict {
        self.summary.verdict(self.allow_undecided)
    }
}

impl Summary {
    /// The suite's verdict; undecided properties fail it unless allowed.
    pub fn verdict(&self, allow_undecided: bool) -> Verdict {
        if self.io_failed {
            Verdict::Unreadable
        } else if self.failed > 0 || (self.undecided > 0 && !allow_undecided) {
            Verdict::Fail
        } else {
            Verdict::Pass
        }
    }

    /// Adds one file's outcome.
    pub fn add(&mut self, outcome: &FileOutcome) {
        match outcome {
            FileOutcome::Unreadable(_) => self.io_failed = true,
            FileOutcome::Errors(_) => self.failed += 1,
            FileOutcome::Ran(_, r) => {
                for t in &r.tests {
                    if t.outcome.passed() {
                        self.passed += 1;
                    } else {
                        self.failed += 1;
                    }
                }
                for p in &r.properties {
                    match p.report.conclusion {
                        Conclusion::Proved { .. } => self.passed += 1,
                        Conclusion::Undecided { .. } => self.undecided += 1,
                        Conclusion::Violated { .. } | Conclusion::Disagree { .. } => self.failed += 1,
                    }
                }
            }
        }
    }
}

/// Runs the suite on every file (each with its includes, read by `loader`).
pub fn run(files: &[PathBuf], loader: &dyn Loader, opts: &Options) -> SuiteReport {
    let mut summary = Summary::default();
    let files: Vec<FileResult> = files
        .iter()
        .map(|path| {
            let outcome = run_file(path, loader, opts);
            summary.add(&outcome);
            FileResult { path: path.clone(), outcome }
        })
        .collect();
    SuiteReport { files, summary, allow_undecided: opts.allow_undecided }
}

/// Checks one file and, when it has no errors, runs its tests and properties.
pub fn run_file(path: &Path, loader: &dyn Loader, opts: &Options) -> FileOutcome {
    match situ_compiler::check(path, loader) {
        Err(e) => FileOutcome::Unreadable(e),
        Ok(checked) if checked.errors() > 0 => FileOutcome::Errors(checked),
        Ok(checked) => {
            let report = run_checked(&checked, opts);
            FileOutcome::Ran(checked, Box::new(report))
        }
    }
}

/// Runs the tests and checks the properties of a checked program without
/// errors, those the filter keeps.
pub fn run_checked(checked: &Checked, opts: &Options) -> FileReport {
    let content = Arc::new(bundle::build(checked));
    let spec = spec::lower(checked);
    let wanted = |name: &str| opts.filter.as_deref().is_none_or(|f| name.contains(f));
    let tests = spec
        .tests
        .into_iter()
        .filter(|t| wanted(&t.name))
        .map(|t| TestResult { outcome: scenario::run(&content, &t), spec: t })
        .collect();
    let props: Vec<PropertySpec> = spec.properties.into_iter().filter(|p| wanted(&p.name)).collect();
    let (session, properties) = if props.is_empty() {
        (None, Vec::new())
    } else {
        let refs: Vec<&PropertySpec> = props.iter().collect();
        let (session, reports) = property::check_all(&content, &refs, &opts.properties);
        let results = props.into_iter().zip(reports).map(|(spec, report)| PropertyResult { spec, report }).collect();
        (Some(session), results)
    };
    FileReport { content, tests, properties, session }
}
