//! From rules to a program: check a source, format it, build its bundle
//! (signed or not), and load a source or a bundle under a trust policy.

use crate::Error;
use situ_compiler::bundle::sign::{self, KeyId, SecretKey};
use situ_compiler::bundle::{self, codec, Content, Encoding, Loaded, Trust};
use situ_compiler::loader::{read_bounded, FsLoader, MAX_BUNDLE_BYTES};
use situ_compiler::Checked;
use std::path::Path;
use std::sync::Arc;

/// Where rules come from: a file (its includes are read relative to it) or
/// a text with a name for messages (no includes).
#[derive(Debug, Clone, Copy)]
pub enum Input<'a> {
    Path(&'a Path),
    Text { name: &'a str, text: &'a str },
}

/// Checks rules: names, types and every static check. Findings are data in
/// the result (a source with errors is still `Ok`); `Err` only when the root
/// file cannot be read.
pub fn check(input: Input<'_>) -> Result<Checked, Error> {
    Ok(match input {
        Input::Path(path) => situ_compiler::check(path, &FsLoader)?,
        Input::Text { name, text } => situ_compiler::check_source(name, text),
    })
}

/// Every finding of a check as a JSON object (`situ check --format json`'s:
/// code, severity, message, file, line, column, end, label, help, related
/// places, witness, allowed).
pub fn findings_json(checked: &Checked) -> Vec<serde_json::Value> {
    checked.diagnostics.iter().map(|d| situ_compiler::render::json_object(&checked.sources, d)).collect()
}

/// Formats a source in the one canonical layout; a source with syntax
/// errors is refused with them.
pub fn format(text: &str) -> Result<String, Error> {
    situ_grammar::format(text).map_err(Error::Syntax)
}

/// How [`build`] writes a bundle.
#[derive(Debug)]
pub struct BuildOptions {
    /// JSON (readable, the default) or binary (compact).
    pub encoding: Encoding,
    /// Signs the bundle with this key (`docs/signing.md`).
    pub key: Option<SecretKey>,
    /// Warnings fail the build as errors do.
    pub deny_warnings: bool,
}

impl Default for BuildOptions {
    fn default() -> Self {
        BuildOptions { encoding: Encoding::Json, key: None, deny_warnings: false }
    }
}

/// A bundle as built: its bytes, their SHA-256 and the key that signed it.
#[derive(Debug, Clone)]
pub struct Built {
    pub bytes: Vec<u8>,
    /// The SHA-256 of `bytes`, in hex.
    pub sha256: String,
    pub content: Content,
    pub signed_by: Option<KeyId>,
}

/// Compiles checked rules to a bundle. Rules with errors (or warnings under
/// `deny_warnings`) are refused with their findings. The bytes are read
/// back as a runtime would before they are returned.
pub fn build(checked: &Checked, options: &BuildOptions) -> Result<Built, Error> {
    if checked.fails(options.deny_warnings) {
        return Err(findings(checked));
    }
    let content = bundle::build(checked);
    let bytes = match &options.key {
        Some(key) => sign::encode_signed(&content, options.encoding, key),
        None => bundle::encode(&content, options.encoding),
    };
    bundle::decode(&bytes)?;
    let sha256 = codec::sha256_hex(&bytes);
    Ok(Built { bytes, sha256, content, signed_by: options.key.as_ref().map(SecretKey::key_id) })
}

/// Decodes and verifies a bundle's bytes under `trust` (any valid bundle, or
/// only those signed by one of its keys), naming the key that signed it.
pub fn load(bytes: &[u8], trust: &Trust) -> Result<Loaded, Error> {
    Ok(situ_compiler::bundle::load(bytes, trust)?)
}

/// Whether a path names a source file (`.situ`), else a bundle.
pub fn is_source(path: &Path) -> bool {
    path.extension().is_some_and(|e| e == "situ")
}

/// A program ready to run, and its checked source when it came from one.
#[derive(Debug, Clone)]
pub struct Program {
    pub content: Arc<Content>,
    pub checked: Option<Checked>,
    /// The bundle file's bytes as read and verified (what a recording
    /// attaches, signature included); `None` for a source.
    pub bytes: Option<Vec<u8>>,
    pub signed_by: Option<KeyId>,
}

/// Loads a `.situ` source (checked and compiled) or a bundle file (decoded
/// and verified). Under [`Trust::Keys`] a source is refused: it carries no
/// signature.
pub fn load_path(path: &Path, trust: &Trust, deny_warnings: bool) -> Result<Program, Error> {
    if is_source(path) {
        if trust.requires_signature() {
            return Err(Error::UnsignedSource { path: path.to_path_buf() });
        }
        let checked = check(Input::Path(path))?;
        if checked.fails(deny_warnings) {
            return Err(findings(&checked));
        }
        let content = Arc::new(bundle::build(&checked));
        return Ok(Program { content, checked: Some(checked), bytes: None, signed_by: None });
    }
    let bytes = read_bounded(path, MAX_BUNDLE_BYTES, "a bundle")
        .map_err(|source| Error::Read { path: path.to_path_buf(), source })?;
    let loaded = load(&bytes, trust)?;
    Ok(Program { content: Arc::new(loaded.content), checked: None, bytes: Some(bytes), signed_by: loaded.signer })
}

fn findings(checked: &Checked) -> Error {
    let name = checked.sources.iter().next().map(|(_, f)| f.name.clone()).unwrap_or_default();
    Error::Findings { name, errors: checked.errors(), warnings: checked.warnings(), checked: Box::new(checked.clone()) }
}
