//! The Python of one agent: a module that joins a stack over Zenoh with the
//! `eclipse-zenoh` package and the wire protocol of `docs/protocol.md`.
//!
//! The module holds the agent's data (states, table or FSM, the links out of
//! it per state, the FSMs of the readers whose FSM state decides a link),
//! an enum per symbol field, a function per event, a `Handlers` class with a
//! method per function, and a run loop (`Runner`, `run`, `run_all` for
//! several agents in one process) that follows the Bulletinboard's status as
//! the Rust runtime does (§10.6-10.7): the mode, function and receivers of
//! the moment, safe mode from the start until the first status and after
//! 600 ms without one (the events reported then held until a status comes),
//! data dropped while asleep, the FSM stepped by status changes and by the
//! agent's own reports, the end at a final state; and the Zenoh session of
//! a deployment file's process as `bus-zenoh/src/deploy.rs` makes it.
//!
//! The output passes `mypy --strict` and is stable under `black` (default
//! settings): one item per line with trailing commas wherever a line could
//! grow past 88 characters.

use super::{field_types, links_out, one_line, quote, snake, table_actions, unique, Header};
use crate::bundle::{Action, AgentDef, Behaviour, Content, FieldType, Mode, Trigger};
use std::fmt::Write;

/// Black's line length.
const WIDTH: usize = 88;

/// Python's keywords and the builtins and module names the generated code
/// uses: a generated name equal to one of them gets a trailing underscore.
const RESERVED: &str =
    "False None True and as assert async await break class continue def del elif else except finally for \
     from global if import in is lambda nonlocal not or pass raise return try while with yield match case \
     type run bool int float str tuple dict list len isinstance print object annotations self step sorted \
     set max min range super";

/// A Python identifier for a generated name.
fn ident(name: String) -> String {
    if RESERVED.split_whitespace().any(|r| r == name) {
        format!("{name}_")
    } else {
        name
    }
}

/// The runtime part: the same for every agent.
const RUNTIME: &str = include_str!("python_runtime.py");

pub(crate) fn generate(content: &Content, me: u32, header: &Header<'_>) -> String {
    let def = &content.agents[me as usize];
    let module = super::file_name(&def.name, super::Lang::Python).trim_end_matches(".py").to_string();
    let mut out = String::new();
    for line in header.lines() {
        out.push_str(&format!("# {line}\n"));
    }
    docstring(&mut out, def, &module);
    out.push_str(
        "from __future__ import annotations\n\n\
         import enum as _enum\n\
         import importlib as _importlib\n\
         import json as _json\n\
         import math as _math\n\
         import os as _os\n\
         import sys as _sys\n\
         import threading as _threading\n\
         import time as _time\n\
         from collections import deque as _deque\n\
         from dataclasses import dataclass as _dataclass\n\
         from typing import Any as _Any\n\
         from typing import Callable as _Callable\n\
         from typing import Protocol as _Protocol\n\
         from typing import Sequence as _Sequence\n\
         from typing import TypeAlias as _TypeAlias\n\
         from typing import Union as _Union\n\n\
         import zenoh as _zenoh\n\n",
    );
    let _ = writeln!(out, "AGENT = {}", quote(&def.name));
    let _ = writeln!(out, "BUNDLE_SHA256 = {}", quote(&header.sha256));
    let _ = writeln!(out, "SITU_VERSION = {}", quote(super::SITU_VERSION));
    let _ = writeln!(out, "SOURCE = {}", quote(header.source));
    out.push_str("PROTOCOL_VERSION = 1\n");
    let states: Vec<String> = content.states.iter().map(|s| quote(&s.name)).collect();
    out.push_str(&tuple_stmt("STATES: tuple[str, ...] = ", &states, 0, ""));
    let _ = writeln!(out, "INITIAL_STATE = {}", quote(&content.states[content.initial as usize].name));
    let finals: Vec<String> = content.states.iter().filter(|s| s.is_final).map(|s| quote(&s.name)).collect();
    out.push_str(&tuple_stmt("FINAL_STATES: tuple[str, ...] = ", &finals, 0, ""));
    match def.rate_hz {
        Some(r) => {
            let _ = writeln!(out, "RATE_HZ: float | None = {}", float(r));
        }
        None => out.push_str("RATE_HZ: float | None = None\n"),
    }
    let functions: Vec<String> = def.functions.iter().map(|f| quote(&f.name)).collect();
    out.push_str(&tuple_stmt("FUNCTIONS: tuple[str, ...] = ", &functions, 0, ""));
    out.push_str("\n\n");
    out.push_str(RUNTIME.split("# @@ GENERATED @@\n").next().unwrap_or(""));

    // An enum per symbol field, a function per event.
    let events: Vec<&crate::bundle::EventDef> = def.events.iter().map(|&e| &content.events[e as usize]).collect();
    let field_types = field_types(&mut out, &events, ["float", "int", "bool"], |out, name, e, f, symbols| {
        let _ = writeln!(out, "class {name}(_enum.Enum):");
        let _ = writeln!(out, "    \"\"\"The symbols of `{}.{}`.\"\"\"\n", e.name, f.name);
        let members = unique(symbols.iter().map(|s| s.to_uppercase()).collect());
        for (m, s) in members.iter().zip(symbols) {
            let _ = writeln!(out, "    {} = {}", ident(m.clone()), quote(s));
        }
        out.push_str("\n\n");
    });
    let event_fns = unique(events.iter().map(|e| ident(snake(&e.name))).collect());
    for ((e, types), fname) in events.iter().zip(&field_types).zip(&event_fns) {
        let params: Vec<String> =
            e.fields.iter().zip(types).map(|(f, t)| format!("{}: {t}", ident(f.name.clone()))).collect();
        out.push_str(&call_stmt(&format!("def {fname}("), &params, ") -> Event:", 0));
        let doc = match &e.description {
            Some(d) => format!("{}: {}", e.name, one_line(d)),
            None => format!("The event {}.", e.name),
        };
        let _ = writeln!(out, "    \"\"\"{}\"\"\"", docstring_text(&doc));
        let entries: Vec<String> = e
            .fields
            .iter()
            .map(|f| {
                let p = ident(f.name.clone());
                let v = match f.ty {
                    FieldType::F64 => format!("_f64({p})"),
                    FieldType::I64 => format!("_i64({p})"),
                    FieldType::Bool => format!("bool({p})"),
                    FieldType::Symbols(_) => format!("{p}.value"),
                };
                format!("{}: {v}", quote(&f.name))
            })
            .collect();
        let inline = format!("    return Event({}, {{{}}})", quote(&e.name), entries.join(", "));
        if inline.len() <= WIDTH {
            let _ = writeln!(out, "{inline}");
        } else {
            let _ = writeln!(out, "    return Event(\n        {},\n        {{", quote(&e.name));
            for entry in &entries {
                let line = format!("            {entry},");
                match entry.split_once('(') {
                    // Black splits a long entry at its call's parenthesis.
                    Some((head, arg)) if line.len() > WIDTH => {
                        let arg = arg.trim_end_matches(')');
                        let _ = writeln!(out, "            {head}(\n                {arg}\n            ),");
                    }
                    _ => {
                        let _ = writeln!(out, "{line}");
                    }
                }
            }
            out.push_str("        },\n    )\n");
        }
        out.push_str("\n\n");
    }
    let mapping: Vec<String> = events.iter().zip(&event_fns).map(|(e, f)| format!("{}: {f}", quote(&e.name))).collect();
    out.push_str(&dict_stmt("EVENTS: dict[str, _Callable[..., Event]] = ", &mapping));
    out.push('\n');

    // The behaviour as data.
    match table_actions(content, def) {
        Some(actions) => {
            let _ = writeln!(
                out,
                "# {}",
                if matches!(def.behaviour, Behaviour::Always) {
                    "No table and no FSM: running in every state, no function, no links."
                } else {
                    "The table, per system state (None: no entry, the agent sleeps)."
                }
            );
            out.push_str("TABLE: dict[str, Action | None] | None = {\n");
            for (s, a) in content.states.iter().zip(&actions) {
                match a {
                    Some(a) => out.push_str(&action_entry(&quote(&s.name), content, def, a, 4)),
                    None => {
                        let _ = writeln!(out, "    {}: None,", quote(&s.name));
                    }
                }
            }
            out.push_str("}\nFSM: Fsm | None = None\n");
        }
        None => {
            let Behaviour::Fsm(fsm) = &def.behaviour else { unreachable!("not a table") };
            out.push_str("# The agent's FSM: its states' actions and its transitions in source order.\n");
            out.push_str("TABLE: dict[str, Action | None] | None = None\n");
            out.push_str("FSM: Fsm | None = ");
            out.push_str(&fsm_literal(content, def, fsm, 0));
        }
    }
    out.push('\n');

    // The receivers: fixed per state, and those that depend on an FSM.
    let links = links_out(content, me);
    out.push_str("# Per system state, the agents a datum reaches when this agent runs (links\n");
    out.push_str("# that do not depend on an FSM, the running readers included).\n");
    out.push_str("LINKS_OUT: dict[str, tuple[str, ...]] = {\n");
    for (s, to) in content.states.iter().zip(&links.fixed) {
        let names: Vec<String> = to.iter().map(|&a| quote(&content.agents[a as usize].name)).collect();
        out.push_str(&tuple_stmt(&format!("{}: ", quote(&s.name)), &names, 4, ","));
    }
    out.push_str("}\n");
    out.push_str("# Links out of this agent that depend on an FSM agent's FSM state:\n");
    out.push_str("# (system state, receiver, FSM agent, FSM state).\n");
    let mut fsm_links = String::new();
    let mut others: Vec<u32> = Vec::new();
    for (s, fl) in content.states.iter().zip(&links.fsm) {
        for &(to, agent, fsm_state) in fl {
            let a = &content.agents[agent as usize];
            let Behaviour::Fsm(f) = &a.behaviour else { continue };
            let _ = writeln!(
                fsm_links,
                "    (\n        {},\n        {},\n        {},\n        {},\n    ),",
                quote(&s.name),
                quote(&content.agents[to as usize].name),
                quote(&a.name),
                quote(&f.states[fsm_state as usize].name)
            );
            if agent != me && !others.contains(&agent) {
                others.push(agent);
            }
        }
    }
    if fsm_links.is_empty() {
        out.push_str("FSM_LINKS_OUT: tuple[tuple[str, str, str, str], ...] = ()\n");
    } else {
        out.push_str("FSM_LINKS_OUT: tuple[tuple[str, str, str, str], ...] = (\n");
        out.push_str(&fsm_links);
        out.push_str(")\n");
    }
    out.push_str("# The FSMs of the other agents whose FSM state decides a link out of this one.\n");
    out.push_str("OTHER_FSMS: dict[str, Fsm] = {");
    if others.is_empty() {
        out.push_str("}\n");
    } else {
        out.push('\n');
        for &o in &others {
            let a = &content.agents[o as usize];
            if let Behaviour::Fsm(f) = &a.behaviour {
                let _ = write!(out, "    {}: ", quote(&a.name));
                let lit = fsm_literal(content, a, f, 4);
                out.push_str(&lit[..lit.len() - 1]);
                out.push_str(",\n");
            }
        }
        out.push_str("}\n");
    }
    out.push_str("\n\n");

    // The handlers: one method per function.
    out.push_str("class Handlers:\n");
    let _ = writeln!(out, "    \"\"\"Your code for {}: override the method of each function.\"\"\"\n", def.name);
    out.push_str("    def on_status(self, state: str, seq: int) -> None:\n");
    out.push_str("        \"\"\"Called for every new status (the first, each change, a restart).\"\"\"\n\n");
    out.push_str("    def on_safe_mode(self, entered: bool) -> None:\n");
    out.push_str("        \"\"\"Called on entering safe mode (True: at start) and on leaving it.\"\"\"\n\n");
    out.push_str("    def on_board_restart(self) -> None:\n");
    out.push_str("        \"\"\"Called when the Bulletinboard restarted (its `seq` went back).\"\"\"\n\n");
    out.push_str("    def without_function(self, step: Step) -> None:\n");
    out.push_str("        \"\"\"A step with no function (a `wait` without one, or no table or FSM).\"\"\"\n");
    let methods = unique(def.functions.iter().map(|f| ident(snake(&f.name))).collect());
    for (f, m) in def.functions.iter().zip(&methods) {
        let _ = writeln!(out, "\n    def {m}(self, step: Step) -> None:");
        let doc = match &f.description {
            Some(d) => format!("{}: {}", f.name, one_line(d)),
            None => format!("The function {}.", f.name),
        };
        let _ = writeln!(out, "        \"\"\"{}\"\"\"", docstring_text(&doc));
        let _ = writeln!(out, "        raise NotImplementedError({})", quote(&format!("{}.{}", def.name, f.name)));
    }
    out.push_str("\n    def _situ_agent(self) -> str:\n        return AGENT\n");
    out.push_str("\n    def _situ_runner(self, session: _zenoh.Session, robot: str) -> Runner:\n");
    out.push_str("        return Runner(self, session, robot)\n");
    out.push_str("\n\ndef _dispatch(handlers: Handlers, step: Step) -> None:\n");
    for (i, (f, m)) in def.functions.iter().zip(&methods).enumerate() {
        let kw = if i == 0 { "if" } else { "elif" };
        let _ = writeln!(out, "    {kw} step.function == {}:\n        handlers.{m}(step)", quote(&f.name));
    }
    if def.functions.is_empty() {
        out.push_str("    handlers.without_function(step)\n");
    } else {
        out.push_str("    else:\n        handlers.without_function(step)\n");
    }
    out.push_str("\n\n");
    out.push_str(RUNTIME.split("# @@ GENERATED @@\n").nth(1).unwrap_or(""));
    out
}

/// The module's docstring, with an example of user code.
fn docstring(out: &mut String, def: &AgentDef, module: &str) {
    let kind = format!("{:?}", def.kind).to_lowercase();
    let what = def.description.as_deref().map(|d| format!(": {}", one_line(d))).unwrap_or_default();
    let _ = writeln!(out, "\"\"\"The agent {} ({kind}){}.", def.name, docstring_text(&what));
    out.push_str(
        "\nIts events as typed functions, its table or FSM as data, and a run loop that\n\
         joins a situ stack over Zenoh (docs/protocol.md), follows the Bulletinboard's\n\
         status and calls your handler for the function of the moment with the agents\n\
         a datum sent now reaches:\n\n",
    );
    let _ = writeln!(out, "    import {module}\n");
    let _ = writeln!(out, "    class Mine({module}.Handlers):");
    match def.functions.first() {
        Some(f) => {
            let _ = writeln!(out, "        def {}(self, step: {module}.Step) -> None:", ident(snake(&f.name)));
        }
        None => {
            let _ = writeln!(out, "        def without_function(self, step: {module}.Step) -> None:");
        }
    }
    out.push_str("            print(step.state, step.receivers, step.inputs)\n");
    out.push_str("            step.send({\"hello\": 1})\n\n");
    let _ = writeln!(out, "    {module}.run(Mine(), connect=[\"tcp/127.0.0.1:7447\"], robot=\"robot\")");
    out.push_str("\"\"\"\n\n");
}

/// Text that can stand in a one-line docstring.
fn docstring_text(s: &str) -> String {
    s.replace('\\', "/").replace('"', "'")
}

fn float(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{x:.1}")
    } else {
        format!("{x}")
    }
}

/// `prefix(...)suffix` on one line if it fits, else one parameter a line
/// with a trailing comma (black's magic trailing comma keeps it so).
fn call_stmt(prefix: &str, items: &[String], suffix: &str, indent: usize) -> String {
    let pad = " ".repeat(indent);
    let inline = format!("{pad}{prefix}{}{suffix}\n", items.join(", "));
    if inline.len() <= WIDTH + 1 || items.is_empty() {
        return inline;
    }
    let mut s = format!("{pad}{prefix}\n");
    for i in items {
        let _ = writeln!(s, "{pad}    {i},");
    }
    let _ = writeln!(s, "{pad}{suffix}");
    s
}

/// `prefix(a, b)trail` as a tuple statement (one-element tuples get their
/// comma), exploded one item a line when it does not fit.
fn tuple_stmt(prefix: &str, items: &[String], indent: usize, trail: &str) -> String {
    let pad = " ".repeat(indent);
    let inline = match items.len() {
        0 => "()".to_string(),
        1 => format!("({},)", items[0]),
        _ => format!("({})", items.join(", ")),
    };
    if pad.len() + prefix.len() + inline.len() + trail.len() <= WIDTH {
        return format!("{pad}{prefix}{inline}{trail}\n");
    }
    let mut s = format!("{pad}{prefix}(\n");
    for i in items {
        let _ = writeln!(s, "{pad}    {i},");
    }
    let _ = writeln!(s, "{pad}){trail}");
    s
}

/// A dict statement, one entry a line.
fn dict_stmt(prefix: &str, entries: &[String]) -> String {
    if entries.is_empty() {
        return format!("{prefix}{{}}\n");
    }
    let mut s = format!("{prefix}{{\n");
    for e in entries {
        let _ = writeln!(s, "    {e},");
    }
    s.push_str("}\n");
    s
}

fn mode(m: Mode) -> &'static str {
    match m {
        Mode::Running => "Mode.RUNNING",
        Mode::Waiting => "Mode.WAITING",
        Mode::Sleeping => "Mode.SLEEPING",
    }
}

/// `key: Action(...),` exploded, at `indent`.
fn action_entry(key: &str, content: &Content, def: &AgentDef, a: &Action, indent: usize) -> String {
    let pad = " ".repeat(indent);
    let names = |ids: &[u32]| -> Vec<String> { ids.iter().map(|&x| quote(&content.agents[x as usize].name)).collect() };
    let function = a.function.map_or("None".to_string(), |f| quote(&def.functions[f as usize].name));
    let mut s = format!("{pad}{key}: Action(\n");
    let _ = writeln!(s, "{pad}    mode={},", mode(a.mode));
    let _ = writeln!(s, "{pad}    function={function},");
    s.push_str(&tuple_stmt("reads_from=", &names(&a.from), indent + 4, ","));
    s.push_str(&tuple_stmt("sends_to=", &names(&a.to), indent + 4, ","));
    let _ = writeln!(s, "{pad}),");
    s
}

/// `Fsm(...)` exploded, starting after a prefix at `indent`, ending in a newline.
fn fsm_literal(content: &Content, def: &AgentDef, fsm: &crate::bundle::Fsm, indent: usize) -> String {
    let pad = " ".repeat(indent);
    let mut s = String::from("Fsm(\n");
    let _ = writeln!(s, "{pad}    initial={},", quote(&fsm.states[fsm.initial as usize].name));
    let _ = writeln!(s, "{pad}    actions={{");
    for st in &fsm.states {
        s.push_str(&action_entry(&quote(&st.name), content, def, &st.action, indent + 8));
    }
    let _ = writeln!(s, "{pad}    }},");
    let _ = writeln!(s, "{pad}    transitions=(");
    for t in &fsm.transitions {
        let p = " ".repeat(indent + 8);
        let _ = writeln!(s, "{p}Transition(");
        let _ = writeln!(s, "{p}    source={},", quote(&fsm.states[t.from as usize].name));
        let _ = writeln!(s, "{p}    target={},", quote(&fsm.states[t.to as usize].name));
        match &t.trigger {
            Trigger::States(states) => {
                let names: Vec<String> = states.iter().map(|&x| quote(&content.states[x as usize].name)).collect();
                s.push_str(&tuple_stmt("on_states=", &names, indent + 12, ","));
            }
            Trigger::Event(e) => {
                let _ = writeln!(s, "{p}    on_event={},", quote(&content.events[*e as usize].name));
            }
        }
        let _ = writeln!(s, "{p}),");
    }
    let _ = writeln!(s, "{pad}    ),");
    let _ = writeln!(s, "{pad})");
    s
}
