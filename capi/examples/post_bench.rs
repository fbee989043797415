//! The Rust side of the C API's benchmark (docs/performance.md, "The C
//! API"): the engine's own figure and `situ_api::Board`'s on one stream.
//!
//!   cargo run --release -p situ-capi --example post_bench -- RULES EVENTS SEED STREAM_OUT
//!
//! 1. the engine: `situ_runtime::bench::run` on a seeded stream, what
//!    `situ bench RULES --events EVENTS --seed SEED --stream-out STREAM_OUT`
//!    runs (it writes the stream to STREAM_OUT);
//! 2. `situ_api::Board`: that stream posted by `payload_in_order` and
//!    `post` (the C fast path's calls, without the C layer), the board made
//!    anew (untimed) after a final state as the engine is reset; two
//!    passes, throughput and latency, as `situ bench` makes them.
//!
//! `capi/bench/post_bench.c` reads STREAM_OUT for the C figure. Each
//! prints one line of JSON.

use situ_api::{Arg, Board, Clock, Posted};
use situ_bundle::{Content, FieldType, Value};
use situ_runtime::bench::{self, Options, Source};
use std::io::Write;
use std::sync::Arc;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [rules, events, seed, stream] = args.as_slice() else {
        eprintln!("usage: post_bench RULES EVENTS SEED STREAM_OUT");
        std::process::exit(2);
    };
    let (events, seed): (u64, u64) = (events.parse().expect("EVENTS"), seed.parse().expect("SEED"));
    let program = situ_api::load_path(std::path::Path::new(rules), &situ_api::Trust::Any, false).expect("the rules");
    let content = program.content;

    let mut out = std::io::BufWriter::new(std::fs::File::create(stream).expect("STREAM_OUT"));
    out.write_all(situ_runtime::stream::header(&content.source, seed).as_bytes()).unwrap();
    let report = bench::run(
        content.clone(),
        Options {
            source: Source::Random { events, seed },
            reset_on_final: true,
            stream_out: Some(&mut out),
            states_out: None,
        },
    );
    out.flush().unwrap();
    println!(
        "{{\"path\": \"engine (situ bench)\", \"events\": {}, \"state_changes\": {}, \"events_per_sec\": {:.0}, \
         \"latency_ns\": {{\"p50\": {}, \"p99\": {}}}, \"timer_overhead_ns\": {}}}",
        report.events,
        report.state_changes,
        report.events_per_sec,
        report.latency_ns.p50,
        report.latency_ns.p99,
        report.timer_overhead_ns
    );

    let text = std::fs::read_to_string(stream).unwrap();
    let stream = situ_runtime::stream::parse(&content, &text).expect("the stream reads back");
    let args: Vec<Vec<Arg>> = stream.iter().map(|e| to_args(&content, e.event, &e.payload)).collect();
    board_figures(&content, &stream, &args);
}

/// An event's values as a caller gives them: symbols by name.
fn to_args<'a>(c: &'a Content, event: u32, payload: &[Value]) -> Vec<Arg<'a>> {
    let fields = &c.events[event as usize].fields;
    fields
        .iter()
        .zip(payload)
        .map(|(f, v)| match (v, &f.ty) {
            (Value::F64(x), _) => Arg::F64(*x),
            (Value::I64(x), _) => Arg::I64(*x),
            (Value::Bool(x), _) => Arg::Bool(*x),
            (Value::Symbol(k), FieldType::Symbols(s)) => Arg::Symbol(&s[*k as usize]),
            (Value::Symbol(k), _) => Arg::I64(*k as i64),
        })
        .collect()
}

/// Posts one event; whether the board is now final.
fn post(b: &mut Board, buf: &mut Vec<Value>, e: &situ_runtime::stream::Event, args: &[Arg], changes: &mut u64) -> bool {
    b.payload_in_order(e.event, args, buf).expect("a payload that fits");
    let Ok(Posted::Taken { change: Some(change), .. }) = b.post(e.event, Some(e.time), buf) else { return false };
    *changes += 1;
    b.content().states.iter().any(|s| s.name == change.to && s.is_final)
}

fn board_figures(content: &Arc<Content>, stream: &[situ_runtime::stream::Event], args: &[Vec<Arg>]) {
    let fresh = || Board::new(content.clone(), Clock::Manual);
    let mut buf = Vec::new();
    let (mut b, mut changes, mut timed) = (fresh(), 0u64, 0f64);
    let mut start = Instant::now();
    for (e, a) in stream.iter().zip(args) {
        if post(&mut b, &mut buf, e, a, &mut changes) {
            timed += start.elapsed().as_secs_f64();
            b = fresh();
            start = Instant::now();
        }
    }
    timed += start.elapsed().as_secs_f64();

    let mut lat = Vec::with_capacity(stream.len());
    let mut again = 0;
    b = fresh();
    for (e, a) in stream.iter().zip(args) {
        let t0 = Instant::now();
        let last = post(&mut b, &mut buf, e, a, &mut again);
        lat.push(t0.elapsed().as_nanos() as u64);
        if last {
            b = fresh();
        }
    }
    lat.sort_unstable();
    assert_eq!(changes, again, "both passes reach the same states");
    println!(
        "{{\"path\": \"situ_api::Board\", \"events\": {}, \"state_changes\": {changes}, \"events_per_sec\": {:.0}, \
         \"latency_ns\": {{\"p50\": {}, \"p99\": {}}}}}",
        stream.len(),
        stream.len() as f64 / timed,
        lat[lat.len() / 2],
        lat[lat.len() * 99 / 100]
    );
}
