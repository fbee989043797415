//! Programs: rules ready to run, loaded from a bundle's bytes or a file
//! under a trust policy, or from a `.situ` source (checked and built).

use crate::error::{call, situ_status, Failure};
use crate::handle::{self, Kind};
use crate::value::{place, slice, text};
use situ_api::{Content, Trust};
use std::ffi::c_char;
use std::path::Path;
use std::sync::Arc;

/// Rules ready to run: make boards of it with `situ_board_new`; free it
/// with `situ_program_free` (its boards keep their own copy).
pub struct situ_program {
    _opaque: [u8; 0],
}

pub(crate) struct ProgramItem {
    pub content: Arc<Content>,
}

impl Kind for ProgramItem {
    const WHAT: &'static str = "situ_program";
}

/// The trust policy of a list of public-key files: none, any valid bundle.
unsafe fn trust(keys: *const *const c_char, count: usize) -> Result<Trust, Failure> {
    let mut trusted = Vec::with_capacity(count);
    for (i, &k) in slice(keys, count, "the key list")?.iter().enumerate() {
        let path = text(k, &format!("key file {i}"))?;
        let key = situ_bundle::key::read_public(Path::new(path))
            .map_err(|e| Failure::new(situ_status::SITU_ERR_KEY, format!("trusted key `{path}`: {e}")))?;
        trusted.push(key);
    }
    Ok(Trust::from_keys(trusted))
}

unsafe fn give(out: *mut *mut situ_program, f: impl FnOnce() -> Result<Arc<Content>, Failure>) -> situ_status {
    call(|| {
        let out = place(out, "the place for the program (out)")?;
        *out = std::ptr::null_mut();
        let content = f()?;
        *out = handle::insert(ProgramItem { content }) as *mut situ_program;
        Ok(())
    })
}

/// Loads a bundle from its bytes (JSON or binary, as `situ build` writes
/// it) under a trust policy: `key_count` public-key files (as `situ key
/// new` writes them), each a path; with none, any valid bundle loads,
/// signed or not. Errors: `SITU_ERR_BUNDLE` (damaged), `SITU_ERR_TRUST`
/// (not signed by a trusted key), `SITU_ERR_KEY` (a key file).
#[no_mangle]
pub unsafe extern "C" fn situ_program_from_bytes(
    bytes: *const u8,
    len: usize,
    trusted_keys: *const *const c_char,
    key_count: usize,
    out: *mut *mut situ_program,
) -> situ_status {
    give(out, || {
        let bytes = slice(bytes, len, "the bundle's bytes")?;
        let trust = trust(trusted_keys, key_count)?;
        Ok(Arc::new(situ_api::load(bytes, &trust)?.content))
    })
}

/// Loads a file: a `.situ` source (checked and compiled; refused with
/// `SITU_ERR_TRUST` when keys are given, as a source is never signed) or
/// a bundle (under the keys, as `situ_program_from_bytes`). Errors also:
/// `SITU_ERR_READ`, `SITU_ERR_RULES` (the first error and its place).
#[no_mangle]
pub unsafe extern "C" fn situ_program_from_file(
    path: *const c_char,
    trusted_keys: *const *const c_char,
    key_count: usize,
    out: *mut *mut situ_program,
) -> situ_status {
    give(out, || {
        let path = text(path, "the path")?;
        let trust = trust(trusted_keys, key_count)?;
        Ok(situ_api::load_path(Path::new(path), &trust, false)?.content)
    })
}

/// Compiles rules from a source text; `name` names it in messages. No
/// includes. Error: `SITU_ERR_RULES` with the first error and its place.
#[no_mangle]
pub unsafe extern "C" fn situ_program_from_source(
    name: *const c_char,
    source: *const c_char,
    out: *mut *mut situ_program,
) -> situ_status {
    give(out, || {
        let name = text(name, "the name")?;
        let source = text(source, "the source")?;
        let checked = situ_api::check(situ_api::Input::Text { name, text: source })?;
        Ok(Arc::new(situ_api::build(&checked, &Default::default())?.content))
    })
}

/// Frees a program (null: nothing to do). `SITU_ERR_HANDLE` if it was
/// freed already.
#[no_mangle]
pub extern "C" fn situ_program_free(program: *mut situ_program) -> situ_status {
    call(|| handle::remove::<ProgramItem>(program as usize))
}
