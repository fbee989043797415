//! Inputs the fuzz targets of `fuzz/` found crashing (`scripts/fuzz.sh`),
//! each kept here as it was found, in `tests/fuzz/`: each must now be
//! refused with a reason, never a panic.

use situ_runtime::record::mcap::{attached_bundle, read_recording, ReadError};

fn input(name: &str) -> Vec<u8> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz").join(name);
    std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `mcap_read`: an attachment record whose header leaves fewer than the 4
/// bytes of its CRC made the `mcap` crate (0.26) slice out of bounds, in
/// `read_recording` and in `attached_bundle`. The scan refuses it first.
#[test]
fn an_attachment_shorter_than_its_crc_is_damage_not_a_panic() {
    let bytes = input("mcap_read-attachment-shorter-than-its-crc.mcap");
    let err = read_recording(&bytes).expect_err("a damaged recording");
    assert!(matches!(&err, ReadError::Damaged { why, .. } if why.contains("attachment")), "{err}");
    assert_eq!(attached_bundle(&bytes), None);
}

/// The check that refuses it accepts the attachment of a whole recording
/// (`situ run tests/run/heartbeat.situ --until 2 --record`, kept as a file):
/// the bundle is found and every message read.
#[test]
fn a_whole_recording_still_reads_with_its_bundle() {
    let bytes = input("heartbeat-whole.mcap");
    let reading = read_recording(&bytes).expect("a whole recording");
    assert!(reading.cut.is_none(), "{:?}", reading.cut);
    assert!(!reading.messages.is_empty());
    let bundle = attached_bundle(&bytes).expect("the attached bundle");
    situ_compiler::bundle::decode(&bundle).expect("the attached bundle decodes");
}
