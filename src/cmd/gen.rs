//! `situ gen`: code generated from the rules. `situ gen agent AGENT FILE
//! --lang python|rust [-o DIR]` writes the code of one agent
//! (`situ_compiler::codegen`) into DIR (default: the current directory) as
//! `<agent>_agent.py` or `<agent>.rs` (the agent's name in snake case),
//! atomically; `-o -` prints it instead (docs/gen.md).

use super::{program, CliError, Outcome, OK};
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

pub fn run(what: What) -> Outcome {
    match what {
        What::Agent { agent, file, lang, output } => agent_code(&agent, &file, &lang, output),
    }
}

fn agent_code(agent: &str, file: &std::path::Path, lang: &str, output: Option<PathBuf>) -> Outcome {
    let Some(lang) = Lang::parse(lang) else {
        return Err(CliError::Usage(format!(
            "unknown language `{lang}` for --lang; expected one of: {}",
            Lang::NAMES.join(", ")
        )));
    };
    let program = program::load(file, false, &situ_compiler::bundle::Trust::Any).map_err(CliError::Reported)?;
    let generated = codegen::agent(&program.content, agent, lang).map_err(|e| CliError::Usage(e.to_string()))?;
    let dir = output.unwrap_or_else(|| PathBuf::from("."));
    if dir.as_os_str() == "-" {
        let mut out = std::io::stdout().lock();
        return match out.write_all(generated.text.as_bytes()).and_then(|()| out.flush()) {
            Ok(()) => Ok(OK),
            Err(e) => Err(CliError::Failed(format!("cannot write to standard output: {e}"))),
        };
    }
    if let Err(e) = std::fs::create_dir_all(&dir) {
        return Err(CliError::Usage(format!("cannot create `{}`: {e}", dir.display())));
    }
    let path = dir.join(&generated.file_name);
    match super::write_atomically(&path, generated.text.as_bytes()) {
        Ok(()) => {
            eprintln!("wrote {} ({} code of agent `{agent}`)", path.display(), lang.name());
            Ok(OK)
        }
        Err(e) => Err(CliError::Usage(format!("cannot write `{}`: {e}", path.display()))),
    }
}
