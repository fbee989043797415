//! `situ-handwritten`: the rules of `rules/outdoor.situ` matched by plain
//! hand-written Rust (a `match` on the state and direct tests on each agent's
//! latest event, no rule network), run on a `.events` stream. It is the
//! benchmark's practical limit: what any rule engine can at best approach.
//!
//! ```text
//! situ-handwritten --stream FILE [--states-out FILE]
//! ```
//!
//! The stream is read and parsed before the clock starts; only the processing
//! loop is timed. Prints one JSON line (bench/README.md):
//! `{"engine":"handwritten","events":N,"seconds":S,"events_per_sec":R,"state_changes":C}`.

mod engine;
mod model;
mod stream;

use std::process::ExitCode;
use std::time::Instant;

use engine::{CascadeError, Engine, MAX_FIRINGS};
use model::{Event, State};

const USAGE: &str = "usage: situ-handwritten --stream FILE [--states-out FILE]";

#[derive(Debug)]
struct Args {
    stream: String,
    states_out: Option<String>,
}

/// Parses the command line; `Ok(None)` for `--help`.
fn parse_args(mut args: impl Iterator<Item = String>) -> Result<Option<Args>, String> {
    let mut stream = None;
    let mut states_out = None;
    while let Some(arg) = args.next() {
        let (flag, inline) = match arg.split_once('=') {
            Some((f, v)) if f.starts_with("--") => (f.to_string(), Some(v.to_string())),
            _ => (arg, None),
        };
        let slot = match flag.as_str() {
            "-h" | "--help" => return Ok(None),
            "--stream" => &mut stream,
            "--states-out" => &mut states_out,
            _ => return Err(format!("unexpected argument `{flag}`")),
        };
        let value = match inline.or_else(|| args.next()) {
            Some(v) if !v.is_empty() => v,
            _ => return Err(format!("`{flag}` needs a FILE")),
        };
        if slot.replace(value).is_some() {
            return Err(format!("`{flag}` given twice"));
        }
    }
    let stream = stream.ok_or("missing `--stream FILE`")?;
    Ok(Some(Args { stream, states_out }))
}

/// The result of a run: the state changes at rest, `(event index, new state)`.
struct Run {
    changes: Vec<(usize, State)>,
}

/// Processes every event; this is the timed part. Collects a line for every
/// event after which the state at rest differs from the state at rest before
/// it. After a final state the engine resets to the initial state before the
/// next event; the reset itself is no change. Never inlined: it is the one
/// function that `bench/instructions.sh` has callgrind count
/// (`--toggle-collect=*::process_stream`).
#[inline(never)]
fn process_stream(events: &[Event]) -> Result<Run, (usize, CascadeError)> {
    let mut engine = Engine::new();
    // A change per event at most: never regrows inside the loop.
    let mut changes = Vec::with_capacity(events.len());
    let mut before = State::INITIAL;
    for (i, e) in events.iter().enumerate() {
        let now = engine.post(e).map_err(|err| (i, err))?;
        if now != before {
            changes.push((i, now));
        }
        before = if now.is_final() { State::INITIAL } else { now };
    }
    Ok(Run { changes })
}

/// Writes the `INDEX STATE` lines.
fn write_states(path: &str, changes: &[(usize, State)]) -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::BufWriter::new(std::fs::File::create(path)?);
    for (i, s) in changes {
        writeln!(out, "{i} {}", s.name())?;
    }
    out.flush()
}

fn main() -> ExitCode {
    let args = match parse_args(std::env::args().skip(1)) {
        Ok(Some(args)) => args,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(msg) => {
            eprintln!("situ-handwritten: {msg}\n{USAGE}");
            return ExitCode::from(2);
        }
    };

    let text = match std::fs::read(&args.stream) {
        Ok(text) => text,
        Err(err) => {
            eprintln!("situ-handwritten: cannot read the stream {}: {err}", args.stream);
            return ExitCode::from(2);
        }
    };
    let events = match stream::parse(&text) {
        Ok(events) => events,
        Err(err) => {
            eprintln!("situ-handwritten: {}:{}: {}", args.stream, err.line, err.msg);
            return ExitCode::from(2);
        }
    };
    drop(text);

    let start = Instant::now();
    let result = process_stream(&events);
    let seconds = start.elapsed().as_secs_f64();

    let run = match result {
        Ok(run) => run,
        Err((i, err)) => {
            let names: Vec<&str> = err.fired.iter().map(|r| r.name()).collect();
            eprintln!(
                "situ-handwritten: {}:{}: event {i}: more than {MAX_FIRINGS} firings in one rest: {}",
                args.stream,
                events[i].line,
                names.join(", ")
            );
            return ExitCode::FAILURE;
        }
    };

    if let Some(path) = &args.states_out {
        if let Err(err) = write_states(path, &run.changes) {
            eprintln!("situ-handwritten: cannot write the states {path}: {err}");
            return ExitCode::from(2);
        }
    }

    let per_sec = if seconds > 0.0 { (events.len() as f64 / seconds).round() } else { 0.0 };
    println!(
        "{{\"engine\":\"handwritten\",\"events\":{},\"seconds\":{seconds},\"events_per_sec\":{per_sec},\"state_changes\":{}}}",
        events.len(),
        run.changes.len()
    );
    ExitCode::SUCCESS
}

#[cfg(test)]
mod tests;
