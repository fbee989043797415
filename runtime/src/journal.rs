//! The board's journal: an append-only file of its log ([`Entry`]), so that
//! a single board restarted after a crash recovers its state and facts
//! instead of starting from the initial state.
//!
//! **The file.** A header, then records:
//!
//! ```text
//! header  = "SITUJRNL" (8 bytes) | version: u32 LE | bundle sha256: 64 hex bytes | crc32 of the 76 bytes before: u32 LE
//! record  = body length: u32 LE | crc32 of the body: u32 LE | body
//! body    = epoch: u64 LE | kind: u8 (0 a heartbeat, 1 an accepted event, 2 a refused one) | …
//! tick    = time: u64 LE
//! event   = agent: u32 LE | event: u32 LE | time: u64 LE | urgent: u8 | fields: u16 LE | value…
//! value   = 0 | f64 bits u64 LE  ·  1 | i64 LE  ·  2 | bool u8  ·  3 | symbol u32 LE
//! ```
//!
//! The header pins the bundle (the content hash of [`content_sha256`], the
//! one `situ build` prints), so records name agents and events by their
//! ids: a journal of another bundle is refused ([`JournalError::OtherBundle`]).
//!
//! **Durability.** Each [`LogOut::write`] is one `write(2)` of the entries
//! taken since the last (the file is not buffered in the process): a
//! process killed at any point loses at most the entries not yet written,
//! and the kernel keeps what was written. Before a change of state is
//! broadcast (`change == true`) the file is `fdatasync`ed, so a change an
//! agent saw survives a power loss too; the entries written between two
//! changes (events that changed nothing, heartbeats) may be lost to a power
//! loss, which only loses what no agent was told.
//!
//! **Recovery.** [`Journal::open`] reads every record; a record cut short
//! or whose checksum fails at the end of the file (the process killed in a
//! write, or a power loss) is a torn tail: it is cut off and its bytes
//! counted ([`Recovered::dropped`]). A bad record followed by more bytes is
//! damage in the middle: an error with its offset
//! ([`JournalError::Damaged`]), never a silent loss of what follows.

use crate::bus::inproc::{Capacity, InProc};
use crate::bus::EventMsg;
use crate::runner::{BoardRunner, Shared};
use crate::standby::{Entry, LogOut, Logged};
use situ_bundle::codec::content_sha256;
use situ_bundle::{Content, Value};
use std::fs::{File, OpenOptions};
use std::io::{Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// The first bytes of a journal.
pub const MAGIC: &[u8; 8] = b"SITUJRNL";
/// The format this module writes and reads.
pub const VERSION: u32 = 1;
/// The header's length in bytes.
pub const HEADER_LEN: usize = 8 + 4 + 64 + 4;
/// A record's body is at most this long (a longer length is damage).
pub const MAX_BODY: u32 = 1 << 20;

/// Why a journal cannot be opened or written.
#[derive(Debug, thiserror::Error)]
pub enum JournalError {
    #[error("the journal {path}: {source}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("the journal {path} is not a regular file (a directory, a FIFO or a device)")]
    NotAFile { path: PathBuf },
    #[error("{path} is not a situ journal (its first bytes are not `SITUJRNL` with a valid header)")]
    NotAJournal { path: PathBuf },
    #[error("the journal {path} has format version {found}; this situ reads version {expected}")]
    Version { path: PathBuf, found: u32, expected: u32 },
    #[error(
        "the journal {path} was written for the bundle {found}, not for this one ({expected}): move it away to start from the initial state"
    )]
    OtherBundle { path: PathBuf, found: String, expected: String },
    #[error("the journal {path} is damaged at byte {offset}: {reason} (records follow it, so it is not a torn tail)")]
    Damaged { path: PathBuf, offset: u64, reason: String },
}

/// What a journal held when it was opened.
#[derive(Debug, Default, Clone, PartialEq)]
pub struct Recovered {
    /// Every entry, in the order the board took them, with its epoch.
    pub entries: Vec<Logged>,
    /// The highest epoch of an entry (0 when none).
    pub epoch: u64,
    /// Bytes of a torn tail cut off (0: the file ended on a record).
    pub dropped: u64,
}

/// An append-only journal of the board's log; a [`LogOut`].
#[derive(Debug)]
pub struct Journal {
    path: PathBuf,
    file: File,
    /// The epoch written with the entries from now on.
    epoch: u64,
    buf: Vec<u8>,
    /// Bytes in the file.
    len: u64,
    /// Records written (recovered ones included).
    records: u64,
    /// Written since the last `fdatasync`.
    dirty: bool,
    /// A write failed: nothing more is written.
    stopped: bool,
    /// The first write that failed; nothing is written after it.
    failed: Arc<Mutex<Option<JournalError>>>,
}

impl Journal {
    /// Opens the journal at `path` for `content` (creates it when there is
    /// none): reads its entries, cuts a torn tail off, and appends after.
    pub fn open(path: &Path, content: &Content) -> Result<(Journal, Recovered), JournalError> {
        Journal::open_for(path, &content_sha256(content))
    }

    /// As [`open`](Self::open), for the bundle whose content hash is
    /// `sha256` (64 hex digits).
    pub fn open_for(path: &Path, sha256: &str) -> Result<(Journal, Recovered), JournalError> {
        let io = |source| JournalError::Io { path: path.to_path_buf(), source };
        let mut file = OpenOptions::new().read(true).write(true).create(true).truncate(false).open(path).map_err(io)?;
        // A FIFO or a device would be read forever.
        if !file.metadata().map_err(io)?.is_file() {
            return Err(JournalError::NotAFile { path: path.to_path_buf() });
        }
        let mut bytes = Vec::new();
        file.read_to_end(&mut bytes).map_err(io)?;
        let header = header(sha256);
        let mut recovered = Recovered::default();
        let keep = if bytes.len() < HEADER_LEN && header.starts_with(&bytes) {
            // None, or a header cut short when the journal was created.
            recovered.dropped = bytes.len() as u64;
            file.set_len(0).map_err(io)?;
            file.seek(SeekFrom::Start(0)).map_err(io)?;
            file.write_all(&header).map_err(io)?;
            file.sync_all().map_err(io)?;
            sync_dir(path);
            HEADER_LEN
        } else {
            check_header(path, &bytes, &header)?;
            let (entries, end) = read_records(path, &bytes)?;
            recovered.epoch = entries.iter().map(|l| l.epoch).max().unwrap_or(0);
            recovered.entries = entries;
            recovered.dropped = (bytes.len() - end) as u64;
            if end < bytes.len() {
                file.set_len(end as u64).map_err(io)?;
                file.sync_all().map_err(io)?;
            }
            end
        };
        file.seek(SeekFrom::Start(keep as u64)).map_err(io)?;
        let journal = Journal {
            path: path.to_path_buf(),
            file,
            epoch: recovered.epoch,
            buf: Vec::new(),
            len: keep as u64,
            records: recovered.entries.len() as u64,
            dirty: false,
            stopped: false,
            failed: Arc::new(Mutex::new(None)),
        };
        Ok((journal, recovered))
    }

    /// The epoch written with the entries from now on (a board that leads
    /// at `epoch`).
    pub fn set_epoch(&mut self, epoch: u64) {
        self.epoch = epoch;
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Bytes in the file.
    pub fn len(&self) -> u64 {
        self.len
    }

    /// Whether it holds no record.
    pub fn is_empty(&self) -> bool {
        self.records == 0
    }

    /// Records in the file.
    pub fn records(&self) -> u64 {
        self.records
    }

    /// Where a failed write is told (the board's loop takes it and says
    /// it); after a failure the journal writes nothing more.
    pub fn failures(&self) -> Arc<Mutex<Option<JournalError>>> {
        self.failed.clone()
    }

    /// Appends `entries` in one write; with `sync`, then `fdatasync`.
    pub fn append(&mut self, entries: &[Entry], sync: bool) -> Result<(), JournalError> {
        let io = |source| JournalError::Io { path: self.path.clone(), source };
        if !entries.is_empty() {
            self.buf.clear();
            for e in entries {
                encode_record(&mut self.buf, self.epoch, e);
            }
            self.file.write_all(&self.buf).map_err(io)?;
            self.len += self.buf.len() as u64;
            self.records += entries.len() as u64;
            self.dirty = true;
        }
        if sync && self.dirty {
            self.file.sync_data().map_err(io)?;
            self.dirty = false;
        }
        Ok(())
    }
}

impl LogOut for Journal {
    fn write(&mut self, entries: &mut Vec<Entry>, change: bool) {
        if !self.stopped && (!entries.is_empty() || change && self.dirty) {
            if let Err(e) = self.append(entries, change) {
                // What follows a failed write could land after half a
                // record: nothing more is written.
                self.stopped = true;
                *self.failed.lock().unwrap_or_else(|p| p.into_inner()) = Some(e);
            }
        }
        entries.clear();
    }
}

impl Drop for Journal {
    /// A board that ends cleanly leaves every entry on the disk.
    fn drop(&mut self) {
        if self.dirty && !self.stopped {
            let _ = self.file.sync_data();
        }
    }
}

/// A journal opened before a run, for the run to take: it applies what
/// was recovered ([`recover`]), says so ([`Opened::telling`]) and writes to
/// it from then on.
#[derive(Clone)]
pub struct Opened {
    slot: Arc<Mutex<Option<(Journal, Recovered)>>>,
    tell: Arc<dyn Fn(&str) + Send + Sync>,
}

impl std::fmt::Debug for Opened {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Opened").field("slot", &self.slot).finish_non_exhaustive()
    }
}

impl Opened {
    /// Opens the journal at `path` for `content` ([`Journal::open`]).
    pub fn open(path: &Path, content: &Content) -> Result<Opened, JournalError> {
        let slot = Arc::new(Mutex::new(Some(Journal::open(path, content)?)));
        Ok(Opened { slot, tell: Arc::new(|_| ()) })
    }

    /// Who is told what was recovered (besides the recording): the
    /// command's standard error.
    pub fn telling(self, tell: impl Fn(&str) + Send + Sync + 'static) -> Opened {
        Opened { tell: Arc::new(tell), ..self }
    }

    /// Says what was recovered.
    pub fn tell(&self, text: &str) {
        (self.tell)(text)
    }

    /// The journal and what it held (once).
    pub fn take(&self) -> Option<(Journal, Recovered)> {
        self.slot.lock().unwrap_or_else(|p| p.into_inner()).take()
    }
}

/// Applies the recovered entries to a board that has just started, as it
/// took them ([`BoardRunner::apply`]): it has their state, facts and FSM
/// states. The agents are told nothing while it does (the changes of the
/// past are not broadcast again: the board's next status says where it
/// is); the recording, if any, gets the entries (so that a replay of it
/// reaches the same state) and the board's counters start at zero.
/// Returns what to say about it.
pub fn recover(board: &mut BoardRunner, shared: &Shared, journal: &Journal, recovered: &Recovered) -> String {
    let content = shared.content.clone();
    let sink = shared.sink.lock().unwrap_or_else(|p| p.into_inner()).take();
    let quiet = Shared::new(content.clone(), Arc::new(InProc::new(content.agents.len(), Capacity::default())), sink);
    *quiet.org_mut() = shared.org().clone();
    for l in &recovered.entries {
        board.apply(&quiet, &l.entry);
    }
    *shared.org_mut() = quiet.org().clone();
    *shared.sink.lock().unwrap_or_else(|p| p.into_inner()) = quiet.sink.into_inner().unwrap_or_else(|p| p.into_inner());
    board.counters = Default::default();
    describe(board, journal, recovered)
}

/// "recovered N entries from the journal P: state X, facts of A, B; M
/// bytes of a torn tail dropped" (or that it holds none).
fn describe(board: &BoardRunner, journal: &Journal, recovered: &Recovered) -> String {
    if recovered.entries.is_empty() {
        let mut text =
            format!("the journal {} holds no entry: the board starts from its initial state", journal.path().display());
        if recovered.dropped > 0 {
            text += &format!(" ({} bytes of a torn write dropped)", recovered.dropped);
        }
        return text;
    }
    let content = board.board.content();
    let engine = board.board.engine();
    let facts: Vec<&str> = (0..content.agents.len() as u32)
        .filter(|&a| engine.fact(a).is_some() && !engine.is_stale(a))
        .map(|a| content.agents[a as usize].name.as_str())
        .collect();
    let facts = if facts.is_empty() { "no fact".to_string() } else { format!("facts of {}", facts.join(", ")) };
    let mut text = format!(
        "recovered {} entries from the journal {}: state {}, {facts}",
        recovered.entries.len(),
        journal.path().display(),
        content.states[board.board.state() as usize].name,
    );
    if recovered.dropped > 0 {
        text += &format!("; {} bytes of a torn tail dropped", recovered.dropped);
    }
    text
}

/// Makes a new file's name durable (its directory's entry).
fn sync_dir(path: &Path) {
    let dir = path.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
    if let Ok(d) = File::open(dir) {
        let _ = d.sync_all();
    }
}

fn header(sha256: &str) -> Vec<u8> {
    let mut h = Vec::with_capacity(HEADER_LEN);
    h.extend_from_slice(MAGIC);
    h.extend_from_slice(&VERSION.to_le_bytes());
    h.extend_from_slice(sha256.as_bytes());
    let crc = crc32(&h);
    h.extend_from_slice(&crc.to_le_bytes());
    h
}

fn check_header(path: &Path, bytes: &[u8], expected: &[u8]) -> Result<(), JournalError> {
    let not = || JournalError::NotAJournal { path: path.to_path_buf() };
    if bytes.len() < HEADER_LEN || &bytes[..8] != MAGIC {
        return Err(not());
    }
    let crc = u32::from_le_bytes(bytes[76..80].try_into().expect("4 bytes"));
    if crc32(&bytes[..76]) != crc {
        return Err(not());
    }
    let version = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes"));
    if version != VERSION {
        return Err(JournalError::Version { path: path.to_path_buf(), found: version, expected: VERSION });
    }
    if bytes[12..76] != expected[12..76] {
        return Err(JournalError::OtherBundle {
            path: path.to_path_buf(),
            found: String::from_utf8_lossy(&bytes[12..76]).into_owned(),
            expected: String::from_utf8_lossy(&expected[12..76]).into_owned(),
        });
    }
    Ok(())
}

/// The records after the header, and where the last whole one ends.
fn read_records(path: &Path, bytes: &[u8]) -> Result<(Vec<Logged>, usize), JournalError> {
    let mut entries = Vec::new();
    let mut at = HEADER_LEN;
    while at < bytes.len() {
        let rest = &bytes[at..];
        let bad = match record_at(rest) {
            Ok((logged, n)) => {
                entries.push(logged);
                at += n;
                continue;
            }
            Err(bad) => bad,
        };
        // A torn tail: the record runs past the end of the file, or the
        // rest is zeros (a power loss extended the file, not its data).
        let torn = match bad {
            Bad::Short => true,
            Bad::Invalid(_) => rest.iter().all(|&b| b == 0),
            Bad::Checksum { end } => end >= rest.len() || rest.iter().all(|&b| b == 0),
        };
        if torn {
            break;
        }
        let reason = match bad {
            Bad::Invalid(why) => why.to_string(),
            _ => "the record's checksum does not match".to_string(),
        };
        return Err(JournalError::Damaged { path: path.to_path_buf(), offset: at as u64, reason });
    }
    Ok((entries, at))
}

/// Why a record could not be read.
enum Bad {
    /// The file ends within it.
    Short,
    /// Its checksum fails; it ends at `end` (from its start).
    Checksum { end: usize },
    /// Its length or body makes no sense.
    Invalid(&'static str),
}

/// One record at the start of `b`, and its length.
fn record_at(b: &[u8]) -> Result<(Logged, usize), Bad> {
    if b.len() < 8 {
        return Err(Bad::Short);
    }
    let len = u32::from_le_bytes(b[0..4].try_into().expect("4 bytes"));
    if len > MAX_BODY {
        return Err(Bad::Invalid("a record longer than 1 MiB"));
    }
    let end = 8 + len as usize;
    if b.len() < end {
        return Err(Bad::Short);
    }
    let crc = u32::from_le_bytes(b[4..8].try_into().expect("4 bytes"));
    let body = &b[8..end];
    if crc32(body) != crc {
        return Err(Bad::Checksum { end });
    }
    let logged =
        decode_body(body).ok_or(Bad::Invalid("a record whose checksum matches but whose body is not an entry"))?;
    Ok((logged, end))
}

fn encode_record(out: &mut Vec<u8>, epoch: u64, entry: &Entry) {
    let start = out.len();
    out.extend_from_slice(&[0; 8]);
    out.extend_from_slice(&epoch.to_le_bytes());
    match entry {
        Entry::Tick { time } => {
            out.push(0);
            out.extend_from_slice(&time.to_le_bytes());
        }
        Entry::Event { msg, accepted } => {
            out.push(if *accepted { 1 } else { 2 });
            out.extend_from_slice(&msg.agent.to_le_bytes());
            out.extend_from_slice(&msg.event.to_le_bytes());
            out.extend_from_slice(&msg.time.to_le_bytes());
            out.push(msg.urgent as u8);
            let n = msg.payload.len().min(u16::MAX as usize);
            out.extend_from_slice(&(n as u16).to_le_bytes());
            for v in &msg.payload[..n] {
                match v {
                    Value::F64(x) => {
                        out.push(0);
                        out.extend_from_slice(&x.to_bits().to_le_bytes());
                    }
                    Value::I64(x) => {
                        out.push(1);
                        out.extend_from_slice(&x.to_le_bytes());
                    }
                    Value::Bool(x) => out.extend_from_slice(&[2, *x as u8]),
                    Value::Symbol(x) => {
                        out.push(3);
                        out.extend_from_slice(&x.to_le_bytes());
                    }
                }
            }
        }
    }
    let body_len = (out.len() - start - 8) as u32;
    let crc = crc32(&out[start + 8..]);
    out[start..start + 4].copy_from_slice(&body_len.to_le_bytes());
    out[start + 4..start + 8].copy_from_slice(&crc.to_le_bytes());
}

/// Reads little-endian fields off a body.
struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        let (head, rest) = (self.0.get(..n)?, self.0.get(n..)?);
        self.0 = rest;
        Some(head)
    }
    fn u8(&mut self) -> Option<u8> {
        self.take(1).map(|b| b[0])
    }
    fn u16(&mut self) -> Option<u16> {
        self.take(2).map(|b| u16::from_le_bytes(b.try_into().expect("2 bytes")))
    }
    fn u32(&mut self) -> Option<u32> {
        self.take(4).map(|b| u32::from_le_bytes(b.try_into().expect("4 bytes")))
    }
    fn u64(&mut self) -> Option<u64> {
        self.take(8).map(|b| u64::from_le_bytes(b.try_into().expect("8 bytes")))
    }
}

fn decode_body(body: &[u8]) -> Option<Logged> {
    let mut r = Reader(body);
    let epoch = r.u64()?;
    let entry = match r.u8()? {
        0 => Entry::Tick { time: r.u64()? },
        kind @ (1 | 2) => {
            let (agent, event, time, urgent) = (r.u32()?, r.u32()?, r.u64()?, r.u8()? != 0);
            let n = r.u16()?;
            let mut payload = Vec::with_capacity(n as usize);
            for _ in 0..n {
                payload.push(match r.u8()? {
                    0 => Value::F64(f64::from_bits(r.u64()?)),
                    1 => Value::I64(r.u64()? as i64),
                    2 => Value::Bool(r.u8()? != 0),
                    3 => Value::Symbol(r.u32()?),
                    _ => return None,
                });
            }
            Entry::Event { msg: EventMsg { agent, event, time, payload, urgent }, accepted: kind == 1 }
        }
        _ => return None,
    };
    r.0.is_empty().then_some(Logged { epoch, entry })
}

/// CRC-32 (IEEE 802.3, the one of zip and PNG).
pub fn crc32(bytes: &[u8]) -> u32 {
    const TABLE: [u32; 256] = {
        let mut t = [0u32; 256];
        let mut i = 0;
        while i < 256 {
            let mut c = i as u32;
            let mut k = 0;
            while k < 8 {
                c = if c & 1 != 0 { 0xEDB8_8320 ^ (c >> 1) } else { c >> 1 };
                k += 1;
            }
            t[i] = c;
            i += 1;
        }
        t
    };
    let mut c = !0u32;
    for &b in bytes {
        c = TABLE[((c ^ b as u32) & 0xFF) as usize] ^ (c >> 8);
    }
    !c
}

#[cfg(test)]
#[path = "journal_tests.rs"]
mod tests;
