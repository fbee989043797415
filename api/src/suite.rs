//! `situ test` as a call: the scenario tests and the properties of rules
//! files, each property proved, violated or undecided (never "ok" for
//! "not found"), and the suite's verdict.

use serde_json::{json, Value};
use situ_compiler::bundle::Content;
use situ_compiler::loader::FsLoader;
use situ_compiler::render;
use situ_compiler::spec::PropertySpec;
use situ_verify::property::{Conclusion, Premise, Report};
use situ_verify::suite::FileOutcome;
use situ_verify::{show_event, Counterexample, Verdict as CheckerVerdict};
use std::path::{Path, PathBuf};

pub use situ_verify::suite::{Options as TestOptions, SuiteReport, Verdict};

/// Runs the tests and checks the properties of `files` (each with its
/// includes). A file that cannot be read or has errors is an outcome of the
/// report, not an error: the other files still run.
pub fn test(files: &[PathBuf], options: &TestOptions) -> SuiteReport {
    situ_verify::suite::run(files, &FsLoader, options)
}

/// A `test` or `property` block of a file, where it is written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Block {
    /// `test` or `property`.
    pub kind: &'static str,
    pub name: String,
    pub file: String,
    pub line: u32,
}

/// The `test` and `property` blocks of checked rules (those of included
/// files too, each with its own file), in the order they are written; none
/// for rules with errors.
pub fn blocks(checked: &situ_compiler::Checked) -> Vec<Block> {
    if checked.errors() > 0 {
        return Vec::new();
    }
    let spec = situ_compiler::spec::lower(checked);
    let tests = spec.tests.iter().map(|t| Block {
        kind: "test",
        name: t.name.clone(),
        file: t.place.file.clone(),
        line: t.place.line,
    });
    let props = spec.properties.iter().map(|p| Block {
        kind: "property",
        name: p.name.clone(),
        file: p.place.file.clone(),
        line: p.place.line,
    });
    tests.chain(props).collect()
}

/// A suite's report as JSON records, the data model of `situ test --format
/// json` and of the bindings: for each file in order, the findings of a
/// file with errors (`situ check --format json`'s objects), or one object
/// per test (`"kind": "test"`) then per property (`"kind": "property"`:
/// `verdict` proved / violated / undecided / disagree, `code`,
/// `proved_by`, `undecided_because`, each checker's answer, the
/// `counterexample` with its events and its replay block as `test` text,
/// and the `premise`); last, the summary (`"kind": "summary"`). A file
/// that could not be read has no record: [`SuiteReport::files`] holds it.
pub fn test_records(report: &SuiteReport) -> Vec<Value> {
    let mut out = Vec::new();
    for file in &report.files {
        let path = &file.path;
        let r = match &file.outcome {
            FileOutcome::Unreadable(_) => continue,
            FileOutcome::Errors(checked) => {
                out.extend(checked.diagnostics.iter().map(|d| render::json_object(&checked.sources, d)));
                continue;
            }
            FileOutcome::Ran(_, r) => r,
        };
        for t in &r.tests {
            let list: Vec<_> = t
                .outcome
                .failures
                .iter()
                .map(|f| json!({"place": f.place.to_string(), "message": f.message}))
                .collect();
            out.push(json!({"kind": "test", "file": path.display().to_string(), "name": t.spec.name,
                   "place": t.spec.place.to_string(), "passed": t.outcome.passed(), "events": t.outcome.events,
                   "failures": list}));
        }
        for p in &r.properties {
            out.push(property_json(&r.content, path, &p.spec, &p.report));
        }
    }
    let s = report.summary;
    out.push(json!({"kind": "summary", "passed": s.passed, "failed": s.failed, "undecided": s.undecided,
           "allow_undecided": report.allow_undecided}));
    out
}

fn property_json(content: &Content, path: &Path, p: &PropertySpec, r: &Report) -> Value {
    let verdict = |v: &Option<CheckerVerdict>| {
        v.as_ref().map(|v| {
            let kind = match v {
                CheckerVerdict::Proved { .. } | CheckerVerdict::Inductive { sampled: None, .. } => "proved",
                CheckerVerdict::Inductive { .. } => "exhausted",
                CheckerVerdict::Disagree { .. } => "disagree",
                CheckerVerdict::Exhausted { .. } => "exhausted",
                CheckerVerdict::Bounded { .. } => "bounded",
                CheckerVerdict::NotFound { .. } => "not_found",
                CheckerVerdict::GaveUp { .. } => "gave_up",
                CheckerVerdict::Failed(_) => "failed",
            };
            json!({"verdict": kind, "summary": v.summary()})
        })
    };
    let run = |c: &Counterexample| -> Vec<Value> {
        c.steps
            .iter()
            .map(|s| {
                json!({"event": show_event(content, s.event, &s.payload), "time_ns": s.time,
                       "state": content.states[s.state as usize].name, "fired": s.fired})
            })
            .collect()
    };
    let cex = match &r.conclusion {
        Conclusion::Violated { by, how, counterexample: c } => Some(json!({
            "found_by": format!("{}, {how}", by.name()), "events": run(c), "point": c.point,
            "reason": c.reason, "test": c.as_test(content, &p.name)})),
        _ => None,
    };
    let (proved_by, reasons) = match &r.conclusion {
        Conclusion::Proved { by, .. } => (Some(by.name()), Vec::new()),
        Conclusion::Undecided { reasons } => (None, reasons.clone()),
        _ => (None, Vec::new()),
    };
    let premise = r.premise.as_ref().map(|pr| match pr {
        Premise::Reachable(c) => json!({"reachable": true, "events": run(c)}),
        Premise::Vacuous { by } => {
            json!({"reachable": false, "vacuous": true, "code": "W0501", "proved_by": by.name()})
        }
        Premise::Unknown => json!({"reachable": null}),
    });
    let code = match r.conclusion {
        Conclusion::Undecided { .. } => Some("E0502"),
        _ => None,
    };
    json!({"kind": "property", "file": path.display().to_string(), "name": p.name, "place": p.place.to_string(),
           "verdict": r.conclusion.word(), "passed": matches!(r.conclusion, Conclusion::Proved { .. }),
           "code": code, "proved_by": proved_by, "undecided_because": reasons,
           "exhaustive": verdict(&r.exhaustive), "symbolic": verdict(&r.symbolic), "random": verdict(&r.random),
           "counterexample": cex, "premise": premise})
}
