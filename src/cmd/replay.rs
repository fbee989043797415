//! `situ replay F.mcap [--bundle B] [--format human|json]`: feeds a
//! recording's events to a bundle — the one attached to the recording, or
//! `--bundle` (a bundle or a `.situ` source) — and reports where the states
//! differ from the recorded ones. Exit 0 when they are the same, 1 when
//! they differ, 2 on an unreadable recording or bundle.

use super::{FAILED, OK, USAGE};
use situ_compiler::bundle;
use situ_runtime::record::mcap::attached_bundle;
use std::path::{Path, PathBuf};
use std::sync::Arc;

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Format {
    Human,
    Json,
}

pub fn run(recording: &Path, bundle_path: Option<&PathBuf>, format: Format) -> u8 {
    let bytes = match std::fs::read(recording) {
        Ok(b) => b,
        Err(e) => {
            eprintln!("error: cannot read `{}`: {e}", recording.display());
            return USAGE;
        }
    };
    let content = match bundle_path {
        Some(p) => match super::program::load(p, false) {
            Ok(p) => p.content,
            Err(code) => return code,
        },
        None => match attached_bundle(&bytes).map(|b| bundle::decode(&b)) {
            Some(Ok(c)) => Arc::new(c),
            Some(Err(e)) => {
                eprintln!("error: the bundle attached to `{}`: {e}", recording.display());
                return USAGE;
            }
            None => {
                eprintln!("error: `{}` has no bundle attached: give one with --bundle", recording.display());
                return USAGE;
            }
        },
    };
    let report = match situ_runtime::replay::replay(&bytes, content) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("error: `{}`: {e}", recording.display());
            return USAGE;
        }
    };
    match format {
        Format::Human => println!("{}", report.describe()),
        Format::Json => println!("{}", serde_json::to_string(&report).expect("the report serializes")),
    }
    if report.same() {
        OK
    } else {
        FAILED
    }
}
