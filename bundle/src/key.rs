//! Key files on disk: reading a secret key (to sign with) or a public key
//! (to trust), the id of either, and making a new key pair (`situ key new`).
//! The text formats are [`crate::sign`]'s; here are the files: bounded
//! reads, the secret written with mode 0600, each file written atomically
//! (a temporary file next to it, then a rename), and the seed of a new key
//! from the operating system's random source.

use crate::file::read_bounded;
use crate::sign::{KeyError, KeyId, PublicKey, SecretKey, SECRET_HEADER};
use std::ffi::OsString;
use std::io;
use std::path::{Path, PathBuf};

/// The largest key file read (a key file is a few hundred bytes).
pub const MAX_KEY_BYTES: u64 = 64 * 1024;

/// Why a key file cannot be read or written.
#[derive(Debug, thiserror::Error)]
pub enum KeyFileError {
    #[error("cannot read `{}`: {source}", path.display())]
    Read { path: PathBuf, source: io::Error },
    #[error("`{}` is not a situ key file (not UTF-8 text)", path.display())]
    NotText { path: PathBuf },
    /// The file's text is not a key of the kind asked for.
    #[error("`{}`: {source}", path.display())]
    Invalid { path: PathBuf, source: KeyError },
    /// A new key would replace this file.
    #[error(
        "`{}` exists; give another name, or --force to replace the key (bundles signed with it will no longer be trusted by its new .pub)",
        path.display()
    )]
    Exists { path: PathBuf },
    #[error("the operating system gave no random bytes for the key: {0}")]
    Random(getrandom::Error),
    #[error("cannot write `{}`: {source}", path.display())]
    Write { path: PathBuf, source: io::Error },
}

fn read_text(path: &Path) -> Result<String, KeyFileError> {
    let bytes = read_bounded(path, MAX_KEY_BYTES, "a key file")
        .map_err(|source| KeyFileError::Read { path: path.to_path_buf(), source })?;
    String::from_utf8(bytes).map_err(|_| KeyFileError::NotText { path: path.to_path_buf() })
}

fn invalid(path: &Path) -> impl FnOnce(KeyError) -> KeyFileError + '_ {
    move |source| KeyFileError::Invalid { path: path.to_path_buf(), source }
}

/// Reads a secret key file (to sign with). See [`exposed_mode`] for the
/// warning a caller should give about its permissions.
pub fn read_secret(path: &Path) -> Result<SecretKey, KeyFileError> {
    SecretKey::from_text(&read_text(path)?).map_err(invalid(path))
}

/// Reads a public key file (to trust).
pub fn read_public(path: &Path) -> Result<PublicKey, KeyFileError> {
    PublicKey::from_text(&read_text(path)?).map_err(invalid(path))
}

/// The id of a key file, public or secret (told apart by its first line);
/// a file that is neither is refused saying what is wrong.
pub fn read_id(path: &Path) -> Result<KeyId, KeyFileError> {
    let text = read_text(path)?;
    let first = text.lines().map(str::trim).find(|l| !l.is_empty() && !l.starts_with('#'));
    let id = if first == Some(SECRET_HEADER) {
        SecretKey::from_text(&text).map(|k| k.key_id())
    } else {
        // A public key, or the error that says what is wrong.
        PublicKey::from_text(&text).map(|k| k.key_id())
    };
    id.map_err(invalid(path))
}

/// The permission bits of a secret key file that others may read (`None`
/// when only its owner can, or where the system has no such bits).
pub fn exposed_mode(path: &Path) -> Option<u32> {
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(path).ok()?.permissions().mode();
        (mode & 0o077 != 0).then_some(mode & 0o777)
    }
    #[cfg(not(unix))]
    {
        let _ = path;
        None
    }
}

/// `NAME` with `.ext` appended (not replacing a dot already in the name).
pub fn with_ext(name: &Path, ext: &str) -> PathBuf {
    let mut s: OsString = name.as_os_str().to_owned();
    s.push(".");
    s.push(ext);
    PathBuf::from(s)
}

/// A key pair written by [`create`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NewKey {
    pub key_id: KeyId,
    /// `NAME.key`, mode 0600.
    pub secret: PathBuf,
    /// `NAME.pub`.
    pub public: PathBuf,
}

/// Makes a key pair from the operating system's random source and writes
/// `NAME.key` (the secret, mode 0600) and `NAME.pub`; refuses to replace
/// either unless `force`.
pub fn create(name: &Path, force: bool) -> Result<NewKey, KeyFileError> {
    let mut seed = [0u8; 32];
    let (secret_path, public_path) = (with_ext(name, "key"), with_ext(name, "pub"));
    if !force {
        if let Some(existing) = [&secret_path, &public_path].into_iter().find(|p| p.exists()) {
            return Err(KeyFileError::Exists { path: existing.clone() });
        }
    }
    getrandom::fill(&mut seed).map_err(KeyFileError::Random)?;
    let key = SecretKey::from_seed(&seed);
    seed.fill(0);
    write_pair(name, &key)?;
    Ok(NewKey { key_id: key.key_id(), secret: secret_path, public: public_path })
}

/// Writes `NAME.key` and `NAME.pub` of `key`, labelled with the file name.
pub fn write_pair(name: &Path, key: &SecretKey) -> Result<(), KeyFileError> {
    let (secret_path, public_path) = (with_ext(name, "key"), with_ext(name, "pub"));
    let label = name.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    crate::file::write_atomically(&secret_path, key.to_text(&label).as_bytes(), true)
        .map_err(|source| KeyFileError::Write { path: secret_path.clone(), source })?;
    crate::file::write_atomically(&public_path, key.public().to_text(&label).as_bytes(), false)
        .map_err(|source| KeyFileError::Write { path: public_path.clone(), source })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir() -> PathBuf {
        let d = std::env::temp_dir().join(format!(
            "situ-bundle-key-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn a_new_pair_reads_back_and_is_not_replaced_without_force() {
        let d = dir();
        let name = d.join("robot");
        let made = create(&name, false).expect("writes");
        assert_eq!((made.secret.clone(), made.public.clone()), (d.join("robot.key"), d.join("robot.pub")));
        assert_eq!(read_secret(&made.secret).expect("reads").key_id(), made.key_id);
        assert_eq!(read_public(&made.public).expect("reads").key_id(), made.key_id);
        assert_eq!(read_id(&made.secret).unwrap(), made.key_id);
        assert_eq!(read_id(&made.public).unwrap(), made.key_id);
        assert_eq!(exposed_mode(&made.secret), None);
        let err = create(&name, false).unwrap_err();
        assert!(matches!(&err, KeyFileError::Exists { path } if *path == made.secret), "{err}");
        let again = create(&name, true).expect("replaces");
        assert_ne!(again.key_id, made.key_id);
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_file_that_is_not_a_key_of_the_kind_asked_for_says_so_with_its_path() {
        let d = dir();
        let key = SecretKey::from_seed(&[5; 32]);
        write_pair(&d.join("k"), &key).unwrap();
        let err = read_public(&d.join("k.key")).unwrap_err();
        assert!(matches!(err, KeyFileError::Invalid { .. }), "{err}");
        assert!(err.to_string().starts_with(&format!("`{}`: this is a secret key file", d.join("k.key").display())));
        std::fs::write(d.join("bin"), [0xff, 0xfe]).unwrap();
        assert!(matches!(read_id(&d.join("bin")), Err(KeyFileError::NotText { .. })));
        assert!(matches!(read_secret(&d.join("none")), Err(KeyFileError::Read { .. })));
        let _ = std::fs::remove_dir_all(&d);
    }
}
