//! `situ completions SHELL` and `situ man [-o DIR]`: what a command-line
//! tool owes its shell and its `man`.

use super::{CliError, Outcome, OK};
use std::io::Write;
use std::path::Path;

/// Prints `shell`'s completion script for `cmd` to standard output.
pub fn completions(shell: clap_complete::Shell, mut cmd: clap::Command) -> Outcome {
    let name = cmd.get_name().to_string();
    let mut script = Vec::new();
    clap_complete::generate(shell, &mut cmd, name, &mut script);
    write_out(&script)
}

/// Prints the man page of `cmd` to standard output; with `dir`, writes it
/// there as `NAME.1` with one page per subcommand (`NAME-SUB.1`, and
/// `NAME-SUB-SUBSUB.1` below that), each atomically.
pub fn man(cmd: clap::Command, dir: Option<&Path>) -> Outcome {
    let Some(dir) = dir else {
        let mut page = Vec::new();
        if let Err(e) = clap_mangen::Man::new(cmd).render(&mut page) {
            return Err(CliError::Usage(format!("cannot render the man page: {e}")));
        }
        return write_out(&page);
    };
    if let Err(e) = std::fs::create_dir_all(dir) {
        return Err(CliError::Usage(format!("cannot create `{}`: {e}", dir.display())));
    }
    let mut cmd = cmd.disable_help_subcommand(true);
    cmd.build();
    let mut pages = Vec::new();
    if let Err(e) = render_all(&cmd, &mut pages) {
        return Err(CliError::Usage(format!("cannot render the man pages: {e}")));
    }
    for (name, page) in &pages {
        let path = dir.join(name);
        if let Err(e) = super::write_atomically(&path, page) {
            return Err(CliError::Usage(format!("cannot write `{}`: {e}", path.display())));
        }
    }
    eprintln!("wrote {} man pages to {}", pages.len(), dir.display());
    Ok(OK)
}

/// The page of `cmd` and of each visible subcommand below it, as (file name, roff).
fn render_all(cmd: &clap::Command, pages: &mut Vec<(String, Vec<u8>)>) -> std::io::Result<()> {
    let man = clap_mangen::Man::new(cmd.clone());
    let mut page = Vec::new();
    man.render(&mut page)?;
    pages.push((man.get_filename(), page));
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        render_all(sub, pages)?;
    }
    Ok(())
}

/// Writes to standard output; a reader that went away (`| head`) is no error.
fn write_out(bytes: &[u8]) -> Outcome {
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Ok(()) => Ok(OK),
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(OK),
        Err(e) => Err(CliError::Usage(format!("cannot write to standard output: {e}"))),
    }
}
