//! What the page draws, computed once when `situ view` starts: the program
//! as JSON, the state graph as SVG, and a recording's timeline.

use crate::cmd::{graph::layout, program, USAGE};
use serde_json::{json, Value as Json};
use situ_compiler::bundle::{self, Action, Behaviour, Content, Mode};
use situ_compiler::checks::transitions::Transitions;
use situ_compiler::loader::FsLoader;
use situ_compiler::Checked;
use situ_runtime::record::mcap::{attached_bundle, read_file, read_topics, topics};
use std::fmt::Write as _;
use std::path::Path;
use std::sync::Arc;

/// A state change of a run.
pub struct Change {
    pub t: u64,
    pub from: String,
    pub to: String,
    pub rules: Vec<String>,
    pub explain: String,
}

/// An agent's mode as recorded.
pub struct ModeAt {
    pub t: u64,
    pub agent: String,
    pub function: String,
    pub mode: String,
}

/// An event the Bulletinboard refused, and why.
pub struct Refusal {
    pub t: u64,
    pub agent: String,
    pub event: String,
    pub reason: String,
}

/// What the page draws of one message of a run (a recording's, or a live
/// run's as its recorder writes it).
pub enum Entry {
    Change(Change),
    Mode(ModeAt),
    Refused(Refusal),
    /// A message of the run that moves only its clock: an accepted event,
    /// a tick, a state message that did not change the state.
    Time(u64),
}

impl Entry {
    /// The entry of a message on `topic` at `time` (ns); `None` when the
    /// topic is not one of a situ run's (a simulation's pose, say).
    pub fn of(topic: &str, time: u64, msg: &Json) -> Option<Entry> {
        let text = |k: &str| msg[k].as_str().unwrap_or("").to_string();
        let t = msg["time_ns"].as_u64().unwrap_or(time);
        Some(match topic {
            topics::STATE if msg["from"] != msg["state"] => {
                let rules = msg["rules"]
                    .as_array()
                    .map(|r| r.iter().filter_map(|x| x.as_str().map(String::from)).collect())
                    .unwrap_or_default();
                Entry::Change(Change { t, from: text("from"), to: text("state"), rules, explain: text("explain") })
            }
            topics::MODES => {
                Entry::Mode(ModeAt { t, agent: text("agent"), function: text("function"), mode: text("mode") })
            }
            topics::EVENTS if msg["accepted"] == Json::Bool(false) => {
                Entry::Refused(Refusal { t, agent: text("agent"), event: text("event"), reason: text("reason") })
            }
            topics::STATE | topics::EVENTS | topics::TICKS => Entry::Time(t),
            _ => return None,
        })
    }

    /// What in the entry is not of `content` (a state, an agent), if anything.
    pub fn foreign(&self, content: &Content) -> Option<String> {
        match self {
            Entry::Change(c) => [&c.from, &c.to]
                .into_iter()
                .find(|s| content.state_id(s).is_none())
                .map(|s| format!("its state `{s}` is not a state")),
            Entry::Mode(m) => {
                content.agent_id(&m.agent).is_none().then(|| format!("its agent `{}` is not an agent", m.agent))
            }
            Entry::Refused(_) | Entry::Time(_) => None,
        }
    }

    pub fn time(&self) -> u64 {
        match self {
            Entry::Change(c) => c.t,
            Entry::Mode(m) => m.t,
            Entry::Refused(r) => r.t,
            Entry::Time(t) => *t,
        }
    }
}

impl Change {
    pub fn json(&self) -> Json {
        json!({ "t": self.t, "from": self.from, "to": self.to, "rules": self.rules, "explain": self.explain })
    }
}

impl ModeAt {
    pub fn json(&self) -> Json {
        json!({ "t": self.t, "agent": self.agent, "function": self.function, "mode": self.mode })
    }
}

impl Refusal {
    pub fn json(&self) -> Json {
        json!({ "t": self.t, "agent": self.agent, "event": self.event, "reason": self.reason })
    }
}

pub struct Site {
    name: String,
    kind: &'static str,
    content: Arc<Content>,
    pub program: String,
    pub graph: String,
    pub timeline: String,
    changes: Vec<Change>,
    modes: Vec<ModeAt>,
}

impl Site {
    /// Loads a source, a bundle or a recording; on failure prints why and
    /// returns the exit code (2 for a damaged recording or other rules).
    pub fn load(file: &Path, rules: Option<&Path>) -> Result<Site, u8> {
        let name = file.display().to_string();
        let is_recording = file.extension().is_some_and(|e| e == "mcap");
        if !is_recording {
            if rules.is_some() {
                eprintln!("error: --rules goes with a recording (`.mcap`); `{name}` is the rules already");
                return Err(USAGE);
            }
            let p = program::load(file, false)?;
            let kind = if p.checked.is_some() { "rules" } else { "bundle" };
            let checked = p.checked.or_else(|| source_of(&p.content));
            return Ok(Site::new(name, kind, p.content, checked.as_ref(), Vec::new(), Vec::new(), Vec::new(), None));
        }
        let bytes = read_file(file).map_err(|e| {
            eprintln!("error: `{name}`: {e}");
            USAGE
        })?;
        // The page draws the rules' topics only (not a simulation's pose,
        // not the /events log that repeats /situ/events).
        let wanted = |t: &str| [topics::STATE, topics::MODES, topics::EVENTS, topics::TICKS].contains(&t);
        let reading = read_topics(&bytes, &wanted).map_err(|e| {
            eprintln!("error: `{name}` is not a readable recording: {e}");
            USAGE
        })?;
        if let Some(why) = &reading.cut {
            eprintln!("warning: `{name}` is cut short: {why}; the page shows the part before the cut");
        }
        let attached =
            attached_bundle(&bytes).map(|b| program::decode_bundle(&b, &format!("the bundle attached to `{name}`")));
        let (content, checked) = match (rules, attached) {
            (Some(r), attached) => {
                let p = program::load(r, false)?;
                if let Some(Ok(a)) = attached {
                    if !same_rules(&a, &p.content) {
                        eprintln!(
                            "error: `{name}` was recorded on other rules than `{}` (its attached bundle differs); \
                             leave --rules out to view it on its own rules",
                            r.display()
                        );
                        return Err(USAGE);
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
            (None, Some(Err(e))) => {
                eprintln!("error: the bundle attached to `{name}`: {e}");
                return Err(USAGE);
            }
            (None, None) => {
                eprintln!("error: `{name}` has no bundle attached: give its rules with --rules");
                return Err(USAGE);
            }
        };
        let mut changes = Vec::new();
        let mut modes = Vec::new();
        let mut refused = Vec::new();
        let mut ours = 0usize;
        for (topic, time, msg) in &reading.messages {
            let Some(entry) = Entry::of(topic, *time, msg) else { continue };
            ours += 1;
            if let Some(why) = entry.foreign(&content) {
                eprintln!("error: `{name}` was recorded on other rules: {why} of `{}`", content.source);
                return Err(USAGE);
            }
            match entry {
                Entry::Change(c) => changes.push(c),
                Entry::Mode(m) => modes.push(m),
                Entry::Refused(r) => refused.push(r.json()),
                Entry::Time(_) => {}
            }
        }
        if ours == 0 {
            eprintln!("error: `{name}` holds no message of a situ run (/state, /situ/events, /situ/modes)");
            return Err(USAGE);
        }
        let end = reading.end;
        Ok(Site::new(name, "recording", content, checked.as_ref(), changes, modes, refused, Some((end, reading.cut))))
    }

    #[allow(clippy::too_many_arguments)]
    fn new(
        name: String,
        kind: &'static str,
        content: Arc<Content>,
        checked: Option<&Checked>,
        changes: Vec<Change>,
        modes: Vec<ModeAt>,
        refused: Vec<Json>,
        recording: Option<(u64, Option<String>)>,
    ) -> Site {
        let program = program_json(&name, kind, &content).to_string();
        let graph = state_graph(&content, checked, &changes);
        let timeline = match &recording {
            None => json!({ "recording": false }),
            Some((end, cut)) => json!({
                "recording": true,
                "end_ns": end,
                "cut": cut,
                "changes": changes.iter().map(Change::json).collect::<Vec<_>>(),
                "modes": modes.iter().map(ModeAt::json).collect::<Vec<_>>(),
                "refused": refused,
            }),
        }
        .to_string();
        Site { name, kind, content, program, graph, timeline, changes, modes }
    }

    /// The page of a run as it goes (`situ run --serve`): the rules, and a
    /// timeline the page fills from `/api/live`.
    pub fn live(name: String, content: Arc<Content>, checked: Option<&Checked>) -> Site {
        let found = checked.is_none().then(|| source_of(&content)).flatten();
        let checked = checked.or(found.as_ref());
        let mut site = Site::new(name, "live run", content, checked, Vec::new(), Vec::new(), Vec::new(), None);
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
            let _ = write!(s, ", {} state changes", self.changes.len());
        }
        s
    }

    /// The state, the states visited, and the agents' recorded modes at
    /// `at` (nanoseconds; none: the end of a recording, the initial state
    /// of rules).
    pub fn state_at(&self, at: Option<u64>) -> String {
        let c = &self.content;
        let t = at.unwrap_or(u64::MAX);
        let mut state = c.states[c.initial as usize].name.clone();
        let mut visited = vec![state.clone()];
        let mut fired = Json::Null;
        for ch in self.changes.iter().take_while(|ch| ch.t <= t) {
            state = ch.to.clone();
            if !visited.contains(&state) {
                visited.push(state.clone());
            }
            fired = json!({ "t": ch.t, "rules": ch.rules, "explain": ch.explain });
        }
        let mut modes = serde_json::Map::new();
        for m in self.modes.iter().take_while(|m| m.t <= t) {
            modes.insert(m.agent.clone(), json!({ "mode": m.mode, "function": m.function }));
        }
        json!({ "at_ns": at, "state": state, "visited": visited, "fired": fired, "modes": modes }).to_string()
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
        None => bare_states(c, changes),
    };
    match layout::svg(&dot) {
        Ok(svg) => mark_states(&svg, c),
        Err(e) => {
            eprintln!("warning: cannot lay out the state graph: {e}");
            format!("<svg xmlns=\"http://www.w3.org/2000/svg\"><text x=\"10\" y=\"20\">cannot lay out the state graph: {}</text></svg>", xml(&e.to_string()))
        }
    }
}

/// The states of a bundle whose source is not at hand, with the changes of
/// its recording as edges.
fn bare_states(c: &Content, changes: &[Change]) -> String {
    let mut out =
        String::from("digraph states {\n  node [shape=box, style=\"rounded,filled\", fillcolor=\"#ffffff\"];\n");
    let edges = if changes.is_empty() { "" } else { "; edges: the changes recorded" };
    let _ = writeln!(
        out,
        "  label=\"{}: {} states (the transitions need the .situ source{edges})\";\n  labelloc=t;",
        dot_text(&c.source),
        c.states.len()
    );
    for (i, s) in c.states.iter().enumerate() {
        let extra = if i == c.initial as usize {
            ", fillcolor=\"#c8e6c9\", penwidth=3"
        } else if s.is_final {
            ", fillcolor=\"#bbdefb\", peripheries=2"
        } else {
            ""
        };
        let _ = writeln!(out, "  \"{}\" [label=\"{}\"{extra}];", dot_text(&s.name), dot_text(&s.name));
    }
    let mut seen = std::collections::BTreeSet::new();
    for ch in changes {
        if seen.insert((ch.from.as_str(), ch.to.as_str())) {
            let _ = writeln!(out, "  \"{}\" -> \"{}\";", dot_text(&ch.from), dot_text(&ch.to));
        }
    }
    out.push_str("}\n");
    out
}

fn dot_text(s: &str) -> String {
    s.replace('\\', "\\\\").replace('"', "\\\"")
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
