//! The checker never panics: not on arbitrary text, not on mutations of the
//! real rule files and UI inputs.

use proptest::prelude::*;
use situ_compiler::check_source;

/// The real inputs of the project, as seeds for mutation.
fn seeds() -> Vec<String> {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let mut out = Vec::new();
    for dir in ["rules", "tests/ui"] {
        let Ok(entries) = std::fs::read_dir(format!("{root}/{dir}")) else { continue };
        for e in entries.flatten() {
            if e.path().extension().is_some_and(|x| x == "situ") {
                if let Ok(text) = std::fs::read_to_string(e.path()) {
                    out.push(text);
                }
            }
        }
    }
    out.sort();
    out.push("states { IT initial RD }\nagent A sensor { stale after 1s event E { d: f64, s: {l, r} } }\nrule r { when state == IT and E(d: ?x, s == l) and not E(d > ?x) then RD }".into());
    out
}

/// Tokens of the language, so that random text looks like situ often enough
/// to reach the resolver.
const TOKENS: &[&str] = &[
    "states",
    "{",
    "}",
    "IT",
    "initial",
    "final",
    "RD",
    "agent",
    "A",
    "B",
    "sensor",
    "processing",
    "event",
    "E",
    "F",
    "(",
    ")",
    "d",
    ":",
    "f64",
    "i64",
    "bool",
    ",",
    "rule",
    "r",
    "when",
    "then",
    "and",
    "not",
    "state",
    "==",
    "in",
    "?x",
    "<",
    "1.0",
    "2",
    "x3",
    "within",
    "200ms",
    "stale",
    "after",
    "table",
    "=>",
    "run",
    "f",
    "from",
    "to",
    "_",
    "sleep",
    "wait",
    "fsm",
    "->",
    "on",
    "test",
    "\"t\"",
    "given",
    "expect",
    "property",
    "always",
    "never",
    "next",
    "eventually",
    "events",
    "function",
    "running",
    "link",
    "#[allow(W0301)]",
    "\n",
    "// c\n",
    "include \"x.situ\"",
];

fn token_soup() -> impl Strategy<Value = String> {
    prop::collection::vec(prop::sample::select(TOKENS), 0..80).prop_map(|t| t.join(" "))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_text(text in ".{0,400}") {
        let _ = check_source("fuzz.situ", &text);
    }

    #[test]
    fn token_soup_never_panics(text in token_soup()) {
        let _ = check_source("soup.situ", &text);
    }

    #[test]
    fn mutated_real_files(seed in any::<prop::sample::Index>(), cuts in prop::collection::vec((any::<prop::sample::Index>(), any::<prop::sample::Index>(), 0u8..3), 1..6)) {
        let seeds = seeds();
        let mut text: Vec<char> = seed.get(&seeds).chars().collect();
        for (a, b, op) in cuts {
            if text.is_empty() { break; }
            let (i, j) = (a.index(text.len()), b.index(text.len()));
            let (lo, hi) = (i.min(j), i.max(j));
            match op {
                0 => { text.drain(lo..hi); }
                1 => { let dup: Vec<char> = text[lo..hi].to_vec(); text.splice(lo..lo, dup); }
                _ => { text.swap(lo, hi); }
            }
        }
        let text: String = text.into_iter().collect();
        let _ = check_source("mutated.situ", &text);
    }
}
