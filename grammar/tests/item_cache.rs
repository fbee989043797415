//! The item cache gives what a fresh parse gives: random edits of the
//! repository's own `.situ` files (`rules/`, `examples/`, `tests/`), each
//! file edited several times in a row, parsed through one cache shared by
//! all files and from scratch, their ASTs (spans included), comments and
//! diagnostics compared.

use proptest::prelude::*;
use situ_grammar::diag::FileId;
use situ_grammar::{parse, ItemCache};
use std::path::Path;
use std::sync::OnceLock;

mod common;
use common::situ_files;

/// The texts of the repository's `.situ` files, those that break included.
fn corpus() -> &'static [String] {
    static CORPUS: OnceLock<Vec<String>> = OnceLock::new();
    CORPUS.get_or_init(|| {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut paths = Vec::new();
        for dir in ["rules", "examples", "tests"] {
            situ_files(&root.join(dir), &mut paths);
        }
        let texts: Vec<String> = paths.iter().filter_map(|p| std::fs::read_to_string(p).ok()).collect();
        assert!(texts.len() > 100, "the corpus is the repository's files: {} found", texts.len());
        texts
    })
}

/// Pieces an edit inserts: item boundaries, braces, a keyword, a name, a
/// comment, a string, a broken token.
const PIECES: &[&str] = &[
    "\n",
    "{",
    "}",
    " ",
    "x",
    "rule ",
    "\nrule r { when E then A }\n",
    "agent ",
    "// note\n",
    "\"",
    "==",
    "1.5s",
    "#[allow(W0301)]\n",
    "\nstates { Z }",
    "é",
];

#[derive(Debug, Clone)]
enum Edit {
    /// At a fraction of the text, insert a piece.
    Insert(f64, usize),
    /// From a fraction of the text, delete up to this many bytes.
    Delete(f64, usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (0.0..1.0f64, 0..PIECES.len()).prop_map(|(at, p)| Edit::Insert(at, p)),
        (0.0..1.0f64, 1..40usize).prop_map(|(at, n)| Edit::Delete(at, n)),
    ]
}

/// The char boundary at or before `at`.
fn boundary(text: &str, mut at: usize) -> usize {
    at = at.min(text.len());
    while !text.is_char_boundary(at) {
        at -= 1;
    }
    at
}

fn apply(text: &mut String, edit: &Edit) {
    match *edit {
        Edit::Insert(at, piece) => {
            let at = boundary(text, (at * text.len() as f64) as usize);
            text.insert_str(at, PIECES[piece]);
        }
        Edit::Delete(at, n) => {
            let start = boundary(text, (at * text.len() as f64) as usize);
            let end = boundary(text, start + n);
            text.replace_range(start..end, "");
        }
    }
}

/// An AST as text: `NaN` literals are unequal to themselves, their text is not.
fn debug(file: &situ_grammar::ast::File) -> String {
    format!("{file:?}")
}

fn assert_same(cache: &mut ItemCache, text: &str, file: FileId) -> Result<(), TestCaseError> {
    let cached = cache.parse(text, file);
    let fresh = parse(text, file);
    prop_assert_eq!(debug(&cached.file), debug(&fresh.file), "the ASTs differ on {:?}", text);
    prop_assert_eq!(&cached.errors, &fresh.errors, "the diagnostics differ on {:?}", text);
    prop_assert_eq!(&cached.comments, &fresh.comments);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn cached_parses_of_edited_files_are_fresh_parses(
        files in prop::collection::vec((any::<prop::sample::Index>(), prop::collection::vec(edit(), 1..6)), 1..4),
    ) {
        let corpus = corpus();
        let mut cache = ItemCache::new();
        for (n, (index, edits)) in files.iter().enumerate() {
            let file = FileId(n as u32);
            let mut text = corpus[index.index(corpus.len())].clone();
            assert_same(&mut cache, &text, file)?;
            for e in edits {
                apply(&mut text, e);
                assert_same(&mut cache, &text, file)?;
            }
            cache.end_round();
        }
    }
}

/// Every file of the corpus, parsed through one cache after another file (so
/// that items shared between files move), is its fresh parse.
#[test]
fn every_file_of_the_corpus_parses_the_same_through_the_cache() {
    let mut cache = ItemCache::new();
    for (n, text) in corpus().iter().enumerate() {
        let file = FileId(n as u32 % 7);
        let cached = cache.parse(text, file);
        let fresh = parse(text, file);
        assert_eq!(debug(&cached.file), debug(&fresh.file), "{text}");
        assert_eq!(cached.errors, fresh.errors, "{text}");
        // The same text shifted by a blank line: every item moves.
        let moved = format!("\n{text}");
        let cached = cache.parse(&moved, file);
        let fresh = parse(&moved, file);
        assert_eq!(debug(&cached.file), debug(&fresh.file), "{text}");
        assert_eq!(cached.errors, fresh.errors, "{text}");
    }
}
