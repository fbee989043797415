//! The tests of `situ_runtime::stream` that compile a situ source (moved
//! here so that the runtime does not depend on the compiler).

use situ_bundle::{Content, Value};
use situ_runtime::rete::Engine;
use situ_runtime::stream::*;
use std::sync::Arc;

fn outdoor() -> Arc<Content> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../rules/outdoor.situ");
    let checked = situ_compiler::check(&path, &situ_compiler::loader::FsLoader).expect("readable");
    Arc::new(situ_compiler::bundle::build(&checked))
}

#[test]
fn the_same_seed_gives_the_same_stream() {
    let c = outdoor();
    let a: Vec<Event> = (0..500).map_while(|_| Generator::new(c.clone(), 7).next_event()).collect();
    let mut g1 = Generator::new(c.clone(), 7);
    let mut g2 = Generator::new(c.clone(), 7);
    let mut g3 = Generator::new(c, 8);
    let s1: Vec<Event> = (0..500).filter_map(|_| g1.next_event()).collect();
    let s2: Vec<Event> = (0..500).filter_map(|_| g2.next_event()).collect();
    let s3: Vec<Event> = (0..500).filter_map(|_| g3.next_event()).collect();
    assert_eq!(s1, s2);
    assert_ne!(s1, s3);
    assert_eq!(a.len(), 500);
    assert!(s1.windows(2).all(|w| w[0].time < w[1].time), "time moves forward");
}

#[test]
fn the_text_form_reads_back_exactly() {
    let c = outdoor();
    let mut g = Generator::new(c.clone(), 1);
    let events: Vec<Event> = (0..20_000).filter_map(|_| g.next_event()).collect();
    let mut text = header("outdoor.situ", 1);
    for e in &events {
        write_line(&c, &mut text, e.event, e.time, &e.payload);
    }
    assert_eq!(parse(&c, &text).unwrap(), events);
    // Thresholds are hit exactly, so the boundaries of the rules are exercised.
    let laobs = c.event_id("LAOBS").unwrap();
    let at_threshold = |e: &&Event| [5.0, 20.0, 30.0].iter().any(|&c| e.payload[0] == Value::F64(c));
    let hits = events.iter().filter(|e| e.event == laobs).filter(at_threshold).count();
    assert!(hits > 0, "LAOBS(distance: 5, 20 or 30) never drawn");
}

#[test]
fn a_line_may_say_when_its_event_arrived_and_carry_non_finite_values() {
    let c = outdoor();
    let text = "10 LAOBS NaN inf @5\n20 LAOBS -inf 0.500\n9223372036854775807 LAOBN @30\n";
    let events = parse(&c, text).unwrap();
    assert_eq!(events[0].clock, Some(5));
    assert!(matches!(events[0].payload[0], Value::F64(x) if x.is_nan()));
    assert_eq!(events[0].payload[1], Value::F64(f64::INFINITY));
    assert_eq!((events[1].clock, events[1].payload[0]), (None, Value::F64(f64::NEG_INFINITY)));
    assert_eq!((events[2].time, events[2].clock), (i64::MAX as u64, Some(30)));
    let mut again = String::new();
    for e in &events {
        write_event(&c, &mut again, e);
    }
    assert_eq!(again, text);
}

#[test]
fn bad_lines_say_where_and_why() {
    let c = outdoor();
    let cases = [
        ("x LAOBN", "expected a timestamp"),
        ("18446744073709551616 LAOBN", "expected a timestamp"),
        ("10", "expected an event name"),
        ("10 LAOBN @soon", "`@soon` is not a clock"),
        ("10 LAOBN @5 6", "unexpected `6`"),
    ];
    for (line, want) in cases {
        let e = parse(&c, &format!("# header\n\n{line}\n")).unwrap_err();
        assert_eq!(e.line, 3, "{line}");
        assert!(e.message.contains(want), "{line}: {}", e.message);
    }
}

#[test]
fn an_event_that_does_not_fit_is_read_for_the_acceptance_rule_to_refuse() {
    let c = outdoor();
    let engine = Engine::new(c.clone());
    let cases = [
        ("10 NOPE", "unknown event"),
        ("10 LAOBS 1.0", "payload"),
        ("10 LAOBS 1.0 @20", "payload"),
        ("10 LAOBS 1.0 high", "payload"),
        ("10 LAOBN 3", "payload"),
        ("10 PLF maybe", "payload"),
    ];
    let text: String = cases.iter().map(|(l, _)| format!("{l}\n")).collect();
    let events = parse(&c, &format!("# header\n{text}")).unwrap();
    assert_eq!(events.len(), cases.len());
    for ((line, key), e) in cases.iter().zip(&events) {
        let refused = engine.admit(e.event, e.time, &e.payload).expect_err(line);
        assert_eq!(refused.key(), *key, "{line}: {refused:?}");
    }
    assert_eq!(events[2].clock, Some(20));
    let why = engine.admit(events[3].event, 10, &events[3].payload).unwrap_err().describe(&c);
    assert_eq!(why, "field `LAOBS.height` is f64, the value is not");
    let mut again = String::new();
    write_event(&c, &mut again, &events[4]);
    assert_eq!(again, "10 LAOBN\n", "a value past the fields is not written back");
    assert_eq!(line_of("# h\n\n1 A\n2 B\n", 1), Some(4));
    assert_eq!(line_of("1 A\n", 1), None);
}
