//! Proofs for runs of any length: a property's bad-state output of the
//! [`Model`] checked by [`ic3`](super::ic3).
//!
//! The circuit's time is exact (ages and gaps are numbers of nanoseconds,
//! capped past the largest duration), so the proof covers every run with
//! any gaps; the payload classes are exact for comparisons with constants
//! ([`Alphabet`]). What the alphabet still samples (values compared with
//! variables in chains of three or more, payloads cut) is said in the
//! verdict, which is then not "proved". A counterexample is a run of
//! letters and gaps, replayed on the real engine: the property must fail
//! on it there too, or the verdict says that the two disagree.

use super::abstraction::Alphabet;
use super::ic3::{self, Outcome};
use super::model::Model;
use super::random;
use super::{Counterexample, RunStep, Verdict};
use situ_compiler::bundle::Content;
use situ_compiler::spec::PropertySpec;
use std::cell::Cell;
use std::sync::Arc;
use std::time::{Duration, Instant};

/// The most frames IC3 opens before it gives up.
pub const MAX_FRAMES: usize = 200;

/// What the alphabet samples other than time (the circuit's time is exact).
pub fn sampled(alphabet: &Alphabet) -> Option<String> {
    let rest: Vec<&str> = alphabet.samples.iter().filter(|s| !s.starts_with("time gaps")).map(String::as_str).collect();
    (!rest.is_empty()).then(|| rest.join("; "))
}

/// Proves property `index` of the model for runs of any length, or finds a
/// counterexample; `None` for a liveness property or when IC3 gives up.
pub fn prove(
    content: &Arc<Content>,
    alphabet: &Alphabet,
    model: &Model,
    index: usize,
    property: &PropertySpec,
    budget: Option<Duration>,
) -> Option<Verdict> {
    let bad = model.bad.get(index).copied().flatten()?;
    let deadline = budget.map(|b| Instant::now() + b);
    match ic3::check(&model.aig, bad, MAX_FRAMES, deadline) {
        Outcome::Proved { frames, clauses } => Some(Verdict::Inductive { frames, clauses, sampled: sampled(alphabet) }),
        Outcome::Unknown { .. } => None,
        Outcome::Counterexample(inputs) => {
            let run: Vec<RunStep> = inputs
                .iter()
                .map(|i| {
                    let (l, gap) = model.choice(i);
                    let letter = &alphabet.letters[l];
                    RunStep { event: letter.event, payload: letter.payload.clone(), gap }
                })
                .collect();
            Some(match random::check_run(content, property, &run, &Cell::new(0)) {
                Err((point, reason)) => Verdict::Failed(Counterexample::replay(content, &run[..point], point, reason)),
                Ok(()) => Verdict::Disagree { events: run.len() },
            })
        }
    }
}
