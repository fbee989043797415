//! `situ test` as a call: the scenario tests and the properties of rules
//! files, each property proved, violated or undecided (never "ok" for
//! "not found"), and the suite's verdict.

use situ_compiler::loader::FsLoader;
use std::path::PathBuf;

pub use situ_verify::suite::{Options as TestOptions, SuiteReport, Verdict};

/// Runs the tests and checks the properties of `files` (each with its
/// includes). A file that cannot be read or has errors is an outcome of the
/// report, not an error: the other files still run.
pub fn test(files: &[PathBuf], options: &TestOptions) -> SuiteReport {
    situ_verify::suite::run(files, &FsLoader, options)
}
