//! `situ run RULES --missions N [--evaluate M]`: DLA's experience. N
//! successive learning missions on the scenario, seeds `--seed`, `--seed +
//! 1`, …, one case base carried from each mission to the next and learning
//! on line (unless `--no-learning`); before the first, after the last and
//! about every N/6 between, a copy of the base as it stands is tried on M
//! held-out missions (seeds [`HELD_OUT`]…, default 8) with learning off:
//! the teacher is gone, the cases alone drive. Prints a line per learning
//! mission, the halves, the evaluations (the curve: held-out missions done
//! against experience), and how much simulated time took how much wall
//! time; with `--out DIR` writes `experience.svg` and `experience.json`;
//! with `--cases FILE` reads the base before the first mission and writes
//! it after the last. Exit 0 when the last learning mission and every
//! held-out mission of the last evaluation are done, 1 otherwise, 2 on
//! usage or I/O.

use super::{FAILED, OK, USAGE};
use situ_compiler::bundle::Content;
use situ_dla::missions::{self, load_or_train, Series, Step, HELD_OUT};
use situ_dla::stack::SharedCases;
use situ_sim::scenario::Scenario;
use situ_sim::stack::{Stack, StackRun};
use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Instant;

/// What `situ run --missions` was given besides the rules and the scenario.
pub struct Args<'a> {
    /// The rules file, for messages.
    pub file: &'a Path,
    /// The first learning mission's seed.
    pub seed: u64,
    /// `--cases`: the case base read before and written after.
    pub cases: Option<&'a Path>,
    /// Whether the missions learn on line.
    pub learn: bool,
    /// `--evaluate`: held-out missions per evaluation.
    pub evaluate: u64,
    /// `--out`: where the curve and its data go.
    pub out: Option<&'a Path>,
}

/// `missions` learning missions (`--missions`), the evaluations of
/// `args.evaluate` held-out missions each ([`missions::experience`]).
pub fn run(
    args: &Args<'_>,
    content: Arc<Content>,
    kind: &dyn Stack,
    scenario: &Scenario,
    missions: u64,
    until: f64,
) -> u8 {
    let held_out = args.evaluate;
    if kind.name() != situ_dla::stack::NAME {
        eprintln!(
            "error: --missions runs successive missions of a DLA stack (agents of rules/dla.situ, whose reactive \
             layer learns); `{}` runs on the {} stack",
            args.file.display(),
            kind.title()
        );
        return USAGE;
    }
    let series = Series { missions, held_out, seed: args.seed, until, learn: args.learn };
    if let Err(e) = missions::check(&series) {
        eprintln!("error: {e}");
        return USAGE;
    }
    let (cases, read) = match load_or_train(args.cases, args.seed) {
        Ok(c) => c,
        Err(e) => {
            eprintln!("error: --cases {e}");
            return USAGE;
        }
    };
    let before = cases.len();
    let handle: SharedCases = Arc::new(Mutex::new(cases));
    let mut line = super::LiveLine::new();
    let start = Instant::now();
    let mut progress = |step: Step, r: &StackRun| match step {
        Step::HeldOut { after, j } => {
            line.draw(|| format!("after {after}: held-out {j}/{held_out}: {}", r.progress().line()))
        }
        Step::Learning(k) => line.draw(|| format!("mission {k}/{missions}: {}", r.progress().line())),
    };
    let result = missions::experience(&content, &scenario.world, &series, &handle, &mut progress);
    line.clear();
    let experience = match result {
        Ok(e) => e,
        Err(e) => {
            eprintln!("error: `{}`: {e}", args.file.display());
            return USAGE;
        }
    };
    let wall = start.elapsed().as_secs_f64();
    println!(
        "{} on {}: {missions} learning mission(s), seeds {}–{}; {before} case(s) {}, {}\n",
        content.source,
        scenario.name,
        args.seed,
        args.seed.wrapping_add(missions - 1),
        if read { "read" } else { "trained" },
        if args.learn { "learning on line" } else { "no learning" }
    );
    print!("{}", experience.table());
    if held_out > 0 {
        println!(
            "\n  the case base on {held_out} held-out mission(s) (seeds {HELD_OUT}–{}), learning off:\n",
            HELD_OUT + held_out - 1
        );
        print!("{}", experience.evaluation_table());
    }
    let simulated = experience.simulated();
    println!(
        "\n  simulated {simulated:.0} s ({:.2} h) in {wall:.2} s of wall time: {:.0}× real time",
        simulated / 3600.0,
        simulated / wall.max(1e-9)
    );
    if let Some(path) = args.cases {
        let cases = handle.lock().unwrap_or_else(|e| e.into_inner());
        if let Err(e) = cases.write(path) {
            eprintln!("error: cannot write the case base `{}`: {e}", path.display());
            return USAGE;
        }
        println!("  case base         {} cases written to {}", cases.len(), path.display());
    }
    if let Some(out) = args.out {
        let title = format!("{} on {}: experience over {missions} missions", content.source, scenario.name);
        let svg = match experience.svg(&title) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("error: {e}");
                return USAGE;
            }
        };
        let json = serde_json::to_string_pretty(&experience).unwrap_or_default();
        for (name, bytes) in [("experience.svg", svg.as_bytes()), ("experience.json", json.as_bytes())] {
            if let Err(e) = super::write_atomically(&out.join(name), bytes) {
                eprintln!("error: cannot write `{}`: {e}", out.join(name).display());
                return USAGE;
            }
        }
        println!("wrote {}", out.display());
    }
    let last_done = experience.missions.last().is_some_and(|m| m.done);
    let held_out_done = experience.evaluations.last().is_none_or(|e| e.missions.iter().all(|m| m.done));
    if last_done && held_out_done {
        OK
    } else {
        FAILED
    }
}
