//! The facade as a client uses it: findings are data, every refusal is a
//! typed error that says which check refused and keeps what it found.

use situ_api::{build, check, format, load, load_path, BuildOptions, Error, Input, Trust};
use situ_compiler::bundle::sign::SecretKey;

const DOOR: &str = "states { Closed initial Open }\n\
agent Door sensor { event OPENED }\n\
rule opened { when state == Closed and OPENED then Open }\n";

fn door() -> situ_api::Checked {
    check(Input::Text { name: "door.situ", text: DOOR }).expect("a text always checks")
}

#[test]
fn a_source_with_errors_checks_to_its_findings_and_does_not_build() {
    let checked =
        check(Input::Text { name: "bad.situ", text: "states { A initial }\nrule r { when state == B then A }\n" })
            .expect("findings are data, not an error");
    assert!(checked.errors() > 0, "an undefined state is an error");
    match build(&checked, &BuildOptions::default()) {
        Err(Error::Findings { name, errors, checked, .. }) => {
            assert_eq!(name, "bad.situ");
            assert_eq!(errors, checked.errors());
        }
        other => panic!("expected the findings, got {other:?}"),
    }
}

#[test]
fn a_missing_root_file_is_an_error_that_names_it() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let missing = dir.path().join("missing.situ");
    let err = check(Input::Path(&missing)).expect_err("nothing to read");
    assert!(matches!(err, Error::Root(_)), "{err:?}");
    assert!(err.to_string().contains("missing.situ"), "{err}");
}

#[test]
fn format_refuses_a_source_with_syntax_errors() {
    assert!(matches!(format("states { A initial"), Err(Error::Syntax(d)) if !d.is_empty()));
    let once = format(DOOR).expect("the door formats");
    assert_eq!(format(&once).expect("formatted text formats"), once);
}

#[test]
fn trust_asks_for_a_trusted_signature() {
    let key = SecretKey::from_seed(&[7; 32]);
    let other = SecretKey::from_seed(&[8; 32]);
    let checked = door();
    let unsigned = build(&checked, &BuildOptions::default()).expect("the door builds");
    let signed = build(&checked, &BuildOptions { key: Some(key.clone()), ..BuildOptions::default() }).expect("signed");
    assert_eq!(signed.signed_by, Some(key.key_id()));

    let trust = Trust::from_keys(vec![key.public()]);
    assert_eq!(load(&signed.bytes, &trust).expect("a trusted signature").signer, Some(key.key_id()));
    assert!(matches!(load(&unsigned.bytes, &trust), Err(Error::Trust(_))));
    assert!(matches!(load(&signed.bytes, &Trust::from_keys(vec![other.public()])), Err(Error::Trust(_))));
    assert!(load(&unsigned.bytes, &Trust::Any).is_ok(), "without keys any valid bundle loads");
    assert!(!Trust::from_keys(Vec::new()).requires_signature());
}

#[test]
fn a_changed_bundle_does_not_load() {
    let mut bytes = build(&door(), &BuildOptions::default()).expect("the door builds").bytes;
    let at = bytes.iter().position(|&b| b == b'O').expect("a letter to change");
    bytes[at] = b'P';
    assert!(matches!(load(&bytes, &Trust::Any), Err(Error::Bundle(_))));
}

#[test]
fn load_path_reads_sources_and_bundles_and_refuses_sources_under_trust() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let source = dir.path().join("door.situ");
    std::fs::write(&source, DOOR).expect("written");
    let program = load_path(&source, &Trust::Any, false).expect("a source loads");
    assert!(program.checked.is_some() && program.bytes.is_none());

    let key = SecretKey::from_seed(&[7; 32]);
    let trust = Trust::from_keys(vec![key.public()]);
    assert!(matches!(load_path(&source, &trust, false), Err(Error::UnsignedSource { .. })));

    let built = build(&door(), &BuildOptions { key: Some(key), ..BuildOptions::default() }).expect("signed");
    let bundle = dir.path().join("door.bundle");
    std::fs::write(&bundle, &built.bytes).expect("written");
    let program = load_path(&bundle, &trust, false).expect("a trusted bundle loads");
    assert_eq!(program.bytes.as_deref(), Some(&built.bytes[..]));
    assert_eq!(program.content.states.len(), 2);

    let missing = dir.path().join("gone.bundle");
    assert!(matches!(load_path(&missing, &Trust::Any, false), Err(Error::Read { .. })));
}

#[test]
fn test_gives_each_verdict_and_the_suites() {
    let dir = tempfile::tempdir().expect("a temporary folder");
    let file = dir.path().join("door.situ");
    let text = format!(
        "{DOOR}\ntest \"it opens\" {{\n    on OPENED at 0ms\n    expect state Open\n}}\n\
         property \"a state of the door\" {{ always state in {{Closed, Open}} }}\n\
         property \"never open\" {{ never state == Open }}\n"
    );
    std::fs::write(&file, text).expect("written");
    let report = situ_api::test(&[file], &situ_api::TestOptions::default());
    // The test passes and the first property is proved; the second is violated.
    assert_eq!((report.summary.passed, report.summary.failed, report.summary.undecided), (2, 1, 0));
    assert_eq!(report.verdict(), situ_api::Verdict::Fail);
}
