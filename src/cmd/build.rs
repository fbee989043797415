//! `situ build FILE -o BUNDLE [--binary] [--stats] [--sign KEY]`: compiles
//! a checked source to a bundle, written atomically; with `--sign`, signed
//! with the secret key of `situ key new` (`docs/signing.md`).

use super::{OK, USAGE};
use situ_compiler::bundle::{self, codec, Encoding};
use std::path::Path;

pub fn run(file: &Path, out: &Path, binary: bool, stats: bool, deny_warnings: bool, sign: Option<&Path>) -> u8 {
    // The key first: a build that cannot sign writes nothing.
    let key = match sign.map(super::key::read_secret).transpose() {
        Ok(k) => k,
        Err(e) => {
            eprintln!("error: --sign: {e}");
            return USAGE;
        }
    };
    let checked = match super::program::check(file, deny_warnings) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let content = bundle::build(&checked);
    let encoding = if binary { Encoding::Binary } else { Encoding::Json };
    let bytes = match &key {
        Some(key) => bundle::sign::encode_signed(&content, encoding, key),
        None => bundle::encode(&content, encoding),
    };
    if let Err(e) = super::write_atomically(out, &bytes) {
        eprintln!("error: cannot write `{}`: {e}", out.display());
        return USAGE;
    }
    let hash = match bundle::decode(&bytes) {
        // The bundle is read back as a runtime would, before it is announced.
        Ok(_) => codec::sha256_hex(&bytes),
        Err(e) => {
            eprintln!("error: the bundle written to `{}` does not read back: {e}", out.display());
            return USAGE;
        }
    };
    println!(
        "{} -> {} ({} bytes, {}, file sha256 {})",
        file.display(),
        out.display(),
        bytes.len(),
        if binary { "binary" } else { "JSON" },
        &hash[..16]
    );
    if let Some(key) = &key {
        println!("signed by key {}", key.key_id());
    }
    if stats {
        let s = content.network.stats;
        let unshared = s.alpha_unshared + s.beta_unshared;
        println!(
            "network: {} alpha nodes ({} without sharing), {} beta nodes ({} without sharing), {} terminals",
            s.alpha, s.alpha_unshared, s.beta, s.beta_unshared, s.terminals
        );
        println!(
            "sharing saved {} of {} alpha and beta nodes ({:.0}%)",
            s.saved(),
            unshared,
            if unshared > 0 { 100.0 * s.saved() as f64 / unshared as f64 } else { 0.0 }
        );
        println!(
            "{} states, {} agents, {} events, {} rules",
            content.states.len(),
            content.agents.len(),
            content.events.len(),
            content.rules.len()
        );
    }
    OK
}
