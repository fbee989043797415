//! `situ key new NAME [--force]`: an ed25519 key pair to sign bundles with
//! (`situ build --sign NAME.key`) and to trust them by (`--trust NAME.pub`):
//! `NAME.key`, the secret key (mode 0600), and `NAME.pub`, the public key,
//! each written atomically (a temporary file, then a rename). `situ key id
//! FILE`: the id of a key file, public or secret.
//!
//! The formats and the key id are `situ_compiler::bundle::sign`'s; the seed
//! comes from the operating system's random source.

use super::{OK, USAGE};
use situ_compiler::bundle::sign::{PublicKey, SecretKey, PUBLIC_HEADER, SECRET_HEADER};
use situ_compiler::loader::read_bounded;
use std::ffi::OsString;
use std::io::Write;
use std::path::{Path, PathBuf};

/// The largest key file read (a key file is a few hundred bytes).
const MAX_KEY_BYTES: u64 = 64 * 1024;

#[derive(clap::Subcommand)]
pub enum What {
    /// Make a key pair: NAME.key (secret, mode 0600) and NAME.pub (public); prints its key id.
    New {
        /// The files' path without extension (e.g. `keys/robot`).
        name: PathBuf,
        /// Replace existing key files (the old key can no longer sign).
        #[arg(long)]
        force: bool,
    },
    /// Print the key id of a key file (`.pub` or `.key`).
    Id { file: PathBuf },
}

pub fn run(what: What) -> u8 {
    match what {
        What::New { name, force } => new(&name, force),
        What::Id { file } => id(&file),
    }
}

/// `NAME` with `.ext` appended (not replacing a dot already in the name).
fn with_ext(name: &Path, ext: &str) -> PathBuf {
    let mut s: OsString = name.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

fn new(name: &Path, force: bool) -> u8 {
    let (secret_path, public_path) = (with_ext(name, "key"), with_ext(name, "pub"));
    if !force {
        if let Some(existing) = [&secret_path, &public_path].into_iter().find(|p| p.exists()) {
            eprintln!(
                "error: `{}` exists; give another name, or --force to replace the key (bundles signed with it will no longer be trusted by its new .pub)",
                existing.display()
            );
            return USAGE;
        }
    }
    let mut seed = [0u8; 32];
    if let Err(e) = getrandom::fill(&mut seed) {
        eprintln!("error: the operating system gave no random bytes for the key: {e}");
        return USAGE;
    }
    let key = SecretKey::from_seed(&seed);
    seed.fill(0);
    let label = name.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    if let Err(e) = write_secret(&secret_path, key.to_text(&label).as_bytes()) {
        eprintln!("error: cannot write `{}`: {e}", secret_path.display());
        return USAGE;
    }
    if let Err(e) = super::write_atomically(&public_path, key.public().to_text(&label).as_bytes()) {
        eprintln!("error: cannot write `{}`: {e}", public_path.display());
        return USAGE;
    }
    println!(
        "key {}: secret {} (keep it; sign with `situ build --sign {}`), public {} (give it to `--trust`)",
        key.key_id(),
        secret_path.display(),
        secret_path.display(),
        public_path.display()
    );
    OK
}

/// Writes a secret file readable by its owner only, atomically: a new
/// temporary file created with mode 0600 next to it, then a rename.
fn write_secret(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."));
    let file_name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let tmp = dir.join(format!(".{file_name}.situ-tmp.{}", std::process::id()));
    let mut options = std::fs::OpenOptions::new();
    options.write(true).create_new(true);
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        options.mode(0o600);
    }
    let result = options.open(&tmp).and_then(|mut f| {
        f.write_all(bytes)?;
        f.sync_all()?;
        std::fs::rename(&tmp, path)
    });
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

fn read_key_text(path: &Path) -> Result<String, String> {
    let bytes = read_bounded(path, MAX_KEY_BYTES, "a key file")
        .map_err(|e| format!("cannot read `{}`: {e}", path.display()))?;
    String::from_utf8(bytes).map_err(|_| format!("`{}` is not a situ key file (not UTF-8 text)", path.display()))
}

/// Reads a secret key file (for `build --sign`); warns when others may
/// read it.
pub fn read_secret(path: &Path) -> Result<SecretKey, String> {
    let text = read_key_text(path)?;
    let key = SecretKey::from_text(&text).map_err(|e| format!("`{}`: {e}", path.display()))?;
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        if let Ok(meta) = std::fs::metadata(path) {
            if meta.permissions().mode() & 0o077 != 0 {
                eprintln!(
                    "warning: `{}` may be read by others (mode {:o}): whoever reads it can sign bundles as key {}; `chmod 600` it",
                    path.display(),
                    meta.permissions().mode() & 0o777,
                    key.key_id()
                );
            }
        }
    }
    Ok(key)
}

/// Reads a public key file (for `--trust`).
pub fn read_public(path: &Path) -> Result<PublicKey, String> {
    let text = read_key_text(path)?;
    PublicKey::from_text(&text).map_err(|e| format!("`{}`: {e}", path.display()))
}

fn id(path: &Path) -> u8 {
    let text = match read_key_text(path) {
        Ok(t) => t,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    let first = text.lines().map(str::trim).find(|l| !l.is_empty() && !l.starts_with('#'));
    let id = if first == Some(SECRET_HEADER) {
        SecretKey::from_text(&text).map(|k| k.key_id())
    } else if first == Some(PUBLIC_HEADER) {
        PublicKey::from_text(&text).map(|k| k.key_id())
    } else {
        PublicKey::from_text(&text).map(|k| k.key_id()) // says what is wrong
    };
    match id {
        Ok(id) => {
            println!("{id}");
            OK
        }
        Err(e) => {
            eprintln!("error: `{}`: {e}", path.display());
            USAGE
        }
    }
}
