//! The journal's cost per event: `cargo run --release -p situ-runtime
//! --example journal_bench -- [DIR]` appends events of two f64 fields to a
//! journal in DIR (default: the system's temporary directory), one
//! `write(2)` per flush, and prints the time per event for flushes of 1
//! and of 16 events, without and with an `fdatasync` per flush (a change
//! broadcast after each), then the time to open (recover) the file.
//! With a second argument N, only N events in flushes of 1 without a sync
//! (for `valgrind --tool=callgrind`: the difference of two Ns' counts is the
//! cost of the events).

use situ_bundle::Value;
use situ_runtime::bus::EventMsg;
use situ_runtime::journal::Journal;
use situ_runtime::standby::{Entry, LogOut};
use std::time::Instant;

const SHA: &str = "0000000000000000000000000000000000000000000000000000000000000000";

fn event(i: u64) -> Entry {
    let payload = vec![Value::F64(i as f64 * 0.5), Value::F64(1.0)];
    Entry::Event {
        msg: EventMsg { agent: (i % 5) as u32, event: 1, time: i * 1000, payload, urgent: false },
        accepted: true,
    }
}

fn main() {
    let dir = std::env::args().nth(1).map(std::path::PathBuf::from).unwrap_or_else(std::env::temp_dir);
    let path = dir.join(format!("journal_bench.{}", std::process::id()));
    let runs = match std::env::args().nth(2).and_then(|n| n.parse().ok()) {
        Some(n) => vec![(1, false, n)],
        None => vec![(1, false, 200_000u64), (16, false, 200_000), (1, true, 2_000), (16, true, 16_000)],
    };
    for (batch, sync, n) in runs {
        let _ = std::fs::remove_file(&path);
        let (mut j, _) = Journal::open_for(&path, SHA).expect("open");
        let mut entries = Vec::with_capacity(batch);
        let start = Instant::now();
        for i in 0..n {
            entries.push(event(i));
            if entries.len() == batch {
                j.write(&mut entries, sync);
            }
        }
        let per = start.elapsed().as_nanos() as f64 / n as f64;
        let bytes = j.len();
        drop(j);
        let start = Instant::now();
        let (_, r) = Journal::open_for(&path, SHA).expect("reopen");
        let open = start.elapsed().as_nanos() as f64 / n as f64;
        assert_eq!(r.entries.len() as u64, n);
        println!(
            "flush of {batch:>2}, fdatasync {:<3}: {per:>8.0} ns/event ({:.1} bytes/event); recovery {open:.0} ns/event",
            if sync { "yes" } else { "no" },
            bytes as f64 / n as f64
        );
    }
    let _ = std::fs::remove_file(&path);
}
