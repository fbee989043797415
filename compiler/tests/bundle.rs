//! Bundles: every kind of damaged file is refused with the error that says
//! which kind, never a panic; a valid bundle reads back to the same content.

use proptest::prelude::*;
use situ_compiler::bundle::{self, decode, encode, Content, Encoding, LoadError};

fn outdoor() -> Content {
    static CONTENT: std::sync::OnceLock<Content> = std::sync::OnceLock::new();
    CONTENT
        .get_or_init(|| {
            let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
            let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("readable");
            assert_eq!(checked.errors(), 0);
            bundle::build(&checked)
        })
        .clone()
}

#[test]
fn json_and_binary_read_back_to_the_same_content() {
    let c = outdoor();
    for enc in [Encoding::Json, Encoding::Binary] {
        let bytes = encode(&c, enc);
        assert_eq!(decode(&bytes).expect("reads back"), c, "{enc:?}");
    }
    // Building twice gives the same bytes: bundles diff cleanly.
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
    let again = bundle::build(&situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap());
    assert_eq!(encode(&again, Encoding::Json), encode(&c, Encoding::Json));
}

#[test]
fn an_edited_bundle_is_refused_as_modified() {
    let bytes = encode(&outdoor(), Encoding::Json);
    let text = String::from_utf8(bytes).unwrap();
    // Move a threshold: `distance < 30.0` becomes `< 31.0`.
    let edited = text.replacen("30.0", "31.0", 1);
    assert_ne!(edited, text);
    assert!(matches!(decode(edited.as_bytes()), Err(LoadError::Modified { .. })));
    let mut bin = encode(&outdoor(), Encoding::Binary);
    let last = bin.len() - 1;
    bin[last] ^= 1;
    assert!(matches!(decode(&bin), Err(LoadError::Modified { .. })));
}

#[test]
fn a_truncated_bundle_is_refused_as_truncated() {
    for enc in [Encoding::Json, Encoding::Binary] {
        let bytes = encode(&outdoor(), enc);
        for cut in [4, 30, 100, bytes.len() / 2, bytes.len() - 3] {
            match decode(&bytes[..cut]) {
                Err(LoadError::Truncated { .. }) => {}
                other => panic!("{enc:?} cut at {cut}: {other:?}"),
            }
        }
    }
}

#[test]
fn a_newer_or_older_format_is_refused_with_both_versions() {
    let text = String::from_utf8(encode(&outdoor(), Encoding::Json)).unwrap();
    let newer = text.replacen("\"format_version\":1", "\"format_version\":2", 1);
    match decode(newer.as_bytes()) {
        Err(e @ LoadError::NewerFormat { found: 2, supported: 1, .. }) => {
            assert!(e.to_string().contains("upgrade situ"), "{e}")
        }
        other => panic!("{other:?}"),
    }
    let older = text.replacen("\"format_version\":1", "\"format_version\":0", 1);
    assert!(matches!(decode(older.as_bytes()), Err(LoadError::OlderFormat { found: 0, .. })));
    let mut bin = encode(&outdoor(), Encoding::Binary);
    bin[8] = 9; // the format version's low byte
    assert!(matches!(decode(&bin), Err(LoadError::NewerFormat { found: 9, .. })));
}

#[test]
fn other_files_are_not_bundles() {
    let source = std::fs::read(std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ")).unwrap();
    let cases: Vec<Vec<u8>> = vec![
        Vec::new(),
        source,
        b"{\"format\": \"geojson\"}".to_vec(),
        b"[1, 2, 3]".to_vec(),
        vec![0xff, 0xfe, 0x00, 0x01],
        b"\x89PNG\r\n\x1a\n".to_vec(),
    ];
    for bytes in cases {
        match decode(&bytes) {
            Err(e @ LoadError::NotABundle { .. }) => assert!(e.to_string().starts_with("not a situ bundle")),
            other => panic!("{:?}: {other:?}", String::from_utf8_lossy(&bytes)),
        }
    }
}

#[test]
fn a_damaged_envelope_is_refused_as_damaged() {
    let text = String::from_utf8(encode(&outdoor(), Encoding::Json)).unwrap();
    let broken = text.replacen("\"sha256\"", "\"sha256\" \"", 1);
    assert!(matches!(decode(broken.as_bytes()), Err(LoadError::Damaged { .. })));
    let no_hash = text.replacen("\"sha256\"", "\"hash\"", 1);
    assert!(matches!(decode(no_hash.as_bytes()), Err(LoadError::Damaged { .. })));
}

#[test]
fn a_rehashed_content_that_lies_is_refused_as_invalid() {
    // A bundle made by hand, hashed correctly, with a rule whose target
    // does not exist: the hash is fine, the content is not.
    let mut c = outdoor();
    c.rules[0].target = 999;
    match decode(&encode(&c, Encoding::Json)) {
        Err(LoadError::Invalid { reason }) => assert!(reason.contains("999"), "{reason}"),
        other => panic!("{other:?}"),
    }
    let mut c = outdoor();
    c.network.beta[3].parent = Some(50);
    assert!(matches!(decode(&encode(&c, Encoding::Binary)), Err(LoadError::Invalid { .. })));
}

#[test]
fn a_rate_out_of_range_is_refused_naming_the_agent() {
    let ladar = outdoor().agent_id("LADAR").expect("LADAR") as usize;
    for hz in [0.0, -10.0, 1e308, 1e9, 1000.5, 0.0005, f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut c = outdoor();
        c.agents[ladar].rate_hz = Some(hz);
        // JSON has no NaN or infinity: those go through the binary encoding.
        let encodings: &[Encoding] =
            if hz.is_finite() { &[Encoding::Json, Encoding::Binary] } else { &[Encoding::Binary] };
        for &enc in encodings {
            match decode(&encode(&c, enc)) {
                Err(e @ LoadError::Invalid { .. }) => {
                    assert!(e.to_string().contains("agent `LADAR` has rate"), "{hz} {enc:?}: {e}")
                }
                other => panic!("{hz} {enc:?}: {other:?}"),
            }
        }
    }
    for hz in [bundle::MIN_RATE_HZ, 10.0, bundle::MAX_RATE_HZ] {
        let mut c = outdoor();
        c.agents[ladar].rate_hz = Some(hz);
        assert_eq!(decode(&encode(&c, Encoding::Binary)).expect("in range"), c, "{hz}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    /// Any change of any byte: an error (never a panic), and never a
    /// bundle that differs from the original.
    #[test]
    fn mutated_bundles_never_load_as_something_else(
        binary in any::<bool>(),
        edits in prop::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..4),
    ) {
        let original = outdoor();
        let mut bytes = encode(&original, if binary { Encoding::Binary } else { Encoding::Json });
        for (at, byte) in edits {
            let i = at.index(bytes.len());
            bytes[i] = byte;
        }
        if let Ok(c) = decode(&bytes) {
            prop_assert_eq!(c, original);
        }
    }
}

/// Found by the `parse_check` fuzz target (`tests/fuzz/`, as found): a
/// condition may compare with `-inf` or `inf`, which serde_json writes as
/// `null`; the JSON bundle of a program without errors did not read back.
#[test]
fn an_infinite_bound_in_a_condition_reads_back_in_both_encodings() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz");
    let found = dir.join("parse_check-an-infinite-bound.situ");
    let written = "states { A initial B }\n\
                   agent L sensor { event E { d: f64 } }\n\
                   rule up { when state == A and E(d >= -inf) and not E(d in -inf..inf) then B }\n\
                   rule down { when state == B and E(d < inf) and E(d != -inf) then A }\n";
    let loader = situ_compiler::loader::MemLoader::new().with("written.situ", written);
    for (path, loader) in [
        (found.as_path(), &situ_compiler::loader::FsLoader as &dyn situ_compiler::loader::Loader),
        (std::path::Path::new("written.situ"), &loader),
    ] {
        let checked = situ_compiler::check(path, loader).expect("readable");
        assert_eq!(checked.errors(), 0, "{}", path.display());
        let content = bundle::build(&checked);
        let json = String::from_utf8(encode(&content, Encoding::Json)).unwrap();
        assert!(json.contains(r#""f64": "-inf""#), "{json}");
        for enc in [Encoding::Json, Encoding::Binary] {
            assert_eq!(decode(&encode(&content, enc)).expect("reads back"), content, "{}: {enc:?}", path.display());
        }
    }
}
