//! Verdicts as findings, for the reports that carry findings (SARIF): a
//! failed test is E0504 at its block; a violated property E0503 (with the
//! run as a witness and as a test to paste), an undecided one E0502, a
//! vacuous one W0501 (`situ explain CODE` says each).

use super::property::{Conclusion, Premise, Report};
use super::scenario::TestOutcome;
use super::show_event;
use serde_json::json;
use situ_compiler::bundle::Content;
use situ_compiler::codes;
use situ_compiler::spec::{PropertySpec, TestSpec};
use situ_compiler::Diagnostic;

/// A failed test as a finding (E0504), at its block.
pub fn of_test(t: &TestSpec, outcome: &TestOutcome) -> Diagnostic {
    let first = outcome.failures.first().map_or(String::new(), |f| format!(": {}", f.message));
    let help: Vec<String> = outcome.failures.iter().map(|f| format!("{}: {}", f.place, f.message)).collect();
    Diagnostic::error(
        codes::FAILED_TEST,
        format!("test \"{}\" failed{first}", t.name),
        t.origin.file,
        t.origin.span,
        "this test",
    )
    .with_help(help.join("\n"))
}

/// A property's verdict as findings: violated (E0503), undecided (E0502),
/// vacuous (W0501); none for a proved property with a reachable premise.
pub fn of_property(content: &Content, p: &PropertySpec, r: &Report) -> Vec<Diagnostic> {
    let (file, span) = (p.origin.file, p.origin.span);
    let mut out = Vec::new();
    match &r.conclusion {
        Conclusion::Violated { by, counterexample: c, .. } => {
            let mut d = Diagnostic::error(
                codes::VIOLATED_PROPERTY,
                format!(
                    "property \"{}\" is broken by a run of {} events (found by {}): {}",
                    p.name,
                    c.steps.len(),
                    by.name(),
                    c.reason
                ),
                file,
                span,
                "this property",
            )
            .with_help(format!("the run as a test to paste into the file:\n{}", c.as_test(content, &p.name)));
            let steps: Vec<_> = c
                .steps
                .iter()
                .map(|s| json!({"event": show_event(content, s.event, &s.payload), "time_ns": s.time,
                                 "state": content.states[s.state as usize].name}))
                .collect();
            d.witness = Some(json!({"events": steps, "point": c.point, "reason": c.reason}));
            out.push(d);
        }
        Conclusion::Undecided { reasons } => out.push(
            Diagnostic::error(
                codes::UNDECIDED_PROPERTY,
                format!("property \"{}\" is undecided: no checker proved or broke it within its budget", p.name),
                file,
                span,
                "this property",
            )
            .with_help(reasons.join("\n")),
        ),
        Conclusion::Disagree { events } => out.push(Diagnostic::error(
            codes::VIOLATED_PROPERTY,
            format!(
                "property \"{}\": IC3's counterexample of {events} events does not replay on the engine (an error of situ, please report it)",
                p.name
            ),
            file,
            span,
            "this property",
        )),
        Conclusion::Proved { .. } => {}
    }
    if let Some(Premise::Vacuous { by }) = &r.premise {
        out.push(
            Diagnostic::warning(
                codes::VACUOUS_PROPERTY,
                format!("property \"{}\" is vacuous: its premise never holds ({} proved it)", p.name, by.name()),
                file,
                span,
                "this property",
            )
            .with_help("check the premise: a state, mode or event pattern that no run reaches together"),
        );
    }
    out
}
