//! Signed bundles of a compiled program: signing, verifying and refusing
//! (the signing code is `situ_bundle::sign`; these tests need a program,
//! so they live with the compiler that builds one).

use situ_compiler::bundle::codec::{self, Encoding, LoadError};
use situ_compiler::bundle::sign::*;
use situ_compiler::bundle::Content;

const RULES: &str = include_str!("../../examples/fig5/fig5.situ");

fn content() -> Content {
    let checked = situ_compiler::check_source("fig5.situ", RULES);
    assert_eq!(checked.errors(), 0, "{:?}", checked.diagnostics);
    situ_compiler::bundle::build(&checked)
}

fn key(n: u8) -> SecretKey {
    SecretKey::from_seed(&[n; 32])
}

#[test]
fn a_signed_bundle_verifies_with_its_key_in_both_encodings() {
    let c = content();
    for enc in [Encoding::Json, Encoding::Binary] {
        let bytes = encode_signed(&c, enc, &key(1));
        let (back, id) = decode_trusted(&bytes, &[key(2).public(), key(1).public()]).expect("trusted");
        assert_eq!(back, c, "{enc:?}");
        assert_eq!(id, key(1).key_id());
        // Without trust it loads as any bundle does.
        assert_eq!(codec::decode(&bytes).expect("loads"), c);
    }
}

#[test]
fn an_edited_bundle_with_a_recomputed_hash_is_refused_naming_the_key() {
    let c = content();
    let text = String::from_utf8(encode_signed(&c, Encoding::Json, &key(1))).unwrap();
    let envelope: serde_json::Value = serde_json::from_str(&text).unwrap();
    let old = envelope["sha256"].as_str().unwrap().to_string();
    // Move the threshold, then put the hash of the new content in place.
    let start = text.find("\"content\":").unwrap() + "\"content\":".len();
    let body = &text[start..text.rfind('}').unwrap()];
    let edited_body = body.replacen("30.0", "3.0", 1);
    assert_ne!(edited_body, body);
    let new = codec::sha256_hex(edited_body.as_bytes());
    let edited = text.replacen(body, &edited_body, 1).replacen(&old, &new, 1);
    // The envelope alone accepts it: the hash is right.
    let decoded = codec::decode_envelope(edited.as_bytes()).expect("the hash matches");
    assert_ne!(decoded.content, c);
    let err = decode_trusted(edited.as_bytes(), &[key(1).public()]).unwrap_err();
    assert_eq!(err, TrustError::BadSignature { key_id: key(1).key_id() });
    assert!(err.to_string().contains(&key(1).key_id().to_string()), "{err}");
}

#[test]
fn a_bundle_signed_by_another_key_is_refused() {
    let bytes = encode_signed(&content(), Encoding::Binary, &key(3));
    let err = decode_trusted(&bytes, &[key(1).public()]).unwrap_err();
    assert_eq!(err, TrustError::Untrusted { key_id: key(3).key_id(), trusted: vec![key(1).key_id()] });
    let text = err.to_string();
    assert!(text.contains(&key(3).key_id().to_string()) && text.contains(&key(1).key_id().to_string()));
}

#[test]
fn a_signature_claiming_a_trusted_key_but_made_by_another_is_refused() {
    // Signed by key 3, relabelled as key 1's.
    let c = content();
    let mut bytes = encode_signed(&c, Encoding::Binary, &key(3));
    let at = bytes.len() - 64 - KEY_ID_BYTES;
    bytes[at..at + KEY_ID_BYTES].copy_from_slice(&key(1).key_id().0);
    let err = decode_trusted(&bytes, &[key(1).public()]).unwrap_err();
    assert_eq!(err, TrustError::BadSignature { key_id: key(1).key_id() });
}

#[test]
fn an_unsigned_bundle_is_refused_under_trust_and_loads_without() {
    let c = content();
    for enc in [Encoding::Json, Encoding::Binary] {
        let bytes = codec::encode(&c, enc);
        let err = decode_trusted(&bytes, &[key(1).public()]).unwrap_err();
        assert_eq!(err, TrustError::Unsigned { trusted: vec![key(1).key_id()] });
        assert!(err.to_string().contains(&key(1).key_id().to_string()));
        assert_eq!(codec::decode(&bytes).expect("loads"), c);
    }
}

#[test]
fn a_damaged_signed_bundle_is_refused_for_its_damage_first() {
    let mut bytes = encode_signed(&content(), Encoding::Binary, &key(1));
    let at = bytes.len() - 64 - KEY_ID_BYTES - 8 - 1;
    bytes[at] ^= 1; // the last content byte
    let err = decode_trusted(&bytes, &[key(1).public()]).unwrap_err();
    assert!(matches!(err, TrustError::Load(LoadError::Modified { .. })), "{err:?}");
}

#[test]
fn a_malformed_signature_field_is_damage() {
    let text = String::from_utf8(encode_signed(&content(), Encoding::Json, &key(1))).unwrap();
    let id = key(1).key_id().to_string();
    let broken = text.replacen(&id, "not-hex", 1);
    assert!(matches!(codec::decode(broken.as_bytes()), Err(LoadError::Damaged { .. })));
}
