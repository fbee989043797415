//! The journal's file: round trip, torn tails, another bundle, damage.

use super::*;

const A: &str = "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa";
const B: &str = "bbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbbb";

fn event(agent: u32, event: u32, time: u64, payload: Vec<Value>, accepted: bool) -> Entry {
    Entry::Event { msg: EventMsg { agent, event, time, payload, urgent: agent % 2 == 1 }, accepted }
}

/// A few entries of every kind and value.
fn sample() -> Vec<Entry> {
    vec![
        event(0, 1, 10, vec![Value::F64(f64::NAN), Value::I64(-7)], true),
        Entry::Tick { time: 20 },
        event(1, 3, 30, vec![Value::Bool(true), Value::Symbol(4), Value::F64(-0.0)], false),
        event(2, 0, 40, vec![], true),
        Entry::Tick { time: u64::MAX },
    ]
}

fn bits(e: &Entry) -> String {
    // NaN != NaN: compare entries by their encoding.
    let mut v = Vec::new();
    encode_record(&mut v, 0, e);
    format!("{v:?}")
}

fn write_all(path: &Path, sha: &str, epoch: u64, entries: &[Entry]) {
    let (mut j, _) = Journal::open_for(path, sha).unwrap();
    j.set_epoch(epoch);
    for e in entries {
        j.write(&mut vec![e.clone()], false);
    }
    assert!(j.failures().lock().unwrap().is_none());
}

#[test]
fn entries_come_back_in_order_with_their_epochs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("board.journal");
    let (j, r) = Journal::open_for(&path, A).unwrap();
    assert_eq!((r.entries.len(), r.dropped, j.len()), (0, 0, HEADER_LEN as u64));
    drop(j);
    write_all(&path, A, 3, &sample()[..2]);
    write_all(&path, A, 5, &sample()[2..]);
    let (j, r) = Journal::open_for(&path, A).unwrap();
    assert_eq!(r.entries.len(), 5);
    assert_eq!(r.epoch, 5);
    assert_eq!(r.dropped, 0);
    assert_eq!(j.records(), 5);
    let epochs: Vec<u64> = r.entries.iter().map(|l| l.epoch).collect();
    assert_eq!(epochs, [3, 3, 5, 5, 5]);
    let got: Vec<String> = r.entries.iter().map(|l| bits(&l.entry)).collect();
    let want: Vec<String> = sample().iter().map(bits).collect();
    assert_eq!(got, want);
}

#[test]
fn a_write_of_several_entries_is_one_append_and_a_change_syncs() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    let (mut j, _) = Journal::open_for(&path, A).unwrap();
    let mut batch = sample();
    j.write(&mut batch, true);
    assert!(batch.is_empty(), "the entries are drained");
    assert!(!j.dirty, "synced before the change");
    j.write(&mut vec![Entry::Tick { time: 1 }], false);
    assert!(j.dirty);
    j.write(&mut Vec::new(), true);
    assert!(!j.dirty, "a change with no new entry still syncs what came before");
    assert_eq!(std::fs::metadata(&path).unwrap().len(), j.len());
    drop(j);
    assert_eq!(Journal::open_for(&path, A).unwrap().1.entries.len(), 6);
}

#[test]
fn a_torn_tail_at_every_byte_of_the_last_record_leaves_the_entries_before() {
    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    write_all(&full, A, 1, &sample());
    let bytes = std::fs::read(&full).unwrap();
    let mut last = Vec::new();
    encode_record(&mut last, 1, sample().last().unwrap());
    let before = bytes.len() - last.len();
    let path = dir.path().join("torn");
    for cut in 0..last.len() {
        std::fs::write(&path, &bytes[..before + cut]).unwrap();
        let (mut j, r) = Journal::open_for(&path, A).unwrap();
        assert_eq!(r.entries.len(), 4, "cut at {cut}");
        assert_eq!(r.dropped, cut as u64, "cut at {cut}");
        assert_eq!(std::fs::metadata(&path).unwrap().len(), before as u64, "the tail is cut off");
        // It goes on appending after the entries it kept.
        j.write(&mut vec![Entry::Tick { time: 99 }], true);
        drop(j);
        let (_, r) = Journal::open_for(&path, A).unwrap();
        assert_eq!((r.entries.len(), r.dropped), (5, 0), "cut at {cut}");
        assert_eq!(r.entries[4].entry, Entry::Tick { time: 99 });
    }
}

#[test]
fn a_torn_tail_of_zeros_or_a_bad_checksum_at_the_end_is_cut() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    write_all(&path, A, 1, &sample());
    let mut bytes = std::fs::read(&path).unwrap();
    let n = bytes.len();
    // The last byte of the last record changed: its checksum fails.
    bytes[n - 1] ^= 0x55;
    std::fs::write(&path, &bytes).unwrap();
    let (_, r) = Journal::open_for(&path, A).unwrap();
    assert_eq!(r.entries.len(), 4);
    // A power loss: the file grew, its data did not come.
    let mut bytes = std::fs::read(&path).unwrap();
    bytes.extend_from_slice(&[0; 100]);
    std::fs::write(&path, &bytes).unwrap();
    let (_, r) = Journal::open_for(&path, A).unwrap();
    assert_eq!((r.entries.len(), r.dropped), (4, 100));
}

#[test]
fn a_header_cut_short_starts_a_new_journal() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    let h = header(A);
    for cut in 0..HEADER_LEN {
        std::fs::write(&path, &h[..cut]).unwrap();
        let (_, r) = Journal::open_for(&path, A).unwrap();
        assert_eq!((r.entries.len(), r.dropped), (0, cut as u64));
        assert_eq!(std::fs::read(&path).unwrap(), h);
    }
}

#[test]
fn a_journal_of_another_bundle_is_refused_and_left_alone() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    write_all(&path, A, 1, &sample());
    let before = std::fs::read(&path).unwrap();
    let err = Journal::open_for(&path, B).unwrap_err();
    assert!(matches!(&err, JournalError::OtherBundle { found, expected, .. } if found == A && expected == B), "{err}");
    assert!(err.to_string().contains("move it away"), "{err}");
    assert_eq!(std::fs::read(&path).unwrap(), before);
}

#[test]
fn another_file_or_version_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    std::fs::write(&path, b"{\"not\": \"a journal at all, but long enough to hold a header and more bytes\"}").unwrap();
    assert!(matches!(Journal::open_for(&path, A), Err(JournalError::NotAJournal { .. })));
    let mut h = MAGIC.to_vec();
    h.extend_from_slice(&2u32.to_le_bytes());
    h.extend_from_slice(A.as_bytes());
    let crc = crc32(&h);
    h.extend_from_slice(&crc.to_le_bytes());
    std::fs::write(&path, &h).unwrap();
    let err = Journal::open_for(&path, A).unwrap_err();
    assert!(matches!(err, JournalError::Version { found: 2, expected: 1, .. }), "{err}");
}

#[test]
fn damage_in_the_middle_is_an_error_at_its_offset() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    write_all(&path, A, 1, &sample());
    let good = std::fs::read(&path).unwrap();
    let mut first = Vec::new();
    encode_record(&mut first, 1, &sample()[0]);
    let second = HEADER_LEN + first.len();
    // A byte of the second record's body.
    let mut bytes = good.clone();
    bytes[second + 12] ^= 1;
    std::fs::write(&path, &bytes).unwrap();
    let err = Journal::open_for(&path, A).unwrap_err();
    assert!(matches!(err, JournalError::Damaged { offset, .. } if offset == second as u64), "{err}");
    assert!(err.to_string().contains(&format!("byte {second}")), "{err}");
    // A length far too long.
    let mut bytes = good.clone();
    bytes[second + 3] = 0x7f;
    std::fs::write(&path, &bytes).unwrap();
    let err = Journal::open_for(&path, A).unwrap_err();
    assert!(matches!(err, JournalError::Damaged { offset, .. } if offset == second as u64), "{err}");
    // Nothing was cut.
    assert_eq!(std::fs::read(&path).unwrap(), bytes);
}

#[test]
fn a_failed_write_is_told_and_stops_the_journal() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("j");
    let (mut j, _) = Journal::open_for(&path, A).unwrap();
    // A file opened read-only in its place: writes fail.
    j.file = File::open(&path).unwrap();
    j.write(&mut sample(), true);
    let failures = j.failures();
    let err = failures.lock().unwrap().take();
    assert!(matches!(err, Some(JournalError::Io { .. })), "{err:?}");
    j.file = OpenOptions::new().append(true).open(&path).unwrap();
    j.write(&mut sample(), true);
    assert!(failures.lock().unwrap().is_none());
    assert_eq!(std::fs::metadata(&path).unwrap().len(), HEADER_LEN as u64, "nothing written after a failure");
}

#[test]
fn the_checksum_is_crc32_ieee() {
    assert_eq!(crc32(b"123456789"), 0xCBF4_3926);
    assert_eq!(crc32(b""), 0);
}

#[test]
fn what_is_not_a_regular_file_is_refused_not_read() {
    let dir = tempfile::tempdir().unwrap();
    let err = Journal::open_for(dir.path(), A).unwrap_err();
    assert!(matches!(err, JournalError::Io { .. } | JournalError::NotAFile { .. }), "{err}");
    let fifo = dir.path().join("fifo");
    let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let err = Journal::open_for(&fifo, A).unwrap_err();
    assert!(matches!(err, JournalError::NotAFile { .. }), "{err}");
    let err = Journal::open_for(Path::new("/dev/null"), A).unwrap_err();
    assert!(matches!(err, JournalError::NotAFile { .. }), "{err}");
}
