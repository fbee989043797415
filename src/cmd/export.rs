//! `situ export --promela FILE [-o OUT] [--depth K] [--max-states N]`: the
//! abstraction that `situ test` explores, with the file's properties, as a
//! Promela model for the spin model checker (`verify/spin-check.sh`).
//!
//! `situ export --aiger FILE [-o OUT] [--property NAME]`: the circuit of the
//! abstraction (`situ_verify::model`), exact in time, with one bad-state
//! output per property, in binary AIGER 1.9 for hardware model checkers
//! (`verify/abc-check.sh` runs ABC's `pdr` and `int` on it).

use super::{FAILED, OK, USAGE};
use situ_compiler::bundle;
use situ_compiler::bundle::Content;
use situ_compiler::spec::{self, PropertySpec, Spec};
use situ_verify::abstraction::Alphabet;
use situ_verify::explore::{Graph, Limits};
use situ_verify::model::Model;
use situ_verify::promela;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub fn run(file: &Path, output: Option<&PathBuf>, depth: usize, max_states: usize) -> u8 {
    let (content, spec) = match load(file) {
        Ok(x) => x,
        Err(code) => return code,
    };
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
                OK
            }
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", path.display());
                USAGE
            }
        },
        None => {
            print!("{text}");
            if props.is_empty() {
                FAILED
            } else {
                OK
            }
        }
    }
}

/// The program and its properties, from a source file with no errors.
fn load(file: &Path) -> Result<(Arc<Content>, Spec), u8> {
    let checked = super::program::check(file, false)?;
    Ok((Arc::new(bundle::build(&checked)), spec::lower(&checked)))
}

pub fn aiger(file: &Path, output: Option<&PathBuf>, only: Option<&str>) -> u8 {
    let (content, spec) = match load(file) {
        Ok(x) => x,
        Err(code) => return code,
    };
    let props: Vec<&PropertySpec> = spec.properties.iter().collect();
    if let Some(name) = only {
        if !props.iter().any(|p| p.name == name) {
            let names: Vec<String> = props.iter().map(|p| format!("\"{}\"", p.name)).collect();
            eprintln!("error: no property \"{name}\"; the properties are: {}", names.join(", "));
            return USAGE;
        }
    }
    let alphabet = Alphabet::new(&content, &props);
    let model = match Model::build(&content, &alphabet, &props) {
        Ok(m) => m,
        Err(why) => {
            eprintln!("error: no circuit for `{}`: {}", file.display(), why.0);
            return FAILED;
        }
    };
    let bad: Vec<(String, u32)> = props
        .iter()
        .zip(&model.bad)
        .filter(|(p, _)| only.is_none_or(|n| p.name == n))
        .filter_map(|(p, b)| b.map(|b| (p.name.clone(), b)))
        .collect();
    if bad.is_empty() {
        eprintln!(
            "error: `{}` has no safety property to export (unbounded `eventually` has no bad state)",
            file.display()
        );
        return FAILED;
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
                OK
            }
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", path.display());
                USAGE
            }
        },
        None => {
            use std::io::Write;
            match std::io::stdout().write_all(&bytes) {
                Ok(()) => OK,
                Err(_) => USAGE,
            }
        }
    }
}
