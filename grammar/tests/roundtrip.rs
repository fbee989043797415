//! The formatter keeps meaning and is a fixed point, on every `.situ` file of
//! the repository (`rules/`, `tests/ui/`) and on the formatter's own inputs
//! (`grammar/tests/fmt/`); and the golden outputs of `grammar/tests/fmt/`.
//!
//! Run with `SITU_BLESS=1` to rewrite the `*.expected.situ` files.

use serde_json::Value;
use situ_grammar::diag::FileId;
use situ_grammar::{format, parse};
use std::path::{Path, PathBuf};

mod common;

/// Every `.situ` file under `dir`, recursively, sorted; none if it is missing.
fn situ_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    common::situ_files(dir, &mut out);
    out
}

/// The folders whose `.situ` files are checked; any may be missing.
fn roots() -> Vec<PathBuf> {
    let manifest = Path::new(env!("CARGO_MANIFEST_DIR"));
    vec![manifest.join("../rules"), manifest.join("../tests/ui"), manifest.join("tests/fmt")]
}

/// The AST of a source, as JSON without spans.
fn ast(src: &str) -> Value {
    situ_grammar::ast::shape(&parse(src, FileId(0)).file)
}

/// The comment texts of a source, sorted.
fn comment_texts(src: &str) -> Vec<String> {
    let mut texts: Vec<String> = parse(src, FileId(0)).comments.into_iter().map(|c| c.text).collect();
    texts.sort();
    texts
}

/// Checks one valid source; returns a description of each failure.
fn check(name: &str, src: &str) -> Vec<String> {
    let mut failures = Vec::new();
    let once = match format(src) {
        Ok(f) => f,
        Err(e) => return vec![format!("{name}: does not format: {}", e[0].message)],
    };
    let reparsed = parse(&once, FileId(0));
    if let Some(e) = reparsed.errors.first() {
        failures.push(format!("{name}: the output does not parse: {} at {:?}\n{once}", e.message, e.primary.span));
        return failures;
    }
    if ast(src) != ast(&once) {
        failures.push(format!("{name}: the output has another AST\n{once}"));
    }
    if comment_texts(src) != comment_texts(&once) {
        failures.push(format!("{name}: comments differ: {:?} vs {:?}", comment_texts(src), comment_texts(&once)));
    }
    match format(&once) {
        Ok(twice) if twice == once => {}
        Ok(twice) => failures.push(format!("{name}: not idempotent\n--- once\n{once}--- twice\n{twice}")),
        Err(_) => failures.push(format!("{name}: the output does not format")),
    }
    failures
}

#[test]
fn formatting_keeps_the_ast_and_the_comments_and_is_idempotent() {
    let (mut checked, mut skipped) = (0, 0);
    let mut failures = Vec::new();
    for root in roots() {
        for path in situ_files(&root) {
            let bytes = std::fs::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            // UI inputs may be deliberately broken: not UTF-8, or not parsing.
            let Ok(src) = String::from_utf8(bytes) else {
                skipped += 1;
                continue;
            };
            if !parse(&src, FileId(0)).errors.is_empty() {
                skipped += 1;
                continue;
            }
            checked += 1;
            failures.extend(check(&path.display().to_string(), &src));
        }
    }
    eprintln!("roundtrip: {checked} files checked, {skipped} broken (not UTF-8 or syntax errors) skipped");
    assert!(checked + skipped > 0, "no .situ file found under {:?}", roots());
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn golden_outputs() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fmt");
    let bless = std::env::var("SITU_BLESS").is_ok_and(|v| v == "1");
    let mut failures = Vec::new();
    let mut count = 0;
    for input in situ_files(&dir) {
        let name = input.file_name().unwrap().to_string_lossy().into_owned();
        let Some(stem) = name.strip_suffix(".situ").filter(|s| !s.ends_with(".expected")) else { continue };
        count += 1;
        let src = std::fs::read_to_string(&input).unwrap();
        let out = format(&src).unwrap_or_else(|e| panic!("{name} does not format: {}", e[0].message));
        if out == src {
            failures.push(format!("{name}: the input is already formatted; make it untidy"));
        }
        let expected_path = dir.join(format!("{stem}.expected.situ"));
        if bless {
            std::fs::write(&expected_path, &out).unwrap();
            continue;
        }
        match std::fs::read_to_string(&expected_path) {
            Ok(expected) if expected == out => {}
            Ok(expected) => failures
                .push(format!("{name}: differs from {stem}.expected.situ\n--- expected\n{expected}--- got\n{out}")),
            Err(_) => failures.push(format!("{name}: no {stem}.expected.situ; run with SITU_BLESS=1")),
        }
    }
    assert!(count > 0, "no golden input in {}", dir.display());
    assert!(failures.is_empty(), "{}", failures.join("\n\n"));
}

#[test]
fn broken_files_are_not_formatted() {
    assert!(format("rule r { when A then }").is_err());
    assert!(format("agent A sensor { event }\nrule r { when A then S }").is_err());
}

#[test]
fn empty_and_comment_only_files() {
    assert_eq!(format("").unwrap(), "");
    assert_eq!(format("  \n\n").unwrap(), "");
    assert_eq!(format("// a\n\n\n//b   \n").unwrap(), "// a\n\n//b\n");
}

#[test]
fn crlf_line_endings_become_lf() {
    let src = "states {\r\n    A initial // a\r\n\r\n    B\r\n}\r\n// end\r\n";
    assert_eq!(check("crlf", src), Vec::<String>::new());
    assert_eq!(format(src).unwrap(), "states {\n    A initial // a\n\n    B\n}\n// end\n");
}
