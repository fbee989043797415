//! `situ graph FILE --view wiring|rete|states [--state S] [--format dot|svg]`:
//! pictures. The compiler writes DOT (`situ_compiler::graph`); DOT is printed
//! as is, SVG is laid out by `situ_pictures`: by Graphviz's `dot` when it
//! is on the PATH, else by its built-in layered layout.
//!
//! Findings are drawn, not refused: the diagnostics of a source go to
//! standard error, and the states view of a file with errors draws what
//! resolved (exit 1, the picture written all the same). The wiring and Rete
//! views come from a compiled program and need a file without errors.

// The layout, as the commands that draw name it.
pub use situ_pictures as layout;

use super::{CliError, Outcome, FAILED, OK};
use situ_compiler::bundle::{self, Content};
use situ_compiler::checks::transitions::Transitions;
use situ_compiler::graph;
use situ_compiler::loader::FsLoader;
use situ_compiler::render;
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub use layout::svg;

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

/// What a picture is drawn from: the checked source (when given one) and
/// the compiled program (when it has no errors).
struct Input {
    checked: Option<situ_compiler::Checked>,
    content: Option<Arc<Content>>,
}

fn load(file: &Path) -> Result<Input, CliError> {
    if !super::program::is_source(file) {
        let p = super::program::load(file, false, &situ_compiler::bundle::Trust::Any).map_err(CliError::Reported)?;
        return Ok(Input { checked: p.checked, content: Some(p.content) });
    }
    let checked = situ_compiler::check(file, &FsLoader).map_err(|e| CliError::Usage(e.to_string()))?;
    // The findings on standard error: standard output is the picture.
    let style = render::Style { colour: false, ..super::style() };
    eprint!("{}", render::human_all(&checked, style));
    let content = (checked.errors() == 0).then(|| Arc::new(bundle::build(&checked)));
    Ok(Input { checked: Some(checked), content })
}

// The arguments of `situ graph`.
#[derive(clap::Args)]
pub struct Args {
    /// A `.situ` source or a bundle (the states view needs the source).
    pub file: PathBuf,
    #[arg(long, value_enum)]
    pub view: View,
    /// The state whose wiring to draw (default: all, as clusters).
    #[arg(long)]
    pub state: Option<String>,
    #[arg(long, value_enum, default_value_t = Format::Dot)]
    pub format: Format,
    /// Write here instead of standard output.
    #[arg(short, long)]
    pub output: Option<PathBuf>,
}

pub fn run(args: &Args) -> Outcome {
    let (file, view, state, format, out) =
        (&args.file, args.view, args.state.as_deref(), args.format, args.output.as_ref());
    let input = load(file)?;
    let name = file.display().to_string();
    let errors = input.checked.as_ref().map_or(0, |c| c.errors());
    let content = match (&input.content, view) {
        (_, View::States) => None,
        (Some(c), _) => Some(c.clone()),
        (None, _) => {
            return Err(CliError::Failed(format!(
                "`{name}` has {errors} error(s): the wiring and Rete views are drawn from a program without errors \
                 (the states view draws what resolved; `situ check` explains each)"
            )));
        }
    };
    let state = match (state, &content) {
        (Some(s), Some(c)) => match c.state_id(s) {
            Some(id) => Some(id),
            None => {
                let names: Vec<&str> = c.states.iter().map(|s| s.name.as_str()).collect();
                return Err(CliError::Usage(format!("no state `{s}`; the states are: {}", names.join(", "))));
            }
        },
        _ => None,
    };
    let dot = match (view, &content) {
        (View::States, _) => match &input.checked {
            Some(ch) => graph::states(&ch.model, &Transitions::build(&ch.model), &name, &ch.diagnostics),
            None => {
                return Err(CliError::Usage(
                    "the states view comes from the static checks: give the `.situ` source, not a bundle".into(),
                ));
            }
        },
        (View::Wiring, Some(c)) => graph::wiring(c, state),
        (View::Rete, Some(c)) => graph::rete(c, &name),
        (_, None) => unreachable!("refused above"),
    };
    let text = match format {
        Format::Dot => dot,
        Format::Svg => {
            let engine = layout::engine();
            if let layout::Engine::Builtin(why) = &engine {
                eprintln!("note: {why}: laid out by the built-in layout (install Graphviz for the better one)");
            }
            let laid = match (view, &content, state) {
                (View::Wiring, Some(c), None) => small_multiples(&engine, c, &name),
                _ => layout::svgs(&engine, &[dot.as_str()]).map(|mut v| v.remove(0)),
            };
            match laid {
                Ok(svg) => svg,
                Err(e) => {
                    return Err(CliError::Usage(format!("cannot lay out the graph: {e}")));
                }
            }
        }
    };
    let code = if errors > 0 { FAILED } else { OK };
    match out {
        None => {
            print!("{text}");
            Ok(code)
        }
        Some(path) => match super::write_atomically(path, text.as_bytes()) {
            Ok(()) => Ok(code),
            Err(e) => Err(CliError::Usage(format!("cannot write `{}`: {e}", path.display()))),
        },
    }
}

/// The wiring of every state in SVG: one small picture per state in a grid,
/// the legend last, laid out by one run of the engine.
fn small_multiples(engine: &layout::Engine, c: &Content, name: &str) -> Result<String, layout::LayoutError> {
    let mut dots: Vec<String> = (0..c.states.len() as u32).map(|s| graph::wiring_cell(c, s)).collect();
    dots.push(graph::wiring_legend());
    let refs: Vec<&str> = dots.iter().map(String::as_str).collect();
    let cells = layout::svgs(engine, &refs)?;
    Ok(layout::compose(&format!("Wiring of every state of {name}"), &cells))
}
