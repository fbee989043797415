//! Loading what `build`, `run`, `bench` and `graph` take: a `.situ` source
//! (checked and compiled here) or a bundle file (decoded and verified under
//! the trust policy, a `situ_bundle::Trust` value built from `--trust`).

use super::{FAILED, USAGE};
use situ_compiler::bundle::{self, Content, Trust};
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

/// The trust policy of this process's `--trust` flags, once read.
///
/// Kept as a global for one release: the commands that load a program
/// (`run`, `graph`, `gen`, `repl`, `bench`, `replay`, `view`, `up`, `ros2`)
/// call [`load`], [`decode_bundle`] and [`refuse_source_under_trust`] from
/// files that are being reworked at the same time; each can move to the
/// `*_under` forms, which take the [`Trust`] value, and then this goes.
static TRUST: OnceLock<Trust> = OnceLock::new();

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

/// Reads the `--trust` public keys ([`trust_of`]) as the policy of every
/// program this process loads.
pub fn trust(paths: &[PathBuf]) -> Result<(), u8> {
    let trust = trust_of(paths)?;
    if TRUST.set(trust).is_err() {
        eprintln!("error: the trusted keys were already read");
        return Err(USAGE);
    }
    Ok(())
}

fn trusted() -> &'static Trust {
    static ANY: Trust = Trust::Any;
    TRUST.get().unwrap_or(&ANY)
}

/// With `--trust`, a source is refused: it carries no signature.
pub fn refuse_source_under_trust(path: &Path) -> Result<(), u8> {
    refuse_source_under(path, trusted())
}

/// [`refuse_source_under_trust`] with the policy given.
pub fn refuse_source_under(path: &Path, trust: &Trust) -> Result<(), u8> {
    if !trust.requires_signature() {
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
    decode_bundle_under(bytes, what, trusted())
}

/// [`decode_bundle`] with the policy given.
pub fn decode_bundle_under(bytes: &[u8], what: &str, trust: &Trust) -> Result<Content, String> {
    let loaded = bundle::load(bytes, trust).map_err(|e| e.to_string())?;
    if let Some(key_id) = loaded.signer {
        eprintln!("{what}: signed by trusted key {key_id}");
    }
    Ok(loaded.content)
}

/// Loads a source or a bundle; on failure prints why and returns the exit
/// code: 1 for findings in a source, 2 for I/O and damaged bundles. With
/// `--trust`, a source is refused (it carries no signature) and a bundle
/// must be signed by a trusted key (exit 2, naming the key).
pub fn load(path: &Path, deny_warnings: bool) -> Result<Program, u8> {
    load_under(path, deny_warnings, trusted())
}

/// [`load`] with the policy given.
pub fn load_under(path: &Path, deny_warnings: bool, trust: &Trust) -> Result<Program, u8> {
    if is_source(path) {
        refuse_source_under(path, trust)?;
        let checked = check(path, deny_warnings)?;
        let content = Arc::new(bundle::build(&checked));
        return Ok(Program { content, checked: Some(checked), bytes: None });
    }
    let bytes = read_bundle(path).map_err(|e| {
        eprintln!("error: cannot read `{}`: {e}", path.display());
        USAGE
    })?;
    match decode_bundle_under(&bytes, &format!("`{}`", path.display()), trust) {
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
