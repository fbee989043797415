//! The recordings at their boundaries (issue 14), on the real binary: a
//! damaged recording is exit 2 with the reason and never an abort; what is
//! not a recording (junk, a device, a FIFO, a directory) is refused at once
//! with exit 2; a recording cut short replays up to the cut and says so; a
//! run killed with SIGKILL leaves a file that the `mcap` package from PyPI
//! reads with its standard reader.

mod common;

use common::{code, stderr, stdout, text};
use situ_runtime::record::mcap::read_recording;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

/// Every wait of these tests ends by this deadline.
const DEADLINE: Duration = Duration::from_secs(120);

fn s(p: &Path) -> &str {
    p.to_str().expect("a UTF-8 temp path")
}

/// Waits for `child` to end, at most [`DEADLINE`] (killed and a failure
/// after that).
fn wait_bounded(mut child: Child, what: &str) -> Output {
    let start = Instant::now();
    loop {
        match child.try_wait().expect("the child can be waited for") {
            Some(_) => return child.wait_with_output().expect("its output"),
            None if start.elapsed() > DEADLINE => {
                let _ = child.kill();
                let o = child.wait_with_output().expect("its output");
                panic!("`{what}` still running after {DEADLINE:?}: {}", text(&o));
            }
            None => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// `situ ARGS…`, bounded by [`DEADLINE`].
fn situ(args: &[&str]) -> Output {
    let child = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(args)
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the binary runs");
    wait_bounded(child, &format!("situ {}", args.join(" ")))
}

/// A 30 s drive of the outdoor stack, recorded (the recording of the issue).
fn outdoor_recording(dir: &Path) -> PathBuf {
    let rec = dir.join("drive.mcap");
    let o = situ(&["run", "rules/outdoor.situ", "--until", "30", "--record", s(&rec)]);
    assert!(rec.is_file(), "{}", text(&o));
    let same = situ(&["replay", s(&rec)]);
    assert_eq!(code(&same), 0, "the whole recording replays: {}", text(&same));
    rec
}

/// The top-level records of an MCAP file: (offset, opcode, length).
fn records(bytes: &[u8]) -> Vec<(usize, u8, u64)> {
    let mut out = Vec::new();
    let mut at = 8;
    while at + 9 <= bytes.len() {
        let len = u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap());
        out.push((at, bytes[at], len));
        match usize::try_from(len).ok().and_then(|l| at.checked_add(9 + l)) {
            Some(next) if next <= bytes.len() => at = next,
            _ => break,
        }
    }
    out
}

#[test]
fn a_damaged_recording_is_exit_2_with_the_reason_never_an_abort() {
    let dir = tempfile::tempdir().unwrap();
    let rec = outdoor_recording(dir.path());
    let bytes = std::fs::read(&rec).unwrap();
    let chunks: Vec<(usize, u64)> =
        records(&bytes).into_iter().filter(|(_, op, _)| *op == 0x06).map(|(at, _, len)| (at, len)).collect();
    assert!(chunks.len() >= 3, "a 30 s drive has chunks: {}", chunks.len());
    let damaged = dir.path().join("damaged.mcap");
    let replay_flipped = |at: usize, bit: u8| {
        let mut b = bytes.clone();
        b[at] ^= bit;
        std::fs::write(&damaged, &b).unwrap();
        situ(&["replay", s(&damaged)])
    };
    // The top bit of a chunk's length, of its uncompressed size, and a byte
    // of its compressed data (the chunk's CRC): each a damaged recording.
    let (mid, len) = chunks[chunks.len() / 2];
    for (at, bit, why) in [
        (mid + 8, 0x80, "claims"),
        (mid + 9 + 16 + 7, 0x80, "uncompressed"),
        (mid + 9 + 44 + 9, 0x80, "damaged"),
        (mid + 9 + (len as usize) / 2, 0x04, "damaged"),
    ] {
        let o = replay_flipped(at, bit);
        assert_eq!(code(&o), 2, "a flip at byte {at}: {}", text(&o));
        assert!(stderr(&o).contains("not a readable recording") && stderr(&o).contains(why), "{}", stderr(&o));
        assert!(!stdout(&o).contains("identical"), "{}", stdout(&o));
    }
    // One flipped bit at 40 places over the whole file: every replay ends
    // by itself with an exit code (`code` fails on a signal, an abort).
    for i in 0..40 {
        let at = 8 + i * (bytes.len() - 9) / 40;
        let o = replay_flipped(at, 1 << (i % 8));
        assert!(matches!(code(&o), 0..=2), "a flip at byte {at}: {}", text(&o));
    }
}

#[test]
fn what_is_not_a_recording_is_refused_at_once_with_exit_2() {
    let dir = tempfile::tempdir().unwrap();
    let junk = common::write(dir.path(), "junk.mcap", "not a recording");
    let empty = common::write(dir.path(), "empty.mcap", "");
    let fifo = dir.path().join("fifo.mcap");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo runs");
    assert!(made.success());
    let missing = dir.path().join("missing.mcap");
    for (path, why) in [
        (junk.as_str(), "not an MCAP file"),
        (empty.as_str(), "not an MCAP file"),
        ("/dev/zero", "not a regular file"),
        (s(&fifo), "not a regular file"),
        (s(dir.path()), "not a regular file"),
        (s(&missing), "cannot read it"),
    ] {
        // A FIFO with no writer would block an open: the wait is bounded.
        let o = situ(&["replay", path]);
        assert_eq!(code(&o), 2, "{path}: {}", text(&o));
        assert!(stderr(&o).contains(why), "{path}: {}", stderr(&o));
        assert!(stdout(&o).is_empty(), "{path}: no report: {}", stdout(&o));
    }
}

#[test]
fn a_recording_cut_short_replays_up_to_the_cut_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let rec = outdoor_recording(dir.path());
    let bytes = std::fs::read(&rec).unwrap();
    let whole = read_recording(&bytes).unwrap().messages.len();
    let cut = dir.path().join("cut.mcap");
    std::fs::write(&cut, &bytes[..bytes.len() * 6 / 10]).unwrap();
    let o = situ(&["replay", s(&cut)]);
    assert_eq!(code(&o), 0, "the part before the cut replays the same: {}", text(&o));
    assert!(stdout(&o).contains("cut short: it ends inside its last record"), "{}", stdout(&o));
    assert!(stdout(&o).contains("same states up to the cut"), "{}", stdout(&o));
    assert!(stderr(&o).starts_with("warning:") && stderr(&o).contains("is cut short"), "{}", stderr(&o));
    let read = read_recording(&bytes[..bytes.len() * 6 / 10]).unwrap().messages.len();
    assert!(read > 0 && read < whole, "{read} of {whole} messages");
    // The JSON report says it too.
    let o = situ(&["replay", s(&cut), "--format", "json"]);
    let report: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(report["cut"], true);
    assert!(report["cut_reason"].as_str().is_some_and(|r| r.contains("last record")), "{report}");
    // Cut right after the bundle: nothing of the run to replay.
    let attachment = records(&bytes).into_iter().find(|(_, op, _)| *op == 0x09).unwrap();
    let end = attachment.0 + 9 + attachment.2 as usize;
    std::fs::write(&cut, &bytes[..end]).unwrap();
    let o = situ(&["replay", s(&cut)]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("nothing to replay before the cut"), "{}", stderr(&o));
}

/// Size of `path`, 0 when it is not there yet.
fn size(path: &Path) -> u64 {
    std::fs::metadata(path).map(|m| m.len()).unwrap_or(0)
}

#[test]
fn a_run_killed_mid_recording_leaves_a_file_the_mcap_package_reads() {
    // The mcap package must be there (scripts/test.sh installs
    // examples/python/requirements.txt): its absence fails this test.
    let import = Command::new("python3").args(["-c", "import mcap.reader, zstandard"]).output();
    let import = import.expect("python3 runs");
    assert!(
        import.status.success(),
        "the Python packages mcap and zstandard are missing (pip install -r examples/python/requirements.txt): {}",
        String::from_utf8_lossy(&import.stderr)
    );
    let dir = tempfile::tempdir().unwrap();
    let rec = dir.path().join("killed.mcap");
    // The Fig. 5 demo in real time for two minutes: still running when killed.
    let mut child = Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(["run", "examples/fig5/fig5.situ", "--stack", "demo", "--duration", "120", "--record", s(&rec)])
        .env("NO_COLOR", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("the binary runs");
    // Wait for two flushes with messages after the first (the file grows
    // at each flush): about 2 s of the run on disk.
    let start = Instant::now();
    let mut flushes = 0;
    let mut last = size(&rec);
    while flushes < 3 {
        assert!(start.elapsed() < DEADLINE, "the recording did not grow: {} bytes", size(&rec));
        assert!(child.try_wait().unwrap().is_none(), "the run ended before it was killed");
        std::thread::sleep(Duration::from_millis(50));
        let now = size(&rec);
        if now > last {
            flushes += 1;
            last = now;
        }
    }
    child.kill().expect("SIGKILL");
    let status = child.wait().expect("the killed run is reaped");
    assert!(!status.success(), "killed, not finished");
    let bytes = std::fs::read(&rec).unwrap();
    let ours = read_recording(&bytes).expect("situ reads it");
    assert!(ours.cut.as_deref().is_some_and(|w| w.contains("not finished")), "{:?}", ours.cut);
    assert!(!ours.messages.is_empty());
    let events = ours.messages.iter().filter(|(t, _, _)| t == "/situ/events").count();

    let python = Command::new("python3").arg("tests/python/read_killed.py").arg(&rec).output().expect("python3 runs");
    let out = String::from_utf8_lossy(&python.stdout);
    assert!(python.status.success(), "{out}{}", String::from_utf8_lossy(&python.stderr));
    // The standard reader reads every message situ reads, and the bundle.
    let want = format!("messages {} /situ/events {events} bundle yes", ours.messages.len());
    assert_eq!(out.trim(), want);

    let o = situ(&["replay", s(&rec)]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(stdout(&o).contains("the recording was not finished"), "{}", stdout(&o));
}
