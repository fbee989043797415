//! `situ build FILE -o BUNDLE [--binary] [--stats] [--sign KEY] [--native FILE.rs]`:
//! compiles a checked source to a bundle, written atomically; with
//! `--sign`, signed with the secret key of `situ key new`
//! (`docs/signing.md`); with `--native`, also the bundle's native code, a
//! Rust module (`situ_runtime::rete::native`, docs/performance.md).

use super::{CliError, Outcome, OK};
use situ_compiler::bundle::{self, codec, Encoding};
use std::path::PathBuf;

// The arguments of `situ build`.
#[derive(clap::Args)]
pub struct Args {
    pub file: PathBuf,
    /// The bundle file to write.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Write the compact binary form instead of JSON.
    #[arg(long)]
    pub binary: bool,
    /// Print the network's node counts and what sharing saved.
    #[arg(long)]
    pub stats: bool,
    /// Refuse to build on warnings too.
    #[arg(long)]
    pub deny_warnings: bool,
    /// Sign the bundle with this secret key (`situ key new NAME` writes NAME.key).
    #[arg(long, value_name = "KEY")]
    pub sign: Option<PathBuf>,
    /// Also write the bundle's rules as a Rust module, for
    /// `Engine::with_native` in a program that links situ-runtime.
    #[arg(long, value_name = "FILE.rs")]
    pub native: Option<PathBuf>,
}

pub fn run(args: &Args) -> Outcome {
    let (file, out, binary) = (&args.file, &args.output, args.binary);
    // The key first: a build that cannot sign writes nothing.
    let key = args
        .sign
        .as_deref()
        .map(super::key::read_secret)
        .transpose()
        .map_err(|e| CliError::Usage(format!("--sign: {e}")))?;
    let checked = super::program::check(file, args.deny_warnings).map_err(CliError::Reported)?;
    let content = bundle::build(&checked);
    // Native code before anything is written: a bundle it cannot take
    // writes nothing.
    let native = match &args.native {
        Some(path) => {
            let name =
                file.file_name().map_or_else(|| file.display().to_string(), |n| n.to_string_lossy().into_owned());
            let code = situ_runtime::rete::native::generate(&content, &name)
                .map_err(|e| CliError::Failed(format!("--native: {e}")))?;
            Some((path, code))
        }
        None => None,
    };
    let encoding = if binary { Encoding::Binary } else { Encoding::Json };
    let bytes = match &key {
        Some(key) => bundle::sign::encode_signed(&content, encoding, key),
        None => bundle::encode(&content, encoding),
    };
    super::write_atomically(out, &bytes)
        .map_err(|e| CliError::Usage(format!("cannot write `{}`: {e}", out.display())))?;
    // The bundle is read back as a runtime would, before it is announced.
    bundle::decode(&bytes)
        .map_err(|e| CliError::Usage(format!("the bundle written to `{}` does not read back: {e}", out.display())))?;
    let hash = codec::sha256_hex(&bytes);
    println!(
        "{} -> {} ({} bytes, {}, file sha256 {})",
        file.display(),
        out.display(),
        bytes.len(),
        if binary { "binary" } else { "JSON" },
        &hash[..16]
    );
    if let Some(key) = &key {
        println!("signed by key {}", key.key_id());
    }
    if let Some((path, code)) = &native {
        super::write_atomically(path, code.as_bytes())
            .map_err(|e| CliError::Usage(format!("cannot write `{}`: {e}", path.display())))?;
        println!("{} -> {} (native code, {} lines)", file.display(), path.display(), code.lines().count());
    }
    if args.stats {
        let s = content.network.stats;
        let unshared = s.alpha_unshared + s.beta_unshared;
        println!(
            "network: {} alpha nodes ({} without sharing), {} beta nodes ({} without sharing), {} terminals",
            s.alpha, s.alpha_unshared, s.beta, s.beta_unshared, s.terminals
        );
        println!(
            "sharing saved {} of {} alpha and beta nodes ({:.0}%)",
            s.saved(),
            unshared,
            if unshared > 0 { 100.0 * s.saved() as f64 / unshared as f64 } else { 0.0 }
        );
        println!(
            "{} states, {} agents, {} events, {} rules",
            content.states.len(),
            content.agents.len(),
            content.events.len(),
            content.rules.len()
        );
    }
    Ok(OK)
}
