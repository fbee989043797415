//! The circuit is the abstraction: random runs on the real engine and on
//! the circuit reach the same abstract state at every point, on the
//! repository's rule files, the planted bugs and the examples. A cascade
//! error of the engine is the circuit's too.

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use situ_compiler::bundle;
use situ_compiler::bundle::Value;
use situ_compiler::loader::FsLoader;
use situ_compiler::spec::{self, PropertySpec};
use situ_runtime::stream::Generator;
use situ_verify::abstraction::Alphabet;
use situ_verify::model::Model;
use situ_verify::System;
use std::path::{Path, PathBuf};
use std::sync::Arc;

fn files() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut out = vec![root.join("rules/outdoor.situ"), root.join("rules/ugv.situ")];
    for dir in ["tests/verify", "examples"] {
        let Ok(rd) = std::fs::read_dir(root.join(dir)) else { continue };
        let mut fs: Vec<PathBuf> =
            rd.map(|e| e.expect("entry").path()).filter(|p| p.extension().is_some_and(|e| e == "situ")).collect();
        fs.sort();
        out.extend(fs);
    }
    out
}

/// Walks `runs` random runs of `len` events on both and compares the keys.
fn agree(path: &Path, runs: usize, len: usize) -> Result<usize, String> {
    let checked = situ_compiler::check(path, &FsLoader).map_err(|e| format!("{e:?}"))?;
    if checked.errors() > 0 {
        return Ok(0);
    }
    let content = Arc::new(bundle::build(&checked));
    let spec = spec::lower(&checked);
    let props: Vec<&PropertySpec> = spec.properties.iter().collect();
    let alphabet = Alphabet::new(&content, &props);
    let model = match Model::build(&content, &alphabet, &props) {
        Ok(m) => m,
        Err(_) => return Ok(0),
    };
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (mut want, mut got) = (Vec::new(), Vec::new());
    let mut points = 0;
    let mut states = std::collections::BTreeSet::new();
    for run in 0..runs {
        let mut sys = System::new(content.clone());
        let mut latches = vec![false; model.aig.latches().len()];
        let mut last = 0;
        for step in 0..len {
            // Mostly short gaps, so that runs build up.
            let g = if rng.random_bool(0.6) { 0 } else { rng.random_range(0..alphabet.gaps.len()) };
            // The circuit takes any gap: a fifth of them at random.
            let largest = alphabet.gaps.iter().copied().max().unwrap_or(0);
            let gap =
                if rng.random_bool(0.2) { rng.random_range(0..=largest + largest / 4 + 1) } else { alphabet.gaps[g] };
            let mut l = rng.random_range(0..alphabet.letters.len());
            // Often the same letter again, so that runs (`xN`) build up.
            if step > 0 && rng.random_bool(0.3) {
                l = last;
            }
            // Half the time, a letter that changes the state (when one does),
            // so that the runs leave the first states.
            if rng.random_bool(0.5) {
                let movers: Vec<usize> = (0..alphabet.letters.len())
                    .filter(|&k| {
                        let mut t = sys.clone();
                        let x = &alphabet.letters[k];
                        let time = t.engine.now().saturating_add(gap);
                        t.post(x.event, time, &x.payload).is_ok_and(|s| s.to != s.from)
                    })
                    .collect();
                if !movers.is_empty() {
                    l = movers[rng.random_range(0..movers.len())];
                }
            }
            last = l;
            let (next, _) = model.simulate(&latches, &model.inputs(l, gap));
            latches = next;
            let (_, val) = model.simulate(&latches, &model.inputs(0, 0));
            let letter = &alphabet.letters[l];
            let time = sys.engine.now().saturating_add(gap);
            let posted = sys.post(letter.event, time, &letter.payload);
            if posted.is_err() {
                if !model.cascade(&val) {
                    return Err(format!(
                        "{}: run {run} step {step}: the engine's cascade error is not the circuit's",
                        path.display()
                    ));
                }
                break;
            }
            alphabet.key(&sys, &mut want);
            model.key(&alphabet, &val, &mut got);
            if want != got || model.cascade(&val) {
                return Err(format!(
                    "{}: run {run} step {step} ({}): engine {want:?}, circuit {got:?}",
                    path.display(),
                    situ_verify::show_event(&content, letter.event, &letter.payload)
                ));
            }
            points += 1;
            states.insert(sys.engine.state());
        }
    }
    // Runs of the rule-guided stream generator (`situ bench`'s), its
    // values taken to their classes and its gaps as they come.
    for seed in 0..20 {
        let mut gen = Generator::new(content.clone(), seed).reset_on_final(false);
        let mut sys = System::new(content.clone());
        let mut latches = vec![false; model.aig.latches().len()];
        for step in 0..200 {
            let Some(ev) = gen.next_event() else { break };
            let payload: Vec<Value> =
                ev.payload.iter().enumerate().map(|(f, v)| alphabet.representative(ev.event, f, *v)).collect();
            let Some(l) = alphabet.letters.iter().position(|x| x.event == ev.event && same(&x.payload, &payload))
            else {
                continue;
            };
            let gap = ev.time - sys.engine.now();
            let (next, _) = model.simulate(&latches, &model.inputs(l, gap));
            latches = next;
            let (_, val) = model.simulate(&latches, &model.inputs(0, 0));
            if sys.post(ev.event, ev.time, &payload).is_err() {
                if !model.cascade(&val) {
                    return Err(format!(
                        "{}: stream {seed} step {step}: the engine's cascade error is not the circuit's",
                        path.display()
                    ));
                }
                break;
            }
            alphabet.key(&sys, &mut want);
            model.key(&alphabet, &val, &mut got);
            if want != got || model.cascade(&val) {
                return Err(format!("{}: stream {seed} step {step}: engine {want:?}, circuit {got:?}", path.display()));
            }
            points += 1;
            states.insert(sys.engine.state());
        }
    }
    if content.states.len() > 2 && states.len() < 3 {
        return Err(format!("{}: the runs visited only {} states", path.display(), states.len()));
    }
    Ok(points)
}

#[test]
fn the_circuit_steps_as_the_engine_does() {
    let mut total = 0;
    let mut failures = Vec::new();
    let mut modelled = 0;
    for f in files() {
        match agree(&f, 40, 60) {
            Ok(0) => {}
            Ok(n) => {
                total += n;
                modelled += 1;
            }
            Err(e) => failures.push(e),
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    assert!(modelled >= 8, "only {modelled} files modelled");
    assert!(total > 10_000, "only {total} points compared");
}

fn same(a: &[Value], b: &[Value]) -> bool {
    a.len() == b.len()
        && a.iter().zip(b).all(|(x, y)| match (x, y) {
            (Value::F64(x), Value::F64(y)) => x.to_bits() == y.to_bits(),
            _ => x == y,
        })
}
