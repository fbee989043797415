//! Loading what the commands run: a `.situ` source (checked and compiled)
//! or a bundle file (decoded and verified under the trust policy of
//! `--trust`), through `situ_api::load_path`. The decisions are the
//! library's; this module says them as the command line does.

use super::{FAILED, USAGE};
use situ_api::Error;
use situ_compiler::bundle::{Content, Trust};
use situ_compiler::loader::FsLoader;
use situ_compiler::{render, Checked};
use std::path::{Path, PathBuf};

pub use situ_api::{is_source, Program};

/// The trust policy of `--trust` public keys (none: every valid bundle
/// loads, signed or not); prints why a key file is refused and returns the
/// exit code.
pub fn trust_of(paths: &[PathBuf]) -> Result<Trust, u8> {
    let mut keys = Vec::new();
    for path in paths {
        match super::key::read_public(path) {
            Ok(k) => keys.push(k),
            Err(e) => {
                eprintln!("error: --trust: {e}");
                return Err(USAGE);
            }
        }
    }
    Ok(Trust::from_keys(keys))
}

/// Under a policy that asks for signatures, a source is refused: it
/// carries none.
pub fn refuse_source(path: &Path, trust: &Trust) -> Result<(), u8> {
    if !trust.requires_signature() {
        return Ok(());
    }
    unsigned_source(path);
    Err(USAGE)
}

fn unsigned_source(path: &Path) {
    eprintln!(
        "error: `{}` is a source, which carries no signature: with --trust only bundles signed by a trusted key run (`situ build {} -o BUNDLE --sign KEY.key`)",
        path.display(),
        path.display()
    );
}

/// Decodes a bundle's bytes under `trust`; says which key signed it when
/// the policy asked for one.
pub fn decode_bundle(bytes: &[u8], what: &str, trust: &Trust) -> Result<Content, Error> {
    let loaded = situ_api::load(bytes, trust)?;
    if let Some(key_id) = loaded.signer {
        eprintln!("{what}: signed by trusted key {key_id}");
    }
    Ok(loaded.content)
}

/// Loads a source or a bundle under `trust`; on failure prints why and
/// returns the exit code: 1 for findings in a source, 2 for I/O, damaged
/// bundles, and (under `--trust`) sources and bundles no trusted key signed.
pub fn load(path: &Path, deny_warnings: bool, trust: &Trust) -> Result<Program, u8> {
    match situ_api::load_path(path, trust, deny_warnings) {
        Ok(program) => {
            if let Some(key_id) = program.signed_by {
                eprintln!("`{}`: signed by trusted key {key_id}", path.display());
            }
            Ok(program)
        }
        Err(Error::UnsignedSource { .. }) => {
            unsigned_source(path);
            Err(USAGE)
        }
        Err(Error::Findings { checked, .. }) => Err(failed_check(path, &checked)),
        Err(Error::Read { source, .. }) => {
            eprintln!("error: cannot read `{}`: {source}", path.display());
            Err(USAGE)
        }
        Err(e @ (Error::Bundle(_) | Error::Trust(_))) => {
            eprintln!("error: `{}`: {e}", path.display());
            Err(USAGE)
        }
        Err(e) => {
            eprintln!("error: {e}");
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
        return Err(failed_check(path, &checked));
    }
    Ok(checked)
}

/// Prints the findings of a source that fails its check; the exit code.
fn failed_check(path: &Path, checked: &Checked) -> u8 {
    print!("{}", render::human_all(checked, super::style()));
    eprintln!(
        "error: `{}` has {} error(s) and {} warning(s); fix them first (`situ check` explains each)",
        path.display(),
        checked.errors(),
        checked.warnings()
    );
    FAILED
}
