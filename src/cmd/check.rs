//! `situ check FILE… [--format human|json|sarif] [--deny-warnings] [--watch]`.

use super::{FAILED, OK, USAGE};
use situ_compiler::loader::{FsLoader, Loader};
use situ_compiler::render;
use std::path::PathBuf;

/// The output formats of `check`.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Format {
    /// miette reports and a summary line per file.
    Human,
    /// One JSON object per finding, one per line.
    Json,
    /// One SARIF 2.1.0 log.
    Sarif,
}

pub fn run(files: &[PathBuf], format: Format, deny_warnings: bool, watch: bool) -> u8 {
    if watch {
        let machine = !matches!(format, Format::Human);
        return super::watch::run(|loader| check_all(files, format, deny_warnings, loader).1, machine);
    }
    check_all(files, format, deny_warnings, &FsLoader).0
}

/// Checks every root and prints the report; the exit code and a one-line
/// summary of the whole (for `--watch`).
fn check_all(files: &[PathBuf], format: Format, deny_warnings: bool, loader: &dyn Loader) -> (u8, String) {
    let mut checks = Vec::new();
    let mut failures = Vec::new();
    for path in files {
        match situ_compiler::check(path, loader) {
            Ok(checked) => checks.push((path, checked)),
            Err(err) => {
                eprintln!("error: {err}");
                failures.push(err);
            }
        }
    }
    match format {
        Format::Human => {
            let style = super::style();
            for (path, checked) in &checks {
                print!("{}", render::human_all(checked, style));
                println!("{}", summary(path, checked));
            }
        }
        Format::Json => {
            for failure in &failures {
                print!("{}", render::json_failure(failure));
            }
            for (_, checked) in &checks {
                print!("{}", render::json_lines(checked));
            }
        }
        Format::Sarif => {
            let all: Vec<_> = checks.iter().map(|(_, c)| c).collect();
            let failed: Vec<_> = failures.iter().collect();
            println!("{}", render::sarif_with_failures(&all, &failed));
        }
    }
    let code = if !failures.is_empty() {
        USAGE
    } else if checks.iter().any(|(_, c)| c.fails(deny_warnings)) {
        FAILED
    } else {
        OK
    };
    let (errors, warnings) = checks.iter().fold((0, 0), |(e, w), (_, c)| (e + c.errors(), w + c.warnings()));
    let mut parts = Vec::new();
    if errors + warnings > 0 || failures.is_empty() {
        parts.push(if errors + warnings > 0 {
            format!("{}, {}", count(errors, "error"), count(warnings, "warning"))
        } else {
            "no findings".to_string()
        });
    }
    parts.extend(failures.iter().map(|f| format!("cannot read `{}`", f.path.display())));
    (code, parts.join("; "))
}

fn summary(path: &std::path::Path, c: &situ_compiler::Checked) -> String {
    let (errors, warnings) = (c.errors(), c.warnings());
    let path = path.display();
    if errors + warnings > 0 {
        return format!("{path}: {}, {}", count(errors, "error"), count(warnings, "warning"));
    }
    let m = &c.model;
    format!(
        "{path}: no findings ({}, {}, {}, {}, {}, {})",
        count(m.states.len(), "state"),
        count(m.agents.len(), "agent"),
        count(m.events.len(), "event"),
        count(m.rules.len(), "rule"),
        count(m.tests.len(), "test"),
        count(m.properties.len(), "property"),
    )
}

fn count(n: usize, what: &str) -> String {
    match (n, what) {
        (1, _) => format!("1 {what}"),
        (_, "property") => format!("{n} properties"),
        _ => format!("{n} {what}s"),
    }
}
