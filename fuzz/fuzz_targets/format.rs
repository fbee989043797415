//! Arbitrary text that parses without errors: the formatter's output parses
//! to the same AST (spans aside), keeps every comment, and formats to itself
//! (invariant 6; the properties `grammar/tests/roundtrip.rs` checks on the
//! repository's files). Text with syntax errors must not panic either.
#![no_main]

use libfuzzer_sys::fuzz_target;
use situ_grammar::diag::FileId;
use situ_grammar::ast::shape;
use situ_grammar::{format, parse};

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
    assert_eq!(shape(&parsed.file), shape(&reparsed.file), "the formatted text has another AST:\n{once}");
    let mut before: Vec<String> = parsed.comments.into_iter().map(|c| c.text).collect();
    let mut after: Vec<String> = reparsed.comments.into_iter().map(|c| c.text).collect();
    before.sort();
    after.sort();
    assert_eq!(before, after, "the formatter lost or changed a comment:\n{once}");
    let twice = format(&once).expect("the formatted text formats");
    assert_eq!(once, twice, "formatting is not idempotent");
});
