//! `situ repl FILE|BUNDLE`: step through the rules by hand (the session
//! itself is `situ_runtime::repl`). On a terminal: a prompt with history
//! and completion of commands, agents, events, `field=` and symbols
//! (rustyline). Otherwise the commands are read line by line from standard
//! input, so that sessions can be scripted. A bad line prints an error and
//! the session goes on; from a script, the exit code is then 1.

use super::{CliError, Outcome, FAILED, OK};
use rustyline::completion::{Completer, Pair};
use rustyline::error::ReadlineError;
use rustyline::{Context, Editor, Helper, Highlighter, Hinter, Validator};
use situ_runtime::repl::{Reply, Session};
use std::io::{BufRead, IsTerminal};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Completion from the session's words.
#[derive(Helper, Highlighter, Hinter, Validator)]
struct Words(Arc<Mutex<Vec<String>>>);

impl Completer for Words {
    type Candidate = Pair;

    fn complete(&self, line: &str, pos: usize, _: &Context<'_>) -> rustyline::Result<(usize, Vec<Pair>)> {
        let start = line[..pos].rfind(char::is_whitespace).map_or(0, |i| i + 1);
        let word = &line[start..pos];
        let words = self.0.lock().unwrap_or_else(|p| p.into_inner());
        let found = words
            .iter()
            .filter(|w| w.starts_with(word))
            .map(|w| Pair { display: w.clone(), replacement: w.clone() })
            .collect();
        Ok((start, found))
    }
}

// The arguments of `situ repl`.
#[derive(clap::Args)]
pub struct Args {
    /// A `.situ` source or a bundle.
    pub file: std::path::PathBuf,
}

pub fn run(file: &Path) -> Outcome {
    let program = super::program::load(file, false, &situ_compiler::bundle::Trust::Any).map_err(CliError::Reported)?;
    let mut session = Session::new(program.content);
    let terminal = std::io::stdin().is_terminal();
    if terminal {
        println!(
            "situ repl: {} ({} states, {} agents); `help` lists the commands",
            file.display(),
            session.content().states.len(),
            session.content().agents.len()
        );
        println!("{}", session.state());
        interactive(file, &mut session)
    } else {
        scripted(file, &mut session)
    }
}

fn interactive(file: &Path, session: &mut Session) -> Outcome {
    let words = Arc::new(Mutex::new(session.words()));
    let mut editor: Editor<Words, rustyline::history::DefaultHistory> = match Editor::new() {
        Ok(e) => e,
        Err(e) => {
            return Err(CliError::Usage(format!("no terminal editor: {e}")));
        }
    };
    editor.set_helper(Some(Words(words.clone())));
    loop {
        let prompt = format!("{}> ", session.state());
        match editor.readline(&prompt) {
            Ok(line) => {
                let _ = editor.add_history_entry(line.as_str());
                if !handle(file, session, &line) {
                    return Ok(OK);
                }
                *words.lock().unwrap_or_else(|p| p.into_inner()) = session.words();
            }
            Err(ReadlineError::Interrupted) => continue,
            Err(ReadlineError::Eof) => return Ok(OK),
            Err(e) => {
                return Err(CliError::Usage(e.to_string()));
            }
        }
    }
}

fn scripted(file: &Path, session: &mut Session) -> Outcome {
    let mut failed = false;
    for line in std::io::stdin().lock().lines() {
        let Ok(line) = line else {
            return Err(CliError::Usage("standard input is not UTF-8 text".into()));
        };
        if !line.trim().is_empty() && !line.trim_start().starts_with("//") {
            println!("> {}", line.trim());
        }
        match session.execute(&line) {
            Err(e) => {
                println!("error: {e}");
                failed = true;
            }
            Ok(reply) => {
                if !carry_out(file, session, reply) {
                    break;
                }
            }
        }
    }
    Ok(if failed { FAILED } else { OK })
}

/// One line on the terminal; false to quit.
fn handle(file: &Path, session: &mut Session, line: &str) -> bool {
    match session.execute(line) {
        Err(e) => {
            println!("error: {e}");
            true
        }
        Ok(reply) => carry_out(file, session, reply),
    }
}

/// Does what a reply asks; false to quit.
fn carry_out(file: &Path, session: &mut Session, reply: Reply) -> bool {
    match reply {
        Reply::Text(t) => {
            if !t.is_empty() {
                println!("{t}");
            }
        }
        Reply::Quit => return false,
        Reply::Reload => match super::program::load(file, false, &situ_compiler::bundle::Trust::Any) {
            Ok(p) => match session.reload(p.content) {
                Ok(report) => println!("{report}"),
                Err(e) => println!("error: {e}"),
            },
            Err(_) => println!("error: the rules have errors (above); the old rules stay"),
        },
        Reply::Save(to) => {
            let to = PathBuf::from(to);
            let include = super::program::is_source(file).then(|| include_line(file, &to));
            let name = to.file_stem().map_or("repl session".into(), |s| s.to_string_lossy().into_owned());
            let text = session.test_block(&name, include.as_deref());
            match super::write_atomically(&to, text.as_bytes()) {
                Ok(()) => println!("saved {} (`situ test {}` replays it)", to.display(), to.display()),
                Err(e) => println!("error: cannot write `{}`: {e}", to.display()),
            }
        }
    }
    true
}

/// `include "…"` of the rules, relative to the saved file's folder.
fn include_line(rules: &Path, saved: &Path) -> String {
    let abs = |p: &Path| std::path::absolute(p).unwrap_or_else(|_| p.to_path_buf());
    let (rules, dir) = (abs(rules), abs(saved).parent().map(Path::to_path_buf).unwrap_or_default());
    let rel = relative(&rules, &dir);
    format!("include \"{}\"", rel.display().to_string().replace('\\', "/"))
}

fn relative(target: &Path, from: &Path) -> PathBuf {
    let t: Vec<_> = target.components().collect();
    let f: Vec<_> = from.components().collect();
    let common = t.iter().zip(&f).take_while(|(a, b)| a == b).count();
    let mut out = PathBuf::new();
    for _ in common..f.len() {
        out.push("..");
    }
    for c in &t[common..] {
        out.push(c);
    }
    out
}
