//! The parser's speed on a large realistic file: `cargo bench -p situ-grammar --bench parse`.
//!
//! The file is the repository's `rules/*.situ`, copied with every name renamed
//! (`Fusion` → `Fusion_3`) until it reaches about 1.7 MB; `SITU_BENCH_FILE=path`
//! times that file instead. Prints the best of several runs of the parse, of
//! the formatter (parse and print), of the item splitter alone, and of a
//! parse of the same items with a syntax error in each (the error path).

use situ_grammar::diag::FileId;
use std::time::{Duration, Instant};

const SOURCES: &[&str] = &[
    include_str!("../../rules/dla.situ"),
    include_str!("../../rules/outdoor.situ"),
    include_str!("../../rules/ugv-merge.situ"),
    include_str!("../../rules/ugv.situ"),
];

/// Words kept as they are when renaming: keywords, contextual words, units.
fn kept(word: &str) -> bool {
    situ_grammar::parse::KEYWORDS.contains(&word)
        || matches!(
            word,
            "script" | "every" | "silent" | "random" | "seed" | "commands" | "allow" | "NaN" | "inf" | "situ" | "_"
        )
        || word.len() > 1 && word.starts_with('x') && word[1..].bytes().all(|b| b.is_ascii_digit())
        || word.len() == 5 && word.as_bytes()[0].is_ascii_uppercase() && word[1..].bytes().all(|b| b.is_ascii_digit())
}

/// `src` with every name outside strings suffixed `_k`.
fn renamed(src: &str, k: usize) -> String {
    let mut out = String::with_capacity(src.len() + src.len() / 4);
    let b = src.as_bytes();
    let mut i = 0;
    let mut in_string = false;
    while i < b.len() {
        let c = b[i];
        if in_string {
            out.push(c as char);
            if c == b'\\' && i + 1 < b.len() {
                out.push(b[i + 1] as char);
                i += 1;
            } else if c == b'"' || c == b'\n' {
                in_string = false;
            }
            i += 1;
        } else if c == b'"' {
            in_string = true;
            out.push('"');
            i += 1;
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'_') {
                i += 1;
            }
            let word = &src[start..i];
            out.push_str(word);
            if !kept(word) {
                out.push('_');
                out.push_str(&k.to_string());
            }
        } else if c.is_ascii_digit() {
            // A number and its unit (`200ms`, `x3` is handled as a word).
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'.') {
                i += 1;
            }
            out.push_str(&src[start_of_number(src, i)..i]);
        } else {
            let ch = src[i..].chars().next().unwrap();
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

fn start_of_number(src: &str, end: usize) -> usize {
    let b = src.as_bytes();
    let mut s = end;
    while s > 0 && (b[s - 1].is_ascii_alphanumeric() || b[s - 1] == b'.') {
        s -= 1;
    }
    s
}

fn large_file(target: usize) -> String {
    let mut out = String::new();
    let mut k = 0;
    while out.len() < target {
        for src in SOURCES {
            out.push_str(&renamed(src, k));
            out.push('\n');
        }
        k += 1;
    }
    out
}

fn best<T>(runs: usize, mut f: impl FnMut() -> T) -> Duration {
    let mut best = Duration::MAX;
    for _ in 0..runs {
        let t = Instant::now();
        std::hint::black_box(f());
        best = best.min(t.elapsed());
    }
    best
}

fn report(what: &str, bytes: usize, d: Duration) {
    let mbs = bytes as f64 / d.as_secs_f64() / 1e6;
    println!("{what:<28} {:>9.1} ms  {mbs:>6.2} MB/s", d.as_secs_f64() * 1e3);
}

fn main() {
    // `cargo bench` passes `--bench`; a filter or other flags are ignored.
    let src = match std::env::var("SITU_BENCH_FILE") {
        Ok(path) => std::fs::read_to_string(&path).expect("SITU_BENCH_FILE"),
        Err(_) => large_file(1_700_000),
    };
    let runs: usize = std::env::var("SITU_BENCH_RUNS").ok().and_then(|s| s.parse().ok()).unwrap_or(5);
    let parsed = situ_grammar::parse(&src, FileId(0));
    println!("{} bytes, {} items, {} syntax errors", src.len(), parsed.file.items.len(), parsed.errors.len());
    report("parse", src.len(), best(runs, || situ_grammar::parse(&src, FileId(0))));
    report("format", src.len(), best(runs, || situ_grammar::format(&src)));
    // The item splitter alone (part of the parse).
    report("split items", src.len(), best(runs * 4, || situ_grammar::lex::split_items(&src)));
    // The error path: the first 40 items, each with a mistake after its
    // first `{` (the parse stops reporting after 50 errors per file).
    let spans = situ_grammar::lex::split_items(&src);
    let mut broken = Vec::new();
    for s in spans.iter().take(40) {
        let item = &src[s.start..s.end];
        let item = item.replacen('{', "{ ) ", 1);
        broken.push(item);
    }
    let bytes: usize = broken.iter().map(|b| b.len()).sum();
    report(
        "parse, 40 broken items",
        bytes,
        best(runs * 4, || broken.iter().map(|b| situ_grammar::parse(b, FileId(0)).errors.len()).sum::<usize>()),
    );
}
