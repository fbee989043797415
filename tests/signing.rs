//! Signed bundles through the real binary: `situ key new`, `situ build
//! --sign`, and `--trust` on run, bench and replay, which accept a bundle
//! signed by a trusted key and refuse (exit 2, naming the key) an unsigned
//! one, one signed by another key, one edited after signing with its hash
//! recomputed, and a recording whose attached bundle was swapped for such
//! an edited one.

mod common;

use common::{code, stderr, stdout, text};
use situ_compiler::bundle::codec::sha256_hex;
use std::path::{Path, PathBuf};

fn situ(dir: &Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_situ"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("the binary runs")
}

fn repo(path: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path).display().to_string()
}

/// `situ key new NAME` in `dir`; the key id it printed.
fn key_new(dir: &Path, name: &str) -> String {
    let o = situ(dir, &["key", "new", name]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let id = stdout(&o).split_whitespace().nth(1).expect("`key ID: …`").trim_end_matches(':').to_string();
    assert_eq!(id.len(), 16, "{}", stdout(&o));
    id
}

/// A temporary directory with keys `robot` and `other`, and
/// rules/outdoor.situ built to `signed.json` (signed by `robot`) and
/// `unsigned.json`.
struct Setup {
    dir: tempfile::TempDir,
    robot: String,
    other: String,
}

impl Setup {
    fn new() -> Setup {
        let dir = tempfile::tempdir().expect("temp dir");
        let robot = key_new(dir.path(), "robot");
        let other = key_new(dir.path(), "other");
        let rules = repo("rules/outdoor.situ");
        let o = situ(dir.path(), &["build", &rules, "-o", "signed.json", "--sign", "robot.key"]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        assert!(stdout(&o).contains(&format!("signed by key {robot}")), "{}", stdout(&o));
        let o = situ(dir.path(), &["build", &rules, "-o", "unsigned.json"]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        Setup { dir, robot, other }
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }

    fn file(&self, name: &str) -> PathBuf {
        self.dir.path().join(name)
    }

    fn run(&self, args: &[&str]) -> std::process::Output {
        situ(self.path(), args)
    }
}

/// The JSON bundle `text` with a threshold moved (`distance < 30.0` becomes
/// `< 90.0`, same length) and the envelope's hash recomputed: what a person
/// who edits a bundle does. The signature is left as it was.
fn edit_with_new_hash(text: &str) -> String {
    let start = text.find("\"content\":").expect("an envelope") + "\"content\":".len();
    let end = text.trim_end().len() - 1; // the envelope's closing brace
    let body = &text[start..end];
    let edited = body.replacen("\"f64\": 30.0", "\"f64\": 90.0", 1);
    assert_ne!(edited, body, "the threshold is in the bundle");
    let (old, new) = (sha256_hex(body.as_bytes()), sha256_hex(edited.as_bytes()));
    assert!(text.contains(&old), "the envelope records the content's hash");
    format!("{}{}{}", &text[..start], edited, &text[end..]).replacen(&old, &new, 1)
}

#[test]
fn key_new_writes_a_private_secret_key_and_a_public_key() {
    let dir = tempfile::tempdir().unwrap();
    let id = key_new(dir.path(), "robot");
    let secret = std::fs::read_to_string(dir.path().join("robot.key")).unwrap();
    let public = std::fs::read_to_string(dir.path().join("robot.pub")).unwrap();
    assert!(secret.starts_with("situ ed25519 secret key v1\n"), "{secret}");
    assert!(public.starts_with("situ ed25519 public key v1\n"), "{public}");
    assert!(public.contains(&format!("key-id: {id}")) && secret.contains(&format!("key-id: {id}")));
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = std::fs::metadata(dir.path().join("robot.key")).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o600, "the secret key is the owner's only");
    }
    // Both files give the same id.
    for file in ["robot.key", "robot.pub"] {
        let o = situ(dir.path(), &["key", "id", file]);
        assert_eq!((code(&o), stdout(&o).trim()), (0, id.as_str()), "{}", text(&o));
    }
    // No temporary file is left behind.
    let names: Vec<String> =
        std::fs::read_dir(dir.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names.len(), 2, "{names:?}");
    // An existing key is never replaced by accident.
    let o = situ(dir.path(), &["key", "new", "robot"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("robot.key` exists"), "{}", stderr(&o));
    assert_eq!(std::fs::read_to_string(dir.path().join("robot.key")).unwrap(), secret);
    let o = situ(dir.path(), &["key", "new", "robot", "--force"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert_ne!(std::fs::read_to_string(dir.path().join("robot.key")).unwrap(), secret);
}

#[test]
fn a_signed_bundle_runs_benches_and_replays_under_trust() {
    let s = Setup::new();
    let o = s.run(&["bench", "signed.json", "--events", "2000", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(stderr(&o).contains(&format!("signed by trusted key {}", s.robot)), "{}", stderr(&o));
    // One of several trusted keys is enough; the binary form is signed too.
    let o = s.run(&["build", &repo("rules/outdoor.situ"), "-o", "signed.bin", "--binary", "--sign", "robot.key"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = s.run(&["bench", "signed.bin", "--events", "2000", "--trust", "other.pub", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    // `--trust` takes one key: it may come before the file.
    let o = s.run(&["bench", "--trust", "robot.pub", "signed.bin", "--events", "2000"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    // A mission (cut short: the result does not matter, the trust does) and
    // its recording, replayed under trust.
    let o = s.run(&["run", "signed.json", "--until", "3", "--record", "run.mcap", "--trust", "robot.pub"]);
    assert!(matches!(code(&o), 0 | 1), "{}", text(&o));
    assert!(s.file("run.mcap").exists());
    let o = s.run(&["replay", "run.mcap", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    assert!(stderr(&o).contains(&format!("signed by trusted key {}", s.robot)), "{}", stderr(&o));
    // A real-time run (the demo stack of examples/fig5) attaches the signed
    // bundle as it was read.
    let o = s.run(&["build", &repo("examples/fig5/fig5.situ"), "-o", "fig5.json", "--sign", "robot.key"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = s.run(&[
        "run",
        "fig5.json",
        "--stack",
        "demo",
        "--duration",
        "0.3",
        "--record",
        "demo.mcap",
        "--trust",
        "robot.pub",
    ]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    let o = s.run(&["replay", "demo.mcap", "--trust", "robot.pub"]);
    assert_ne!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains(&format!("signed by trusted key {}", s.robot)), "{}", stderr(&o));
    // Without --trust, signed and unsigned bundles load alike.
    for b in ["signed.json", "unsigned.json", "signed.bin"] {
        let o = s.run(&["bench", b, "--events", "100"]);
        assert_eq!(code(&o), 0, "{b}: {}", text(&o));
    }
}

#[test]
fn untrusted_bundles_are_refused_naming_the_keys() {
    let s = Setup::new();
    // Unsigned: refused, naming the trusted key.
    for cmd in [&["bench", "unsigned.json", "--events", "10"][..], &["run", "unsigned.json", "--until", "1"]] {
        let o = s.run(&[cmd, &["--trust", "robot.pub"]].concat());
        assert_eq!(code(&o), 2, "{}", text(&o));
        assert!(stderr(&o).contains("is not signed") && stderr(&o).contains(&s.robot), "{}", stderr(&o));
    }
    // Signed by a key that is not trusted: both ids named.
    let o = s.run(&["run", "signed.json", "--until", "1", "--trust", "other.pub"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    let err = stderr(&o);
    assert!(
        err.contains(&format!("signed by key {}, which is not trusted", s.robot)) && err.contains(&s.other),
        "{err}"
    );
    // A source carries no signature.
    let o = s.run(&["bench", &repo("rules/outdoor.situ"), "--events", "10", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("is a source"), "{}", stderr(&o));
    // A secret key given to --trust, or a file that is no key.
    let o = s.run(&["bench", "signed.json", "--events", "10", "--trust", "robot.key"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("secret key file"), "{}", stderr(&o));
    std::fs::write(s.file("notes.txt"), "not a key\n").unwrap();
    let o = s.run(&["bench", "signed.json", "--events", "10", "--trust", "notes.txt"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("not a situ key file"), "{}", stderr(&o));
    let o = s.run(&["bench", "signed.json", "--events", "10", "--trust", "signed.json"]);
    assert_eq!(code(&o), 2, "a bundle is no key: {}", text(&o));
    // And --sign with a public key builds nothing.
    let o = s.run(&["build", &repo("rules/outdoor.situ"), "-o", "x.json", "--sign", "robot.pub"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(!s.file("x.json").exists());
}

#[test]
fn an_edited_bundle_with_a_recomputed_hash_is_refused_under_trust() {
    let s = Setup::new();
    let signed = std::fs::read_to_string(s.file("signed.json")).unwrap();
    std::fs::write(s.file("edited.json"), edit_with_new_hash(&signed)).unwrap();
    // The hash alone lets it through: that is the hole signatures close.
    let o = s.run(&["bench", "edited.json", "--events", "100"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
    for cmd in [&["bench", "edited.json", "--events", "100"][..], &["run", "edited.json", "--until", "1"]] {
        let o = s.run(&[cmd, &["--trust", "robot.pub"]].concat());
        assert_eq!(code(&o), 2, "{}", text(&o));
        let err = stderr(&o);
        assert!(err.contains(&format!("signature by key {} does not verify", s.robot)), "{err}");
    }
}

/// The IEEE CRC-32 of MCAP records.
fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= b as u32;
        for _ in 0..8 {
            crc = if crc & 1 != 0 { (crc >> 1) ^ 0xEDB8_8320 } else { crc >> 1 };
        }
    }
    !crc
}

#[test]
fn a_recording_whose_bundle_was_swapped_is_refused_by_replay_under_trust() {
    let s = Setup::new();
    let o = s.run(&["run", "signed.json", "--until", "3", "--record", "run.mcap", "--trust", "robot.pub"]);
    assert!(matches!(code(&o), 0 | 1), "{}", text(&o));
    // Swap the attached bundle for an edited one of the same length, with its
    // hash and the attachment's CRC recomputed: a well-formed recording.
    let mut mcap = std::fs::read(s.file("run.mcap")).unwrap();
    let bundle = std::fs::read(s.file("signed.json")).unwrap();
    let at = mcap.windows(bundle.len()).position(|w| w == bundle).expect("the bundle is attached as it is");
    let edited = edit_with_new_hash(std::str::from_utf8(&bundle).unwrap());
    assert_eq!(edited.len(), bundle.len());
    mcap[at..at + bundle.len()].copy_from_slice(edited.as_bytes());
    // The attachment's CRC covers log time, create time, name, media type and data.
    let fields = 8 + 8 + 4 + "bundle.json".len() + 4 + "application/json".len() + 8;
    let end = at + bundle.len();
    let crc = crc32(&mcap[at - fields..end]);
    mcap[end..end + 4].copy_from_slice(&crc.to_le_bytes());
    std::fs::write(s.file("swapped.mcap"), &mcap).unwrap();
    // Without trust it replays (on the edited rules).
    let o = s.run(&["replay", "swapped.mcap"]);
    assert!(matches!(code(&o), 0 | 1), "the swapped recording reads: {}", text(&o));
    let o = s.run(&["replay", "swapped.mcap", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    let err = stderr(&o);
    assert!(
        err.contains("the bundle attached to") && err.contains(&s.robot) && err.contains("does not verify"),
        "{err}"
    );
    // A recording of an unsigned bundle, or a signed one under another key.
    let o = s.run(&["run", "unsigned.json", "--until", "3", "--record", "plain.mcap"]);
    assert!(matches!(code(&o), 0 | 1), "{}", text(&o));
    let o = s.run(&["replay", "plain.mcap", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains("is not signed"), "{}", stderr(&o));
    let o = s.run(&["replay", "run.mcap", "--trust", "other.pub"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    assert!(stderr(&o).contains(&format!("signed by key {}, which is not trusted", s.robot)), "{}", stderr(&o));
    // --bundle is checked the same way.
    let o = s.run(&["replay", "run.mcap", "--bundle", "unsigned.json", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 2, "{}", text(&o));
    let o = s.run(&["replay", "plain.mcap", "--bundle", "signed.json", "--trust", "robot.pub"]);
    assert_eq!(code(&o), 0, "{}", text(&o));
}

/// Over Zenoh (`--features zenoh`): `situ up --trust` checks the bundle and
/// hands the keys to its processes; an open deployment (no `[tls]`) is
/// said to be open.
#[cfg(feature = "zenoh")]
mod zenoh {
    use super::*;

    /// A deployment of one process (the Bulletinboard) on a free port.
    fn deployment(dir: &Path) -> &'static str {
        let port = std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port();
        let text = format!(
            "robot = \"s{port}\"\n[[process]]\nname = \"board\"\nboard = true\nlisten = [\"tcp/127.0.0.1:{port}\"]\n"
        );
        std::fs::write(dir.join("deploy.toml"), text).unwrap();
        "deploy.toml"
    }

    #[test]
    fn up_and_run_over_zenoh_trust_and_warn_of_an_open_deployment() {
        let s = Setup::new();
        let fig5 = repo("examples/fig5/fig5.situ");
        let o = s.run(&["build", &fig5, "-o", "fig5.json", "--sign", "robot.key"]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        let d = deployment(s.path());
        let o = s.run(&[
            "run",
            "fig5.json",
            "--stack",
            "none",
            "--transport",
            "zenoh",
            "--deploy",
            d,
            "--process",
            "board",
            "--duration",
            "0.3",
            "--trust",
            "robot.pub",
        ]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        let err = stderr(&o);
        assert!(err.contains("has no [tls] section") && err.contains("forged status"), "{err}");
        assert!(err.contains(&format!("signed by trusted key {}", s.robot)), "{err}");
        let o = s.run(&["up", d, "fig5.json", "--stack", "none", "--duration", "0.3", "--trust", "robot.pub"]);
        assert_eq!(code(&o), 0, "{}", text(&o));
        let err = stderr(&o);
        assert!(err.contains("has no [tls] section"), "{err}");
        // The process started by `up` checked the bundle too.
        assert!(err.matches(&format!("signed by trusted key {}", s.robot)).count() >= 2, "{err}");
        let o = s.run(&["up", d, "unsigned.json", "--stack", "none", "--duration", "0.3", "--trust", "robot.pub"]);
        assert_eq!(code(&o), 2, "{}", text(&o));
        assert!(stderr(&o).contains("is not signed"), "{}", stderr(&o));
    }
}
