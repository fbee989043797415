//! What the page draws, computed once when `situ view` starts: the program
//! as JSON, the state graph as SVG, and a recording's timeline (read by
//! the runtime: `situ_runtime::record::timeline`).

use crate::cmd::{graph::layout, program, CliError};
use serde_json::{json, Value as Json};
use situ_compiler::bundle::{self, Action, Behaviour, Content, Mode};
use situ_compiler::checks::transitions::Transitions;
use situ_compiler::loader::FsLoader;
use situ_compiler::Checked;
use situ_runtime::record::mcap::{attached_bundle, read_file, read_topics};
use situ_runtime::record::timeline::{Change, Timeline, TimelineError, TOPICS};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

pub struct Site {
    name: String,
    kind: &'static str,
    content: Arc<Content>,
    pub program: String,
    pub graph: String,
    pub timeline: String,
    /// A recording's run; empty for rules.
    run: Timeline,
}

impl Site {
    /// Loads a source, a bundle or a recording; the error says why (exit 2
    /// for a damaged recording or other rules).
    pub fn load(file: &Path, rules: Option<&Path>) -> Result<Site, CliError> {
        let name = file.display().to_string();
        let is_recording = file.extension().is_some_and(|e| e == "mcap");
        if !is_recording {
            if rules.is_some() {
                return Err(CliError::Usage(format!(
                    "--rules goes with a recording (`.mcap`); `{name}` is the rules already"
                )));
            }
            let p = program::load(file, false, &situ_compiler::bundle::Trust::Any).map_err(CliError::Reported)?;
            let kind = if p.checked.is_some() { "rules" } else { "bundle" };
            let checked = p.checked.or_else(|| source_of(&p.content));
            return Ok(Site::new(name, kind, p.content, checked.as_ref(), None));
        }
        let bytes = read_file(file).map_err(|e| CliError::Usage(format!("`{name}`: {e}")))?;
        // The page draws the rules' topics only (not a simulation's pose,
        // not the /events log that repeats /situ/events).
        let wanted = |t: &str| TOPICS.contains(&t);
        let reading = read_topics(&bytes, &wanted)
            .map_err(|e| CliError::Usage(format!("`{name}` is not a readable recording: {e}")))?;
        if let Some(why) = &reading.cut {
            eprintln!("warning: `{name}` is cut short: {why}; the page shows the part before the cut");
        }
        let attached = attached_bundle(&bytes).map(|b| {
            program::decode_bundle(&b, &format!("the bundle attached to `{name}`"), &situ_compiler::bundle::Trust::Any)
        });
        let (content, checked) = match (rules, attached) {
            (Some(r), attached) => {
                let p = program::load(r, false, &situ_compiler::bundle::Trust::Any).map_err(CliError::Reported)?;
                if let Some(Ok(a)) = attached {
                    if !same_rules(&a, &p.content) {
                        return Err(CliError::Usage(format!(
                            "`{name}` was recorded on other rules than `{}` (its attached bundle differs); \
                             leave --rules out to view it on its own rules",
                            r.display()
                        )));
                    }
                }
                let checked = p.checked.or_else(|| source_of(&p.content));
                (p.content, checked)
            }
            (None, Some(Ok(c))) => {
                let c = Arc::new(c);
                let checked = source_of(&c);
                (c, checked)
            }
            (None, Some(Err(e))) => return Err(CliError::Usage(format!("the bundle attached to `{name}`: {e}"))),
            (None, None) => {
                return Err(CliError::Usage(format!("`{name}` has no bundle attached: give its rules with --rules")))
            }
        };
        let run = Timeline::read(&reading, &content).map_err(|e| {
            CliError::Usage(match e {
                TimelineError::OtherRules { what } => {
                    format!("`{name}` was recorded on other rules: {what} of `{}`", content.source)
                }
                TimelineError::NothingOfSitu => format!("`{name}` {e}"),
            })
        })?;
        Ok(Site::new(name, "recording", content, checked.as_ref(), Some(run)))
    }

    /// The site of rules (`run`: none) or of a recording's run.
    fn new(
        name: String,
        kind: &'static str,
        content: Arc<Content>,
        checked: Option<&Checked>,
        run: Option<Timeline>,
    ) -> Site {
        let program = program_json(&name, kind, &content).to_string();
        let run = run.unwrap_or_default();
        let graph = state_graph(&content, checked, &run.changes);
        let timeline = match kind {
            "recording" => run.json(),
            _ => json!({ "recording": false }),
        }
        .to_string();
        Site { name, kind, content, program, graph, timeline, run }
    }

    /// The page of a run as it goes (`situ run --serve`): the rules, and a
    /// timeline the page fills from `/api/live`.
    pub fn live(name: String, content: Arc<Content>, checked: Option<&Checked>) -> Site {
        let found = checked.is_none().then(|| source_of(&content)).flatten();
        let checked = checked.or(found.as_ref());
        let mut site = Site::new(name, "live run", content, checked, None);
        site.timeline = json!({
            "recording": true, "live": true, "end_ns": 0, "cut": null, "changes": [], "modes": [], "refused": [],
        })
        .to_string();
        site
    }

    /// One line for the terminal: what is served.
    pub fn summary(&self) -> String {
        let c = &self.content;
        let mut s = format!(
            "{} `{}`: {} states, {} agents, {} rules",
            self.kind,
            self.name,
            c.states.len(),
            c.agents.len(),
            c.rules.len()
        );
        if self.kind == "recording" {
            let _ = write!(s, ", {} state changes", self.run.changes.len());
        }
        s
    }

    /// The state, the states visited, and the agents' recorded modes at
    /// `at` (nanoseconds; none: the end of a recording, the initial state
    /// of rules).
    pub fn state_at(&self, at: Option<u64>) -> String {
        self.run.state_at(&self.content, at).to_string()
    }
}

/// Whether two programs are the same rules (the name of their source aside).
fn same_rules(a: &Content, b: &Content) -> bool {
    let mut a = a.clone();
    a.source = b.source.clone();
    a == *b
}

/// The checked source a bundle was built from, when it is still where the
/// bundle says and still builds to the same program: the state graph is
/// drawn from the static checks.
fn source_of(c: &Content) -> Option<Checked> {
    let path = Path::new(&c.source);
    if !program::is_source(path) || !path.is_file() {
        return None;
    }
    let checked = situ_compiler::check(path, &FsLoader).ok()?;
    (checked.errors() == 0 && same_rules(&bundle::build(&checked), c)).then_some(checked)
}

/// An agent's action in a state, as the bundle says (an FSM agent: the
/// action of its initial FSM state).
fn action(c: &Content, agent: usize, state: usize) -> (Option<&Action>, &'static str) {
    match &c.agents[agent].behaviour {
        Behaviour::Always => (None, "always"),
        Behaviour::Table { actions } => (actions.get(state).and_then(Option::as_ref), "table"),
        Behaviour::Fsm(f) => (f.states.get(f.initial as usize).map(|s| &s.action), "fsm"),
    }
}

fn program_json(name: &str, kind: &str, c: &Content) -> Json {
    let agent_name = |i: &u32| c.agents.get(*i as usize).map_or("?", |a| a.name.as_str());
    let agents: Vec<Json> = c
        .agents
        .iter()
        .enumerate()
        .map(|(i, a)| {
            let per_state: Vec<Json> = (0..c.states.len())
                .map(|s| {
                    let (act, how) = action(c, i, s);
                    let mode = match (act, how) {
                        (Some(a), _) => a.mode.adjective(),
                        (None, "always") => Mode::Running.adjective(),
                        (None, _) => Mode::Sleeping.adjective(),
                    };
                    let function = act.and_then(|a| a.function).and_then(|f| a.functions.get(f as usize));
                    json!({
                        "mode": mode,
                        "function": function.map(|f| f.name.as_str()),
                        "from": act.map(|a| a.from.iter().map(agent_name).collect::<Vec<_>>()).unwrap_or_default(),
                        "to": act.map(|a| a.to.iter().map(agent_name).collect::<Vec<_>>()).unwrap_or_default(),
                        "by": how,
                    })
                })
                .collect();
            json!({
                "name": a.name,
                "kind": a.kind,
                "description": a.description,
                "functions": a.functions.iter().map(|f| json!({"name": f.name, "description": f.description})).collect::<Vec<_>>(),
                "states": per_state,
            })
        })
        .collect();
    let rules: Vec<Json> = c
        .rules
        .iter()
        .map(|r| {
            json!({
                "name": r.name,
                "salience": r.salience,
                "target": c.states.get(r.target as usize).map(|s| s.name.as_str()),
                "description": r.description,
                "file": r.source.file,
                "line": r.source.line,
                "text": r.source.text,
            })
        })
        .collect();
    json!({
        "name": name,
        "kind": kind,
        "source": c.source,
        "initial": c.states[c.initial as usize].name,
        "states": c.states.iter().map(|s| json!({"name": s.name, "final": s.is_final, "description": s.description})).collect::<Vec<_>>(),
        "agents": agents,
        "rules": rules,
    })
}

/// The state graph in SVG: from the static checks when the source is at
/// hand (`situ graph --view states`), else the states alone with the
/// changes a recording made; each state's node marked `data-state`.
fn state_graph(c: &Content, checked: Option<&Checked>, changes: &[Change]) -> String {
    let dot = match checked {
        Some(ch) => situ_compiler::graph::states(&ch.model, &Transitions::build(&ch.model), &c.source, &ch.diagnostics),
        None => situ_compiler::graph::bundle_states(c, changes.iter().map(|ch| (ch.from.as_str(), ch.to.as_str()))),
    };
    match layout::svg(&dot) {
        Ok(svg) => mark_states(&svg, c),
        Err(e) => {
            eprintln!("warning: cannot lay out the state graph: {e}");
            format!("<svg xmlns=\"http://www.w3.org/2000/svg\"><text x=\"10\" y=\"20\">cannot lay out the state graph: {}</text></svg>", xml(&e.to_string()))
        }
    }
}

fn xml(s: &str) -> String {
    s.replace('&', "&amp;").replace('<', "&lt;").replace('>', "&gt;").replace('"', "&quot;")
}

/// Marks each node of a state with `data-state="NAME"` (Graphviz's SVG:
/// `<g id="node1" class="node"><title>NAME</title>`); the page finds the
/// current state by it.
fn mark_states(svg: &str, c: &Content) -> String {
    const NODE: &str = "class=\"node\"";
    let mut out = String::with_capacity(svg.len() + 64 * c.states.len());
    let mut rest = svg;
    while let Some(at) = rest.find(NODE) {
        let end = at + NODE.len();
        out.push_str(&rest[..end]);
        rest = &rest[end..];
        let title = rest
            .split_once("<title>")
            .and_then(|(before, after)| (!before.contains('<')).then_some(after))
            .and_then(|after| after.split_once("</title>"))
            .map(|(t, _)| t);
        if let Some(t) = title.filter(|t| c.state_id(t).is_some()) {
            let _ = write!(out, " data-state=\"{t}\"");
        }
    }
    out.push_str(rest);
    out
}
