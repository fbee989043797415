//! Signatures of bundles: who built a bundle, not only whether it is whole.
//!
//! The envelope's SHA-256 guards against damage; anyone who edits a bundle
//! can recompute it. A signed bundle also carries an ed25519 signature
//! (`signature: {key_id, ed25519}` in JSON, a trailer in binary, see
//! [`crate::codec`]) over [`message`]: the format's identity and the
//! content hash of the envelope. It is checked after the envelope's own
//! checks (format, version, hash, indexes), so a bundle that fails them is
//! refused for that first; then [`verify`] tells a bundle signed by a
//! trusted key from an unsigned one, one signed by another key, and one
//! whose signature does not verify (edited after signing, hash recomputed).
//!
//! Keys are text files with a header line ([`SECRET_HEADER`],
//! [`PUBLIC_HEADER`]) and `field: value` lines; a key's id is the first
//! [`KEY_ID_BYTES`] bytes of the SHA-256 of its public key, in hex. Nothing
//! here reads or writes a file, or draws randomness: [`crate::key::create`] hands
//! [`SecretKey::from_seed`] 32 bytes from the operating system.

use crate::codec::{self, Decoded, Encoding, LoadError};
use crate::signature::{hex, unhex};
pub use crate::signature::{KeyId, Signature, KEY_ID_BYTES};
use crate::{Content, FORMAT_NAME, FORMAT_VERSION};
use ed25519_dalek::{Signer, SigningKey, VerifyingKey};
use sha2::{Digest, Sha256};
use std::fmt;

/// The first line of a secret key file.
pub const SECRET_HEADER: &str = "situ ed25519 secret key v1";

/// The first line of a public key file.
pub const PUBLIC_HEADER: &str = "situ ed25519 public key v1";

/// A secret (signing) key. Its `Debug` shows only its id.
#[derive(Clone)]
pub struct SecretKey(SigningKey);

impl fmt::Debug for SecretKey {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "SecretKey({})", self.key_id())
    }
}

/// A public (verifying) key.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PublicKey(VerifyingKey);

/// Why a key file's text is refused (the message says what is wrong).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct KeyError(pub String);

impl SecretKey {
    /// The key of a 32-byte seed (from a good random source).
    pub fn from_seed(seed: &[u8; 32]) -> SecretKey {
        SecretKey(SigningKey::from_bytes(seed))
    }

    pub fn public(&self) -> PublicKey {
        PublicKey(self.0.verifying_key())
    }

    pub fn key_id(&self) -> KeyId {
        self.public().key_id()
    }

    /// The text of a secret key file.
    pub fn to_text(&self, name: &str) -> String {
        format!(
            "{SECRET_HEADER}\n# Keep this file secret: whoever has it can sign bundles as this key.\nname: {}\nkey-id: {}\nseed: {}\n",
            one_line(name),
            self.key_id(),
            hex(&self.0.to_bytes())
        )
    }

    /// Reads a secret key file's text.
    pub fn from_text(text: &str) -> Result<SecretKey, KeyError> {
        let fields = parse_fields(text, SECRET_HEADER, "seed")?;
        let seed = unhex::<32>(&fields.key).ok_or_else(|| KeyError("`seed` is not 64 hex digits".into()))?;
        let key = SecretKey::from_seed(&seed);
        check_id(&fields, key.key_id())?;
        Ok(key)
    }
}

impl PublicKey {
    /// The key of its 32 bytes; refused when they are not a valid point.
    pub fn from_bytes(bytes: &[u8; 32]) -> Result<PublicKey, KeyError> {
        VerifyingKey::from_bytes(bytes)
            .map(PublicKey)
            .map_err(|_| KeyError("the key is not a valid ed25519 public key".into()))
    }

    pub fn to_bytes(&self) -> [u8; 32] {
        self.0.to_bytes()
    }

    pub fn key_id(&self) -> KeyId {
        let digest = Sha256::digest(self.0.as_bytes());
        let mut id = [0u8; KEY_ID_BYTES];
        id.copy_from_slice(&digest[..KEY_ID_BYTES]);
        KeyId(id)
    }

    /// The text of a public key file.
    pub fn to_text(&self, name: &str) -> String {
        format!(
            "{PUBLIC_HEADER}\nname: {}\nkey-id: {}\nkey: {}\n",
            one_line(name),
            self.key_id(),
            hex(self.0.as_bytes())
        )
    }

    /// Reads a public key file's text.
    pub fn from_text(text: &str) -> Result<PublicKey, KeyError> {
        let fields = parse_fields(text, PUBLIC_HEADER, "key")?;
        let bytes = unhex::<32>(&fields.key).ok_or_else(|| KeyError("`key` is not 64 hex digits".into()))?;
        let key = PublicKey::from_bytes(&bytes)?;
        check_id(&fields, key.key_id())?;
        Ok(key)
    }
}

/// What a key file says.
struct Fields {
    key: String,
    key_id: Option<String>,
}

fn parse_fields(text: &str, header: &str, key_field: &str) -> Result<Fields, KeyError> {
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#'));
    match lines.next() {
        Some(h) if h == header => {}
        Some(SECRET_HEADER) => {
            return Err(KeyError(
                "this is a secret key file (`.key`); give the public key (`.pub`) here, and keep the secret one secret"
                    .into(),
            ))
        }
        Some(PUBLIC_HEADER) => {
            return Err(KeyError(
                "this is a public key file (`.pub`); signing needs the secret key (`.key`) made with it".into(),
            ))
        }
        _ => return Err(KeyError(format!("not a situ key file (its first line is not `{header}`)"))),
    }
    let (mut key, mut key_id) = (None, None);
    for line in lines {
        let Some((field, value)) = line.split_once(':') else {
            return Err(KeyError(format!("the line `{}` is not `field: value`", one_line(line))));
        };
        let value = value.trim().to_string();
        match field.trim() {
            "name" => {}
            "key-id" => key_id = Some(value),
            f if f == key_field => key = Some(value),
            other => return Err(KeyError(format!("unknown field `{}`", one_line(other)))),
        }
    }
    let key = key.ok_or_else(|| KeyError(format!("the `{key_field}` line is missing")))?;
    Ok(Fields { key, key_id })
}

/// A file's `key-id`, when it gives one, must be the key's.
fn check_id(fields: &Fields, id: KeyId) -> Result<(), KeyError> {
    match &fields.key_id {
        Some(given) if !given.eq_ignore_ascii_case(&id.to_string()) => Err(KeyError(format!(
            "the file says `key-id: {}` but its key's id is {id}: the file was edited",
            one_line(given)
        ))),
        _ => Ok(()),
    }
}

/// What a bundle's signature signs: the format's identity and the content
/// hash recorded in the envelope (which covers the content's exact bytes).
pub fn message(sha256_hex: &str) -> Vec<u8> {
    format!("situ bundle signature v1\nformat: {FORMAT_NAME}\nformat_version: {FORMAT_VERSION}\nsha256: {sha256_hex}\n")
        .into_bytes()
}

/// The signature of the bundle whose content hashes to `sha256_hex`.
pub fn sign_hash(key: &SecretKey, sha256_hex: &str) -> Signature {
    Signature { key_id: key.key_id(), ed25519: key.0.sign(&message(sha256_hex)).to_bytes() }
}

/// The file bytes of a bundle signed with `key`.
pub fn encode_signed(content: &Content, encoding: Encoding, key: &SecretKey) -> Vec<u8> {
    codec::encode_with(content, encoding, Some(&|sha: &str| sign_hash(key, sha)))
}

/// Why a bundle is not trusted.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum TrustError {
    /// Not a bundle that loads at all (damaged, edited without re-hashing…).
    #[error(transparent)]
    Load(#[from] LoadError),
    /// A bundle without a signature.
    #[error(
        "the bundle is not signed, and only bundles signed by a trusted key ({}) are accepted: sign it with `situ build --sign KEY`",
        ids(trusted)
    )]
    Unsigned { trusted: Vec<KeyId> },
    /// Signed by a key that is not trusted.
    #[error("the bundle is signed by key {key_id}, which is not trusted (trusted: {})", ids(trusted))]
    Untrusted { key_id: KeyId, trusted: Vec<KeyId> },
    /// Says it is signed by a trusted key, but the signature does not verify:
    /// the bundle was changed after it was signed.
    #[error(
        "the bundle's signature by key {key_id} does not verify: it was changed after it was signed; rebuild and sign it again"
    )]
    BadSignature { key_id: KeyId },
}

fn ids(keys: &[KeyId]) -> String {
    keys.iter().map(KeyId::to_string).collect::<Vec<_>>().join(", ")
}

/// Checks the signature of a decoded bundle against the trusted keys; the
/// id of the key that signed it.
pub fn verify(decoded: &Decoded, trusted: &[PublicKey]) -> Result<KeyId, TrustError> {
    let trusted_ids = || trusted.iter().map(PublicKey::key_id).collect::<Vec<_>>();
    let Some(sig) = &decoded.signature else {
        return Err(TrustError::Unsigned { trusted: trusted_ids() });
    };
    let Some(key) = trusted.iter().find(|k| k.key_id() == sig.key_id) else {
        return Err(TrustError::Untrusted { key_id: sig.key_id, trusted: trusted_ids() });
    };
    let signature = ed25519_dalek::Signature::from_bytes(&sig.ed25519);
    key.0
        .verify_strict(&message(&decoded.sha256), &signature)
        .map_err(|_| TrustError::BadSignature { key_id: sig.key_id })?;
    Ok(sig.key_id)
}

/// Reads a bundle file (all of [`codec::decode`]'s checks), then requires a
/// valid signature by one of `trusted`: the content and the signer's id.
pub fn decode_trusted(bytes: &[u8], trusted: &[PublicKey]) -> Result<(Content, KeyId), TrustError> {
    let decoded = codec::decode_envelope(bytes).map_err(TrustError::Load)?;
    let key_id = verify(&decoded, trusted)?;
    Ok((decoded.content, key_id))
}

/// A name or a line from a file, safe to print on one line.
fn one_line(s: &str) -> String {
    s.chars().filter(|c| !c.is_control()).take(80).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(n: u8) -> SecretKey {
        SecretKey::from_seed(&[n; 32])
    }

    #[test]
    fn key_files_round_trip_and_say_what_is_wrong() {
        let k = key(7);
        let secret = SecretKey::from_text(&k.to_text("robot a")).expect("reads");
        assert_eq!(secret.key_id(), k.key_id());
        let public = PublicKey::from_text(&k.public().to_text("robot a")).expect("reads");
        assert_eq!(public, k.public());
        assert_eq!(k.key_id().to_string().len(), 2 * KEY_ID_BYTES);
        let err = PublicKey::from_text(&k.to_text("a")).unwrap_err();
        assert!(err.0.contains("secret key file"), "{err}");
        let err = SecretKey::from_text(&k.public().to_text("a")).unwrap_err();
        assert!(err.0.contains("public key file"), "{err}");
        assert!(PublicKey::from_text("hello\n").unwrap_err().0.contains("not a situ key file"));
        let other = key(8).public().to_text("a").replace(&key(8).key_id().to_string(), &k.key_id().to_string());
        assert!(PublicKey::from_text(&other).unwrap_err().0.contains("was edited"));
        let short = k.public().to_text("a").replace("key: ", "key: 00");
        assert!(PublicKey::from_text(&short).unwrap_err().0.contains("64 hex digits"));
        // The secret never shows in Debug.
        assert!(!format!("{k:?}").contains(&hex(&[7u8; 32])));
    }
}
