//! Where source text comes from. The compiler itself does no I/O: it asks a
//! [`Loader`] for bytes. [`FsLoader`] reads the file system (the only place in
//! this crate that does), [`MemLoader`] serves tests and tools from memory.

use std::collections::BTreeMap;
use std::io;
use std::path::{Component, Path, PathBuf};

/// The largest source file the compiler reads.
pub const MAX_FILE_BYTES: u64 = 16 * 1024 * 1024;

pub use situ_bundle::file::{read_bounded, MAX_BUNDLE_BYTES};

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
        read_bounded(path, MAX_FILE_BYTES, "a source file")
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
    fn bounded_reads_refuse_what_is_not_a_small_regular_file() {
        let dir = std::env::temp_dir().join(format!("situ-loader-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let small = dir.join("small.situ");
        std::fs::write(&small, b"states { A initial }").unwrap();
        assert_eq!(read_bounded(&small, 20, "a source file").unwrap(), b"states { A initial }");
        let err = read_bounded(&small, 19, "a source file").unwrap_err();
        assert!(err.to_string().contains("larger than the limit of 19 bytes for a source file"), "{err}");
        let err = read_bounded(&dir, 100, "a source file").unwrap_err();
        assert!(err.to_string().contains("is a directory"), "{err}");
        #[cfg(unix)]
        {
            let err = read_bounded(Path::new("/dev/zero"), 100, "a bundle").unwrap_err();
            assert!(err.to_string().contains("is a character device, not a regular file"), "{err}");
            let fifo = dir.join("fifo.situ");
            let made = std::process::Command::new("mkfifo").arg(&fifo).status().is_ok_and(|s| s.success());
            if made {
                // Refused from its metadata: opening it would wait for a writer.
                let err = FsLoader.read(&fifo).unwrap_err();
                assert!(err.to_string().contains("is a FIFO, not a regular file"), "{err}");
            }
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn mem_loader_finds_normalized_paths() {
        let l = MemLoader::new().with("dir/a.situ", "states {}");
        assert_eq!(l.read(Path::new("dir/sub/../a.situ")).unwrap(), b"states {}");
        assert!(l.read(Path::new("b.situ")).is_err());
    }
}
