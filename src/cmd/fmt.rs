//! `situ fmt FILE… [--check]`: formats in place, atomically (a temporary
//! file next to the original, then a rename), so that no file is ever left
//! half written.

use super::{FAILED, OK, USAGE};
use situ_compiler::loader::{read_bounded, MAX_FILE_BYTES};
use situ_compiler::render;
use situ_compiler::source::{SourceFile, SourceMap};
use std::path::{Path, PathBuf};

// The arguments of `situ fmt`.
#[derive(clap::Args)]
pub struct Args {
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// Change nothing; exit 1 if a file is not formatted.
    #[arg(long)]
    pub check: bool,
}

/// Formats each file, going on past a file that cannot be: the worst exit
/// code of them all (each file's error is said as it comes).
pub fn run(args: &Args) -> u8 {
    let mut status = OK;
    for path in &args.files {
        let code = one(path, args.check);
        status = status.max(code);
    }
    status
}

fn one(path: &Path, check: bool) -> u8 {
    let text = match read_bounded(path, MAX_FILE_BYTES, "a source file").map(String::from_utf8) {
        Ok(Ok(text)) => text,
        Ok(Err(_)) => {
            eprintln!("error: `{}` is not UTF-8 text", path.display());
            return FAILED;
        }
        Err(err) => {
            eprintln!("error: cannot read `{}`: {err}", path.display());
            return USAGE;
        }
    };
    let formatted = match situ_grammar::format(&text) {
        Ok(f) => f,
        Err(diags) => {
            let mut sources = SourceMap::new();
            sources.add(SourceFile::new(path.display().to_string(), text));
            print!("{}", render::human_list(&sources, &diags, super::style()));
            eprintln!("error: `{}` has syntax errors; not formatted", path.display());
            return FAILED;
        }
    };
    if formatted == text {
        return OK;
    }
    if check {
        println!("would reformat {}", path.display());
        return FAILED;
    }
    match super::write_atomically(path, formatted.as_bytes()) {
        Ok(()) => {
            println!("formatted {}", path.display());
            OK
        }
        Err(err) => {
            eprintln!("error: cannot write `{}`: {err}", path.display());
            USAGE
        }
    }
}
