//! Where source text comes from. The compiler itself does no I/O: it asks a
//! [`Loader`] for bytes. [`FsLoader`] reads the file system (the only place in
//! this crate that does), [`MemLoader`] serves tests and tools from memory.

use std::collections::BTreeMap;
use std::io;
use std::path::{Component, Path, PathBuf};

/// The largest source file the compiler reads.
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;

/// A source of files.
pub trait Loader {
    /// The bytes of the file at `path`.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;

    /// A name that is the same for two paths to the same file, so that a file
    /// included twice is read once and include cycles are found.
    fn identity(&self, path: &Path) -> io::Result<PathBuf> {
        Ok(normalize(path))
    }
}

/// Reads files from the file system.
#[derive(Debug, Clone, Copy, Default)]
pub struct FsLoader;

impl Loader for FsLoader {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        use std::io::Read;
        let file = std::fs::File::open(path)?;
        let meta = file.metadata()?;
        if meta.is_dir() {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "is a directory"));
        }
        let mut bytes = Vec::new();
        // Read one byte more than the limit to tell "at the limit" from "over it",
        // also for files whose size the metadata does not know (pipes).
        file.take(MAX_FILE_BYTES + 1).read_to_end(&mut bytes)?;
        if bytes.len() as u64 > MAX_FILE_BYTES {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("larger than the limit of {} MiB for a source file", MAX_FILE_BYTES / (1024 * 1024)),
            ));
        }
        Ok(bytes)
    }

    fn identity(&self, path: &Path) -> io::Result<PathBuf> {
        std::fs::canonicalize(path)
    }
}

/// Serves files from memory, keyed by normalized path.
#[derive(Debug, Clone, Default)]
pub struct MemLoader {
    files: BTreeMap<PathBuf, Vec<u8>>,
}

impl MemLoader {
    pub fn new() -> Self {
        Self::default()
    }

    /// Adds (or replaces) a file.
    pub fn with(mut self, path: impl AsRef<Path>, content: impl Into<Vec<u8>>) -> Self {
        self.files.insert(normalize(path.as_ref()), content.into());
        self
    }
}

impl Loader for MemLoader {
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.files
            .get(&normalize(path))
            .cloned()
            .ok_or_else(|| io::Error::new(io::ErrorKind::NotFound, "No such file or directory"))
    }
}

/// Removes `.` and resolves `..` lexically.
pub fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            Component::CurDir => {}
            Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other.as_os_str()),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normalize_resolves_dots() {
        assert_eq!(normalize(Path::new("a/./b/../c.situ")), PathBuf::from("a/c.situ"));
        assert_eq!(normalize(Path::new("../x.situ")), PathBuf::from("../x.situ"));
    }

    #[test]
    fn mem_loader_finds_normalized_paths() {
        let l = MemLoader::new().with("dir/a.situ", "states {}");
        assert_eq!(l.read(Path::new("dir/sub/../a.situ")).unwrap(), b"states {}");
        assert!(l.read(Path::new("b.situ")).is_err());
    }
}
