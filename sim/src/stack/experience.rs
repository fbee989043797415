//! Experience runs of the DLA stack (the data and the curve are
//! [`crate::dla::experience`]'s): one mission with a given case base, and
//! the evaluation of a base on held-out missions with learning off.
//! `situ run --missions N` and the tests drive these.

use super::{dla, Outcome, Recording, StackConfig, StackKind, StackRun};
use crate::dla::experience::{Evaluation, Mission};
use crate::world::World;
use situ_compiler::bundle::Content;
use std::sync::{Arc, Mutex};

/// The seeds of the held-out missions: `HELD_OUT + j`, far from the
/// learning missions' (`--seed` onwards).
pub const HELD_OUT: u64 = 1_000_000;

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
    cases: &dla::CasesHandle,
    progress: &mut dyn FnMut(&StackRun),
) -> Result<Mission, String> {
    let cfg = StackConfig { seed, until, samples: false, learn, cases: Some(cases.clone()), ..StackConfig::default() };
    let mut run = StackRun::new(content.clone(), StackKind::Dla, world, cfg, Recording::default())
        .map_err(|e| format!("the rules cannot run on the DLA stack: {e}"))?;
    run.run(progress);
    let plans = run.plans().cloned();
    let report = run.finish()?;
    let (routes, learnt) = plans.map_or((0, 0), |p| {
        let p = p.lock().unwrap_or_else(|e| e.into_inner());
        (p.routes, p.learnt)
    });
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
        cases: cases.0.lock().unwrap_or_else(|e| e.into_inner()).len(),
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
    cases: &dla::CasesHandle,
    progress: &mut dyn FnMut(u64, &StackRun),
) -> Result<Evaluation, String> {
    let copy = cases.0.lock().unwrap_or_else(|e| e.into_inner()).clone();
    let n = copy.len();
    let copy = dla::CasesHandle(Arc::new(Mutex::new(copy)));
    let mut missions = Vec::new();
    for j in 0..count {
        let mut each = |r: &StackRun| progress(j, r);
        missions.push(mission(content, world, j as usize + 1, HELD_OUT + j, until, false, &copy, &mut each)?);
    }
    Ok(Evaluation { after, cases: n, missions })
}
