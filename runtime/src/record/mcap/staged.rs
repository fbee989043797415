//! The file under a recording, kept a valid MCAP file at every flush.
//!
//! The MCAP writer buffers each chunk and writes it whole ([`Staged`] is
//! given to it with seeking disabled), and everything it writes stays in
//! memory until it flushes. A flush writes what came since the last one,
//! followed by a provisional end — a Data End record, a Footer with no
//! summary and the closing magic — with one `write_all` at the end of the
//! data so far. The next flush writes over that provisional end. So the
//! file on disk is always the whole records of the last flush and an end
//! that every reader accepts (Python's `mcap`, Foxglove, `situ replay`):
//! a process killed mid-run leaves a recording that reads up to its last
//! flush. Only the finished recording has a summary; a Footer without one
//! tells a reader that the run did not finish its recording.
//!
//! The bytes of a finished recording are the writer's own, whatever the
//! flushes were: every provisional end is overwritten or cut off.

use std::fs::File;
use std::io::{self, Seek, SeekFrom, Write};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// The provisional end: Data End (no CRC), Footer (no summary), magic.
pub const PROVISIONAL_END: [u8; 50] = {
    let mut b = [0u8; 50];
    // Data End: opcode 0x0F, length 4, data section CRC 0 (not computed).
    b[0] = 0x0F;
    b[1] = 4;
    // Footer: opcode 0x02, length 20, summary start 0, summary offset start 0, CRC 0.
    b[13] = 0x02;
    b[14] = 20;
    // The magic.
    let magic = [0x89, b'M', b'C', b'A', b'P', 0x30, b'\r', b'\n'];
    let mut i = 0;
    while i < 8 {
        b[42 + i] = magic[i];
        i += 1;
    }
    b
};

/// A recording file written one flush at a time (see the module).
pub struct Staged {
    file: File,
    /// Written by the MCAP writer since the last flush.
    pending: Vec<u8>,
    /// Bytes of records on disk (the provisional end comes after them).
    written: u64,
    /// Set before the writer writes its summary: the next flush is the
    /// last one, and writes no provisional end.
    finishing: Arc<AtomicBool>,
}

impl Staged {
    /// A staged file over `file` (empty, at its start), and the flag that
    /// says the recording is being finished.
    pub fn new(file: File) -> (Staged, Arc<AtomicBool>) {
        let finishing = Arc::new(AtomicBool::new(false));
        (Staged { file, pending: Vec::new(), written: 0, finishing: finishing.clone() }, finishing)
    }

    /// Bytes waiting for the next flush.
    pub fn pending(&self) -> usize {
        self.pending.len()
    }

    fn position(&self) -> u64 {
        self.written + self.pending.len() as u64
    }

    fn write_out(&mut self) -> io::Result<()> {
        let last = self.finishing.load(Ordering::SeqCst);
        let records = self.pending.len();
        if records == 0 && self.written > 0 && !last {
            return Ok(());
        }
        if !last {
            self.pending.extend_from_slice(&PROVISIONAL_END);
        }
        self.file.seek(SeekFrom::Start(self.written))?;
        let result = self.file.write_all(&self.pending);
        self.pending.truncate(records);
        result?;
        self.written += records as u64;
        self.pending.clear();
        if last {
            // Nothing of a provisional end may stay after the summary.
            self.file.set_len(self.written)?;
        }
        self.file.flush()
    }
}

impl Write for Staged {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        self.pending.extend_from_slice(buf);
        Ok(buf.len())
    }

    fn flush(&mut self) -> io::Result<()> {
        self.write_out()
    }
}

/// The writer only asks where it is (its chunks are buffered, so it never
/// seeks back): any other seek is an error, never a write in the wrong place.
impl Seek for Staged {
    fn seek(&mut self, pos: SeekFrom) -> io::Result<u64> {
        let here = self.position();
        match pos {
            SeekFrom::Current(0) | SeekFrom::End(0) => Ok(here),
            SeekFrom::Start(p) if p == here => Ok(here),
            _ => Err(io::Error::new(io::ErrorKind::Unsupported, "a recording is written in order, never sought")),
        }
    }

    fn stream_position(&mut self) -> io::Result<u64> {
        Ok(self.position())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_provisional_end_is_a_data_end_a_footer_and_the_magic() {
        let end = &PROVISIONAL_END;
        assert_eq!(end[0], ::mcap::records::op::DATA_END);
        assert_eq!(u64::from_le_bytes(end[1..9].try_into().unwrap()), 4);
        assert_eq!(end[13], ::mcap::records::op::FOOTER);
        assert_eq!(u64::from_le_bytes(end[14..22].try_into().unwrap()), 20);
        assert!(end[22..42].iter().all(|b| *b == 0));
        assert_eq!(&end[42..], ::mcap::MAGIC);
    }

    #[test]
    fn each_flush_writes_over_the_last_provisional_end() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f");
        let (mut s, finishing) = Staged::new(File::create(&path).unwrap());
        s.write_all(b"abc").unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"", "nothing before a flush");
        s.flush().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), [&b"abc"[..], &PROVISIONAL_END].concat());
        s.write_all(b"de").unwrap();
        assert_eq!(s.stream_position().unwrap(), 5);
        assert!(s.seek(SeekFrom::Start(0)).is_err(), "never sought back");
        s.flush().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), [&b"abcde"[..], &PROVISIONAL_END].concat());
        finishing.store(true, Ordering::SeqCst);
        s.write_all(b"f").unwrap();
        s.flush().unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), b"abcdef", "the last flush cuts the provisional end off");
    }
}
