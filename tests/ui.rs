//! UI tests over two folders of `.situ` inputs with their expectations inline:
//! `tests/ui/` (front end: syntax, names, types; reports snapshotted as
//! people see them) and `tests/checks/` (static checks; reports snapshotted as
//! JSON, so that the witnesses are part of the expectation). Every input is
//! checked as a root, and
//! 1. its findings must be exactly the ones its comments announce: a comment
//!    `//~ E0101 E0103` says that findings with these codes start on that
//!    line (in the root or in a file it includes);
//! 2. the report must match its snapshot in `snapshots/` of the folder;
//! 3. every snapshot there must belong to an input (no stale snapshots);
//! 4. every diagnostic code of the registry is announced by some input, and
//!    every static check has three inputs that raise it and three near misses
//!    (`CODE_near_*.situ`) that do not.
//!
//! Files in an `include/` folder are only ever included, never roots.
//! To accept changed reports: `INSTA_UPDATE=always cargo test --test ui`.

use situ_compiler::loader::FsLoader;
use situ_compiler::render::{self, Style};
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// (file name, line, code)
type Finding = (String, usize, String);

fn inputs(dir: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{dir}: {e}"))
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

/// How a folder's reports are snapshotted.
#[derive(Clone, Copy)]
enum Report {
    Human,
    Json,
}

/// Checks every input of `dir`; returns the announced (file, line, code)s.
fn run(dir: &str, report: Report) -> BTreeSet<Finding> {
    let mut failures = Vec::new();
    let mut announced = BTreeSet::new();
    let mut reports = Vec::new();
    let files = inputs(dir);
    assert!(!files.is_empty(), "no inputs in {dir}");
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
        announced.extend(expected.iter().cloned());
        for missing in expected.difference(&actual) {
            failures.push(format!(
                "{}: expected {} at {}:{}, not reported",
                path.display(),
                missing.2,
                missing.0,
                missing.1
            ));
        }
        for extra in actual.difference(&expected) {
            failures.push(format!("{}: unexpected {} at {}:{}", path.display(), extra.2, extra.0, extra.1));
        }
        let mut text = match report {
            Report::Human => render::human_all(&checked, Style::PLAIN),
            Report::Json => pretty_json_lines(&checked),
        };
        text.push_str(&format!("errors: {}, warnings: {}\n", checked.errors(), checked.warnings()));
        reports.push((stem(path), text));
    }
    assert!(failures.is_empty(), "UI test failures in {dir}:\n{}", failures.join("\n"));

    let stems: BTreeSet<String> = reports.iter().map(|(s, _)| s.clone()).collect();
    let mut stale = Vec::new();
    let snapshots = format!("{dir}/snapshots");
    if let Ok(entries) = std::fs::read_dir(&snapshots) {
        for entry in entries {
            let name = entry.expect("readable directory").file_name().to_string_lossy().into_owned();
            let Some(stem) = name.strip_suffix(".snap") else { continue };
            if !stems.contains(stem) {
                stale.push(name);
            }
        }
    }
    assert!(stale.is_empty(), "snapshots without an input in {dir} (delete them): {stale:?}");

    let snapshot_path = format!("../{snapshots}");
    insta::with_settings!({ snapshot_path => snapshot_path, prepend_module_to_snapshot => false, omit_expression => true }, {
        for (stem, report) in &reports {
            insta::assert_snapshot!(stem.as_str(), report);
        }
    });
    announced
}

/// The JSON findings, one pretty object each, with the file names of the
/// compilation (stable across machines since they are relative).
fn pretty_json_lines(checked: &situ_compiler::Checked) -> String {
    let mut out = String::new();
    for d in &checked.diagnostics {
        let v = render::json_object(&checked.sources, d);
        out.push_str(&serde_json::to_string_pretty(&v).expect("JSON"));
        out.push('\n');
    }
    out
}

#[test]
fn front_end() {
    run("tests/ui", Report::Human);
}

#[test]
fn static_checks() {
    run("tests/checks", Report::Json);
}

/// The annotations of every input of a folder and of its `include/` files
/// (in subfolders too).
fn announced_in(dir: &str) -> BTreeSet<Finding> {
    let mut out = BTreeSet::new();
    let mut folders = vec![PathBuf::from(dir), Path::new(dir).join("include")];
    while let Some(sub) = folders.pop() {
        let Ok(entries) = std::fs::read_dir(&sub) else { continue };
        for e in entries.flatten() {
            let path = e.path();
            if path.is_dir() && path.starts_with(Path::new(dir).join("include")) {
                folders.push(path);
            } else if path.extension().is_some_and(|x| x == "situ") {
                let bytes = std::fs::read(&path).expect("readable input");
                out.extend(annotations(&path.display().to_string(), &String::from_utf8_lossy(&bytes)));
            }
        }
    }
    out
}

#[test]
fn every_code_has_inputs() {
    let mut announced = announced_in("tests/ui");
    announced.extend(announced_in("tests/checks"));
    let mut failures = Vec::new();
    // The ROS 2 map's codes have their inputs in tests/ros2/ (tests/ros2_map.rs)
    // and in situ-ros2-map's own tests.
    // The verdicts' codes (E05xx, W05xx) are raised by `situ test`: their
    // inputs are in tests/verify/ (tests/verify.rs, tests/test_cmd.rs).
    let mine = |c: &str| !situ_compiler::codes::is_ros2_map(c) && !situ_compiler::codes::is_verdict(c);
    for code in situ_compiler::codes::ALL.iter().filter(|c| mine(c.code)) {
        let raising: BTreeSet<&str> =
            announced.iter().filter(|(_, _, c)| c == code.code).map(|(f, _, _)| f.as_str()).collect();
        if raising.is_empty() {
            failures.push(format!("no input announces {} ({})", code.code, code.title));
        }
        if code.code.starts_with("E03") || code.code.starts_with("W03") {
            let near =
                inputs("tests/checks").iter().filter(|p| stem(p).starts_with(&format!("{}_near", code.code))).count();
            if raising.len() < 3 || near < 3 {
                failures.push(format!(
                    "{}: {} inputs raise it and {near} near misses do not; at least 3 of each are needed",
                    code.code,
                    raising.len()
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
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
