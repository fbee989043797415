//! `situ export --promela FILE [-o OUT] [--depth K] [--max-states N]`: the
//! abstraction that `situ test` explores, with the file's properties, as a
//! Promela model for the spin model checker (`verify/spin-check.sh`).

use super::{FAILED, OK, USAGE};
use situ_compiler::bundle;
use situ_compiler::spec::{self, PropertySpec};
use situ_runtime::verify::explore::{Graph, Limits};
use situ_runtime::verify::promela;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub fn run(file: &Path, output: Option<&PathBuf>, depth: usize, max_states: usize) -> u8 {
    let checked = match super::program::check(file, false) {
        Ok(c) => c,
        Err(code) => return code,
    };
    let content = Arc::new(bundle::build(&checked));
    let spec = spec::lower(&checked);
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
