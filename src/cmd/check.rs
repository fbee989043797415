//! `situ check FILE… [--format human|json|sarif] [--deny-warnings] [--watch]
//! [--ros2-map MAP [--msg-path DIR]…]`.

use super::{CliError, FAILED, OK, USAGE};
use situ_compiler::loader::{FsLoader, Loader};
use situ_compiler::render;
use situ_compiler::source::SourceFile;
use situ_compiler::RootError;
use std::path::{Path, PathBuf};

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

// The arguments of `situ check` (its help is the doc comment of `Command::Check` in main.rs).
#[derive(clap::Args)]
pub struct Args {
    /// The root files to check (each with its includes).
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// How to print findings.
    #[arg(long, value_enum, default_value_t = Format::Human)]
    pub format: Format,
    /// Fail (exit 1) on warnings too.
    #[arg(long)]
    pub deny_warnings: bool,
    /// Check again on every save of a file or of any file it includes, until Ctrl-C
    /// (exit 0); each round ends with a line of the time and the summary.
    #[arg(long)]
    pub watch: bool,
    /// Also check this ROS 2 map (TOML, docs/ros2.md) against the rules; one root file only.
    #[arg(long, value_name = "MAP")]
    pub ros2_map: Option<PathBuf>,
    /// A folder of ROS 2 message definitions for the map, searched before the map's `msg_path`,
    /// AMENT_PREFIX_PATH and situ's own (repeatable): an install prefix (with `share/`), a
    /// folder of packages (`DIR/<pkg>/msg/*.msg`) or one package (`DIR/msg/*.msg`).
    #[arg(long, value_name = "DIR", requires = "ros2_map")]
    pub msg_path: Vec<PathBuf>,
}

/// `--msg-path` folders that are not folders: a usage error.
pub fn msg_path_folders(dirs: &[PathBuf]) -> Result<(), CliError> {
    match dirs.iter().find(|d| !d.is_dir()) {
        Some(d) => Err(CliError::Usage(format!(
            "--msg-path {}: not a folder (give a prefix with `share/`, a folder of packages, or a package)",
            d.display()
        ))),
        None => Ok(()),
    }
}

pub fn run(args: &Args) -> super::Outcome {
    let (files, format, deny_warnings) = (&args.files, args.format, args.deny_warnings);
    let ros2_map = args.ros2_map.as_deref().map(|m| (m, args.msg_path.as_slice()));
    if ros2_map.is_some() && files.len() > 1 {
        return Err(CliError::Usage(format!("--ros2-map applies to one root file; {} were given", files.len())));
    }
    msg_path_folders(&args.msg_path)?;
    if args.watch {
        let machine = !matches!(format, Format::Human);
        return super::recheck::run(|loader| check_all(files, format, deny_warnings, ros2_map, loader).1, machine);
    }
    Ok(check_all(files, format, deny_warnings, ros2_map, &FsLoader).0)
}

/// Checks the ROS 2 map `map` against the checked rules: the map becomes one
/// more source of the check and its findings join the rules' ones, so every
/// format renders them with the map's name, line and column. Not done when
/// the rules have errors (their model is then partial). A map that cannot be
/// read, or is not UTF-8, is an I/O error like an unreadable root. Its
/// message types are looked for in the `msg_path` folders first.
fn check_map(
    checked: &mut situ_compiler::Checked,
    map: &Path,
    msg_path: &[PathBuf],
    loader: &dyn Loader,
) -> Result<(), RootError> {
    let failure = |error| RootError { path: map.to_path_buf(), error };
    let bytes = loader.read(map).map_err(failure)?;
    let text = String::from_utf8(bytes)
        .map_err(|_| failure(std::io::Error::new(std::io::ErrorKind::InvalidData, "the map is not UTF-8 text")))?;
    if checked.errors() > 0 {
        eprintln!("note: `{}` is not checked: the rules have errors", map.display());
        return Ok(());
    }
    let file = checked.sources.add(SourceFile::new(map.display().to_string(), text));
    let dir = map.parent().unwrap_or(Path::new(""));
    let text = &checked.sources.get(file).text;
    let (found, _) = situ_ros2_map::load::check_map_file(&checked.model, text, dir, msg_path, file);
    checked.diagnostics.extend(found);
    Ok(())
}

/// Checks every root and prints the report; the exit code and a one-line
/// summary of the whole (for `--watch`).
fn check_all(
    files: &[PathBuf],
    format: Format,
    deny_warnings: bool,
    ros2_map: Option<(&Path, &[PathBuf])>,
    loader: &dyn Loader,
) -> (u8, String) {
    let mut checks = Vec::new();
    let mut failures = Vec::new();
    for path in files {
        match situ_compiler::check(path, loader) {
            Ok(mut checked) => {
                if let Some((map, msg_path)) = ros2_map {
                    if let Err(err) = check_map(&mut checked, map, msg_path, loader) {
                        eprintln!("error: {err}");
                        failures.push(err);
                    }
                }
                checks.push((path, checked));
            }
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
