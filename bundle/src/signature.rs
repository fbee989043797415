//! A bundle's signature as the envelope carries it: the id of the key that
//! made it and the ed25519 signature, with their hex text. Both the codec
//! (which reads and writes it) and [`crate::sign`] (which makes and checks
//! it) build on this module; neither imports the other's internals.

use serde::{Deserialize, Serialize};
use std::fmt;

/// How many bytes of the public key's SHA-256 make its id.
pub const KEY_ID_BYTES: usize = 8;

/// The id of a key: the first bytes of the SHA-256 of its public key.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct KeyId(pub [u8; KEY_ID_BYTES]);

impl fmt::Display for KeyId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&hex(&self.0))
    }
}

/// A bundle's signature: the key that made it and the ed25519 signature of
/// [`crate::sign::message`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Signature {
    pub key_id: KeyId,
    pub ed25519: [u8; 64],
}

/// The signature as the JSON envelope writes it: hex strings.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub(crate) struct SignatureJson {
    pub key_id: String,
    pub ed25519: String,
}

impl Signature {
    pub(crate) fn to_json(&self) -> SignatureJson {
        SignatureJson { key_id: self.key_id.to_string(), ed25519: hex(&self.ed25519) }
    }

    /// The signature of a JSON envelope; the error says which field is
    /// malformed.
    pub(crate) fn from_json(s: &SignatureJson) -> Result<Signature, String> {
        let key_id = unhex::<KEY_ID_BYTES>(&s.key_id)
            .ok_or_else(|| format!("`signature.key_id` is not {} hex digits", 2 * KEY_ID_BYTES))?;
        let ed25519 = unhex::<64>(&s.ed25519).ok_or("`signature.ed25519` is not 128 hex digits")?;
        Ok(Signature { key_id: KeyId(key_id), ed25519 })
    }
}

pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

pub(crate) fn unhex<const N: usize>(text: &str) -> Option<[u8; N]> {
    let text = text.trim();
    if text.len() != 2 * N || !text.is_ascii() {
        return None;
    }
    let mut out = [0u8; N];
    for (i, byte) in out.iter_mut().enumerate() {
        *byte = u8::from_str_radix(&text[2 * i..2 * i + 2], 16).ok()?;
    }
    Some(out)
}
