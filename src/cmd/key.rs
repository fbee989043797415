//! `situ key new NAME [--force]`: an ed25519 key pair to sign bundles with
//! (`situ build --sign NAME.key`) and to trust them by (`--trust NAME.pub`):
//! `NAME.key`, the secret key (mode 0600), and `NAME.pub`, the public key,
//! each written atomically (a temporary file, then a rename). `situ key id
//! FILE`: the id of a key file, public or secret.
//!
//! The key files, their formats and the key id are the bundle crate's
//! (`situ_bundle::key`, `situ_bundle::sign`); this is the command line:
//! arguments, messages and exit codes.

use super::{OK, USAGE};
use situ_compiler::bundle::key;
use situ_compiler::bundle::sign::{PublicKey, SecretKey};
use std::path::{Path, PathBuf};

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

fn new(name: &Path, force: bool) -> u8 {
    match key::create(name, force) {
        Ok(made) => {
            println!(
                "key {}: secret {} (keep it; sign with `situ build --sign {}`), public {} (give it to `--trust`)",
                made.key_id,
                made.secret.display(),
                made.secret.display(),
                made.public.display()
            );
            OK
        }
        Err(e) => {
            eprintln!("error: {e}");
            USAGE
        }
    }
}

/// Reads a secret key file (for `build --sign`); warns when others may
/// read it.
pub fn read_secret(path: &Path) -> Result<SecretKey, String> {
    let key = key::read_secret(path).map_err(|e| e.to_string())?;
    if let Some(mode) = key::exposed_mode(path) {
        eprintln!(
            "warning: `{}` may be read by others (mode {mode:o}): whoever reads it can sign bundles as key {}; `chmod 600` it",
            path.display(),
            key.key_id()
        );
    }
    Ok(key)
}

/// Reads a public key file (for `--trust`).
pub fn read_public(path: &Path) -> Result<PublicKey, String> {
    key::read_public(path).map_err(|e| e.to_string())
}

fn id(path: &Path) -> u8 {
    match key::read_id(path) {
        Ok(id) => {
            println!("{id}");
            OK
        }
        Err(e) => {
            eprintln!("error: {e}");
            USAGE
        }
    }
}
