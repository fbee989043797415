//! Arbitrary text that parses without errors: the formatter's output parses
//! to the same AST (spans aside), keeps every comment, and formats to itself
//! (invariant 6; the properties `grammar/tests/roundtrip.rs` checks on the
//! repository's files). Text with syntax errors must not panic either.
#![no_main]

use libfuzzer_sys::fuzz_target;
use serde_json::Value;
use situ_grammar::diag::FileId;
use situ_grammar::{format, parse};

fn is_span(v: &Value) -> bool {
    matches!(v, Value::Object(m) if m.len() == 2 && m.get("start").is_some_and(Value::is_u64) && m.get("end").is_some_and(Value::is_u64))
}

/// As in `grammar/tests/roundtrip.rs`: drops `span` and `*_span` keys and
/// replaces every other span by a marker.
fn strip_spans(v: &mut Value) {
    if is_span(v) {
        *v = Value::String("<span>".into());
        return;
    }
    match v {
        Value::Object(m) => {
            m.retain(|k, _| k != "span" && !k.ends_with("_span"));
            m.values_mut().for_each(strip_spans);
        }
        Value::Array(a) => a.iter_mut().for_each(strip_spans),
        _ => {}
    }
}

fn ast(file: &situ_grammar::ast::File) -> Value {
    let mut v = serde_json::to_value(file).expect("the AST serializes");
    strip_spans(&mut v);
    v
}

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    let parsed = parse(src, FileId(0));
    if !parsed.errors.is_empty() {
        // `fmt` never formats a file with syntax errors (invariant 5).
        assert!(format(src).is_err(), "a file with syntax errors was formatted");
        return;
    }
    let once = format(src).expect("a file that parses formats");
    let reparsed = parse(&once, FileId(0));
    assert!(reparsed.errors.is_empty(), "the formatted text does not parse:\n{once}");
    assert_eq!(ast(&parsed.file), ast(&reparsed.file), "the formatted text has another AST:\n{once}");
    let mut before: Vec<String> = parsed.comments.into_iter().map(|c| c.text).collect();
    let mut after: Vec<String> = reparsed.comments.into_iter().map(|c| c.text).collect();
    before.sort();
    after.sort();
    assert_eq!(before, after, "the formatter lost or changed a comment:\n{once}");
    let twice = format(&once).expect("the formatted text formats");
    assert_eq!(once, twice, "formatting is not idempotent");
});
