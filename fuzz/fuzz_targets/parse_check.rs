//! Arbitrary bytes as a rules file, checked through an in-memory loader
//! (with one included file, so that includes are reached): loading never
//! panics, every finding renders, and a program without errors builds a
//! bundle that decodes in both encodings and runs (invariants 1, 4, 8).
#![no_main]

use libfuzzer_sys::fuzz_target;
use situ_compiler::loader::MemLoader;
use situ_fuzz::{check_all, MAIN};

/// A file the fuzzed program may include (`include "lib.situ"`).
const LIB: &str = "agent LibAgent sensor { event LIB_EV { x: f64 } }\n";

fuzz_target!(|data: &[u8]| {
    let loader = MemLoader::new().with(MAIN, data.to_vec()).with("fuzz/lib.situ", LIB);
    check_all(&loader, MAIN, &[]);
});
