//! The native modules of `runtime-tests/native/` and the rules files
//! (from the repository's root) they are generated from: `native.rs`
//! compiles and runs them, `native_golden.rs` generates them again.

use std::path::{Path, PathBuf};

pub const SOURCES: &[(&str, &str)] = &[
    ("outdoor", "rules/outdoor.situ"),
    ("ugv", "rules/ugv.situ"),
    ("ugv_merge", "rules/ugv-merge.situ"),
    ("dla", "rules/dla.situ"),
    ("fig5", "examples/fig5/fig5.situ"),
    ("mower", "examples/mower/mower.situ"),
    ("r01", "runtime-tests/native/random/r01.situ"),
    ("r02", "runtime-tests/native/random/r02.situ"),
    ("r03", "runtime-tests/native/random/r03.situ"),
    ("r04", "runtime-tests/native/random/r04.situ"),
    ("r05", "runtime-tests/native/random/r05.situ"),
    ("r06", "runtime-tests/native/random/r06.situ"),
    ("r07", "runtime-tests/native/random/r07.situ"),
    ("r08", "runtime-tests/native/random/r08.situ"),
    ("r09", "runtime-tests/native/random/r09.situ"),
    ("r10", "runtime-tests/native/random/r10.situ"),
    ("r11", "runtime-tests/native/random/r11.situ"),
    ("r12", "runtime-tests/native/random/r12.situ"),
];

/// The repository's root.
pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The bundle's content of a rules file (from the repository's root),
/// validated. The random rule sets have findings of the static checks
/// (unreachable states, unread events): as in `differential.rs`, only the
/// front end's errors stop a build here.
pub fn content(source: &str) -> situ_compiler::bundle::Content {
    let checked = situ_compiler::check(&root().join(source), &situ_compiler::loader::FsLoader).expect("readable");
    let front: Vec<_> = checked.diagnostics.iter().filter(|d| d.code < "E0300").collect();
    assert!(front.is_empty(), "{source}: {front:?}");
    let content = situ_compiler::bundle::build(&checked);
    situ_compiler::bundle::codec::validate(&content).expect("valid");
    content
}
