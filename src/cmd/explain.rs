//! `situ explain CODE`.

use super::{CliError, Outcome, OK};
use situ_compiler::codes;

// The arguments of `situ explain`.
#[derive(clap::Args)]
pub struct Args {
    /// A code such as E0101 or situ::E0101.
    pub code: Option<String>,
}

pub fn run(args: &Args) -> Outcome {
    let Some(code) = args.code.as_deref() else {
        for c in codes::ALL {
            println!("situ::{}  {:<7}  {}", c.code, c.severity.as_str(), c.title);
        }
        return Ok(OK);
    };
    match codes::lookup(code) {
        Some(c) => {
            print!("{}", c.explain);
            Ok(OK)
        }
        None => Err(CliError::Usage(format!("unknown diagnostic code `{code}`; `situ explain` lists them all"))),
    }
}
