//! Native code (`situ build --native`, `situ_runtime::rete::native`) held
//! to the interpreter.
//!
//! The modules under `runtime-tests/native/` were generated from the
//! repository's rules files and from the random rule sets of
//! `native/random/` (drawn as `differential.rs` draws them), and are
//! compiled into this test:
//! - each must be what `generate` writes today, byte for byte (after a
//!   change of the generator: `SITU_BLESS=1 cargo test -p
//!   situ-runtime-tests --test native` writes them again, and the test
//!   must then be built and run once more);
//! - each, run by `Engine::with_native`, must answer every operation as
//!   the Rete interpreter does (`twin::twins_with`: steps, refusals,
//!   cascade errors, recorded firings with their facts, heartbeats, forced
//!   facts and states, resets, copies) on seeded streams and on random
//!   operations, and leave the same working memory;
//! - a module refuses a bundle other than its own.

mod twin;

use proptest::prelude::*;
use situ_compiler::bundle::{Content, Value};
use situ_runtime::rete::native::{self, Native, NativeError};
use situ_runtime::rete::Engine;
use situ_runtime::stream::Generator;
use std::path::{Path, PathBuf};
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

/// Each module: its name, the rules file it was generated from (from the
/// repository's root), its entry point.
const MODULES: &[(&str, &str, &Native)] = &[
    ("outdoor", "rules/outdoor.situ", &outdoor::NATIVE),
    ("ugv", "rules/ugv.situ", &ugv::NATIVE),
    ("ugv_merge", "rules/ugv-merge.situ", &ugv_merge::NATIVE),
    ("dla", "rules/dla.situ", &dla::NATIVE),
    ("fig5", "examples/fig5/fig5.situ", &fig5::NATIVE),
    ("mower", "examples/mower/mower.situ", &mower::NATIVE),
    ("r01", "runtime-tests/native/random/r01.situ", &r01::NATIVE),
    ("r02", "runtime-tests/native/random/r02.situ", &r02::NATIVE),
    ("r03", "runtime-tests/native/random/r03.situ", &r03::NATIVE),
    ("r04", "runtime-tests/native/random/r04.situ", &r04::NATIVE),
    ("r05", "runtime-tests/native/random/r05.situ", &r05::NATIVE),
    ("r06", "runtime-tests/native/random/r06.situ", &r06::NATIVE),
    ("r07", "runtime-tests/native/random/r07.situ", &r07::NATIVE),
    ("r08", "runtime-tests/native/random/r08.situ", &r08::NATIVE),
    ("r09", "runtime-tests/native/random/r09.situ", &r09::NATIVE),
    ("r10", "runtime-tests/native/random/r10.situ", &r10::NATIVE),
    ("r11", "runtime-tests/native/random/r11.situ", &r11::NATIVE),
    ("r12", "runtime-tests/native/random/r12.situ", &r12::NATIVE),
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The bundle's content of a rules file. The random rule sets have
/// findings of the static checks (unreachable states, unread events): as
/// in `differential.rs`, only the front end's errors stop a build here.
fn content(source: &str) -> Arc<Content> {
    let path = root().join(source);
    let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("readable");
    let front: Vec<_> = checked.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front.is_empty(), "{source}: {front:?}");
    let content = situ_compiler::bundle::build(&checked);
    situ_compiler::bundle::codec::validate(&content).expect("valid");
    Arc::new(content)
}

fn native_engine(native: &'static Native) -> impl Fn(Arc<Content>) -> Engine {
    move |c| Engine::with_native(c, native).expect("the module of this bundle")
}

#[test]
fn each_module_is_what_the_generator_writes_today() {
    let bless = std::env::var_os("SITU_BLESS").is_some_and(|v| v == "1");
    let mut stale = Vec::new();
    for (name, source, _) in MODULES {
        let file = Path::new(source).file_name().unwrap().to_string_lossy().into_owned();
        let code = native::generate(&content(source), &file).unwrap_or_else(|e| panic!("{source}: {e}"));
        let path = root().join("runtime-tests/native").join(format!("{name}.rs"));
        let committed = std::fs::read_to_string(&path).unwrap_or_default();
        if committed != code {
            if bless {
                std::fs::write(&path, &code).unwrap();
            }
            stale.push(path.display().to_string());
        }
    }
    assert!(
        stale.is_empty(),
        "native code not what the generator writes today{}: {stale:?}",
        if bless { " (written again: build and run the test once more)" } else { " (SITU_BLESS=1 writes it again)" }
    );
}

#[test]
fn native_code_answers_as_the_interpreter_on_seeded_streams() {
    let mut fired = 0;
    for (_, source, native) in MODULES {
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
        let (_, source, native) = MODULES[m];
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
    let path = root().join("rules/outdoor.situ");
    let text = std::fs::read_to_string(&path).unwrap();
    let changed = text.replacen("stale after 400ms", "stale after 401ms", 1);
    assert_ne!(changed, text, "outdoor.situ has no `stale after 400ms` to change");
    let checked = situ_compiler::check_source("outdoor.situ", &changed);
    let other = Arc::new(situ_compiler::bundle::build(&checked));
    assert!(matches!(Engine::with_native(other, &outdoor::NATIVE), Err(NativeError::Mismatch { .. })));
}
