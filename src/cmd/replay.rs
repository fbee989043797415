//! `situ replay F.mcap [--bundle B] [--format human|json]`: feeds a
//! recording's events to a bundle — the one attached to the recording, or
//! `--bundle` (a bundle or a `.situ` source) — and reports where the states
//! differ from the recorded ones. Exit 0 when they are the same, 1 when
//! they differ, 2 on an unreadable recording or bundle: not a regular file,
//! larger than 1 GiB, not MCAP, damaged (a record or chunk that does not
//! hold together), or with nothing of situ's to replay.
//!
//! A recording cut short (a run that was killed: no summary, or a last
//! record cut off) is replayed up to the cut; the report and a warning on
//! standard error say so, and the exit code compares what was replayed
//! (0 the same, 1 different).
//!
//! With `--trust PUBKEY` (once per key), the bundle replayed on (attached or `--bundle`)
//! must be signed by one of the keys: a recording whose attached bundle was
//! swapped or edited is refused (exit 2, naming the key).

use super::{CliError, Outcome, Trust, FAILED, OK};
use situ_api::{Error, Recording};
use situ_runtime::record::mcap::read_file;
use std::path::PathBuf;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Format {
    Human,
    Json,
}

// The arguments of `situ replay`.
#[derive(clap::Args)]
#[command(mut_arg("trust", |a| a.help(
    "Replay only on bundles (the attached one or --bundle) signed by one of these public keys (`situ key new`); refuse others (exit 2)"
)))]
pub struct Args {
    /// An MCAP recording of `situ run --record`.
    pub recording: PathBuf,
    /// The rules to replay on (a bundle or a `.situ` source); default: the recording's own.
    #[arg(long)]
    pub bundle: Option<PathBuf>,
    #[arg(long, value_enum, default_value_t = Format::Human)]
    pub format: Format,
    #[command(flatten)]
    pub trust: Trust,
}

pub fn run(args: &Args) -> Outcome {
    let trust = args.trust.policy()?;
    let (recording, bundle_path, format) = (args.recording.as_path(), args.bundle.as_ref(), args.format);
    let name = recording.display();
    let bytes = read_file(recording).map_err(|e| CliError::Usage(format!("`{name}`: {e}")))?;
    let read = Recording::read(bytes).map_err(|e| match e {
        Error::Recording(e) => CliError::Usage(format!("`{name}` is not a readable recording: {e}")),
        e => CliError::Usage(format!("`{name}`: {e}")),
    })?;
    let bundle = match bundle_path {
        Some(p) => Some(super::program::load(p, false, &trust).map_err(CliError::Reported)?.content),
        None => None,
    };
    let replayed = read.replay(bundle, &trust).map_err(|e| match e {
        Error::NoAttachedBundle => CliError::Usage(format!("`{name}` has no bundle attached: give one with --bundle")),
        Error::Attached(e) => CliError::Usage(format!("the bundle attached to `{name}`: {e}")),
        e => CliError::Usage(format!("`{name}`: {e}")),
    })?;
    if let Some(key_id) = replayed.signed_by {
        eprintln!("the bundle attached to `{name}`: signed by trusted key {key_id}");
    }
    let report = replayed.report;
    if let Some(why) = &report.cut_reason {
        eprintln!(
            "warning: `{}` is cut short ({} messages read): {why}; the replay covers the part before the cut",
            recording.display(),
            read.messages()
        );
    }
    match format {
        Format::Human => println!("{}", report.describe()),
        Format::Json => println!("{}", serde_json::to_string(&report).expect("the report serializes")),
    }
    Ok(if report.same() { OK } else { FAILED })
}
