//! Parses arbitrary bytes; when they parse, formats them and checks that the
//! result formats to itself and parses without errors.
#![no_main]

use libfuzzer_sys::fuzz_target;
use situ_grammar::diag::FileId;

fuzz_target!(|data: &[u8]| {
    let Ok(src) = std::str::from_utf8(data) else { return };
    let parsed = situ_grammar::parse(src, FileId(0));
    if !parsed.errors.is_empty() {
        return;
    }
    let once = situ_grammar::format(src).expect("a file that parses formats");
    let reparsed = situ_grammar::parse(&once, FileId(0));
    assert!(reparsed.errors.is_empty(), "the formatted text does not parse:\n{once}");
    let twice = situ_grammar::format(&once).expect("the formatted text formats");
    assert_eq!(once, twice, "formatting is not idempotent");
});
