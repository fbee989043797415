//! `situ bench FILE|BUNDLE [--events N] [--seed S]`: the Bulletinboard's
//! throughput and latency on a seeded random event stream, as one JSON
//! object. `--stream-out`, `--states-out` and `--stream-in` make the runs
//! comparable with other engines (`bench/README.md`). The events the
//! acceptance rule refuses are counted by reason in the object and said on
//! standard error (file and line, why); the run goes on past them.

use super::{CliError, Outcome, Trust, OK};
use situ_runtime::bench::{self, Options, Source};
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::PathBuf;

// The arguments of `situ bench`.
#[derive(clap::Args)]
#[command(mut_arg("trust", |a| a.help(
    "Bench only bundles signed by one of these public keys (`situ key new`); refuse others (exit 2)"
)))]
pub struct Args {
    /// A `.situ` source or a bundle.
    pub file: PathBuf,
    /// How many events.
    #[arg(long, default_value_t = 1_000_000)]
    pub events: u64,
    /// The stream's seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Read the events from this stream file instead (bench/README.md).
    #[arg(long)]
    pub stream_in: Option<PathBuf>,
    /// Write the generated stream here.
    #[arg(long)]
    pub stream_out: Option<PathBuf>,
    /// Write the `INDEX STATE` lines of the state changes here.
    #[arg(long)]
    pub states_out: Option<PathBuf>,
    /// Do not reset to the initial state after a final state.
    #[arg(long)]
    pub no_reset: bool,
    #[command(flatten)]
    pub trust: Trust,
}

/// The largest event stream `--stream-in` reads.
const MAX_STREAM_BYTES: u64 = 256 * 1024 * 1024;

pub fn run(args: &Args) -> Outcome {
    let trust = args.trust.policy()?;
    let program = super::program::load(&args.file, false, &trust).map_err(CliError::Reported)?;
    let content = program.content;
    let mut stream_text = None;
    let events = match &args.stream_in {
        None => None,
        Some(path) => {
            let read = situ_compiler::loader::read_bounded(path, MAX_STREAM_BYTES, "an event stream");
            let text = match read.and_then(|b| String::from_utf8(b).map_err(std::io::Error::other)) {
                Ok(t) => t,
                Err(e) => {
                    return Err(CliError::Usage(format!("cannot read `{}`: {e}", path.display())));
                }
            };
            let parsed = situ_runtime::stream::parse(&content, &text);
            stream_text = Some(text);
            match parsed {
                Ok(events) => Some(events),
                Err(e) => {
                    return Err(CliError::Usage(format!("`{}`: {e}", path.display())));
                }
            }
        }
    };
    let create = |path: &Option<PathBuf>| -> Result<Option<BufWriter<File>>, CliError> {
        path.as_ref()
            .map(|p| {
                File::create(p)
                    .map(BufWriter::new)
                    .map_err(|e| CliError::Usage(format!("cannot write `{}`: {e}", p.display())))
            })
            .transpose()
    };
    // Both files are created before an error is said; both errors are said.
    let (mut stream_out, mut states_out) = match (create(&args.stream_out), create(&args.states_out)) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), Ok(_)) | (Ok(_), Err(e)) => return Err(e),
        (Err(first), Err(second)) => {
            eprintln!("error: {first}");
            return Err(second);
        }
    };
    if let Some(out) = stream_out.as_mut() {
        let _ = out.write_all(situ_runtime::stream::header(&content.source, args.seed).as_bytes());
    }
    let source = match &events {
        Some(events) => Source::File(events),
        None => Source::Random { events: args.events, seed: args.seed },
    };
    let report = bench::run(
        content,
        Options {
            source,
            reset_on_final: !args.no_reset,
            stream_out: stream_out.as_mut().map(|w| w as &mut dyn Write),
            states_out: states_out.as_mut().map(|w| w as &mut dyn Write),
        },
    );
    for (out, path) in [(stream_out, &args.stream_out), (states_out, &args.states_out)] {
        if let (Some(mut out), Some(path)) = (out, path) {
            if let Err(e) = out.flush() {
                return Err(CliError::Usage(format!("cannot write `{}`: {e}", path.display())));
            }
        }
    }
    println!("{}", serde_json::to_string(&report).expect("the report serializes"));
    // The refused events, for a person: where in the stream, and why.
    let place = |i: u64| match (&stream_text, &args.stream_in) {
        (Some(text), Some(path)) => situ_runtime::stream::line_of(text, i)
            .map_or(format!("event {i}"), |line| format!("{}:{line}", path.display())),
        _ => format!("event {i}"),
    };
    for line in report.refusals(place) {
        eprintln!("{line}");
    }
    Ok(OK)
}
