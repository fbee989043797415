//! Random search for counterexamples, with shrinking (proptest).
//!
//! A run is drawn by [`RunStrategy`]: the seeded generator of
//! [`stream`](situ_runtime::stream) — events guided by the rules that can fire in
//! the current state half of the time, agents in proportion to their rates
//! otherwise, payloads near the rules' thresholds, exponential gaps — run
//! without resets for `length` events, from a seed that proptest draws (one
//! run in four slowed down, so that bounds in time are exceeded). A
//! failing run shrinks (its [`RunTree`]) by removing events one at a time
//! (the others keep their times; repeated while it helps), then by replacing each payload value by the
//! representative of its class ([`Alphabet`]: a round value that every
//! comparison treats alike), then by rounding gaps to 0, 10 ms or 1 ms.
//! Every candidate is checked on the real system; what is left is
//! 1-minimal: removing any one event makes it pass.

use super::abstraction::Alphabet;
use super::monitor::{Monitor, MonitorState};
use super::{Counterexample, RunStep, System, Verdict};
use proptest::prelude::Rng;
use proptest::strategy::{NewTree, Strategy, ValueTree};
use proptest::test_runner::{Config, RngAlgorithm, TestCaseError, TestError, TestRng, TestRunner};
use situ_compiler::bundle::{Content, Value};
use situ_compiler::spec::PropertySpec;
use situ_runtime::rete::PostError;
use situ_runtime::stream::Generator;
use std::cell::Cell;
use std::sync::Arc;

/// How much to search.
#[derive(Debug, Clone, Copy)]
pub struct Search {
    pub seed: u64,
    /// Runs.
    pub cases: u32,
    /// Events per run.
    pub length: usize,
}

/// Runs drawn from a program's event alphabet, guided by its rules.
#[derive(Clone)]
pub struct RunStrategy {
    content: Arc<Content>,
    alphabet: Arc<Alphabet>,
    length: usize,
}

impl std::fmt::Debug for RunStrategy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "RunStrategy({} events of {})", self.length, self.content.source)
    }
}

impl RunStrategy {
    pub fn new(content: Arc<Content>, alphabet: Arc<Alphabet>, length: usize) -> RunStrategy {
        RunStrategy { content, alphabet, length }
    }

    /// The run of a seed. One run in four is slowed down (its gaps times
    /// 4 or 20), so that bounds in time are exceeded without long runs.
    pub fn draw(&self, seed: u64) -> Vec<RunStep> {
        let mut g = Generator::new(self.content.clone(), seed).reset_on_final(false);
        let scale = [1, 1, 1, 1, 1, 1, 4, 20][(seed >> 61) as usize];
        let mut last = 0u64;
        let mut run = Vec::with_capacity(self.length);
        for _ in 0..self.length {
            let Some(e) = g.next_event() else { break };
            run.push(RunStep { event: e.event, payload: e.payload, gap: (e.time - last).saturating_mul(scale) });
            last = e.time;
        }
        run
    }
}

impl Strategy for RunStrategy {
    type Tree = RunTree;
    type Value = Vec<RunStep>;

    fn new_tree(&self, runner: &mut TestRunner) -> NewTree<Self> {
        let seed = runner.rng().next_u64();
        Ok(RunTree::new(self.draw(seed), self.alphabet.clone()))
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Remove,
    Values,
    Gaps,
    Done,
}

/// A run and how to shrink it.
#[derive(Debug, Clone)]
pub struct RunTree {
    current: Vec<RunStep>,
    /// The run before the latest simplification (to go back to).
    previous: Option<Vec<RunStep>>,
    alphabet: Arc<Alphabet>,
    phase: Phase,
    cursor: usize,
    removed_in_pass: bool,
    passes: u32,
}

/// The gaps a gap is rounded to, in order.
const GAP_OPTIONS: usize = 3;

impl RunTree {
    fn new(run: Vec<RunStep>, alphabet: Arc<Alphabet>) -> RunTree {
        RunTree {
            current: run,
            previous: None,
            alphabet,
            phase: Phase::Remove,
            cursor: 0,
            removed_in_pass: false,
            passes: 0,
        }
    }

    /// The next candidate at or after the cursor, if any.
    fn candidate(&mut self) -> Option<Vec<RunStep>> {
        loop {
            match self.phase {
                Phase::Remove => {
                    if self.cursor < self.current.len() {
                        // The others keep their times: the gap goes to the next event.
                        let mut c = self.current.clone();
                        let removed = c.remove(self.cursor);
                        if let Some(next) = c.get_mut(self.cursor) {
                            next.gap = next.gap.saturating_add(removed.gap);
                        }
                        return Some(c);
                    }
                    if self.removed_in_pass && self.passes < 8 {
                        self.passes += 1;
                        self.removed_in_pass = false;
                    } else {
                        self.phase = Phase::Values;
                    }
                    self.cursor = 0;
                }
                Phase::Values => {
                    let fields: usize = self.current.iter().map(|s| s.payload.len()).sum();
                    if self.cursor >= fields {
                        self.phase = Phase::Gaps;
                        self.cursor = 0;
                        continue;
                    }
                    let (mut step, mut field) = (0, self.cursor);
                    while field >= self.current[step].payload.len() {
                        field -= self.current[step].payload.len();
                        step += 1;
                    }
                    let s = &self.current[step];
                    let v = s.payload[field];
                    let rep = self.alphabet.representative(s.event, field, v);
                    if !same(rep, v) {
                        let mut c = self.current.clone();
                        c[step].payload[field] = rep;
                        return Some(c);
                    }
                    self.cursor += 1;
                }
                Phase::Gaps => {
                    if self.cursor >= self.current.len() * GAP_OPTIONS {
                        self.phase = Phase::Done;
                        continue;
                    }
                    let (step, option) = (self.cursor / GAP_OPTIONS, self.cursor % GAP_OPTIONS);
                    let gap = self.current[step].gap;
                    let rounded = match option {
                        0 => 0,
                        1 => round(gap, 10_000_000),
                        _ => round(gap, 1_000_000),
                    };
                    if rounded != gap {
                        let mut c = self.current.clone();
                        c[step].gap = rounded;
                        return Some(c);
                    }
                    self.cursor += 1;
                }
                Phase::Done => return None,
            }
        }
    }
}

fn round(x: u64, unit: u64) -> u64 {
    (x + unit / 2) / unit * unit
}

fn same(a: Value, b: Value) -> bool {
    match (a, b) {
        (Value::F64(x), Value::F64(y)) => x.to_bits() == y.to_bits(),
        _ => a == b,
    }
}

impl ValueTree for RunTree {
    type Value = Vec<RunStep>;

    fn current(&self) -> Vec<RunStep> {
        self.current.clone()
    }

    fn simplify(&mut self) -> bool {
        if self.previous.take().is_some() {
            // The latest candidate still fails: keep it and go on.
            match self.phase {
                Phase::Remove => self.removed_in_pass = true,
                _ => self.cursor += 1,
            }
        }
        match self.candidate() {
            Some(c) => {
                self.previous = Some(std::mem::replace(&mut self.current, c));
                true
            }
            None => false,
        }
    }

    fn complicate(&mut self) -> bool {
        match self.previous.take() {
            Some(p) => {
                self.current = p;
                self.cursor += 1;
                true
            }
            None => false,
        }
    }
}

/// Checks a property on one run: `Err((point, reason))` where it fails.
pub fn check_run(
    content: &Arc<Content>,
    property: &PropertySpec,
    run: &[RunStep],
    steps: &Cell<u64>,
) -> Result<(), (usize, String)> {
    let monitor = Monitor::new(property);
    let mut sys = System::new(content.clone());
    let mut st = MonitorState::default();
    let (p, q) = sys.point(property);
    if let Some(r) = monitor.step(&mut st, p, q, 0) {
        return Err((0, r));
    }
    let mut time = 0u64;
    for (i, s) in run.iter().enumerate() {
        time = time.saturating_add(s.gap);
        steps.set(steps.get() + 1);
        match sys.post(s.event, time, &s.payload) {
            Ok(_) => {}
            Err(e @ PostError::Cascade { .. }) => return Err((i + 1, e.describe(content))),
            // Refused: the event changes nothing (cannot happen with the generator's events).
            Err(_) => continue,
        }
        let (p, q) = sys.point(property);
        if let Some(r) = monitor.step(&mut st, p, q, s.gap) {
            return Err((i + 1, r));
        }
    }
    Ok(())
}

/// The most candidates tried while shrinking a run.
const MAX_SHRINK: u32 = 20_000;

/// Shrinks a run that breaks the property as the search's failures are
/// (events removed one at a time, values to their class's representative,
/// gaps rounded), each candidate checked on the real system. `run` must
/// break the property; so does the result, which is 1-minimal when the
/// candidates ran out before [`MAX_SHRINK`].
pub fn shrink(
    content: &Arc<Content>,
    alphabet: &Arc<Alphabet>,
    property: &PropertySpec,
    run: Vec<RunStep>,
) -> Vec<RunStep> {
    let steps = Cell::new(0u64);
    let fails = |r: &[RunStep]| check_run(content, property, r, &steps).is_err();
    if !fails(&run) {
        return run;
    }
    let mut tree = RunTree::new(run.clone(), alphabet.clone());
    let mut best = run;
    if !tree.simplify() {
        return best;
    }
    for _ in 0..MAX_SHRINK {
        let current = tree.current();
        if fails(&current) {
            best = current;
            if !tree.simplify() {
                break;
            }
        } else if !tree.complicate() {
            break;
        }
    }
    best
}

/// Searches runs for a counterexample; a failing run is shrunk first.
pub fn search(content: &Arc<Content>, alphabet: &Arc<Alphabet>, property: &PropertySpec, s: Search) -> Verdict {
    let strategy = RunStrategy::new(content.clone(), alphabet.clone(), s.length);
    let config = Config {
        cases: s.cases.max(1),
        failure_persistence: None,
        max_shrink_iters: MAX_SHRINK,
        // No wall-clock limit: the shrunk run must not depend on the machine's load.
        max_shrink_time: 0,
        ..Config::default()
    };
    let mut seed = [0u8; 32];
    seed[..8].copy_from_slice(&s.seed.to_le_bytes());
    let mut runner = TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &seed));
    let steps = Cell::new(0u64);
    let result = runner
        .run(&strategy, |run| check_run(content, property, &run, &steps).map_err(|(_, why)| TestCaseError::fail(why)));
    match result {
        Ok(()) => Verdict::NotFound { runs: s.cases as u64, length: s.length, steps: steps.get() },
        Err(TestError::Fail(_, run)) => {
            let (point, reason) =
                check_run(content, property, &run, &steps).err().unwrap_or((run.len(), String::new()));
            let run = &run[..point.min(run.len())];
            Verdict::Failed(Counterexample::replay(content, run, point, reason))
        }
        // Too many rejections: cannot happen, no case is rejected.
        Err(TestError::Abort(_)) => Verdict::NotFound { runs: 0, length: s.length, steps: steps.get() },
    }
}

/// Steps per second of the random checker on a property (for the benchmark):
/// `(steps, seconds)` for `cases` runs of `length` events.
pub fn throughput(content: &Arc<Content>, property: &PropertySpec, seed: u64, cases: u32, length: usize) -> (u64, f64) {
    let alphabet = Arc::new(Alphabet::new(content, &[property]));
    let strategy = RunStrategy::new(content.clone(), alphabet, length);
    let runs: Vec<Vec<RunStep>> = (0..cases as u64).map(|k| strategy.draw(seed ^ k)).collect();
    let steps = Cell::new(0u64);
    let start = std::time::Instant::now();
    for run in &runs {
        let _ = check_run(content, property, run, &steps);
    }
    (steps.get(), start.elapsed().as_secs_f64())
}
