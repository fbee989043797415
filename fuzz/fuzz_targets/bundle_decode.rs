//! Arbitrary bytes as a bundle file (`compiler::bundle::decode`), in three
//! ways chosen by the first byte:
//!
//! - 0: the bytes as they are, JSON or binary (told apart by the magic);
//! - 1: the bytes as the `content` of a JSON bundle whose envelope and hash
//!   are made right, so that the fuzzer reaches past the hash;
//! - 2: the bytes as the postcard body of a binary bundle whose header and
//!   hash are made right.
//!
//! A bundle that decodes is whole and true (invariant 8): its engine builds
//! and runs every event without a panic, indexing without checking again.
#![no_main]

use libfuzzer_sys::fuzz_target;
use sha2::{Digest, Sha256};
use situ_compiler::bundle::{self, codec::COMPILER_VERSION, FORMAT_NAME, FORMAT_VERSION};

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

fn json_envelope(content: &str) -> Vec<u8> {
    let sha = hex(&Sha256::digest(content.as_bytes()));
    format!(
        "{{\"format\":\"{FORMAT_NAME}\",\"format_version\":{FORMAT_VERSION},\"compiler_version\":\"{COMPILER_VERSION}\",\"sha256\":\"{sha}\",\"content\":{content}}}\n"
    )
    .into_bytes()
}

fn binary_envelope(body: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(body.len() + 64);
    out.extend_from_slice(b"SITUBNDL");
    out.extend_from_slice(&FORMAT_VERSION.to_le_bytes());
    out.extend_from_slice(&(body.len() as u64).to_le_bytes());
    out.extend_from_slice(&Sha256::digest(body));
    out.extend_from_slice(&(COMPILER_VERSION.len() as u32).to_le_bytes());
    out.extend_from_slice(COMPILER_VERSION.as_bytes());
    out.extend_from_slice(body);
    out
}

fuzz_target!(|data: &[u8]| {
    let Some((&mode, rest)) = data.split_first() else {
        let _ = bundle::decode(data);
        return;
    };
    let bytes = match mode % 3 {
        1 => {
            // Only valid JSON makes a well-formed envelope around it.
            let Ok(text) = std::str::from_utf8(rest) else { return };
            if serde_json::from_str::<serde::de::IgnoredAny>(text).is_err() {
                return;
            }
            json_envelope(text)
        }
        2 => binary_envelope(rest),
        _ => rest.to_vec(),
    };
    if let Ok(content) = bundle::decode(&bytes) {
        situ_fuzz::run(content);
    }
});
