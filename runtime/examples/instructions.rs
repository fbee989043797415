//! The engine's processing loop alone, for counting its instructions
//! (`bench/instructions.sh`, docs/performance.md):
//!
//! ```text
//! cargo build --release -p situ-runtime --example instructions
//! target/release/examples/instructions BUNDLE STREAM [STATES_OUT]
//! ```
//!
//! Loads a bundle and reads a `.events` stream before anything is counted;
//! then [`process_stream`], the one function that callgrind counts
//! (`--toggle-collect=*::process_stream`), steps every event as `situ bench`
//! does (the event's clock set, `Engine::step`, the state at rest compared,
//! a mission reset in a final state) on the engine's fast path, or on the
//! Rete interpreter with `INTERPRETED=1` in the environment, or on the
//! native code of `rules/outdoor.situ` with `NATIVE=1` (both of which
//! `bench/instructions.sh` passes on). Writes the `INDEX STATE` lines of
//! `situ bench --states-out` to STATES_OUT, so that the script checks the
//! state sequence against the hand-written matcher's.

// The native code of `rules/outdoor.situ` (`situ build --native`), held
// to the interpreter by `runtime-tests/tests/native.rs`.
#[rustfmt::skip]
#[path = "../../runtime-tests/native/outdoor.rs"]
mod outdoor_native;

use situ_runtime::rete::Engine;
use situ_runtime::stream::{self, Event};
use std::io::Write;
use std::process::ExitCode;
use std::sync::Arc;

/// The events of the stream, flat: `(event, time, clock, payload start, end)`
/// and the payloads in one arena, as `situ bench`'s chunks hold them.
struct Flat {
    events: Vec<(u32, u64, Option<u64>, u32, u32)>,
    values: Vec<situ_bundle::Value>,
}

/// `process_stream` and `process_stream_native`: every event through the
/// engine, as `situ bench`'s timed loop, each step `$step`; returns the
/// refused events and collects the state changes `(index, state)` into
/// `changes` (reserved beforehand: it does not grow here). Two functions
/// with one body, so that each is compiled alone (a generic one is not
/// inlined as a plain one is). Never inlined: callgrind counts these
/// functions and what they call, nothing else.
macro_rules! process {
    ($name:ident, |$engine:ident, $event:ident, $time:ident, $payload:ident| $step:expr) => {
        #[inline(never)]
        fn $name($engine: &mut Engine, flat: &Flat, changes: &mut Vec<(u64, u32)>) -> u64 {
            let mut refused = 0;
            let mut at_rest = $engine.state();
            for (i, &($event, $time, clock, s, e)) in flat.events.iter().enumerate() {
                $engine.set_clock(clock);
                let $payload = &flat.values[s as usize..e as usize];
                if $step.is_err() {
                    refused += 1;
                }
                let state = $engine.state();
                if state != at_rest {
                    changes.push((i as u64, state));
                    at_rest = state;
                }
                if $engine.reset_if_final() {
                    at_rest = $engine.state();
                }
            }
            refused
        }
    };
}

process!(process_stream, |engine, event, time, payload| engine.step(event, time, payload));
// Native code's step as a program that links the module calls it: its
// `step`, inlined, which checks that the engine runs the module.
process!(process_stream_native, |engine, event, time, payload| outdoor_native::step(engine, event, time, payload));

fn main() -> ExitCode {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 || args.len() > 3 {
        eprintln!("usage: instructions BUNDLE STREAM [STATES_OUT]");
        return ExitCode::from(2);
    }
    let content = match std::fs::read(&args[0]).map(|b| situ_bundle::codec::decode(&b)) {
        Ok(Ok(c)) => Arc::new(c),
        Ok(Err(e)) => {
            eprintln!("instructions: {}: {e}", args[0]);
            return ExitCode::from(2);
        }
        Err(e) => {
            eprintln!("instructions: cannot read {}: {e}", args[0]);
            return ExitCode::from(2);
        }
    };
    let events: Vec<Event> = match std::fs::read_to_string(&args[1]).map(|t| stream::parse(&content, &t)) {
        Ok(Ok(events)) => events,
        Ok(Err(e)) => {
            eprintln!("instructions: {}: {e}", args[1]);
            return ExitCode::from(2);
        }
        Err(e) => {
            eprintln!("instructions: cannot read {}: {e}", args[1]);
            return ExitCode::from(2);
        }
    };
    let mut flat = Flat { events: Vec::with_capacity(events.len()), values: Vec::new() };
    for e in &events {
        let s = flat.values.len() as u32;
        flat.values.extend_from_slice(&e.payload);
        flat.events.push((e.event, e.time, e.clock, s, flat.values.len() as u32));
    }
    drop(events);

    // `INTERPRETED=1`: the Rete interpreter, the fast path's reference.
    // `NATIVE=1`: the native code of `rules/outdoor.situ`, which refuses
    // any other bundle.
    let flag = |name: &str| std::env::var_os(name).is_some_and(|v| v == "1");
    let mut engine = if flag("INTERPRETED") {
        Engine::interpreted(content.clone())
    } else if flag("NATIVE") {
        match Engine::with_native(content.clone(), &outdoor_native::NATIVE) {
            Ok(engine) => engine,
            Err(e) => {
                eprintln!("instructions: {e}");
                return ExitCode::from(2);
            }
        }
    } else {
        Engine::new(content.clone())
    };
    let mut changes = Vec::with_capacity(flat.events.len());
    // Native code's step is called as a program that links it calls it
    // (inlined: `outdoor_native::step`, which checks that the engine
    // runs it); the others through `Engine::step`.
    let start = std::time::Instant::now();
    let refused = if engine.is_native() {
        process_stream_native(&mut engine, &flat, &mut changes)
    } else {
        process_stream(&mut engine, &flat, &mut changes)
    };
    let seconds = start.elapsed().as_secs_f64();

    if let Some(path) = args.get(2) {
        let mut text = String::new();
        for (i, s) in &changes {
            text.push_str(&format!("{i} {}\n", content.states[*s as usize].name));
        }
        if let Err(e) = std::fs::File::create(path).and_then(|mut f| f.write_all(text.as_bytes())) {
            eprintln!("instructions: cannot write {path}: {e}");
            return ExitCode::from(2);
        }
    }
    // The loop's wall-clock time (`bench/vs-clips.sh` reads it for native
    // code); meaningless under callgrind.
    let per_sec = if seconds > 0.0 { (flat.events.len() as f64 / seconds).round() } else { 0.0 };
    println!(
        "{{\"engine\":\"situ\",\"native\":{},\"events\":{},\"state_changes\":{},\"refused\":{refused},\"seconds\":{seconds},\"events_per_sec\":{per_sec}}}",
        engine.is_native(),
        flat.events.len(),
        changes.len()
    );
    ExitCode::SUCCESS
}
