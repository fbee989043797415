//! `situ test` as a library call: `suite::run` on rules files with tests and
//! properties gives every test's outcome, every property's conclusion, the
//! counts of the summary and the suite's verdict, with no command line.

use situ_compiler::loader::FsLoader;
use situ_verify::explore::Limits;
use situ_verify::property::{self, Conclusion, Engines, DEFAULT_EFFORT};
use situ_verify::random::Search;
use situ_verify::suite::{self, FileOutcome, Options, Summary, Verdict};
use std::path::PathBuf;
use std::time::Duration;

const RULES: &str = r#"states { Idle initial Busy Done final }
agent Button sensor { event PRESS event RELEASE }
rule start { when state == Idle and PRESS then Busy }
rule stop { when state == Busy and RELEASE then Done }

test "a press starts it" {
    on PRESS at 0ms
    expect state Busy
}
test "a release alone does nothing" {
    on RELEASE at 0ms
    expect state Busy
}
property "never done from idle at once" { never state == Done }
property "busy or not" { always state in {Idle, Busy, Done} }
"#;

fn options(filter: Option<&str>, allow_undecided: bool) -> Options {
    Options {
        filter: filter.map(String::from),
        properties: property::Options {
            engines: Engines::Both,
            search: Search { seed: 1, cases: 16, length: 10 },
            limits: Limits { depth: 6, max_states: 1_000 },
            effort: DEFAULT_EFFORT,
            timeout: Some(Duration::from_secs(60)),
        },
        allow_undecided,
    }
}

fn write(dir: &tempfile::TempDir, name: &str, text: &str) -> PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn one_call_runs_the_tests_checks_the_properties_and_counts_them() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(&dir, "button.situ", RULES);
    let report = suite::run(std::slice::from_ref(&file), &FsLoader, &options(None, false));
    assert_eq!(report.files.len(), 1);
    let FileOutcome::Ran(_, r) = &report.files[0].outcome else { panic!("the file has no errors") };
    let tests: Vec<(&str, bool)> = r.tests.iter().map(|t| (t.spec.name.as_str(), t.outcome.passed())).collect();
    assert_eq!(tests, [("a press starts it", true), ("a release alone does nothing", false)]);
    let words: Vec<(&str, &str)> =
        r.properties.iter().map(|p| (p.spec.name.as_str(), p.report.conclusion.word())).collect();
    assert_eq!(words, [("never done from idle at once", "violated"), ("busy or not", "proved")]);
    match &r.properties[0].report.conclusion {
        Conclusion::Violated { counterexample, .. } => assert_eq!(counterexample.steps.len(), 2),
        other => panic!("{other:?}"),
    }
    assert!(r.session.is_some());
    assert_eq!(report.summary, Summary { passed: 2, failed: 2, undecided: 0, io_failed: false });
    assert_eq!(report.verdict(), Verdict::Fail);
}

#[test]
fn the_filter_keeps_what_it_names_and_a_passing_suite_passes() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(&dir, "button.situ", RULES);
    let report = suite::run(&[file], &FsLoader, &options(Some("busy"), false));
    let FileOutcome::Ran(_, r) = &report.files[0].outcome else { panic!("the file has no errors") };
    assert!(r.tests.is_empty());
    assert_eq!(r.properties.len(), 1);
    assert_eq!(report.summary, Summary { passed: 1, ..Summary::default() });
    assert_eq!(report.verdict(), Verdict::Pass);
}

#[test]
fn a_file_with_errors_runs_nothing_and_an_unreadable_one_fails_the_suite() {
    let dir = tempfile::tempdir().unwrap();
    let broken = write(&dir, "broken.situ", "states { A initial }\nrule r { when state == A and NOPE then A }\n");
    let missing = dir.path().join("missing.situ");
    let report = suite::run(&[broken, missing], &FsLoader, &options(None, false));
    assert!(matches!(report.files[0].outcome, FileOutcome::Errors(_)));
    assert!(matches!(report.files[1].outcome, FileOutcome::Unreadable(_)));
    assert_eq!(report.summary, Summary { passed: 0, failed: 1, undecided: 0, io_failed: true });
    assert_eq!(report.verdict(), Verdict::Unreadable);
}

#[test]
fn undecided_properties_fail_the_suite_unless_allowed() {
    let s = Summary { passed: 3, failed: 0, undecided: 1, io_failed: false };
    assert_eq!(s.verdict(false), Verdict::Fail);
    assert_eq!(s.verdict(true), Verdict::Pass);
}

#[test]
fn the_verdicts_are_findings_with_their_codes() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(&dir, "button.situ", RULES);
    let report = suite::run(&[file], &FsLoader, &options(None, false));
    let FileOutcome::Ran(_, r) = &report.files[0].outcome else { panic!("the file has no errors") };
    let findings = r.findings();
    let codes: Vec<&str> = findings.iter().map(|d| d.code).collect();
    // The failed test (E0504), then the violated property (E0503); the proved one has none.
    assert_eq!(codes, ["E0504", "E0503"]);
    assert!(findings[0].message.starts_with("test \"a release alone does nothing\" failed"), "{}", findings[0].message);
    assert!(findings[1].witness.is_some());
}
