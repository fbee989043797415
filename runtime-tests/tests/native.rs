//! Native code (`situ build --native`, `situ_runtime::rete::native`) held
//! to the interpreter.
//!
//! The modules under `runtime-tests/native/` were generated from the
//! repository's rules files and from the random rule sets of
//! `native/random/` (drawn as `differential.rs` draws them), and are
//! compiled into this test:
//! - each must be what `generate` writes today, byte for byte
//!   (`native_golden.rs`, a test of its own so that it builds however
//!   stale the modules are);
//! - each, run by `Engine::with_native`, must answer every operation as
//!   the Rete interpreter does (`twin::twins_with`: steps, refusals,
//!   cascade errors, recorded firings with their facts, heartbeats, forced
//!   facts and states, resets, copies) on seeded streams and on random
//!   operations, and leave the same working memory;
//! - a module refuses a bundle other than its own.

mod native_modules;
mod twin;

use proptest::prelude::*;
use situ_compiler::bundle::{Content, Value};
use situ_runtime::rete::native::{Native, NativeError};
use situ_runtime::rete::{Engine, StepError};
use situ_runtime::stream::Generator;
use std::sync::Arc;
use twin::{ops, pool, posts, twins_with, Op};

#[rustfmt::skip]
#[path = "../native/outdoor.rs"]
mod outdoor;
#[rustfmt::skip]
#[path = "../native/ugv.rs"]
mod ugv;
#[rustfmt::skip]
#[path = "../native/ugv_merge.rs"]
mod ugv_merge;
#[rustfmt::skip]
#[path = "../native/dla.rs"]
mod dla;
#[rustfmt::skip]
#[path = "../native/fig5.rs"]
mod fig5;
#[rustfmt::skip]
#[path = "../native/mower.rs"]
mod mower;
#[rustfmt::skip]
#[path = "../native/r01.rs"]
mod r01;
#[rustfmt::skip]
#[path = "../native/r02.rs"]
mod r02;
#[rustfmt::skip]
#[path = "../native/r03.rs"]
mod r03;
#[rustfmt::skip]
#[path = "../native/r04.rs"]
mod r04;
#[rustfmt::skip]
#[path = "../native/r05.rs"]
mod r05;
#[rustfmt::skip]
#[path = "../native/r06.rs"]
mod r06;
#[rustfmt::skip]
#[path = "../native/r07.rs"]
mod r07;
#[rustfmt::skip]
#[path = "../native/r08.rs"]
mod r08;
#[rustfmt::skip]
#[path = "../native/r09.rs"]
mod r09;
#[rustfmt::skip]
#[path = "../native/r10.rs"]
mod r10;
#[rustfmt::skip]
#[path = "../native/r11.rs"]
mod r11;
#[rustfmt::skip]
#[path = "../native/r12.rs"]
mod r12;

/// A module's `step`, which a program that links it calls (inlined).
type Step = fn(&mut Engine, u32, u64, &[Value]) -> Result<situ_runtime::rete::Step, StepError>;

/// Each module: its name, the rules file it was generated from (from the
/// repository's root), its entry point, its `step`.
const MODULES: &[(&str, &str, &Native, Step)] = &[
    ("outdoor", "rules/outdoor.situ", &outdoor::NATIVE, outdoor::step),
    ("ugv", "rules/ugv.situ", &ugv::NATIVE, ugv::step),
    ("ugv_merge", "rules/ugv-merge.situ", &ugv_merge::NATIVE, ugv_merge::step),
    ("dla", "rules/dla.situ", &dla::NATIVE, dla::step),
    ("fig5", "examples/fig5/fig5.situ", &fig5::NATIVE, fig5::step),
    ("mower", "examples/mower/mower.situ", &mower::NATIVE, mower::step),
    ("r01", "runtime-tests/native/random/r01.situ", &r01::NATIVE, r01::step),
    ("r02", "runtime-tests/native/random/r02.situ", &r02::NATIVE, r02::step),
    ("r03", "runtime-tests/native/random/r03.situ", &r03::NATIVE, r03::step),
    ("r04", "runtime-tests/native/random/r04.situ", &r04::NATIVE, r04::step),
    ("r05", "runtime-tests/native/random/r05.situ", &r05::NATIVE, r05::step),
    ("r06", "runtime-tests/native/random/r06.situ", &r06::NATIVE, r06::step),
    ("r07", "runtime-tests/native/random/r07.situ", &r07::NATIVE, r07::step),
    ("r08", "runtime-tests/native/random/r08.situ", &r08::NATIVE, r08::step),
    ("r09", "runtime-tests/native/random/r09.situ", &r09::NATIVE, r09::step),
    ("r10", "runtime-tests/native/random/r10.situ", &r10::NATIVE, r10::step),
    ("r11", "runtime-tests/native/random/r11.situ", &r11::NATIVE, r11::step),
    ("r12", "runtime-tests/native/random/r12.situ", &r12::NATIVE, r12::step),
];

fn content(source: &str) -> Arc<Content> {
    Arc::new(native_modules::content(source))
}

fn native_engine(native: &'static Native) -> impl Fn(Arc<Content>) -> Engine {
    move |c| Engine::with_native(c, native).expect("the module of this bundle")
}

#[test]
fn native_code_answers_as_the_interpreter_on_seeded_streams() {
    let mut fired = 0;
    for (_, source, native, _) in MODULES {
        let content = content(source);
        let engine = Engine::with_native(content.clone(), native).unwrap_or_else(|e| panic!("{source}: {e}"));
        assert!(engine.is_native() && engine.is_fast());
        for seed in 0..3u64 {
            let mut g = Generator::new(content.clone(), seed);
            let events: Vec<(u32, u64, Vec<Value>)> =
                (0..3000).filter_map(|_| g.next_event()).map(|e| (e.event, e.time, e.payload)).collect();
            fired += twins_with(&content, &posts(&events, true), &native_engine(native))
                .unwrap_or_else(|e| panic!("{source}, seed {seed}: {e}"));
        }
    }
    assert!(fired > 5000, "the streams fired only {fired} rules");
}

/// The time steps of the random operations (ms): the random rule sets'
/// 30 ms windows and 50 ms stale time, the files' stale times and
/// windows, and events stamped before now.
const OP_GAPS_MS: [i64; 12] = [0, 1, 10, 20, 30, 31, 50, 51, -30, 250, 501, 1001];

fn module_and_ops() -> impl Strategy<Value = (usize, Vec<Op>)> {
    (0..MODULES.len()).prop_flat_map(|m| (Just(m), ops(content(MODULES[m].1), &OP_GAPS_MS, pool, 120)))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Every entry point of the engine, on each module's bundle: native
    /// code answers as the interpreter.
    #[test]
    fn native_code_answers_as_the_interpreter_on_random_operations((m, ops) in module_and_ops()) {
        let (_, source, native, _) = MODULES[m];
        let result = twins_with(&content(source), &ops, &native_engine(native));
        prop_assert!(result.is_ok(), "{}: {:?}", source, result);
    }
}

#[test]
fn a_module_refuses_a_bundle_other_than_its_own() {
    let ugv = content("rules/ugv.situ");
    match Engine::with_native(ugv, &outdoor::NATIVE) {
        Err(NativeError::Mismatch { expected, found }) => {
            assert_eq!(found, outdoor::NATIVE.digest);
            assert_ne!(expected, found);
        }
        other => panic!("outdoor's native code took ugv's bundle: {:?}", other.map(|e| e.is_native())),
    }
    // The same rules with one constant changed are another bundle.
    let path = native_modules::root().join("rules/outdoor.situ");
    let text = std::fs::read_to_string(&path).unwrap();
    let changed = text.replacen("stale after 400ms", "stale after 401ms", 1);
    assert_ne!(changed, text, "outdoor.situ has no `stale after 400ms` to change");
    let checked = situ_compiler::check_source("outdoor.situ", &changed);
    let other = Arc::new(situ_compiler::bundle::build(&checked));
    assert!(matches!(Engine::with_native(other, &outdoor::NATIVE), Err(NativeError::Mismatch { .. })));
}

/// A module's `step`, called directly as a program that links it calls
/// it, is the engine's `step`: on the engine that runs the module, the same
/// answers and working memory as `Engine::step` of a twin; on any other
/// engine, that engine's own step.
#[test]
fn a_module_s_step_is_the_engine_s_step() {
    for (_, source, native, step) in MODULES {
        let content = content(source);
        let mut direct = Engine::with_native(content.clone(), native).unwrap();
        let mut through = Engine::with_native(content.clone(), native).unwrap();
        // A fast-path engine of the same bundle does not run the module:
        // the module's `step` is then its own.
        let mut other = Engine::new(content.clone());
        let mut reference = Engine::new(content.clone());
        let mut g = Generator::new(content.clone(), 7);
        let mut steps = 0;
        for (event, time, payload) in (0..2000).filter_map(|_| g.next_event()).map(|e| (e.event, e.time, e.payload)) {
            for (a, b) in [(&mut direct, &mut through), (&mut other, &mut reference)] {
                let x = step(a, event, time, &payload);
                let y = b.step(event, time, &payload);
                assert_eq!(format!("{x:?}"), format!("{y:?}"), "{source}: step {steps}");
                assert_eq!(
                    format!("{:?}", a.last_change()),
                    format!("{:?}", b.last_change()),
                    "{source}: step {steps}"
                );
                assert_eq!(a.state(), b.state());
                a.reset_if_final();
                b.reset_if_final();
            }
            steps += 1;
        }
        // An event the bundle does not have is refused alike.
        let n = content.events.len() as u32;
        assert_eq!(format!("{:?}", step(&mut direct, n, 0, &[])), format!("{:?}", through.step(n, 0, &[])));
        assert!(!other.is_native() && steps > 0);
    }
}

#[test]
fn the_modules_compiled_here_are_those_the_golden_test_checks() {
    let here: Vec<(&str, &str)> = MODULES.iter().map(|m| (m.0, m.1)).collect();
    assert_eq!(here, native_modules::SOURCES);
}
