//! Files: reading an input whole, with a bound (the one way a bundle, a key
//! or a source is read from disk), and writing an output atomically.

use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The largest bundle a command reads.
pub const MAX_BUNDLE_BYTES: u64 = 256 * 1024 * 1024;

/// Reads a whole regular file of at most `limit` bytes: the one way the
/// command line reads an input (a source, a bundle, a scenario, a stream).
/// `what` names the kind of file in the error ("a source file").
///
/// What is not a regular file (a directory, a FIFO, a device such as
/// `/dev/zero`) is refused from its metadata, before it is opened: opening a
/// FIFO would wait for a writer. The read takes one byte more than the
/// limit, so that a file that grows while it is read is refused too.
pub fn read_bounded(path: &Path, limit: u64, what: &str) -> io::Result<Vec<u8>> {
    use std::io::Read;
    let kind = |meta: &std::fs::Metadata| -> io::Result<()> {
        let file_type = meta.file_type();
        if file_type.is_file() {
            return Ok(());
        }
        if file_type.is_dir() {
            return Err(io::Error::new(io::ErrorKind::InvalidInput, "is a directory"));
        }
        let is = not_regular(&file_type);
        Err(io::Error::new(io::ErrorKind::InvalidInput, format!("is {is}, not a regular file")))
    };
    kind(&std::fs::metadata(path)?)?;
    let file = std::fs::File::open(path)?;
    let meta = file.metadata()?;
    kind(&meta)?; // replaced between the two looks
    let too_large = || {
        let mib = limit / (1024 * 1024);
        let limit = if mib > 0 { format!("{mib} MiB") } else { format!("{limit} bytes") };
        io::Error::new(io::ErrorKind::InvalidData, format!("larger than the limit of {limit} for {what}"))
    };
    if meta.len() > limit {
        return Err(too_large());
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large());
    }
    Ok(bytes)
}

/// What a file that is neither a regular file nor a directory is.
fn not_regular(file_type: &std::fs::FileType) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return "a FIFO";
        }
        if file_type.is_char_device() {
            return "a character device";
        }
        if file_type.is_block_device() {
            return "a block device";
        }
        if file_type.is_socket() {
            return "a socket";
        }
    }
    let _ = file_type;
    "a special file"
}

/// Where an output is written before it is whole: a hidden file beside
/// `path`, named for it and for this process, renamed onto `path` at the end.
pub fn partial_path(path: &Path) -> PathBuf {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let file_name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    dir.join(format!(".{file_name}.situ-tmp.{}", std::process::id()))
}

/// Writes a file so that it is never half written: a new temporary file
/// next to it ([`partial_path`]), synced, then a rename (the one way situ
/// writes an output). A `secret` file is created readable by its owner
/// only; another keeps the permissions of the file it replaces.
pub fn write_atomically(path: &Path, bytes: &[u8], secret: bool) -> io::Result<()> {
    let tmp = partial_path(path);
    let mut options = std::fs::OpenOptions::new();
    options.write(true);
    if secret {
        // A new file, so that the mode is the one it is created with.
        options.create_new(true);
        #[cfg(unix)]
        {
            use std::os::unix::fs::OpenOptionsExt;
            options.mode(0o600);
        }
    } else {
        options.create(true).truncate(true);
    }
    let result = options.open(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()?;
        if !secret {
            if let Ok(meta) = std::fs::metadata(path) {
                std::fs::set_permissions(&tmp, meta.permissions())?;
            }
        }
        std::fs::rename(&tmp, path)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}
