//! Static checks over the checked [`Model`](crate::model::Model): the
//! semantic layer they share. [`domain`] decides constant payload
//! constraints exactly; [`situation`] turns rule conditions into sets of
//! working memories, meets them, and finds a concrete witness memory;
//! [`transitions`] builds the state graph. Each check is one module.

pub mod behaviour;
pub mod budget;
pub mod conflicts;
pub mod domain;
pub mod escape;
pub mod fsm;
pub mod oscillation;
pub mod shadowed;
pub mod situation;
pub mod tables;
pub mod transitions;
pub mod trap;
pub mod unreachable;
pub mod unsatisfiable;
pub mod unused;
pub mod wiring;

use crate::model::Model;
use situ_grammar::diag::Diagnostic;

/// Runs every static check on a model without errors; returns all findings.
pub fn run(model: &Model) -> Vec<Diagnostic> {
    let timing = std::env::var_os("SITU_TIME_CHECKS").is_some();
    let mut clock = std::time::Instant::now();
    let mut lap = |what: &str| {
        if timing {
            eprintln!("{what:>14}: {:.1} ms", clock.elapsed().as_secs_f64() * 1e3);
        }
        clock = std::time::Instant::now();
    };
    let tr = transitions::Transitions::build(model);
    lap("transitions");
    let checks: [(&str, Check); 10] = [
        ("unsatisfiable", unsatisfiable::check),
        ("unreachable", unreachable::check),
        ("conflicts", conflicts::check),
        ("shadowed", shadowed::check),
        ("oscillation", oscillation::check),
        ("trap", trap::check),
        ("unused", unused::check),
        ("tables", tables::check),
        ("fsm", fsm::check),
        ("wiring", wiring::check),
    ];
    let mut out = Vec::new();
    for (name, check) in checks {
        out.extend(check(model, &tr));
        lap(name);
    }
    out
}

/// One static check: all its findings on a model.
type Check = fn(&Model, &transitions::Transitions) -> Vec<Diagnostic>;

#[cfg(test)]
mod tests;

#[cfg(test)]
mod budget_tests;
