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
use super::ic3::{self, Limits, Outcome};
use super::model::Model;
use super::random;
use super::{Counterexample, RunStep, Verdict};
use situ_compiler::bundle::Content;
use situ_compiler::spec::PropertySpec;
use std::cell::Cell;
use std::sync::Arc;

/// The most frames IC3 opens before it gives up.
pub const MAX_FRAMES: usize = 200;

/// What the alphabet samples other than time (the circuit's time is exact).
pub fn sampled(alphabet: &Alphabet) -> Option<String> {
    let rest: Vec<&str> = alphabet.samples.iter().filter(|s| !s.starts_with("time gaps")).map(String::as_str).collect();
    (!rest.is_empty()).then(|| rest.join("; "))
}

/// Proves property `index` of the model for runs of any length, or finds a
/// counterexample (shrunk as the random checker's are: fewest events, round
/// values and gaps), or says where it gave up ([`Verdict::GaveUp`]); `None`
/// for a liveness property (the circuit has no bad output for it).
pub fn prove(
    content: &Arc<Content>,
    alphabet: &Arc<Alphabet>,
    model: &Model,
    index: usize,
    property: &PropertySpec,
    limits: Limits,
) -> Option<Verdict> {
    let bad = model.bad.get(index).copied().flatten()?;
    match ic3::check(&model.aig, bad, limits) {
        Outcome::Proved { frames, clauses } => Some(Verdict::Inductive { frames, clauses, sampled: sampled(alphabet) }),
        Outcome::Unknown { depth, work, stop } => Some(Verdict::GaveUp { depth, work, stop }),
        Outcome::Counterexample(inputs) => {
            let run: Vec<RunStep> = model.run_of(alphabet, &inputs);
            Some(match random::check_run(content, property, &run, &Cell::new(0)) {
                Err((point, _)) => {
                    let run = random::shrink(content, alphabet, property, run[..point].to_vec());
                    let (point, reason) = random::check_run(content, property, &run, &Cell::new(0))
                        .err()
                        .unwrap_or((run.len(), String::new()));
                    Verdict::Failed(Counterexample::replay(content, &run[..point.min(run.len())], point, reason))
                }
                Ok(()) => Verdict::Disagree { events: run.len() },
            })
        }
    }
}
