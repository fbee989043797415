//! Layout never changes meaning: every `.situ` file of the repository, its
//! lines re-indented by random amounts of spaces and tabs (so that its items
//! start at any column), parses to the same AST (spans aside), with the same
//! comments and the same diagnostics (columns aside), and formats to the same
//! canonical text.
//!
//! `PROPTEST_CASES=N cargo test -p situ-grammar --test layout` for a longer run.

use proptest::prelude::*;
use serde_json::Value;
use situ_grammar::diag::FileId;
use situ_grammar::{format, parse};
use std::path::Path;
use std::sync::OnceLock;

mod common;
use common::situ_files;

/// The repository's `.situ` files that are UTF-8, as (name, text): the valid
/// ones and the deliberately broken ones (UI inputs) alike.
fn corpus() -> &'static [(String, String)] {
    static CORPUS: OnceLock<Vec<(String, String)>> = OnceLock::new();
    CORPUS.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut paths = Vec::new();
        situ_files(&root, &mut paths);
        paths
            .into_iter()
            .filter_map(|p| {
                let text = String::from_utf8(std::fs::read(&p).ok()?).ok()?;
                Some((p.strip_prefix(&root).unwrap_or(&p).display().to_string(), text))
            })
            .collect()
    })
}

/// A small deterministic generator (xorshift64*), so that a seed names a layout.
struct Rng(u64);

impl Rng {
    fn below(&mut self, n: u64) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D) % n
    }
}

/// `src` with the indentation of every line replaced by a random run of
/// spaces and tabs (none, sometimes). Strings and tokens never span lines, so
/// only the layout changes.
fn reindent(src: &str, seed: u64) -> String {
    let mut rng = Rng(seed | 1);
    let mut out = String::with_capacity(src.len() * 2);
    for line in src.split_inclusive('\n') {
        let body = line.trim_start_matches([' ', '\t']);
        let width = match rng.below(4) {
            0 => 0,
            _ => rng.below(13),
        };
        for _ in 0..width {
            out.push(if rng.below(3) == 0 { '\t' } else { ' ' });
        }
        out.push_str(body);
    }
    out
}

/// The 1-based line of a byte offset.
fn line(src: &str, at: usize) -> usize {
    src[..at.min(src.len())].matches('\n').count() + 1
}

/// What a parse means, layout aside: the AST without spans, the comments,
/// and each diagnostic's code, message, help, fix titles and labels with the
/// lines (not the columns) they point at.
fn meaning(src: &str) -> (Value, Vec<String>, Vec<String>) {
    let parsed = parse(src, FileId(0));
    let ast = situ_grammar::ast::shape(&parsed.file);
    let comments = parsed.comments.iter().map(|c| format!("{}: {}", line(src, c.span.start), c.text)).collect();
    let diagnostics = parsed
        .errors
        .iter()
        .map(|d| {
            let labels: Vec<String> = std::iter::once(&d.primary)
                .chain(&d.secondary)
                .map(|l| format!("{}-{} {}", line(src, l.span.start), line(src, l.span.end), l.text))
                .collect();
            let fixes: Vec<&str> = d.fixes.iter().map(|f| f.title.as_str()).collect();
            format!("{} {} | help: {:?} | labels: {labels:?} | fixes: {fixes:?}", d.code, d.message, d.help)
        })
        .collect();
    (ast, comments, diagnostics)
}

/// Checks one file under one layout; describes the first difference.
fn same_meaning(name: &str, src: &str, seed: u64) -> Result<(), String> {
    let moved = reindent(src, seed);
    let (before, after) = (meaning(src), meaning(&moved));
    let context = || format!("{name}, re-indented with seed {seed}:\n{moved}");
    if before.2 != after.2 {
        return Err(format!("other diagnostics: {:#?}\nvs {:#?}\nin {}", before.2, after.2, context()));
    }
    if before.0 != after.0 {
        return Err(format!("another AST in {}", context()));
    }
    if before.1 != after.1 {
        return Err(format!("other comments: {:?} vs {:?} in {}", before.1, after.1, context()));
    }
    if before.2.is_empty() {
        let (canonical, formatted) = (format(src), format(&moved));
        if canonical.as_ref().ok() != formatted.as_ref().ok() {
            return Err(format!("another formatted text in {}", context()));
        }
    }
    Ok(())
}

#[test]
fn every_file_means_the_same_at_any_indentation() {
    let corpus = corpus();
    assert!(corpus.len() > 100, "too few .situ files: {}", corpus.len());
    let failures: Vec<String> = corpus
        .iter()
        .enumerate()
        .flat_map(|(i, (name, text))| (0..3).map(move |k| same_meaning(name, text, (i * 3 + k) as u64 + 1)))
        .filter_map(Result::err)
        .collect();
    assert!(failures.is_empty(), "{} failures; the first:\n{}", failures.len(), failures[0]);
}

#[test]
fn an_indented_test_after_an_include_is_an_item() {
    // What `situ test` prints for a counterexample, pasted after an include.
    let src = "include \"drone.situ\"\n    test \"counterexample\" {\n        given state Hover\n        on GPFIX\n        expect state Hover\n    }\n";
    let parsed = parse(src, FileId(0));
    assert_eq!(parsed.errors.iter().map(|d| d.message.as_str()).collect::<Vec<_>>(), Vec::<&str>::new());
    assert_eq!(parsed.file.items.len(), 2);
    assert_eq!(
        format(src).expect("it formats"),
        "include \"drone.situ\"\n\ntest \"counterexample\" {\n    given state Hover\n    on GPFIX\n    expect state Hover\n}\n"
    );
}

/// 256 cases, or `PROPTEST_CASES`.
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
    fn any_file_at_any_indentation(file in any::<prop::sample::Index>(), seed in any::<u64>()) {
        let corpus = corpus();
        let (name, text) = &corpus[file.index(corpus.len())];
        if let Err(e) = same_meaning(name, text, seed) {
            prop_assert!(false, "{}", e);
        }
    }
}
