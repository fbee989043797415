//! Experience runs of the DLA stack (the data and the curve are
//! [`crate::experience`]'s): one mission with a given case base
//! ([`mission`]), the evaluation of a base on held-out missions with
//! learning off ([`evaluate`]), and the whole series `situ run --missions
//! N` makes ([`experience`]); [`load_or_train`] is the base a run or a
//! series starts from.

use crate::experience::{evaluation_points, Evaluation, Experience, Mission};
use crate::stack::{train, Cases, Dla, SharedCases, NOVELTY, TRAINING_SECONDS};
use situ_compiler::bundle::Content;
use situ_sim::stack::{Outcome, Recording, StackConfig, StackError, StackRun};
use situ_sim::world::World;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The seeds of the held-out missions: `HELD_OUT + j`, far from the
/// learning missions' (`--seed` onwards).
pub const HELD_OUT: u64 = 1_000_000;

/// At most this many missions (and held-out missions) in one series.
pub const MAX_MISSIONS: u64 = 10_000;

/// A case base file that cannot be used (it is left as it was).
#[derive(Debug, thiserror::Error)]
#[error("`{}`: {source} (the file is left as it was)", .path.display())]
pub struct CasesFileError {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub source: crate::cases::CaseError,
}

/// The case base of a DLA run: the file's, or a new one trained by the
/// scripted driver (seeded with `seed`) when the file does not exist or
/// none was given. Returns the base and whether it was read.
pub fn load_or_train(path: Option<&Path>, seed: u64) -> Result<(Cases, bool), CasesFileError> {
    match path {
        Some(path) if path.exists() => {
            Cases::read(path).map(|c| (c, true)).map_err(|source| CasesFileError { path: path.to_path_buf(), source })
        }
        _ => Ok((train(seed, TRAINING_SECONDS, NOVELTY), false)),
    }
}

/// A mission that could not be run.
#[derive(Debug, thiserror::Error)]
pub enum MissionError {
    /// The rules' agents do not bind to the DLA stack's.
    #[error("the rules cannot run on the DLA stack: {0}")]
    Setup(StackError),
    /// The run could not be finished (its recording).
    #[error(transparent)]
    Run(StackError),
}

/// One mission of the DLA stack in `world` with the case base `cases`
/// (learning into it when `learn`); `progress` is called once a simulated
/// second.
#[allow(clippy::too_many_arguments)]
pub fn mission(
    content: &Arc<Content>,
    world: &World,
    index: usize,
    seed: u64,
    until: f64,
    learn: bool,
    cases: &SharedCases,
    progress: &mut dyn FnMut(&StackRun),
) -> Result<Mission, MissionError> {
    let cfg = StackConfig { seed, until, samples: false, ..StackConfig::default() };
    let stack = Arc::new(Dla::new(Some(cases.clone()), learn));
    let mut run =
        StackRun::new(content.clone(), stack.clone(), world, cfg, Recording::default()).map_err(MissionError::Setup)?;
    run.run(progress);
    let report = run.finish().map_err(MissionError::Run)?;
    let (routes, learnt) = {
        let p = crate::stack::lock_plans(stack.plans());
        (p.routes, p.learnt)
    };
    Ok(Mission {
        index,
        seed,
        done: report.outcome.success(),
        collision: matches!(report.outcome, Outcome::Collision { .. }),
        end: report.outcome.time(),
        outcome: report.outcome.brief(),
        distance: report.metrics.summary.distance,
        routes,
        learnt,
        cases: cases.lock().unwrap_or_else(|e| e.into_inner()).len(),
    })
}

/// A copy of the base as it stands after `after` learning missions, tried
/// on `count` held-out missions (seeds [`HELD_OUT`]…) with learning off.
pub fn evaluate(
    content: &Arc<Content>,
    world: &World,
    after: usize,
    count: u64,
    until: f64,
    cases: &SharedCases,
    progress: &mut dyn FnMut(u64, &StackRun),
) -> Result<Evaluation, MissionError> {
    let copy = cases.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let n = copy.len();
    let copy: SharedCases = Arc::new(Mutex::new(copy));
    let mut missions = Vec::new();
    for j in 0..count {
        let mut each = |r: &StackRun| progress(j, r);
        missions.push(mission(content, world, j as usize + 1, HELD_OUT + j, until, false, &copy, &mut each)?);
    }
    Ok(Evaluation { after, cases: n, missions })
}

/// How a series of missions is made.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Learning missions.
    pub missions: u64,
    /// Held-out missions per evaluation (0: no evaluation).
    pub held_out: u64,
    /// The first learning mission's seed (then `seed + 1`, …).
    pub seed: u64,
    /// Each mission's time limit (s).
    pub until: f64,
    /// Whether the missions learn on line.
    pub learn: bool,
}

/// A series that cannot be made.
#[derive(Debug, thiserror::Error)]
pub enum SeriesError {
    /// Too few or too many missions.
    #[error("--missions must be between 1 and {MAX_MISSIONS}, --evaluate at most {MAX_MISSIONS}")]
    Count,
    /// A mission failed to run.
    #[error(transparent)]
    Mission(#[from] MissionError),
}

/// Where a series is: a learning mission (from 1), or a held-out mission
/// (from 1) of the evaluation after so many learning missions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Learning mission `k` of `n`.
    Learning(usize),
    /// Held-out mission `j` of the evaluation after `after` missions.
    HeldOut {
        /// Learning missions before the evaluation.
        after: usize,
        /// The held-out mission, from 1.
        j: u64,
    },
}

/// Checks a series' counts before anything is trained or read.
pub fn check(series: &Series) -> Result<(), SeriesError> {
    if !(1..=MAX_MISSIONS).contains(&series.missions) || series.held_out > MAX_MISSIONS {
        return Err(SeriesError::Count);
    }
    Ok(())
}

/// DLA's experience: `series.missions` learning missions on `world`, one
/// case base (`cases`) carried from each to the next; before the first,
/// after the last and about every sixth between, a copy of the base tried
/// on `series.held_out` held-out missions with learning off (none when 0).
/// `progress` is called once a simulated second with where the series is.
pub fn experience(
    content: &Arc<Content>,
    world: &World,
    series: &Series,
    cases: &SharedCases,
    progress: &mut dyn FnMut(Step, &StackRun),
) -> Result<Experience, SeriesError> {
    check(series)?;
    let mut experience = Experience::default();
    let n = series.missions as usize;
    let points = if series.held_out > 0 { evaluation_points(n) } else { Vec::new() };
    for k in 0..=n {
        if points.contains(&k) {
            let mut each = |j: u64, r: &StackRun| progress(Step::HeldOut { after: k, j: j + 1 }, r);
            let e = evaluate(content, world, k, series.held_out, series.until, cases, &mut each)?;
            experience.evaluations.push(e);
        }
        if k == n {
            break;
        }
        let seed = series.seed.wrapping_add(k as u64);
        let mut each = |r: &StackRun| progress(Step::Learning(k + 1), r);
        experience.missions.push(mission(content, world, k + 1, seed, series.until, series.learn, cases, &mut each)?);
    }
    Ok(experience)
}
