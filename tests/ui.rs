//! UI tests: every `tests/ui/*.situ` file is checked as a root, and
//! 1. its findings must be exactly the ones its comments announce: a comment
//!    `//~ E0101 E0103` says that findings with these codes start on that
//!    line (in the root or in a file it includes);
//! 2. the rendered report (miette, no colour, 80 columns) must match its
//!    snapshot in `tests/ui/snapshots/`;
//! 3. every snapshot there must belong to an input (no stale snapshots);
//! 4. every diagnostic code of the registry must be announced by some input.
//!
//! Files under `tests/ui/include/` are only ever included, never roots.
//! To accept changed reports: `INSTA_UPDATE=always cargo test --test ui`.

use situ_compiler::loader::FsLoader;
use situ_compiler::render::{self, Style};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// (file name, line, code)
type Finding = (String, usize, String);

fn inputs() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir("tests/ui")
        .expect("tests/ui exists")
        .map(|e| e.expect("readable directory").path())
        .filter(|p| p.extension().is_some_and(|e| e == "situ"))
        .collect();
    files.sort();
    files
}

/// The `//~ CODE…` annotations of a file.
fn annotations(name: &str, text: &str) -> Vec<Finding> {
    let mut found = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let Some(at) = line.find("//~") else { continue };
        for word in line[at + 3..].split_whitespace() {
            if word.len() == 5 && word.starts_with(['E', 'W']) && word[1..].chars().all(|c| c.is_ascii_digit()) {
                found.push((name.to_string(), i + 1, word.to_string()));
            } else {
                break;
            }
        }
    }
    found
}

#[test]
fn ui() {
    let mut failures = Vec::new();
    let mut announced = BTreeSet::new();
    let mut reports = Vec::new();
    let files = inputs();
    assert!(files.len() >= 20, "expected the UI inputs in tests/ui, found {}", files.len());
    for path in &files {
        let checked = situ_compiler::check(path, &FsLoader).unwrap_or_else(|e| panic!("{e}"));
        let mut expected = BTreeSet::new();
        for (_, file) in checked.sources.iter() {
            expected.extend(annotations(&file.name, &file.text));
        }
        let actual: BTreeSet<Finding> = checked
            .visible()
            .map(|d| {
                let file = checked.sources.get(d.primary.file);
                (file.name.clone(), file.line_col(d.primary.span.start).0, d.code.to_string())
            })
            .collect();
        announced.extend(expected.iter().map(|(_, _, c)| c.clone()));
        for missing in expected.difference(&actual) {
            failures.push(format!("{}: expected {} at {}:{}, not reported", path.display(), missing.2, missing.0, missing.1));
        }
        for extra in actual.difference(&expected) {
            failures.push(format!("{}: unexpected {} at {}:{}", path.display(), extra.2, extra.0, extra.1));
        }
        let mut report = render::human_all(&checked, Style::PLAIN);
        report.push_str(&format!("errors: {}, warnings: {}\n", checked.errors(), checked.warnings()));
        reports.push((stem(path), report));
    }
    for code in situ_compiler::codes::ALL {
        if !announced.contains(code.code) {
            failures.push(format!("no UI input announces {} ({})", code.code, code.title));
        }
    }
    assert!(failures.is_empty(), "UI test failures:\n{}", failures.join("\n"));

    let stems: BTreeSet<String> = reports.iter().map(|(s, _)| s.clone()).collect();
    let mut stale = Vec::new();
    if let Ok(dir) = std::fs::read_dir("tests/ui/snapshots") {
        for entry in dir {
            let name = entry.expect("readable directory").file_name().to_string_lossy().into_owned();
            let Some(stem) = name.strip_suffix(".snap") else { continue };
            if !stems.contains(stem) {
                stale.push(name);
            }
        }
    }
    assert!(stale.is_empty(), "snapshots without an input in tests/ui (delete them): {stale:?}");

    insta::with_settings!({ snapshot_path => "ui/snapshots", prepend_module_to_snapshot => false, omit_expression => true }, {
        for (stem, report) in &reports {
            insta::assert_snapshot!(stem.as_str(), report);
        }
    });
}

fn stem(path: &Path) -> String {
    path.file_stem().expect("a file name").to_string_lossy().into_owned()
}

#[test]
fn annotations_are_read() {
    let a = annotations("a.situ", "x //~ E0101 E0203 and more\n\nstates //~ W0301");
    assert_eq!(
        a,
        [
            ("a.situ".to_string(), 1, "E0101".to_string()),
            ("a.situ".to_string(), 1, "E0203".to_string()),
            ("a.situ".to_string(), 3, "W0301".to_string()),
        ]
    );
}
