//! `situ export --promela FILE [-o OUT] [--depth K] [--max-states N]`: the
//! abstraction that `situ test` explores, with the file's properties, as a
//! Promela model for the spin model checker (`verify/spin-check.sh`).
//!
//! `situ export --aiger FILE [-o OUT] [--property NAME]`: the circuit of the
//! abstraction (`situ_verify::model`), exact in time, with one bad-state
//! output per property, in binary AIGER 1.9 for hardware model checkers
//! (`verify/abc-check.sh` runs ABC's `pdr` and `int` on it).

use super::{CliError, Outcome, FAILED, OK};
use situ_compiler::bundle;
use situ_compiler::bundle::Content;
use situ_compiler::spec::{self, PropertySpec, Spec};
use situ_verify::abstraction::Alphabet;
use situ_verify::explore::{Graph, Limits};
use situ_verify::model::Model;
use situ_verify::promela;
use std::path::{Path, PathBuf};
use std::sync::Arc;

// The arguments of `situ export`.
#[derive(clap::Args)]
pub struct Args {
    /// A Promela model for spin (one property per `-DPROP=k`).
    #[arg(long, required_unless_present = "aiger", conflicts_with = "aiger")]
    pub promela: bool,
    /// A binary AIGER 1.9 circuit for hardware model checkers such as ABC:
    /// the abstraction for runs of any length, one bad-state output per
    /// property (unbounded `eventually` has none).
    #[arg(long)]
    pub aiger: bool,
    /// Only this property (by name), as the circuit's single bad-state output.
    #[arg(long, requires = "aiger")]
    pub property: Option<String>,
    pub file: PathBuf,
    /// Write here instead of standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// The most events the exploration goes from the start.
    #[arg(long, default_value_t = 12)]
    pub depth: usize,
    /// The most abstract states.
    #[arg(long, default_value_t = 20_000)]
    pub max_states: usize,
}

pub fn run(args: &Args) -> Outcome {
    if args.aiger {
        return aiger(&args.file, args.output.as_ref(), args.property.as_deref());
    }
    promela(&args.file, args.output.as_ref(), args.depth, args.max_states)
}

fn promela(file: &Path, output: Option<&PathBuf>, depth: usize, max_states: usize) -> Outcome {
    let (content, spec) = load(file)?;
    let props: Vec<&PropertySpec> = spec.properties.iter().collect();
    let graph = Graph::build(&content, &props, Limits { depth, max_states });
    let text = promela::export(&content, &graph, &props);
    match output {
        Some(path) => match super::write_atomically(path, text.as_bytes()) {
            Ok(()) => {
                eprintln!(
                    "wrote {}: {} abstract states, {} properties (spin -a -DPROP=k)",
                    path.display(),
                    graph.states(),
                    props.len()
                );
                Ok(OK)
            }
            Err(e) => Err(CliError::Usage(format!("cannot write `{}`: {e}", path.display()))),
        },
        None => {
            print!("{text}");
            Ok(if props.is_empty() { FAILED } else { OK })
        }
    }
}

/// The program and its properties, from a source file with no errors.
fn load(file: &Path) -> Result<(Arc<Content>, Spec), CliError> {
    let checked = super::program::check(file, false).map_err(CliError::Reported)?;
    Ok((Arc::new(bundle::build(&checked)), spec::lower(&checked)))
}

fn aiger(file: &Path, output: Option<&PathBuf>, only: Option<&str>) -> Outcome {
    let (content, spec) = load(file)?;
    let props: Vec<&PropertySpec> = spec.properties.iter().collect();
    if let Some(name) = only {
        if !props.iter().any(|p| p.name == name) {
            let names: Vec<String> = props.iter().map(|p| format!("\"{}\"", p.name)).collect();
            return Err(CliError::Usage(format!("no property \"{name}\"; the properties are: {}", names.join(", "))));
        }
    }
    let alphabet = Alphabet::new(&content, &props);
    let model = match Model::build(&content, &alphabet, &props) {
        Ok(m) => m,
        Err(why) => {
            return Err(CliError::Failed(format!("no circuit for `{}`: {}", file.display(), why.0)));
        }
    };
    let bad: Vec<(String, u32)> = props
        .iter()
        .zip(&model.bad)
        .filter(|(p, _)| only.is_none_or(|n| p.name == n))
        .filter_map(|(p, b)| b.map(|b| (p.name.clone(), b)))
        .collect();
    if bad.is_empty() {
        return Err(CliError::Failed(format!(
            "`{}` has no safety property to export (unbounded `eventually` has no bad state)",
            file.display()
        )));
    }
    let bytes = model.aig.to_aig(&bad);
    match output {
        Some(path) => match super::write_atomically(path, &bytes) {
            Ok(()) => {
                eprintln!(
                    "wrote {}: {} latches, {} inputs, {} bad-state outputs",
                    path.display(),
                    model.aig.latches().len(),
                    model.aig.inputs().len(),
                    bad.len()
                );
                Ok(OK)
            }
            Err(e) => Err(CliError::Usage(format!("cannot write `{}`: {e}", path.display()))),
        },
        None => {
            use std::io::Write;
            match std::io::stdout().write_all(&bytes) {
                Ok(()) => Ok(OK),
                Err(_) => Err(CliError::Reported(super::USAGE)),
            }
        }
    }
}
