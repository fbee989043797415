//! Reading a recording back, bounded: a damaged or foreign file is an
//! error that says where and why, never a panic, an abort or an allocation
//! the file cannot justify.
//!
//! Before the `mcap` crate sees a byte, [`scan`] walks the top-level records
//! and checks each length against the bytes actually present (a chunk's
//! header too, and its uncompressed size against [`MAX_RECORD`]). Then the
//! crate's reader decodes the checked prefix with the same limit on every
//! record and every chunk, and checks each chunk's CRC before it yields a
//! message of it.
//!
//! What a file can be:
//!
//! - **whole**: every record up to a Footer with a summary and the magic;
//! - **cut**: a run that was killed or crashed. The recording ends with the
//!   provisional Footer of its last flush (no summary), or in the middle of
//!   a record whose length is plausible: everything before is read;
//! - **damaged** (an error): not MCAP, a length no file of ours has, a
//!   chunk that does not fit its record, a CRC or decompression failure,
//!   bytes after the end.

use super::Recorded;
use ::mcap::records::op;
use ::mcap::sans_io::{LinearReaderOptions, MessageReadEvent, MessageReader};
use serde_json::Value as Json;
use std::io::Read;
use std::path::Path;

/// The longest record, and the most a chunk may hold uncompressed (the
/// recorder's chunks hold about 1 MiB).
pub const MAX_RECORD: u64 = 64 << 20;

/// The largest recording read ([`read_file`]).
pub const MAX_FILE: u64 = 1 << 30;

const MAGIC: &[u8] = ::mcap::MAGIC;
/// Opcode and length.
const RECORD_HEAD: usize = 9;

/// Why a recording's bytes do not read: each says where and why.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ReadError {
    /// The bytes do not start with the MCAP magic.
    #[error("not an MCAP file (it does not start with the MCAP magic)")]
    NotMcap,
    /// A top-level record that does not hold together, at byte `at` of a
    /// file of `size` bytes.
    #[error("damaged at byte {at} of {size}: {why}")]
    Damaged { at: usize, size: usize, why: String },
    /// The MCAP reader failed before byte `near` (a chunk's CRC, its
    /// compression, a record inside it), after `messages` messages.
    #[error("damaged before byte {near} of {size}: {why} ({messages} messages read before it)")]
    DamagedBefore { near: usize, size: usize, why: String, messages: usize },
    /// A record inside a chunk is malformed (the MCAP reader failed on it).
    #[error("damaged: a record inside a chunk is malformed (the MCAP reader failed on it); {size} bytes")]
    MalformedChunk { size: usize },
}

/// Why a recording file is not read ([`read_file`]).
#[derive(Debug, thiserror::Error)]
pub enum FileError {
    #[error("cannot read it: {0}")]
    Io(#[from] std::io::Error),
    /// A device, a FIFO, a directory.
    #[error("not a regular file: a recording is a file")]
    NotAFile,
    /// Larger than [`MAX_FILE`] (`size`: as the file system says, when it said so).
    #[error("{}larger than the {MAX_FILE} bytes a recording may have", size.map_or(String::new(), |s| format!("{s} bytes: ")))]
    TooLarge { size: Option<u64> },
}

/// A recording read back.
#[derive(Debug, Clone)]
pub struct Reading {
    /// Every message, in file order.
    pub messages: Vec<Recorded>,
    /// The file's size in bytes.
    pub size: usize,
    /// Why the recording stops before its end, when it does (a run that
    /// was killed): everything before that point is in `messages`.
    pub cut: Option<String>,
    /// The latest log time of any message (those left out by
    /// [`read_topics`] too).
    pub end: u64,
}

/// Where the checked records stop, and why when it is not the end.
struct Scan {
    /// The end of the last whole record to read.
    end: usize,
    cut: Option<String>,
    /// Attachment records: (start of the body, its length).
    attachments: Vec<(usize, usize)>,
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at.checked_add(4)?)?.try_into().ok()?))
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at.checked_add(8)?)?.try_into().ok()?))
}

/// Reserved opcodes (0x00, 0x10–0x7F): no MCAP writer writes them.
fn reserved(opcode: u8) -> bool {
    opcode == 0 || (0x10..0x80).contains(&opcode)
}

/// Checks a chunk record's body: its header fits, its compressed data is
/// present, its uncompressed size is at most [`MAX_RECORD`].
fn check_chunk(body: &[u8]) -> Result<(), String> {
    // start time, end time, uncompressed size, CRC, compression length
    const FIXED: usize = 8 + 8 + 8 + 4 + 4;
    let uncompressed = u64_at(body, 16).ok_or("a chunk too short for its header")?;
    let name_len = u32_at(body, 28).ok_or("a chunk too short for its header")? as usize;
    let name_end = FIXED
        .checked_add(name_len)
        .filter(|e| *e <= body.len())
        .ok_or_else(|| format!("a chunk's compression name claims {name_len} bytes, {} present", body.len() - FIXED))?;
    let name = &body[FIXED..name_end];
    let compressed = u64_at(body, name_end).ok_or("a chunk too short for its header")?;
    let present = (body.len() - name_end - 8) as u64;
    if compressed > present {
        return Err(format!("a chunk claims {compressed} compressed bytes, {present} present"));
    }
    if uncompressed > MAX_RECORD {
        return Err(format!("a chunk claims {uncompressed} bytes uncompressed (at most {MAX_RECORD})"));
    }
    match name {
        b"" if compressed != uncompressed => {
            Err(format!("an uncompressed chunk of {compressed} bytes claims {uncompressed}"))
        }
        b"" | b"zstd" => Ok(()),
        other => Err(format!("a chunk compressed with `{}`, which situ does not read", String::from_utf8_lossy(other))),
    }
}

/// Checks an attachment record's body: its header, its data and its CRC
/// fill it exactly. The `mcap` crate (0.26) slices the body before it
/// compares the lengths, and panics when the header leaves fewer than the
/// CRC's 4 bytes (found by the `mcap_read` fuzz target).
fn check_attachment(body: &[u8]) -> Result<(), String> {
    const SHORT: &str = "an attachment too short for its header";
    let string_end = |at: usize| -> Result<usize, String> {
        let len = u32_at(body, at).ok_or(SHORT)? as usize;
        at.checked_add(4).and_then(|s| s.checked_add(len)).filter(|e| *e <= body.len()).ok_or_else(|| SHORT.to_string())
    };
    // log time, create time, name, media type, data length
    let name_end = string_end(16)?;
    let media_end = string_end(name_end)?;
    let data_len = u64_at(body, media_end).ok_or(SHORT)?;
    let present = (body.len() - media_end - 8) as u64;
    if present < 4 || data_len != present - 4 {
        return Err(format!("an attachment claims {data_len} bytes of data, {present} present with its CRC"));
    }
    Ok(())
}

/// Walks the top-level records (see the module).
fn scan(bytes: &[u8]) -> Result<Scan, ReadError> {
    if !bytes.starts_with(MAGIC) {
        return Err(ReadError::NotMcap);
    }
    let size = bytes.len();
    let mut at = MAGIC.len();
    let mut attachments = Vec::new();
    // A run that was cut short: the records before `end` are read.
    macro_rules! cut {
        ($end:expr, $($why:tt)*) => {
            return Ok(Scan { end: $end, cut: Some(format!($($why)*)), attachments })
        };
    }
    loop {
        let rest = size - at;
        if rest == 0 {
            cut!(at, "it ends after {at} bytes, with no footer");
        }
        if rest < RECORD_HEAD {
            cut!(at, "it ends inside a record's header at byte {at}");
        }
        let opcode = bytes[at];
        let len = u64_at(bytes, at + 1).unwrap_or(u64::MAX);
        let damaged = |why: String| Err(ReadError::Damaged { at, size, why });
        if at == MAGIC.len() && opcode != op::HEADER {
            return damaged(format!("the first record has opcode {opcode:#04x}, not a header"));
        }
        if reserved(opcode) {
            return damaged(format!("a record with the reserved opcode {opcode:#04x}"));
        }
        if len > MAX_RECORD {
            return damaged(format!("a record claims {len} bytes (at most {MAX_RECORD})"));
        }
        let body_start = at + RECORD_HEAD;
        let present = size - body_start;
        if len > present as u64 {
            cut!(at, "it ends inside its last record (byte {at}: {present} of its {len} bytes)");
        }
        let body_end = body_start + len as usize;
        let body = &bytes[body_start..body_end];
        match opcode {
            op::CHUNK => {
                if let Err(why) = check_chunk(body) {
                    return damaged(why);
                }
            }
            op::ATTACHMENT => {
                if let Err(why) = check_attachment(body) {
                    return damaged(why);
                }
                attachments.push((body_start, len as usize))
            }
            op::FOOTER => {
                let Some(summary_start) = u64_at(body, 0) else {
                    return damaged("a footer too short".into());
                };
                let after = &bytes[body_end..];
                if after != MAGIC && !(after.len() < MAGIC.len() && MAGIC.starts_with(after)) {
                    return damaged(format!("{} bytes after the footer that are not the closing magic", after.len()));
                }
                let why = if summary_start == 0 {
                    Some("the recording was not finished (the run was killed or crashed): it holds everything up to its last flush".into())
                } else if after != MAGIC {
                    Some("it ends inside its closing magic".into())
                } else {
                    None
                };
                return Ok(Scan { end: body_end, cut: why, attachments });
            }
            _ => {}
        }
        at = body_end;
    }
}

/// Reads every message of a recording, whole or cut short (see the module);
/// an error says what is wrong with the file and where.
pub fn read_recording(bytes: &[u8]) -> Result<Reading, ReadError> {
    read_topics(bytes, &|_| true)
}

/// [`read_recording`] keeping only the messages of the topics `keep`
/// accepts (the others are checked as the file is, not decoded).
pub fn read_topics(bytes: &[u8], keep: &dyn Fn(&str) -> bool) -> Result<Reading, ReadError> {
    let scan = scan(bytes)?;
    // The scan checks the top-level records; inside a chunk whose CRC is 0
    // ("not checked", by the MCAP specification) a malformed record could
    // still reach a slicing bug of the `mcap` crate (one was found by the
    // fuzz target at the top level): a panic there is damage, not a crash.
    std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| decode(bytes, scan, keep)))
        .unwrap_or(Err(ReadError::MalformedChunk { size: bytes.len() }))
}

/// The `mcap` crate's reader over the records [`scan`] checked.
fn decode(bytes: &[u8], scan: Scan, keep: &dyn Fn(&str) -> bool) -> Result<Reading, ReadError> {
    let options = LinearReaderOptions::default()
        .with_skip_end_magic(true)
        .with_validate_chunk_crcs(true)
        .with_prevalidate_chunk_crcs(true)
        .with_record_length_limit(MAX_RECORD as usize);
    let mut reader = MessageReader::new_with_options(options);
    let mut rest = &bytes[..scan.end];
    let mut messages = Vec::new();
    let mut end = 0u64;
    // The last channel asked about, and the answer (messages come in runs
    // of one channel).
    let mut kept: Option<(u16, bool)> = None;
    while let Some(event) = reader.next_event() {
        match event {
            Ok(MessageReadEvent::ReadRequest(need)) => {
                // Never more than the bytes present: a request is a hint.
                let n = need.min(rest.len());
                reader.insert(n).copy_from_slice(&rest[..n]);
                reader.notify_read(n);
                rest = &rest[n..];
            }
            Ok(MessageReadEvent::Message(m)) => {
                end = end.max(m.log_time);
                let wanted = match kept {
                    Some((id, k)) if id == m.channel.id => k,
                    _ => {
                        let k = keep(&m.channel.topic);
                        kept = Some((m.channel.id, k));
                        k
                    }
                };
                if wanted {
                    let json: Json = serde_json::from_slice(&m.data).unwrap_or(Json::Null);
                    messages.push((m.channel.topic.clone(), m.log_time, json));
                }
            }
            Err(e) => {
                let near = scan.end - rest.len();
                return Err(ReadError::DamagedBefore {
                    near,
                    size: bytes.len(),
                    why: e.to_string(),
                    messages: messages.len(),
                });
            }
        }
    }
    Ok(Reading { messages, size: bytes.len(), cut: scan.cut, end })
}

/// Reads every message of a recording, whole or cut short, in file order,
/// and whether the file was cut short; a damaged file is an error.
pub fn read_messages(bytes: &[u8]) -> Result<(Vec<Recorded>, bool), ReadError> {
    let r = read_recording(bytes)?;
    Ok((r.messages, r.cut.is_some()))
}

/// The bundle attached to a recording, if any (`None` for a damaged file
/// too: [`read_recording`] says what is wrong with it).
pub fn attached_bundle(bytes: &[u8]) -> Option<Vec<u8>> {
    let scan = scan(bytes).ok()?;
    for (start, len) in scan.attachments {
        let body = bytes.get(start..start.checked_add(len)?)?;
        // The crate checks the attachment's lengths against the body and its CRC.
        if let Ok(::mcap::records::Record::Attachment { header, data, .. }) = ::mcap::parse_record(op::ATTACHMENT, body)
        {
            if header.name == "bundle.json" {
                return Some(data.into_owned());
            }
        }
    }
    None
}

/// Reads a recording file, refusing at once what is not a regular file
/// (a device, a FIFO, a directory) or is larger than [`MAX_FILE`].
pub fn read_file(path: &Path) -> Result<Vec<u8>, FileError> {
    let meta = std::fs::metadata(path)?;
    if !meta.is_file() {
        return Err(FileError::NotAFile);
    }
    if meta.len() > MAX_FILE {
        return Err(FileError::TooLarge { size: Some(meta.len()) });
    }
    let file = std::fs::File::open(path)?;
    // The file may have changed since: read at most one byte more than allowed.
    let mut bytes = Vec::new();
    file.take(MAX_FILE + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > MAX_FILE {
        return Err(FileError::TooLarge { size: None });
    }
    Ok(bytes)
}
