//! Runs `test` blocks (language reference §10.9) on the engine and the
//! organisation: `given` forces the state and facts (stamped at 0) without
//! firing rules or stepping FSMs; `on` posts events at the times the
//! compiler computed (10 ms apart unless `at`); `expect` checks the system
//! and reports every failed expectation.

use super::{show_event, System};
use situ_compiler::bundle::Content;
use situ_compiler::spec::{Expected, Place, TestSpec, TestStep};
use situ_runtime::rete::format_time;
use std::sync::Arc;

/// A failed expectation, or an event the engine could not process.
#[derive(Debug, Clone, PartialEq)]
pub struct Failure {
    pub place: Place,
    pub message: String,
}

/// What a test did.
#[derive(Debug, Clone, PartialEq)]
pub struct TestOutcome {
    pub failures: Vec<Failure>,
    /// Events posted.
    pub events: usize,
}

impl TestOutcome {
    pub fn passed(&self) -> bool {
        self.failures.is_empty()
    }
}

/// Runs one test from a fresh system.
pub fn run(content: &Arc<Content>, test: &TestSpec) -> TestOutcome {
    let mut sys = System::new(content.clone());
    let mut failures = Vec::new();
    let mut events = 0;
    for step in &test.steps {
        match step {
            TestStep::Given { state, facts } => {
                if let Some(s) = state {
                    sys.engine.force_state(*s);
                    sys.org.set_state(*s);
                }
                for f in facts {
                    if let Err(e) = sys.engine.force_fact(f.event, 0, &f.payload, f.run) {
                        failures.push(Failure { place: f.place.clone(), message: e.describe(content) });
                    }
                }
            }
            TestStep::On { events: posted } => {
                for p in posted {
                    events += 1;
                    if let Err(e) = sys.post(p.event, p.time, &p.payload) {
                        failures.push(Failure {
                            place: p.place.clone(),
                            message: format!(
                                "{} at {}: {}",
                                show_event(content, p.event, &p.payload),
                                format_time(p.time),
                                e.describe(content)
                            ),
                        });
                        return TestOutcome { failures, events };
                    }
                }
            }
            TestStep::Expect { expectations } => {
                for e in expectations {
                    if let Some(message) = check(&sys, e.what) {
                        failures.push(Failure { place: e.place.clone(), message });
                    }
                }
            }
        }
    }
    TestOutcome { failures, events }
}

/// `None` when the expectation holds; otherwise what was expected and what was found.
fn check(sys: &System, what: Expected) -> Option<String> {
    let c = sys.content();
    let state = |s: u32| c.states[s as usize].name.as_str();
    let agent = |a: u32| c.agents[a as usize].name.as_str();
    match what {
        Expected::State(s) => {
            let now = sys.engine.state();
            (now != s).then(|| format!("expected state {}, found {}", state(s), state(now)))
        }
        Expected::Mode { agent: a, mode } => {
            let found = sys.org.mode(a);
            (found != mode).then(|| {
                format!(
                    "expected {} {}, found {} {} in {}",
                    agent(a),
                    mode.adjective(),
                    agent(a),
                    found.adjective(),
                    state(sys.engine.state())
                )
            })
        }
        Expected::Runs { agent: a, function } => {
            let want = &c.agents[a as usize].functions[function as usize].name;
            let found = sys.org.function(a);
            (found != Some(want.as_str())).then(|| {
                let mode = sys.org.mode(a).adjective();
                match found {
                    Some(f) => format!("expected {} runs {want}, found {} {mode} with {f}", agent(a), agent(a)),
                    None => format!("expected {} runs {want}, found {} {mode} with no function", agent(a), agent(a)),
                }
            })
        }
        Expected::Link { from, to, present } => {
            let found = sys.org.has_link(from, to);
            (found != present).then(|| {
                let links: Vec<String> =
                    sys.org.links().iter().map(|&(x, y)| format!("{} -> {}", agent(x), agent(y))).collect();
                let what = if present { "expected link" } else { "expected no link" };
                format!(
                    "{what} {} -> {} in {}; the wiring is: {}",
                    agent(from),
                    agent(to),
                    state(sys.engine.state()),
                    if links.is_empty() { "no link".to_string() } else { links.join(", ") }
                )
            })
        }
    }
}
