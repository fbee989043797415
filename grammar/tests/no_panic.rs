//! No input makes the parser or the formatter panic or hang: arbitrary
//! strings, strings of grammar tokens, mutations of valid files, and a few
//! nasty inputs. Whenever a mutated input still parses, the formatter's
//! guarantees are checked on it too.

use proptest::prelude::*;
use serde_json::Value;
use situ_grammar::diag::FileId;
use situ_grammar::{format, parse};
use std::path::Path;
use std::sync::OnceLock;

/// The formatter's own inputs: valid files that cover the whole grammar.
fn seeds() -> &'static [String] {
    static SEEDS: OnceLock<Vec<String>> = OnceLock::new();
    SEEDS.get_or_init(|| {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fmt");
        let mut paths: Vec<_> = std::fs::read_dir(&dir)
            .map(|d| d.flatten().map(|e| e.path()).filter(|p| p.extension().is_some_and(|e| e == "situ")).collect())
            .unwrap_or_default();
        paths.sort();
        let seeds: Vec<String> = paths.iter().filter_map(|p| std::fs::read_to_string(p).ok()).collect();
        assert!(!seeds.is_empty(), "no seed in {}", dir.display());
        seeds
    })
}

/// The AST as JSON, without spans (see `roundtrip.rs`).
fn ast(src: &str) -> Value {
    fn strip(v: &mut Value) {
        let is_span = matches!(v, Value::Object(m) if m.len() == 2 && m.contains_key("start") && m.contains_key("end"));
        if is_span {
            *v = Value::String("<span>".into());
            return;
        }
        match v {
            Value::Object(m) => {
                m.retain(|k, _| k != "span" && !k.ends_with("_span"));
                m.values_mut().for_each(strip);
            }
            Value::Array(a) => a.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = serde_json::to_value(&parse(src, FileId(0)).file).expect("the AST serializes");
    strip(&mut v);
    v
}

/// Parses and formats `src`; when it parses, checks that the formatter keeps
/// its meaning and its comments and is idempotent.
fn exercise(src: &str) -> Result<(), TestCaseError> {
    let parsed = parse(src, FileId(0));
    let formatted = format(src);
    prop_assert_eq!(parsed.errors.is_empty(), formatted.is_ok());
    let Ok(once) = formatted else { return Ok(()) };
    let reparsed = parse(&once, FileId(0));
    prop_assert!(reparsed.errors.is_empty(), "the output does not parse: {:?}\n{}", reparsed.errors[0].message, once);
    prop_assert_eq!(ast(src), ast(&once), "the AST changed:\n{}", once);
    let texts = |cs: Vec<situ_grammar::lex::Comment>| {
        let mut t: Vec<String> = cs.into_iter().map(|c| c.text).collect();
        t.sort();
        t
    };
    prop_assert_eq!(texts(parsed.comments), texts(reparsed.comments));
    let twice = format(&once).expect("the output formats");
    prop_assert_eq!(&once, &twice, "not idempotent");
    Ok(())
}

/// Tokens of the language, valid and invalid in places.
#[rustfmt::skip]
const VOCABULARY: &[&str] = &[
    "states", "agent", "rule", "test", "property", "include", "initial", "final", "sensor", "actuator", "processing",
    "interface", "stale", "after", "event", "function", "table", "fsm", "rate", "when", "then", "salience", "and", "or",
    "not", "in", "state", "within", "run", "sleep", "wait", "from", "to", "on", "given", "expect", "at", "link", "no",
    "always", "never", "next", "eventually", "events", "true", "false", "runs", "running", "sleeping", "waiting", "f64",
    "i64", "bool", "{", "}", "(", ")", "[", "]", "#[allow(W0301)]", "#[", "->", "=>", "==", "!=", "<", "<=", ">", ">=",
    "..", "..=", ",", ":", "_", "?d", "x3", "A", "RS", "LADAR", "LAOBS", "distance", "fuse()", "fuse", "0", "-3", "30.0",
    "1e-7", "-0.5", "NaN", "inf", "-inf", "200ms", "1.5s", "2min", "3us", "5ns", "20Hz", "2.5Hz", "\"desc\"", "\"a \\\" b\"", "\"open",
    "// comment", "//", "// note\n", " // note\n", "\n// note\n", "\n", "\n\n", " ", "\t", "é", "\u{0}",
];

/// A sequence of tokens with random separators.
fn token_soup() -> impl Strategy<Value = String> {
    prop::collection::vec((prop::sample::select(VOCABULARY), prop::sample::select(&[" ", "", "\n"][..])), 0..80)
        .prop_map(|tokens| tokens.into_iter().flat_map(|(t, sep)| [t, sep]).collect())
}

/// One edit of a text, with positions as fractions of its length.
#[derive(Debug, Clone)]
enum Edit {
    Delete(f64, usize),
    Insert(f64, &'static str),
    Duplicate(f64, usize),
    Swap(f64, f64, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    let at = 0.0..1.0f64;
    prop_oneof![
        (at.clone(), 1..40usize).prop_map(|(a, n)| Edit::Delete(a, n)),
        (at.clone(), prop::sample::select(VOCABULARY)).prop_map(|(a, t)| Edit::Insert(a, t)),
        (at.clone(), 1..200usize).prop_map(|(a, n)| Edit::Duplicate(a, n)),
        (at.clone(), at, 1..30usize).prop_map(|(a, b, n)| Edit::Swap(a, b, n)),
    ]
}

/// The char boundary nearest below `fraction` of the text.
fn boundary(s: &str, fraction: f64) -> usize {
    let mut at = ((s.len() as f64) * fraction) as usize;
    at = at.min(s.len());
    while !s.is_char_boundary(at) {
        at -= 1;
    }
    at
}

/// The range of `len` bytes from `at`, shrunk to char boundaries.
fn range(s: &str, at: usize, len: usize) -> std::ops::Range<usize> {
    let mut end = (at + len).min(s.len());
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    at..end.max(at)
}

fn apply(mut s: String, e: &Edit) -> String {
    match *e {
        Edit::Delete(a, n) => {
            let r = range(&s, boundary(&s, a), n);
            s.replace_range(r, "");
        }
        Edit::Insert(a, t) => {
            let at = boundary(&s, a);
            s.insert_str(at, t);
        }
        Edit::Duplicate(a, n) => {
            let r = range(&s, boundary(&s, a), n);
            let copy = s[r.clone()].to_string();
            s.insert_str(r.end, &copy);
        }
        Edit::Swap(a, b, n) => {
            let (a, b) = (boundary(&s, a.min(b)), boundary(&s, a.max(b)));
            let first = range(&s, a, n.min(b - a));
            let second = range(&s, b, n);
            let (x, y) = (s[first.clone()].to_string(), s[second.clone()].to_string());
            s.replace_range(second, &x);
            s.replace_range(first, &y);
        }
    }
    s
}

/// 256 cases each, or `PROPTEST_CASES` for a longer run.
fn config() -> ProptestConfig {
    let mut config = ProptestConfig { failure_persistence: None, ..ProptestConfig::default() };
    if std::env::var_os("PROPTEST_CASES").is_none() {
        config.cases = 256;
    }
    config
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn arbitrary_strings(s in ".*") {
        exercise(&s)?;
    }

    #[test]
    fn token_soups(s in token_soup()) {
        exercise(&s)?;
    }

    #[test]
    fn mutated_valid_files(seed in 0..64usize, edits in prop::collection::vec(edit(), 1..4)) {
        let seeds = seeds();
        let src = edits.iter().fold(seeds[seed % seeds.len()].clone(), apply);
        exercise(&src)?;
    }
}

#[test]
fn the_seeds_are_valid() {
    for s in seeds() {
        exercise(s).unwrap();
    }
}

#[test]
fn nasty_inputs() {
    let cases: Vec<(&str, String)> = vec![
        ("empty", String::new()),
        ("only comments", "// a\n//b\n\n   // c".into()),
        ("10k parentheses", format!("property \"p\" {{ always {} }}", "(".repeat(10_000))),
        ("100k braces", "{".repeat(100_000)),
        ("100k closing braces", "}".repeat(100_000)),
        ("deep nots", format!("property \"p\" {{ always {}A }}", "not ".repeat(20_000))),
        ("long and", format!("rule r {{ when {} then S }}", vec!["A"; 5_000].join(" and "))),
        ("unclosed string", "states { A \"open\n}".into()),
        ("binary", String::from_utf8_lossy(&(0..=255u8).cycle().take(4096).collect::<Vec<_>>()).into_owned()),
    ];
    for (name, src) in &cases {
        let parsed = parse(src, FileId(0));
        let formatted = format(src);
        assert_eq!(parsed.errors.is_empty(), formatted.is_ok(), "{name}");
    }
    assert!(format("").unwrap().is_empty());
    assert!(format(&cases[1].1).is_ok());
    assert!(format(&cases[2].1).is_err());
    assert!(format(&cases[3].1).is_err());
}

/// A 2 MB file of rules, each with a comment, parses and formats: nothing is
/// quadratic in the number of items. (One `format`, which parses once: the
/// dev profile parses about 200 kB per second.)
#[test]
fn a_two_megabyte_file_parses() {
    let rule = "rule r salience 10 \"d\" { when state == RS and LAOBS(distance < 30.0) x3 within 500ms then RO }\n";
    let comment = format!("//{}\n", "-".repeat(rule.len()));
    let unit = format!("{rule}{comment}");
    let count = 2_000_000 / unit.len() + 1;
    let src = unit.repeat(count);
    assert!(src.len() >= 2_000_000);
    let formatted = format(&src).unwrap_or_else(|e| panic!("{}", e[0].message));
    assert_eq!(formatted.matches("rule r salience 10").count(), count);
    assert_eq!(formatted.matches("\n//---").count(), count);
}
