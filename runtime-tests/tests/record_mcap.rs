//! The recording's boundaries: every flush leaves a valid file, a damaged
//! file is an error and never an abort or a panic, whatever bit is flipped.

use situ_compiler::bundle::{self, Content, Encoding, Value};
use situ_runtime::record::mcap::read::{attached_bundle, read_recording, ReadError, MAX_RECORD};
use situ_runtime::record::mcap::staged::PROVISIONAL_END;
use situ_runtime::record::mcap::{topics, McapRecorder};
use situ_runtime::record::{EventRecord, Sink, Verdict};
use std::path::Path;
use std::sync::Arc;

const RULES: &str = "states { RS initial RO }
agent LADAR sensor { rate 10Hz event LAOBS { distance: f64 } event LAOBN function detect table { _ => run detect() } }
rule obstacle { when state == RS and LAOBS(distance < 30.0) then RO }
rule clear { when state == RO and LAOBN x3 then RS }
";

fn content() -> Arc<Content> {
    let c = situ_compiler::check_source("t.situ", RULES);
    assert!(c.diagnostics.iter().all(|d| d.code >= "E0300"), "{:?}", c.diagnostics);
    Arc::new(bundle::build(&c))
}

fn event(c: &Content, time: u64) -> EventRecord {
    let (name, payload) =
        if (time / (100 * MS)).is_multiple_of(2) { ("LAOBS", vec![Value::F64(25.0)]) } else { ("LAOBN", vec![]) };
    EventRecord { time, agent: 0, event: c.event_id(name).unwrap(), payload, urgent: false, verdict: Verdict::Accepted }
}

const MS: u64 = 1_000_000;

/// A recorder at `path`, flushing by the messages' time.
fn recorder(path: &Path, c: &Arc<Content>) -> McapRecorder {
    let bundle = bundle::encode(c, Encoding::Json);
    McapRecorder::create(path, c.clone(), &bundle).unwrap().flush_by_message_time()
}

/// A finished recording of `n` events 100 ms apart (a chunk a second).
fn recording(n: u64) -> Vec<u8> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.mcap");
    let c = content();
    let mut r = recorder(&path, &c);
    for i in 0..n {
        r.event(&event(&c, i * 100 * MS));
    }
    r.finish().unwrap();
    std::fs::read(&path).unwrap()
}

/// The top-level records: (offset, opcode, length).
fn records(bytes: &[u8]) -> Vec<(usize, u8, u64)> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap());
        out.push((at, bytes[at], len));
        if len > (bytes.len() - at - 9) as u64 {
            break;
        }
        at += 9 + len as usize;
    }
    out
}

#[test]
fn a_whole_recording_reads_back_whole() {
    let bytes = recording(40);
    let r = read_recording(&bytes).unwrap();
    assert_eq!(r.cut, None);
    assert_eq!(r.messages.iter().filter(|(t, _, _)| t == topics::EVENTS).count(), 40);
    assert!(attached_bundle(&bytes).is_some());
    assert_eq!(recording(40), bytes, "the same records give the same bytes");
}

#[test]
fn every_flush_leaves_a_valid_file_with_no_placeholder_length() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.mcap");
    let c = content();
    let mut r = recorder(&path, &c);
    let on_disk = std::fs::read(&path).unwrap();
    assert!(on_disk.ends_with(&PROVISIONAL_END), "a valid file from the start");
    assert!(attached_bundle(&on_disk).is_some(), "with its bundle");
    for i in 0..30 {
        r.event(&event(&c, i * 100 * MS));
    }
    r.flush().unwrap();
    let flushed = std::fs::read(&path).unwrap();
    // Many more records, no flush: what is on disk does not change, and is
    // never a chunk whose length is still to be written.
    for i in 30..3000 {
        r.event(&event(&c, 2_900 * MS + i));
    }
    let later = std::fs::read(&path).unwrap();
    assert_eq!(later, flushed, "nothing written between flushes");
    for (at, op, len) in records(&later) {
        assert!(len <= MAX_RECORD, "record {op:#04x} at {at} has length {len}");
    }
    let read = read_recording(&later).unwrap();
    assert_eq!(read.messages.iter().filter(|(t, _, _)| t == topics::EVENTS).count(), 30);
    assert!(read.cut.as_deref().is_some_and(|w| w.contains("not finished")), "{:?}", read.cut);
    // The process dies here: the file stays what the last flush wrote.
    std::mem::forget(r);
    assert_eq!(std::fs::read(&path).unwrap(), flushed);
}

#[test]
fn a_finished_recording_has_no_provisional_end_left() {
    let bytes = recording(25);
    assert!(bytes.ends_with(::mcap::MAGIC));
    assert!(!bytes.windows(PROVISIONAL_END.len()).any(|w| w == PROVISIONAL_END));
    let summary = ::mcap::read::Summary::read(&bytes).unwrap().expect("a summary");
    assert!(summary.stats.is_some_and(|s| s.message_count > 0));
}

#[test]
fn an_absurd_chunk_length_is_an_error_not_an_allocation() {
    let bytes = recording(25);
    let (at, _, _) = *records(&bytes).iter().find(|(_, op, _)| *op == ::mcap::records::op::CHUNK).unwrap();
    // The top bit of the chunk's length: 2^63 more bytes than the file has.
    let mut damaged = bytes.clone();
    damaged[at + 8] ^= 0x80;
    match read_recording(&damaged).unwrap_err() {
        ReadError::Damaged { at: where_, size, why } => {
            assert_eq!((where_, size), (at, bytes.len()));
            assert!(why.contains("claims"), "{why}");
        }
        e => panic!("{e}"),
    }
    // Its uncompressed size (offset 16 of the chunk's body): too large to decompress.
    let mut damaged = bytes.clone();
    damaged[at + 9 + 16 + 7] ^= 0x40;
    let e = read_recording(&damaged).unwrap_err();
    assert!(matches!(&e, ReadError::Damaged { why, .. } if why.contains("uncompressed")), "{e}");
    // Bytes of its compressed data: the chunk's CRC or zstd says so. The
    // 10th, bit 7, is the flip of issue 14: the `mcap` crate's own reader
    // decompressed it to a record length of 8.2e18 bytes and aborted.
    let data = at + 9 + 8 + 8 + 8 + 4 + 4 + 4 + 8;
    for (i, bit) in [(9, 0x80), (20, 0x10)] {
        let mut damaged = bytes.clone();
        damaged[data + i] ^= bit;
        let e = read_recording(&damaged).unwrap_err();
        assert!(e.to_string().starts_with("damaged"), "{e}");
    }
}

#[test]
fn garbage_and_foreign_files_are_errors() {
    for junk in [&b""[..], b"not a recording", b"\x89MCAP0\r\n", &[0u8; 64]] {
        match read_recording(junk) {
            Err(e) => assert!(matches!(e, ReadError::NotMcap | ReadError::Damaged { .. }), "{e}"),
            // Only the magic: a recording cut right after it.
            Ok(r) => assert!(r.messages.is_empty() && r.cut.is_some()),
        }
        assert!(attached_bundle(junk).is_none());
    }
}

#[test]
fn a_recording_cut_anywhere_reads_what_is_before_the_cut() {
    let bytes = recording(25);
    let whole = read_recording(&bytes).unwrap().messages.len();
    let mut last = 0;
    for end in (0..=bytes.len()).step_by(7) {
        match read_recording(&bytes[..end]) {
            Ok(r) => {
                assert!(r.messages.len() >= last, "a longer prefix reads no fewer messages");
                last = r.messages.len();
                assert!(r.cut.is_some() || end == bytes.len());
            }
            Err(e) => assert!(end < 8, "a prefix of {end} bytes: {e}"),
        }
    }
    assert!(last <= whole);
}

/// One flipped bit anywhere: `Ok` or `Err`, never a panic or an abort
/// (the high bit of every byte, and another bit of it). In a chunk's
/// compressed data, the flip is found or changes nothing (the chunk's CRC).
#[test]
fn a_flipped_bit_anywhere_never_panics_or_aborts() {
    let c = content();
    let bytes = recording(25);
    assert!(bytes.len() < 64 * 1024, "a small recording: {} bytes", bytes.len());
    // The compressed data of each chunk (after its 44-byte header with "zstd").
    let chunk_data: Vec<std::ops::Range<usize>> = records(&bytes)
        .into_iter()
        .filter(|(_, op, _)| *op == ::mcap::records::op::CHUNK)
        .map(|(at, _, len)| at + 9 + 44..at + 9 + len as usize)
        .collect();
    assert!(chunk_data.len() >= 3, "{chunk_data:?}");
    let whole = read_recording(&bytes).unwrap().messages;
    let mut errors = 0;
    for at in 0..bytes.len() {
        let in_chunk_data = chunk_data.iter().any(|r| r.contains(&at));
        for bit in [7, at % 7] {
            let mut damaged = bytes.clone();
            damaged[at] ^= 1 << bit;
            match read_recording(&damaged) {
                Ok(r) => {
                    // A flip that leaves the decompressed data as it was (in
                    // zstd's frame header, say) reads the same messages.
                    assert!(
                        !in_chunk_data || r.messages == whole,
                        "a flip of bit {bit} at byte {at}, in a chunk's data, reads other messages"
                    );
                    // What reads is replayed without a panic too.
                    if at % 16 == 0 {
                        let _ = situ_runtime::replay::replay_reading(&r, c.clone());
                    }
                }
                Err(e) => {
                    assert!(!e.to_string().is_empty());
                    errors += 1;
                }
            }
            let _ = attached_bundle(&damaged);
        }
    }
    assert!(errors > 0);
}

/// What cannot be replayed says why as a value: not MCAP, cut before
/// anything of situ's; what is not a recording file says so too.
#[test]
fn replay_and_file_errors_are_typed() {
    use situ_runtime::record::mcap::read::{read_file, FileError};
    use situ_runtime::replay::{replay, ReplayError};
    let c = content();
    assert_eq!(replay(b"not a recording", c.clone()).unwrap_err(), ReplayError::Read(ReadError::NotMcap));
    match replay(::mcap::MAGIC, c.clone()).unwrap_err() {
        ReplayError::NothingBeforeCut(why) => assert!(why.contains("no footer"), "{why}"),
        e => panic!("{e}"),
    }
    let dir = tempfile::tempdir().unwrap();
    let e = read_file(dir.path()).unwrap_err();
    assert!(matches!(e, FileError::NotAFile), "{e}");
    assert_eq!(e.to_string(), "not a regular file: a recording is a file");
    let e = read_file(&dir.path().join("missing.mcap")).unwrap_err();
    assert!(matches!(e, FileError::Io(_)) && e.to_string().starts_with("cannot read it: "), "{e}");
}
