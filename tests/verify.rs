//! The property checkers on planted bugs: `tests/verify/*.situ`, one file
//! per kind of property, each with properties that fail and properties that
//! hold, their expectations inline at the end of the property's line:
//!
//! - `//~ FAILS N`: the exhaustive checker finds a counterexample of exactly
//!   N events (the shortest: it searches breadth first), and the random
//!   checker finds one too, shrunk to at most N + 2 events (unbounded
//!   `eventually` is left to the exhaustive checker);
//! - `//~ PROVED`: the exhaustive checker proves it (closed space, exact
//!   abstraction), and the random checker finds no counterexample;
//! - `//~ EXHAUSTED`: no counterexample in the whole abstract space, whose
//!   time gaps are sampled.
//!
//! Every property of an input must carry an expectation.

use situ_compiler::bundle;
use situ_compiler::loader::FsLoader;
use situ_compiler::spec::{self, Consequent, PropertySpec};
use situ_verify::abstraction::Alphabet;
use situ_verify::explore::{Graph, Limits};
use situ_verify::ic3::Limits as Ic3Limits;
use situ_verify::model::Model;
use situ_verify::prove;
use situ_verify::random::{self, Search};
use situ_verify::Verdict;
use std::collections::BTreeMap;
use std::sync::Arc;

#[derive(Debug, Clone, Copy, PartialEq)]
enum Expect {
    Fails(usize),
    Proved,
    Exhausted,
}

fn expectations(text: &str) -> BTreeMap<u32, Expect> {
    let mut out = BTreeMap::new();
    for (i, line) in text.lines().enumerate() {
        let Some(at) = line.find("//~") else { continue };
        let words: Vec<&str> = line[at + 3..].split_whitespace().collect();
        let e = match words.as_slice() {
            ["FAILS", n] => Expect::Fails(n.parse().expect("FAILS N")),
            ["PROVED"] => Expect::Proved,
            ["EXHAUSTED"] => Expect::Exhausted,
            other => panic!("line {}: unknown expectation {other:?}", i + 1),
        };
        out.insert(i as u32 + 1, e);
    }
    out
}

fn liveness(p: &PropertySpec) -> bool {
    matches!(p.consequent, Consequent::Eventually { bound: None, .. })
}

#[test]
fn planted_bugs_are_found_and_correct_properties_proved() {
    let mut files: Vec<_> = std::fs::read_dir("tests/verify")
        .expect("tests/verify")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "situ"))
        .collect();
    files.sort();
    assert!(files.len() >= 7, "one input per kind of property");
    let mut failures = Vec::new();
    for path in &files {
        let checked = situ_compiler::check(path, &FsLoader).expect("readable");
        assert_eq!(checked.errors(), 0, "{}: {:?}", path.display(), checked.diagnostics);
        let text = std::fs::read_to_string(path).expect("readable");
        let expected = expectations(&text);
        let content = Arc::new(bundle::build(&checked));
        let spec = spec::lower(&checked);
        let props: Vec<&PropertySpec> = spec.properties.iter().collect();
        let graph = Graph::build(&content, &props, Limits { depth: 12, max_states: 100_000 });
        let alphabet = Arc::new(Alphabet::new(&content, &props));
        let model = Model::build(&content, &alphabet, &props);
        for (i, p) in props.iter().enumerate() {
            let name = format!("{}: property \"{}\"", path.display(), p.name);
            let Some(&want) = expected.get(&p.place.line) else {
                failures.push(format!("{name}: no expectation"));
                continue;
            };
            let got = graph.check(i, p);
            match (want, &got) {
                (Expect::Fails(n), Verdict::Failed(c)) if c.steps.len() == n => {}
                (Expect::Proved, Verdict::Proved { .. }) | (Expect::Exhausted, Verdict::Exhausted { .. }) => {}
                _ => failures.push(format!("{name}: expected {want:?}, exhaustive found {got:?}")),
            }
            if want == Expect::Proved && !liveness(p) {
                // What is proved, the random checker cannot break.
                let r = random::search(&content, &alphabet, p, Search { seed: 11, cases: 300, length: 30 });
                if r.failed() {
                    failures.push(format!("{name}: proved, yet the random checker found {}", r.summary()));
                }
            }
            // IC3 on the circuit agrees: what fails has a counterexample that
            // replays on the engine, what holds is proved for runs of any length.
            if !liveness(p) {
                let model = model.as_ref().unwrap_or_else(|e| panic!("{name}: no circuit: {e:?}"));
                match (want, prove::prove(&content, &alphabet, model, i, p, Ic3Limits::frames(prove::MAX_FRAMES))) {
                    (Expect::Fails(_), Some(Verdict::Failed(_)))
                    | (Expect::Proved | Expect::Exhausted, Some(Verdict::Inductive { sampled: None, .. })) => {}
                    (_, other) => failures.push(format!("{name}: expected {want:?}, IC3 found {other:?}")),
                }
            }
            if let (Expect::Fails(n), false) = (want, liveness(p)) {
                let r = random::search(&content, &alphabet, p, Search { seed: 7, cases: 2000, length: 30 });
                match &r {
                    Verdict::Failed(c) if c.steps.len() <= n + 2 => {}
                    _ => failures.push(format!("{name}: the random checker found {}", r.summary())),
                }
            }
        }
    }
    assert!(failures.is_empty(), "\n{}", failures.join("\n"));
}
