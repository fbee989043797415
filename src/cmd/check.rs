//! `situ check FILE… [--format human|json|sarif] [--deny-warnings]`.

use super::{FAILED, OK, USAGE};
use situ_compiler::loader::FsLoader;
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

pub fn run(files: &[PathBuf], format: Format, deny_warnings: bool) -> u8 {
    let mut checks = Vec::new();
    let mut io_failed = false;
    for path in files {
        match situ_compiler::check(path, &FsLoader) {
            Ok(checked) => checks.push((path, checked)),
            Err(err) => {
                eprintln!("error: {err}");
                io_failed = true;
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
            for (_, checked) in &checks {
                print!("{}", render::json_lines(checked));
            }
        }
        Format::Sarif => {
            let all: Vec<_> = checks.iter().map(|(_, c)| c).collect();
            println!("{}", render::sarif(&all));
        }
    }
    if io_failed {
        USAGE
    } else if checks.iter().any(|(_, c)| c.fails(deny_warnings)) {
        FAILED
    } else {
        OK
    }
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
