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
use situ_runtime::record::mcap::{attached_bundle, read_file, read_recording};
use std::path::PathBuf;
use std::sync::Arc;

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
    let bytes = match read_file(recording) {
        Ok(b) => b,
        Err(e) => {
            return Err(CliError::Usage(format!("`{}`: {e}", recording.display())));
        }
    };
    let reading = match read_recording(&bytes) {
        Ok(r) => r,
        Err(e) => {
            return Err(CliError::Usage(format!("`{}` is not a readable recording: {e}", recording.display())));
        }
    };
    let content = match bundle_path {
        Some(p) => super::program::load(p, false, &trust).map_err(CliError::Reported)?.content,
        None => match attached_bundle(&bytes).map(|b| {
            super::program::decode_bundle(&b, &format!("the bundle attached to `{}`", recording.display()), &trust)
        }) {
            Some(Ok(c)) => Arc::new(c),
            Some(Err(e)) => {
                return Err(CliError::Usage(format!("the bundle attached to `{}`: {e}", recording.display())));
            }
            None => {
                return Err(CliError::Usage(format!(
                    "`{}` has no bundle attached: give one with --bundle",
                    recording.display()
                )));
            }
        },
    };
    let report = match situ_runtime::replay::replay_reading(&reading, content) {
        Ok(r) => r,
        Err(e) => {
            return Err(CliError::Usage(format!("`{}`: {e}", recording.display())));
        }
    };
    if let Some(why) = &report.cut_reason {
        eprintln!(
            "warning: `{}` is cut short ({} messages read): {why}; the replay covers the part before the cut",
            recording.display(),
            reading.messages.len()
        );
    }
    match format {
        Format::Human => println!("{}", report.describe()),
        Format::Json => println!("{}", serde_json::to_string(&report).expect("the report serializes")),
    }
    Ok(if report.same() { OK } else { FAILED })
}
