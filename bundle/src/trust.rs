//! The trust policy as a value, and loading a bundle under it.
//!
//! [`Trust::Any`] loads every bundle that passes the envelope's checks,
//! signed or not; [`Trust::Keys`] also requires a valid signature by one of
//! the keys (`docs/signing.md`). The caller builds the value (the command
//! line from its `--trust` flags) and hands it to [`load`]; nothing here is
//! global.

use crate::codec;
use crate::sign::{self, KeyId, PublicKey, TrustError};
use crate::Content;

/// Which bundles load.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub enum Trust {
    /// Every bundle that is whole and valid, signed or not.
    #[default]
    Any,
    /// Only bundles signed by one of these keys (none: no bundle loads).
    Keys(Vec<PublicKey>),
}

impl Trust {
    /// The policy of a list of trusted keys as given on a command line: no
    /// key means [`Trust::Any`].
    pub fn from_keys(keys: Vec<PublicKey>) -> Trust {
        if keys.is_empty() {
            Trust::Any
        } else {
            Trust::Keys(keys)
        }
    }

    /// Whether a program must come as a signed bundle (a source, which
    /// carries no signature, is then refused).
    pub fn requires_signature(&self) -> bool {
        matches!(self, Trust::Keys(_))
    }
}

/// A bundle loaded under a [`Trust`]: its content, and the trusted key that
/// signed it when the policy asked for one.
#[derive(Debug, Clone, PartialEq)]
pub struct Loaded {
    pub content: Content,
    /// `Some` under [`Trust::Keys`]: the key whose signature verified.
    pub signer: Option<KeyId>,
}

/// Reads a bundle file (all of [`codec::decode`]'s checks); under
/// [`Trust::Keys`], then requires a valid signature by one of the keys
/// ([`sign::verify`]).
pub fn load(bytes: &[u8], trust: &Trust) -> Result<Loaded, TrustError> {
    match trust {
        Trust::Any => Ok(Loaded { content: codec::decode(bytes)?, signer: None }),
        Trust::Keys(keys) => {
            let (content, key_id) = sign::decode_trusted(bytes, keys)?;
            Ok(Loaded { content, signer: Some(key_id) })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::codec::{Encoding, LoadError};
    use crate::sign::{encode_signed, SecretKey};

    fn key(n: u8) -> SecretKey {
        SecretKey::from_seed(&[n; 32])
    }

    /// The smallest valid content: one state, nothing else.
    fn tiny() -> Content {
        let json = r#"{"source":"t.situ","states":[{"name":"IT","final":false,"description":null}],"initial":0,
            "agents":[],"events":[],"rules":[],
            "network":{"alpha":[],"beta":[],"terminals":[],
                "stats":{"alpha_unshared":0,"alpha":0,"beta_unshared":0,"beta":0,"terminals":0}},
            "wiring":[{"state":0,"links":[],"fsm_links":[]}]}"#;
        serde_json::from_str(json).expect("a content")
    }

    #[test]
    fn any_loads_signed_and_unsigned_bundles_without_naming_a_signer() {
        let c = tiny();
        for bytes in [codec::encode(&c, Encoding::Json), encode_signed(&c, Encoding::Binary, &key(1))] {
            assert_eq!(load(&bytes, &Trust::Any), Ok(Loaded { content: c.clone(), signer: None }));
        }
    }

    #[test]
    fn keys_load_only_bundles_signed_by_one_of_them_and_name_the_signer() {
        let c = tiny();
        let trust = Trust::from_keys(vec![key(2).public(), key(1).public()]);
        assert!(trust.requires_signature());
        let signed = encode_signed(&c, Encoding::Json, &key(1));
        assert_eq!(load(&signed, &trust), Ok(Loaded { content: c.clone(), signer: Some(key(1).key_id()) }));
        let unsigned = codec::encode(&c, Encoding::Json);
        assert!(matches!(load(&unsigned, &trust), Err(TrustError::Unsigned { .. })));
        let other = encode_signed(&c, Encoding::Json, &key(3));
        assert!(matches!(load(&other, &trust), Err(TrustError::Untrusted { .. })));
        // Damage is refused as damage, under either policy.
        for trust in [Trust::Any, trust] {
            assert!(matches!(load(b"", &trust), Err(TrustError::Load(LoadError::NotABundle { .. }))));
        }
    }

    #[test]
    fn no_key_given_is_any_and_an_empty_key_list_loads_nothing() {
        assert_eq!(Trust::from_keys(Vec::new()), Trust::Any);
        assert!(!Trust::Any.requires_signature());
        let signed = encode_signed(&tiny(), Encoding::Json, &key(1));
        assert!(matches!(load(&signed, &Trust::Keys(Vec::new())), Err(TrustError::Untrusted { .. })));
    }
}
