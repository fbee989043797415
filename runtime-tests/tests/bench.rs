//! The tests of `situ_runtime::bench` that compile a situ source (moved
//! here so that the runtime does not depend on the compiler).

use situ_runtime::bench::*;
use situ_runtime::stream;
use std::sync::Arc;

#[test]
fn a_bench_run_reports_what_it_did_and_writes_matching_files() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
    let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap();
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    let (mut stream_text, mut states_text) = (Vec::new(), Vec::new());
    let report = run(
        content.clone(),
        Options {
            source: Source::Random { events: 20_000, seed: 3 },
            reset_on_final: true,
            stream_out: Some(&mut stream_text),
            states_out: Some(&mut states_text),
        },
    );
    assert_eq!(report.events, 20_000);
    assert!(report.state_changes > 10 && report.missions > 0, "{report:?}");
    let states = String::from_utf8(states_text).unwrap();
    assert_eq!(states.lines().count() as u64, report.state_changes);
    // The written stream, read back and run again, gives the same states.
    let events = stream::parse(&content, &String::from_utf8(stream_text).unwrap()).unwrap();
    assert_eq!(events.len(), 20_000);
    let mut again = Vec::new();
    let replay = run(
        content,
        Options { source: Source::File(&events), reset_on_final: true, stream_out: None, states_out: Some(&mut again) },
    );
    assert_eq!(String::from_utf8(again).unwrap(), states);
    assert_eq!(replay.state_changes, report.state_changes);
}

#[test]
fn a_stream_goes_on_past_the_events_it_refuses_and_counts_them_by_reason() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
    let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).unwrap();
    let content = Arc::new(situ_compiler::bundle::build(&checked));
    // Two events that do not fit, one out of order, one from the future,
    // one unknown: refused and counted; the rest is run.
    let text = "10000000 LAOBS 12.0\n20000000 LAOBS 12.0 0.5\n30000000 LAOBS near 0.5\n\
        5000000 LAOBS 12.0 0.5\n900000000 LAOBN @40000000\n50000000 NOPE\n60000000 LAOBS 12.0 0.5\n";
    let events = stream::parse(&content, text).unwrap();
    let mut states = Vec::new();
    let report = run(
        content,
        Options {
            source: Source::File(&events),
            reset_on_final: true,
            stream_out: None,
            states_out: Some(&mut states),
        },
    );
    assert_eq!(report.events, 7);
    assert_eq!(report.refused, 5, "{report:?}");
    let by: Vec<(&str, u64)> = report.refused_by_reason.iter().map(|(k, n)| (k.as_str(), *n)).collect();
    assert_eq!(by, [("from the future", 1), ("out of order", 1), ("payload", 2), ("unknown event", 1)]);
    let first = &report.first_refused["payload"];
    assert_eq!((first.index, first.reason.as_str()), (0, "event `LAOBS` has 2 payload field(s), 1 given"));
    assert_eq!(report.first_refused["out of order"].index, 3);
    let summary = report.refusals(|i| format!("event {i}"));
    assert_eq!(summary.len(), 5, "{summary:?}");
    assert!(summary[0].starts_with("5 of 7 events refused"), "{summary:?}");
    assert_eq!(summary[3], "  payload: 2, the first at event 0: event `LAOBS` has 2 payload field(s), 1 given");
}
