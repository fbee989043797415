//! Loading what `build`, `run`, `bench` and `graph` take: a `.situ` source
//! (checked and compiled here) or a bundle file (decoded and verified).

use super::{FAILED, USAGE};
use situ_compiler::bundle::{self, Content};
use situ_compiler::loader::FsLoader;
use situ_compiler::{render, Checked};
use std::path::Path;
use std::sync::Arc;

/// A program ready to run, and its checked source when it came from one.
pub struct Program {
    pub content: Arc<Content>,
    pub checked: Option<Checked>,
}

/// Whether a path names a source file (else a bundle).
pub fn is_source(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "situ")
}

/// Loads a source or a bundle; on failure prints why and returns the exit
/// code: 1 for findings in a source, 2 for I/O and damaged bundles.
pub fn load(path: &Path, deny_warnings: bool) -> Result<Program, u8> {
    if is_source(path) {
        let checked = check(path, deny_warnings)?;
        let content = Arc::new(bundle::build(&checked));
        return Ok(Program { content, checked: Some(checked) });
    }
    let bytes = std::fs::read(path).map_err(|e| {
        eprintln!("error: cannot read `{}`: {e}", path.display());
        USAGE
    })?;
    match bundle::decode(&bytes) {
        Ok(content) => Ok(Program { content: Arc::new(content), checked: None }),
        Err(e) => {
            eprintln!("error: `{}`: {e}", path.display());
            Err(USAGE)
        }
    }
}

/// Checks a source; prints the findings when they fail it.
pub fn check(path: &Path, deny_warnings: bool) -> Result<Checked, u8> {
    let checked = situ_compiler::check(path, &FsLoader).map_err(|e| {
        eprintln!("error: {e}");
        USAGE
    })?;
    if checked.fails(deny_warnings) {
        print!("{}", render::human_all(&checked, super::style()));
        eprintln!(
            "error: `{}` has {} error(s) and {} warning(s); fix them first (`situ check` explains each)",
            path.display(),
            checked.errors(),
            checked.warnings()
        );
        return Err(FAILED);
    }
    Ok(checked)
}
