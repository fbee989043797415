//! The Rust of one agent, for the runtime's agent SDK: a struct that
//! implements `situ_runtime::agent::Agent` and dispatches each step to a
//! user trait with one method per function, an `Io` wrapper around the
//! runtime's `Context` with a typed report helper per event (symbol fields
//! as enums), and the table or FSM as data.
//!
//! The output is rustfmt-stable under the workspace's settings (max width
//! 120, `use_small_heuristics = "Max"`): code lines are kept short, and the
//! data tables carry `#[rustfmt::skip]`, one entry a line.

use super::{camel, field_types, one_line, quote, snake, table_actions, unique, Header};
use crate::bundle::{Action, AgentDef, Behaviour, Content, FieldType, Mode, Trigger};
use std::fmt::Write;

const WIDTH: usize = 120;

/// Rust's keywords: a name equal to one becomes a raw identifier (or gets a
/// trailing underscore where raw identifiers are not allowed).
const KEYWORDS: &str =
    "as async await break const continue dyn else enum extern false fn for if impl in let loop match mod \
     move mut pub ref return static struct trait true type unsafe use where while abstract become box do \
     final macro override priv typeof unsized virtual yield try gen";

fn ident(name: String) -> String {
    match name.as_str() {
        "self" | "Self" | "super" | "crate" | "_" | "cx" => format!("{name}_"),
        n if KEYWORDS.split_whitespace().any(|k| k == n) => format!("r#{name}"),
        _ => name,
    }
}

pub(crate) fn generate(content: &Content, me: u32, header: &Header<'_>) -> String {
    let def = &content.agents[me as usize];
    let ty = camel(&def.name);
    let (agent_ty, trait_ty, io_ty) = (format!("{ty}Agent"), format!("{ty}Functions"), format!("{ty}Io"));
    let module = snake(&def.name);
    let events: Vec<&crate::bundle::EventDef> = def.events.iter().map(|&e| &content.events[e as usize]).collect();
    let methods: Vec<String> = unique(
        def.functions
            .iter()
            .map(|f| snake(&f.name))
            .map(|m| if m == "without_function" { format!("{m}_") } else { m })
            .map(ident)
            .collect(),
    );
    let mut out = String::new();

    // The module's doc comment: what it is, the header, how to use it.
    let kind = format!("{:?}", def.kind).to_lowercase();
    let what = def.description.as_deref().map(|d| format!(": {}", one_line(d))).unwrap_or_default();
    let _ = writeln!(out, "//! The agent `{}` ({kind}){what}.\n//!", def.name);
    for line in header.lines() {
        let _ = writeln!(out, "//! {line}");
    }
    let example_method = methods.first().cloned().unwrap_or_else(|| "without_function".into());
    let example_report = match events.first() {
        Some(e) => format!(
            "io.{}({}).expect(\"an event of {}\");",
            ident(snake(&e.name)),
            e.fields.iter().map(|f| example_value(&e.name, f)).collect::<Vec<_>>().join(", "),
            def.name
        ),
        None => "let _ = io.receivers();".to_string(),
    };
    let _ = write!(
        out,
        "//!
//! [`{agent_ty}`] is a `situ_runtime::agent::Agent`: its `step` calls your [`{trait_ty}`] for the function of
//! the moment, with a [`{io_ty}`]: the runtime's `Context`, the agents a datum sent now reaches, and a typed
//! report helper per event. In one process, on the simulated-time scheduler:
//!
//! ```ignore
//! use {module}::{{{agent_ty}, {trait_ty}, {io_ty}}};
//!
//! struct Mine;
//! impl {trait_ty} for Mine {{
//!     fn {example_method}(&mut self, io: &mut {io_ty}<'_, '_>) {{
//!         {example_report}
//!     }}
//! }}
//! let agents: Vec<Box<dyn situ_runtime::agent::Agent>> = vec![Box::new({agent_ty}::new(Mine))];
//! let bound = situ_runtime::agent::bind(&content, agents, false)?;
//! let config = situ_runtime::sched::SimConfig::default();
//! let mut rt = situ_runtime::sched::SimRuntime::new(content.clone(), bound, None, config);
//! rt.run_until(10_000_000_000, &mut |change| println!(\"{{change:?}}\"));
//! ```
//!
//! Over Zenoh it runs unchanged: the Zenoh bus implements the same `Bus` (docs/protocol.md):
//!
//! ```ignore
//! let bus: Arc<dyn Bus> = Arc::new(situ_bus_zenoh::ZenohBus::open(content.clone(), placement, &zenoh_config, capacity)?);
//! situ_runtime::realtime::run_on(content, bound, None, RealtimeConfig::default(), duration, bus, &mut |_| {{}});
//! ```

#![allow(dead_code)]

"
    );
    let uses_value = events.iter().any(|e| !e.fields.is_empty());
    if uses_value {
        out.push_str("use situ_compiler::bundle::{Mode, Value};\n");
    } else {
        out.push_str("use situ_compiler::bundle::Mode;\n");
    }
    out.push_str("use situ_runtime::agent::{Agent, Body, Context, ContextError, Datum};\n\n");
    let _ = writeln!(out, "/// The agent's name, as the rules call it.\npub const AGENT: &str = {};", quote(&def.name));
    let _ = writeln!(out, "/// The hash of the bundle this file was generated from.");
    let _ = writeln!(out, "pub const BUNDLE_SHA256: &str = {};", quote(&header.sha256));
    let _ = writeln!(out, "pub const SITU_VERSION: &str = {};", quote(super::SITU_VERSION));
    let _ = writeln!(out, "pub const SOURCE: &str = {};", quote(header.source));
    let states: Vec<String> = content.states.iter().map(|s| quote(&s.name)).collect();
    out.push_str("/// The system states, in the order of the rules.\n#[rustfmt::skip]\n");
    let _ = writeln!(out, "pub const STATES: &[&str] = &[{}];", states.join(", "));
    let functions: Vec<String> = def.functions.iter().map(|f| quote(&f.name)).collect();
    out.push_str("/// The functions the table or FSM names.\n#[rustfmt::skip]\n");
    let _ = writeln!(out, "pub const FUNCTIONS: &[&str] = &[{}];\n", functions.join(", "));

    // The behaviour as data.
    out.push_str(
        "/// What the agent does in a state: its mode, its function and its links as written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Action {
    pub mode: Mode,
    pub function: Option<&'static str>,
    pub from: &'static [&'static str],
    pub to: &'static [&'static str],
}\n\n",
    );
    match table_actions(content, def) {
        Some(actions) => {
            if matches!(def.behaviour, Behaviour::Always) {
                out.push_str("/// No table and no FSM: running in every state, no function, no links.\n");
            } else {
                out.push_str("/// The table, per system state (`None`: no entry, the agent sleeps).\n");
            }
            out.push_str("#[rustfmt::skip]\npub const TABLE: &[(&str, Option<Action>)] = &[\n");
            for (s, a) in content.states.iter().zip(&actions) {
                let a = a.as_ref().map_or("None".to_string(), |a| format!("Some({})", action(content, def, a)));
                let _ = writeln!(out, "    ({}, {a}),", quote(&s.name));
            }
            out.push_str("];\n\n");
        }
        None => {
            let Behaviour::Fsm(fsm) = &def.behaviour else { unreachable!("not a table") };
            out.push_str(
                "/// What triggers an FSM transition: a new state at rest in the list, or an event of the agent.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Trigger {
    States(&'static [&'static str]),
    Event(&'static str),
}

/// An FSM transition; for each input the first that matches, in this order, fires.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Transition {
    pub from: &'static str,
    pub to: &'static str,
    pub trigger: Trigger,
}\n\n",
            );
            let _ = writeln!(out, "pub const FSM_INITIAL: &str = {};", quote(&fsm.states[fsm.initial as usize].name));
            out.push_str("/// The FSM's states and their actions.\n#[rustfmt::skip]\n");
            out.push_str("pub const FSM_STATES: &[(&str, Action)] = &[\n");
            for st in &fsm.states {
                let _ = writeln!(out, "    ({}, {}),", quote(&st.name), action(content, def, &st.action));
            }
            out.push_str("];\n/// The FSM's transitions, in source order.\n#[rustfmt::skip]\n");
            out.push_str("pub const FSM_TRANSITIONS: &[Transition] = &[\n");
            for t in &fsm.transitions {
                let trigger = match &t.trigger {
                    Trigger::States(s) => format!("Trigger::States(&[{}])", names(s, |x| &content.states[x].name)),
                    Trigger::Event(e) => format!("Trigger::Event({})", quote(&content.events[*e as usize].name)),
                };
                let _ = writeln!(
                    out,
                    "    Transition {{ from: {}, to: {}, trigger: {trigger} }},",
                    quote(&fsm.states[t.from as usize].name),
                    quote(&fsm.states[t.to as usize].name)
                );
            }
            out.push_str("];\n\n");
        }
    }

    // An enum per symbol field.
    let field_types = field_types(&mut out, &events, ["f64", "i64", "bool"], |out, name, e, f, symbols| {
        let variants = unique(symbols.iter().map(|s| camel(s)).collect());
        let _ = writeln!(out, "/// The symbols of `{}.{}`.", e.name, f.name);
        out.push_str("#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]\n");
        let _ = writeln!(out, "pub enum {name} {{");
        for v in &variants {
            let _ = writeln!(out, "    {v},");
        }
        let _ = writeln!(out, "}}\n\nimpl {name} {{");
        out.push_str("    /// The symbol as the rules write it.\n");
        out.push_str("    pub fn name(self) -> &'static str {\n        match self {\n");
        for (v, s) in variants.iter().zip(symbols) {
            let _ = writeln!(out, "            {name}::{v} => {},", quote(s));
        }
        out.push_str("        }\n    }\n\n");
        out.push_str("    /// Its index in the field's type (a payload's `Value::Symbol`).\n");
        out.push_str("    pub fn index(self) -> u32 {\n        self as u32\n    }\n}\n\n");
    });

    // The user trait: one method per function.
    let _ = writeln!(out, "/// Your code for `{}`: one method per function of its table or FSM.", def.name);
    let _ = writeln!(out, "pub trait {trait_ty}: Send {{");
    out.push_str("    /// A step with no function (a `wait` without one, or no table or FSM).\n");
    let _ = writeln!(out, "    fn without_function(&mut self, _io: &mut {io_ty}<'_, '_>) {{}}");
    for (f, m) in def.functions.iter().zip(&methods) {
        let doc = f.description.as_deref().map(|d| format!(": {}", one_line(d))).unwrap_or_default();
        let _ = writeln!(out, "\n    /// `{}`{doc}", f.name);
        let _ = writeln!(out, "    fn {m}(&mut self, io: &mut {io_ty}<'_, '_>);");
    }
    out.push_str("}\n\n");

    // The agent.
    let _ = writeln!(out, "/// The agent `{}` for the runtime: dispatches each step to `F`.", def.name);
    let _ = writeln!(out, "pub struct {agent_ty}<F: {trait_ty}> {{\n    pub user: F,\n}}\n");
    let _ = writeln!(out, "impl<F: {trait_ty}> {agent_ty}<F> {{");
    let _ = writeln!(out, "    pub fn new(user: F) -> {agent_ty}<F> {{\n        {agent_ty} {{ user }}\n    }}\n}}\n");
    let _ = writeln!(out, "impl<F: {trait_ty}> Agent for {agent_ty}<F> {{");
    out.push_str("    fn name(&self) -> &str {\n        AGENT\n    }\n\n");
    out.push_str("    fn functions(&self) -> Vec<String> {\n        FUNCTIONS.iter().map(|f| f.to_string()).collect()\n    }\n\n");
    out.push_str("    fn step(&mut self, cx: &mut Context<'_>) {\n");
    if def.functions.is_empty() {
        let _ = writeln!(out, "        self.user.without_function(&mut {io_ty} {{ cx }});");
    } else {
        out.push_str("        let function = cx.function();\n");
        let _ = writeln!(out, "        let io = &mut {io_ty} {{ cx }};");
        out.push_str("        match function {\n");
        for (f, m) in def.functions.iter().zip(&methods) {
            let _ = writeln!(out, "            Some({}) => self.user.{m}(io),", quote(&f.name));
        }
        out.push_str("            _ => self.user.without_function(io),\n        }\n");
    }
    out.push_str("    }\n}\n\n");

    // The io wrapper and the report helpers.
    let _ = writeln!(out, "/// What a function of `{}` sees and does in one step.", def.name);
    let _ = writeln!(out, "pub struct {io_ty}<'c, 'a> {{\n    /// The runtime's context, for everything else.");
    out.push_str("    pub cx: &'c mut Context<'a>,\n}\n\n");
    let _ = writeln!(out, "impl<'a> {io_ty}<'_, 'a> {{");
    out.push_str(
        "    /// The system state, as the last status said.
    pub fn state(&self) -> &'a str {
        self.cx.state()
    }

    /// Running or waiting (safe mode applied).
    pub fn mode(&self) -> Mode {
        self.cx.mode()
    }

    /// Whether the Bulletinboard fell silent (an actuator should stop).
    pub fn safe_mode(&self) -> bool {
        self.cx.safe_mode()
    }

    /// The time of this step (ns).
    pub fn now(&self) -> u64 {
        self.cx.now()
    }

    /// The function of the moment.
    pub fn function(&self) -> Option<&'a str> {
        self.cx.function()
    }

    /// The data received on the links of the moment since the previous step.
    pub fn inputs(&self) -> &'a [Datum] {
        self.cx.inputs()
    }

    /// The agents a datum sent now reaches: the links of the moment out of this agent, the running readers
    /// included (none while it waits).
    pub fn receivers(&self) -> Vec<&'a str> {
        self.cx.receivers().iter().map(|&a| self.cx.agent_name(a)).collect()
    }

    /// Sends a datum along every link out of this agent active now.
    pub fn send(&mut self, body: Body) {
        self.cx.send(body)
    }

    /// Sends a datum to one agent, if a link to it is active now.
    pub fn send_to(&mut self, agent: &str, body: Body) -> Result<(), ContextError> {
        self.cx.send_to(agent, body)
    }\n",
    );
    let helpers = unique(events.iter().map(|e| snake(&e.name)).collect());
    for ((e, types), h) in events.iter().zip(&field_types).zip(&helpers) {
        let params: Vec<String> =
            e.fields.iter().zip(types).map(|(f, t)| format!("{}: {t}", ident(snake(&f.name)))).collect();
        let values: Vec<String> = e
            .fields
            .iter()
            .map(|f| {
                let p = ident(snake(&f.name));
                match f.ty {
                    FieldType::F64 => format!("Value::F64({p})"),
                    FieldType::I64 => format!("Value::I64({p})"),
                    FieldType::Bool => format!("Value::Bool({p})"),
                    FieldType::Symbols(_) => format!("Value::Symbol({p}.index())"),
                }
            })
            .collect();
        let doc = e.description.as_deref().map(|d| format!(": {}", one_line(d))).unwrap_or_default();
        for urgent in [false, true] {
            let (name, call, what) = if urgent {
                (format!("{h}_urgent"), "report_urgent", "an urgent ")
            } else {
                (ident(h.clone()), "report", "")
            };
            let _ = writeln!(out, "\n    /// Reports {what}`{}`{doc}", e.name);
            let mut all = vec!["&mut self".to_string()];
            all.extend(params.iter().cloned());
            let sig = format!("    pub fn {name}({}) -> Result<(), ContextError> {{", all.join(", "));
            if sig.len() <= WIDTH {
                let _ = writeln!(out, "{sig}");
            } else {
                let _ = writeln!(out, "    pub fn {name}(");
                for p in &all {
                    let _ = writeln!(out, "        {p},");
                }
                out.push_str("    ) -> Result<(), ContextError> {\n");
            }
            if values.is_empty() {
                let _ = writeln!(out, "        self.cx.{call}({}, &[])", quote(&e.name));
            } else {
                let payload = format!("        let payload = [{}];", values.join(", "));
                let next_line = format!("            [{}];", values.join(", "));
                if payload.len() <= WIDTH {
                    let _ = writeln!(out, "{payload}");
                } else if next_line.len() <= WIDTH {
                    // rustfmt puts a long right-hand side on the next line when it fits there.
                    let _ = writeln!(out, "        let payload =\n{next_line}");
                } else {
                    out.push_str("        let payload = [\n");
                    for v in &values {
                        let _ = writeln!(out, "            {v},");
                    }
                    out.push_str("        ];\n");
                }
                let _ = writeln!(out, "        self.cx.{call}({}, &payload)", quote(&e.name));
            }
            out.push_str("    }\n");
        }
    }
    out.push_str("}\n");
    out
}

fn names<'c>(ids: &[u32], name: impl Fn(usize) -> &'c str) -> String {
    ids.iter().map(|&x| quote(name(x as usize))).collect::<Vec<_>>().join(", ")
}

fn action(content: &Content, def: &AgentDef, a: &Action) -> String {
    let mode = match a.mode {
        Mode::Running => "Mode::Running",
        Mode::Waiting => "Mode::Waiting",
        Mode::Sleeping => "Mode::Sleeping",
    };
    let function =
        a.function.map_or("None".to_string(), |f| format!("Some({})", quote(&def.functions[f as usize].name)));
    let agent = |x: usize| content.agents[x].name.as_str();
    format!(
        "Action {{ mode: {mode}, function: {function}, from: &[{}], to: &[{}] }}",
        names(&a.from, agent),
        names(&a.to, agent)
    )
}

fn example_value(event: &str, f: &crate::bundle::FieldDef) -> String {
    match &f.ty {
        FieldType::F64 => "1.0".into(),
        FieldType::I64 => "1".into(),
        FieldType::Bool => "true".into(),
        FieldType::Symbols(s) => format!("{}{}::{}", camel(event), camel(&f.name), camel(&s[0])),
    }
}
