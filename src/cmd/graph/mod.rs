//! `situ graph FILE --view wiring|rete|states [--state S] [--format dot|svg]`:
//! pictures. DOT is printed as is; SVG is laid out by the `layout-rs` crate
//! (no Graphviz needed; for Graphviz's own layout, pipe the DOT into `dot -Tsvg`).

use super::{OK, USAGE};
use situ_compiler::checks::transitions::Transitions;
use situ_compiler::graph;
use std::path::{Path, PathBuf};

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum View {
    /// The wiring graph of a state (or of every state): agents, modes, links.
    Wiring,
    /// The Rete network: alpha nodes, joins, negations, rules.
    Rete,
    /// The state transition graph, unreachable states marked.
    States,
}

#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Format {
    Dot,
    Svg,
}

pub fn run(file: &Path, view: View, state: Option<&str>, format: Format, out: Option<&PathBuf>) -> u8 {
    let program = match super::program::load(file, false) {
        Ok(p) => p,
        Err(code) => return code,
    };
    let c = &program.content;
    let state = match state {
        None => None,
        Some(name) => match c.state_id(name) {
            Some(s) => Some(s),
            None => {
                let names: Vec<&str> = c.states.iter().map(|s| s.name.as_str()).collect();
                eprintln!("error: no state `{name}`; the states are: {}", names.join(", "));
                return USAGE;
            }
        },
    };
    let dot = match view {
        View::Wiring => graph::wiring(c, state),
        View::Rete => graph::rete(c),
        View::States => match &program.checked {
            Some(checked) => graph::states(&checked.model, &Transitions::build(&checked.model)),
            None => {
                eprintln!("error: the states view comes from the static checks: give the `.situ` source, not a bundle");
                return USAGE;
            }
        },
    };
    let text = match format {
        Format::Dot => dot,
        Format::Svg => {
            if matches!(view, View::Wiring) && state.is_none() {
                eprintln!(
                    "error: an SVG shows one state's wiring: add `--state S` (or use `--format dot` for all states)"
                );
                return USAGE;
            }
            match svg(&dot) {
                Ok(svg) => svg,
                Err(e) => {
                    eprintln!("error: cannot lay out the graph: {e}");
                    return USAGE;
                }
            }
        }
    };
    match out {
        None => {
            print!("{text}");
            OK
        }
        Some(path) => match super::write_atomically(path, text.as_bytes()) {
            Ok(()) => OK,
            Err(e) => {
                eprintln!("error: cannot write `{}`: {e}", path.display());
                USAGE
            }
        },
    }
}

/// DOT to SVG with layout-rs.
pub fn svg(dot: &str) -> Result<String, String> {
    use layout::backends::svg::SVGWriter;
    use layout::gv::{DotParser, GraphBuilder};
    let mut parser = DotParser::new(dot);
    let tree = parser.process()?;
    let mut builder = GraphBuilder::new();
    builder.visit_graph(&tree);
    let mut graph = builder.get();
    let mut writer = SVGWriter::new();
    graph.do_it(false, false, false, &mut writer);
    Ok(writer.finalize())
}
