//! Loading what `build`, `run`, `bench` and `graph` take: a `.situ` source
//! (checked and compiled here) or a bundle file (decoded and verified).

use super::{FAILED, USAGE};
use situ_compiler::bundle::sign::{self, PublicKey};
use situ_compiler::bundle::{self, Content};
use situ_compiler::loader::{read_bounded, FsLoader, MAX_BUNDLE_BYTES};
use situ_compiler::{render, Checked};
use std::path::{Path, PathBuf};
use std::sync::{Arc, OnceLock};

/// A program ready to run, and its checked source when it came from one.
pub struct Program {
    pub content: Arc<Content>,
    pub checked: Option<Checked>,
    /// The bundle file's bytes as read and checked (what a recording
    /// attaches, signature included); `None` for a source.
    pub bytes: Option<Vec<u8>>,
}

/// Whether a path names a source file (else a bundle).
pub fn is_source(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "situ")
}

/// The keys of `--trust`, once read: every bundle this process loads must
/// then be signed by one of them (`docs/signing.md`).
static TRUSTED: OnceLock<Vec<PublicKey>> = OnceLock::new();

/// Reads the `--trust` public keys (none: every valid bundle loads, signed
/// or not); prints why a key file is refused and returns the exit code.
pub fn trust(paths: &[PathBuf]) -> Result<(), u8> {
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
    if TRUSTED.set(keys).is_err() {
        eprintln!("error: the trusted keys were already read");
        return Err(USAGE);
    }
    Ok(())
}

fn trusted() -> &'static [PublicKey] {
    TRUSTED.get().map(Vec::as_slice).unwrap_or_default()
}

/// With `--trust`, a source is refused: it carries no signature.
pub fn refuse_source_under_trust(path: &Path) -> Result<(), u8> {
    if trusted().is_empty() {
        return Ok(());
    }
    eprintln!(
        "error: `{}` is a source, which carries no signature: with --trust only bundles signed by a trusted key run (`situ build {} -o BUNDLE --sign KEY.key`)",
        path.display(),
        path.display()
    );
    Err(USAGE)
}

/// Decodes a bundle's bytes; with `--trust`, also checks its signature
/// (after the envelope's own checks) and says which key signed it.
pub fn decode_bundle(bytes: &[u8], what: &str) -> Result<Content, String> {
    let keys = trusted();
    if keys.is_empty() {
        return bundle::decode(bytes).map_err(|e| e.to_string());
    }
    let (content, key_id) = sign::decode_trusted(bytes, keys).map_err(|e| e.to_string())?;
    eprintln!("{what}: signed by trusted key {key_id}");
    Ok(content)
}

/// Loads a source or a bundle; on failure prints why and returns the exit
/// code: 1 for findings in a source, 2 for I/O and damaged bundles. With
/// `--trust`, a source is refused (it carries no signature) and a bundle
/// must be signed by a trusted key (exit 2, naming the key).
pub fn load(path: &Path, deny_warnings: bool) -> Result<Program, u8> {
    if is_source(path) {
        refuse_source_under_trust(path)?;
        let checked = check(path, deny_warnings)?;
        let content = Arc::new(bundle::build(&checked));
        return Ok(Program { content, checked: Some(checked), bytes: None });
    }
    let bytes = read_bundle(path).map_err(|e| {
        eprintln!("error: cannot read `{}`: {e}", path.display());
        USAGE
    })?;
    match decode_bundle(&bytes, &format!("`{}`", path.display())) {
        Ok(content) => Ok(Program { content: Arc::new(content), checked: None, bytes: Some(bytes) }),
        Err(e) => {
            eprintln!("error: `{}`: {e}", path.display());
            Err(USAGE)
        }
    }
}

/// The bytes of a bundle file, bounded (see [`read_bounded`]).
pub fn read_bundle(path: &Path) -> std::io::Result<Vec<u8>> {
    read_bounded(path, MAX_BUNDLE_BYTES, "a bundle")
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
