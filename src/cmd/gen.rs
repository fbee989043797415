//! `situ gen`: code generated from the rules. `situ gen agent AGENT FILE
//! --lang python|rust [-o DIR]` writes the code of one agent
//! (`situ_compiler::codegen`) into DIR (default: the current directory) as
//! `<agent>_agent.py` or `<agent>.rs` (the agent's name in snake case),
//! atomically; `-o -` prints it instead (docs/gen.md).

use super::{program, FAILED, OK, USAGE};
use situ_compiler::codegen::{self, Lang};
use std::io::Write;
use std::path::PathBuf;

/// What to generate.
#[derive(clap::Subcommand)]
pub enum What {
    /// The code of one agent: its events as typed functions, its table or FSM as data, the dispatch to your code.
    Agent {
        /// The agent, as the rules name it.
        agent: String,
        /// A `.situ` source or a bundle.
        file: PathBuf,
        /// The language: python (joins over Zenoh) or rust (the runtime's agent SDK).
        #[arg(long)]
        lang: String,
        /// The directory to write into (default: the current one); `-` prints to standard output.
        #[arg(short, long)]
        output: Option<PathBuf>,
    },
}

pub fn run(what: What) -> u8 {
    match what {
        What::Agent { agent, file, lang, output } => agent_code(&agent, &file, &lang, output),
    }
}

fn agent_code(agent: &str, file: &std::path::Path, lang: &str, output: Option<PathBuf>) -> u8 {
    let Some(lang) = Lang::parse(lang) else {
        eprintln!("error: unknown language `{lang}` for --lang; expected one of: {}", Lang::NAMES.join(", "));
        return USAGE;
    };
    let program = match program::load(file, false) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let generated = match codegen::agent(&program.content, agent, lang) {
        Ok(g) => g,
        Err(e) => {
            eprintln!("error: {e}");
            return USAGE;
        }
    };
    let dir = output.unwrap_or_else(|| PathBuf::from("."));
    if dir.as_os_str() == "-" {
        let mut out = std::io::stdout().lock();
        return match out.write_all(generated.text.as_bytes()).and_then(|()| out.flush()) {
            Ok(()) => OK,
            Err(e) => {
                eprintln!("error: cannot write to standard output: {e}");
                FAILED
            }
        };
    }
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("error: cannot create `{}`: {e}", dir.display());
        return USAGE;
    }
    let path = dir.join(&generated.file_name);
    match super::write_atomically(&path, generated.text.as_bytes()) {
        Ok(()) => {
            eprintln!("wrote {} ({} code of agent `{agent}`)", path.display(), lang.name());
            OK
        }
        Err(e) => {
            eprintln!("error: cannot write `{}`: {e}", path.display());
            USAGE
        }
    }
}
