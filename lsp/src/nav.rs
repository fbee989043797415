//! Navigation: hover, definition, references, highlights, rename, and the
//! document's and the workspace's symbols.

use crate::index::{Occurrence, Sym};
use crate::server::{doc_path, invalid_params, refused, Answer};
use crate::text::valid_name;
use crate::world::{Analysis, World};
use serde_json::{json, Value};
use situ_compiler::model::{Behaviour, Model, StateId};
use situ_grammar::ast::{self, Item, Span};
use situ_grammar::diag::FileId;
use std::collections::BTreeMap;

/// The analysis, file and byte offset of `params.textDocument` and `params.position`.
pub fn locate<'w>(world: &'w World, params: &Value) -> Result<(&'w Analysis, FileId, usize), (i32, String)> {
    let (a, file) = analysis(world, params)?;
    let pos: lsp_types::Position = params
        .get("position")
        .cloned()
        .and_then(|p| serde_json::from_value(p).ok())
        .ok_or_else(|| invalid_params("no position"))?;
    let offset = a.lines[file.0 as usize]
        .offset(a.text(file), pos)
        .ok_or_else(|| invalid_params(format!("line {} is past the end of the document", pos.line)))?;
    Ok((a, file, offset))
}

/// The analysis and file of `params.textDocument`.
pub fn analysis<'w>(world: &'w World, params: &Value) -> Result<(&'w Analysis, FileId), (i32, String)> {
    let path = doc_path(params)?;
    world.primary(&path).ok_or_else(|| invalid_params(format!("`{}` is not open", path.display())))
}

pub fn hover(world: &World, params: &Value) -> Answer {
    let (a, file, offset) = locate(world, params)?;
    let m = &a.checked.model;
    if let Some(w) = a.index.wildcard_at(file, offset) {
        let covered: Vec<&str> = declared_states(a).into_iter().filter(|s| !w.named.iter().any(|n| n == s)).collect();
        let text = format!("`_` in the table of `{}` covers {}", w.agent, list(&covered, "no state"));
        return Ok(json!({ "contents": { "kind": "markdown", "value": text }, "range": a.range(file, w.span) }));
    }
    let Some(o) = a.index.at(file, offset) else { return Ok(Value::Null) };
    let text = match &o.sym {
        Sym::State(name) => state_hover(a, m, name),
        Sym::Agent(name) => agent_hover(a, m, name),
        Sym::Event(name) => event_hover(m, name),
        Sym::Field { event, field } => {
            let ty = m.event_id(event).and_then(|e| {
                let e = m.event(e);
                e.field(field).map(|f| e.fields[f].ty.describe())
            });
            format!("**field** `{event}.{field}`: `{}`", ty.unwrap_or_else(|| "?".into()))
        }
        Sym::Symbol { event, field, symbol } => {
            let all = a.index.symbols_of(event, field).map(|s| s.join(", ")).unwrap_or_default();
            format!("**symbol** `{symbol}` of `{event}.{field}`: `{{{all}}}`")
        }
        Sym::Function { agent, function } => function_hover(m, agent, function),
        Sym::Rule(name) => rule_hover(m, name),
        Sym::FsmState { agent, state } => format!("**FSM state** `{state}` of `{agent}`"),
        Sym::Variable { scope, name } => {
            let ty = m
                .rules
                .iter()
                .find(|r| r.item.file == scope.0 && r.item.span.start == scope.1)
                .and_then(|r| r.variables.iter().find(|v| &v.name == name))
                .map(|v| format!(": `{}`", v.ty.describe()))
                .unwrap_or_default();
            format!("**variable** `?{name}`{ty}")
        }
    };
    Ok(json!({ "contents": { "kind": "markdown", "value": text }, "range": a.range(o.file, o.span) }))
}

/// The states as declared, in order (from the index, so also with errors).
fn declared_states(a: &Analysis) -> Vec<&str> {
    let mut seen = Vec::new();
    for o in &a.index.occurrences {
        if let (Sym::State(n), true) = (&o.sym, o.def) {
            if !seen.contains(&n.as_str()) {
                seen.push(n.as_str());
            }
        }
    }
    seen
}

/// `A`, `B` and `C`; at most 12, then how many more.
fn list<S: AsRef<str>>(names: &[S], none: &str) -> String {
    if names.is_empty() {
        return none.to_string();
    }
    let shown: Vec<String> = names.iter().take(12).map(|n| format!("`{}`", n.as_ref())).collect();
    let more = names.len().saturating_sub(12);
    if more > 0 {
        format!("{} and {more} more", shown.join(", "))
    } else {
        shown.join(", ")
    }
}

fn state_hover(a: &Analysis, m: &Model, name: &str) -> String {
    let Some(id) = m.state_id(name) else { return format!("**state** `{name}` (not declared)") };
    let s = m.state(id);
    let mut flags = Vec::new();
    if m.initial == Some(id) {
        flags.push("initial");
    }
    if s.is_final {
        flags.push("final");
    }
    let flags = if flags.is_empty() { String::new() } else { format!(" ({})", flags.join(", ")) };
    let mut out = format!("**state** `{name}`{flags}");
    if let Some(d) = &s.description {
        out.push_str(&format!("\n\n{d}"));
    }
    let enter: Vec<String> = m.rules.iter().filter(|r| r.target == id).map(|r| r.name.clone()).collect();
    let leave: Vec<String> = m
        .rules
        .iter()
        .filter(|r| r.target != id && r.allowed_states().is_none_or(|s| s.contains(&id)))
        .map(|r| format!("{} → {}", r.name, m.state(r.target).name))
        .collect();
    out.push_str(&format!("\n\nentered by {}", list(&enter, "no rule")));
    out.push_str(&format!("\n\nleft by {}", list(&leave, "no rule")));
    let _ = a;
    out
}

fn agent_hover(a: &Analysis, m: &Model, name: &str) -> String {
    let Some(id) = m.agent_id(name) else { return format!("**agent** `{name}` (not declared)") };
    let ag = m.agent(id);
    let mut out = format!("**agent** `{name}` {}", ag.kind.keyword());
    if let Some(d) = &ag.description {
        out.push_str(&format!(" — {d}"));
    }
    if let Some(hz) = ag.rate_hz {
        out.push_str(&format!("\n\nrate {hz} Hz"));
    }
    match ag.stale_after {
        Some(ns) => out.push_str(&format!("\n\nstale after {}", duration(ns))),
        None => out.push_str("\n\nnever stale"),
    }
    let events: Vec<&str> = ag.events.iter().map(|e| m.event(*e).name.as_str()).collect();
    out.push_str(&format!("\n\nevents {}", list(&events, "none")));
    let behaviour = match &ag.behaviour {
        Behaviour::Always => None,
        Behaviour::Table(t) => Some(t.origin),
        Behaviour::Fsm(f) => Some(f.origin),
    };
    match behaviour {
        None => out.push_str("\n\nno table: running in every state"),
        Some(o) if (o.file.0 as usize) < a.paths.len() => {
            let all = a.text(o.file);
            let line = all.get(..o.span.start).and_then(|t| t.rfind('\n')).map_or(0, |i| i + 1);
            let indent = all.get(line..o.span.start).filter(|i| i.trim().is_empty()).map_or(0, str::len);
            let text = all.get(o.span.start..o.span.end).unwrap_or("");
            let lines: Vec<&str> = text
                .lines()
                .map(|l| if l.len() >= indent && l[..indent].trim().is_empty() { &l[indent..] } else { l })
                .collect();
            out.push_str(&format!("\n\n```situ\n{}\n```", lines.join("\n")));
        }
        Some(_) => {}
    }
    out
}

fn duration(ns: u64) -> String {
    match ns {
        n if n % 1_000_000_000 == 0 => format!("{}s", n / 1_000_000_000),
        n if n % 1_000_000 == 0 => format!("{}ms", n / 1_000_000),
        n if n % 1_000 == 0 => format!("{}us", n / 1_000),
        n => format!("{n}ns"),
    }
}

fn event_hover(m: &Model, name: &str) -> String {
    let Some(id) = m.event_id(name) else { return format!("**event** `{name}` (not declared)") };
    let e = m.event(id);
    let fields: Vec<String> = e.fields.iter().map(|f| format!("{}: {}", f.name, f.ty.describe())).collect();
    let payload = if fields.is_empty() { "no payload".to_string() } else { format!("`{{ {} }}`", fields.join(", ")) };
    let mut out = format!("**event** `{name}` of `{}`: {payload}", m.agent(e.agent).name);
    if let Some(d) = &e.description {
        out.push_str(&format!("\n\n{d}"));
    }
    out
}

fn function_hover(m: &Model, agent: &str, function: &str) -> String {
    let mut out = format!("**function** `{function}` of `{agent}`");
    if let Some(f) = m.agent_id(agent).and_then(|id| m.agent(id).functions.iter().find(|f| f.name == function)) {
        if let Some(d) = &f.description {
            out.push_str(&format!(" — {d}"));
        }
    }
    out
}

fn rule_hover(m: &Model, name: &str) -> String {
    let Some(r) = m.rules.iter().find(|r| r.name == name) else { return format!("**rule** `{name}`") };
    let mut out = format!("**rule** `{name}`: salience {}, then `{}`", r.salience, m.state(r.target).name);
    if let Some(d) = &r.description {
        out.push_str(&format!("\n\n{d}"));
    }
    let from: Vec<&str> = match r.allowed_states() {
        Some(s) => s.iter().map(|s: &StateId| m.state(*s).name.as_str()).collect(),
        None => vec!["every state"],
    };
    out.push_str(&format!("\n\nfires in {}", list(&from, "no state")));
    out
}

fn location(a: &Analysis, o: &Occurrence) -> Value {
    a.location(o.file, o.span)
}

pub fn definition(world: &World, params: &Value) -> Answer {
    let (a, file, offset) = locate(world, params)?;
    let Some(o) = a.index.at(file, offset) else { return Ok(Value::Null) };
    Ok(a.index.definition(&o.sym).map_or(Value::Null, |d| location(a, d)))
}

pub fn references(world: &World, params: &Value) -> Answer {
    let (a, file, offset) = locate(world, params)?;
    let Some(o) = a.index.at(file, offset) else { return Ok(json!([])) };
    let with_decl = params.pointer("/context/includeDeclaration").and_then(Value::as_bool).unwrap_or(true);
    let refs: Vec<Value> = a.index.references(&o.sym).filter(|r| with_decl || !r.def).map(|r| location(a, r)).collect();
    Ok(json!(refs))
}

pub fn highlight(world: &World, params: &Value) -> Answer {
    let (a, file, offset) = locate(world, params)?;
    let Some(o) = a.index.at(file, offset) else { return Ok(json!([])) };
    let out: Vec<Value> = a
        .index
        .references(&o.sym)
        .filter(|r| r.file == file)
        .map(|r| json!({ "range": a.range(file, r.span), "kind": if r.def { 3 } else { 2 } }))
        .collect();
    Ok(json!(out))
}

pub fn prepare_rename(world: &World, params: &Value) -> Answer {
    let (a, file, offset) = locate(world, params)?;
    let o = a.index.at(file, offset).ok_or_else(|| refused("no name to rename here"))?;
    Ok(json!({ "range": a.range(file, o.span), "placeholder": o.sym.name() }))
}

pub fn rename(world: &World, params: &Value) -> Answer {
    let (a, file, offset) = locate(world, params)?;
    let new = params.get("newName").and_then(Value::as_str).ok_or_else(|| invalid_params("no newName"))?;
    let o = a.index.at(file, offset).ok_or_else(|| refused("no name to rename here"))?;
    valid_name(new).map_err(refused)?;
    if new != o.sym.name() && a.index.is_declared(&o.sym, new) {
        let what = o.sym.kind();
        let place = a.index.definition(&o.sym.renamed(new)).map(|d| {
            let (line, col) = a.checked.sources.get(d.file).line_col(d.span.start);
            format!(" at {}:{line}:{col}", a.checked.sources.get(d.file).name)
        });
        return Err(refused(format!("there is already a {what} `{new}`{}", place.unwrap_or_default())));
    }
    let mut changes: BTreeMap<String, Vec<Value>> = BTreeMap::new();
    for r in a.index.references(&o.sym) {
        changes.entry(a.uri(r.file)).or_default().push(json!({ "range": a.range(r.file, r.span), "newText": new }));
    }
    Ok(json!({ "changes": changes }))
}

fn symbol(a: &Analysis, file: FileId, name: &str, kind: u32, span: Span, sel: Span, children: Vec<Value>) -> Value {
    let name = if name.is_empty() { "?" } else { name };
    json!({
        "name": name,
        "kind": kind,
        "range": a.range(file, span),
        "selectionRange": a.range(file, sel),
        "children": children,
    })
}

// The protocol's SymbolKind numbers.
const FILE: u32 = 1;
const MODULE: u32 = 2;
const NAMESPACE: u32 = 3;
const CLASS: u32 = 5;
const METHOD: u32 = 6;
const PROPERTY: u32 = 7;
const FIELD: u32 = 8;
const FUNCTION: u32 = 12;
const ENUM_MEMBER: u32 = 22;
const EVENT: u32 = 24;
const OPERATOR: u32 = 25;

pub fn document_symbols(world: &World, params: &Value) -> Answer {
    let (a, file) = analysis(world, params)?;
    let mut out = Vec::new();
    for item in &a.asts[file.0 as usize].items {
        let s = |name: &str, kind, sel| symbol(a, file, name, kind, item.span(), sel, Vec::new());
        out.push(match item {
            Item::Include(i) => s(&i.path.value, FILE, i.path.span),
            Item::States(b) => {
                let kids = b
                    .states
                    .iter()
                    .map(|st| symbol(a, file, &st.name.name, ENUM_MEMBER, st.span, st.name.span, vec![]))
                    .collect();
                symbol(a, file, "states", NAMESPACE, b.span, b.span, kids)
            }
            Item::Agent(ag) => {
                let mut kids = Vec::new();
                for m in &ag.members {
                    match m {
                        ast::AgentMember::Event(e) => {
                            let fields = e
                                .fields
                                .iter()
                                .map(|f| symbol(a, file, &f.name.name, FIELD, f.span, f.name.span, vec![]))
                                .collect();
                            kids.push(symbol(a, file, &e.name.name, EVENT, e.span, e.name.span, fields));
                        }
                        ast::AgentMember::Function(f) => {
                            kids.push(symbol(a, file, &f.name.name, FUNCTION, f.span, f.name.span, vec![]))
                        }
                        ast::AgentMember::Table(t) => {
                            kids.push(symbol(a, file, "table", OPERATOR, t.span, t.span, vec![]))
                        }
                        ast::AgentMember::Fsm(f) => kids.push(symbol(a, file, "fsm", OPERATOR, f.span, f.span, vec![])),
                        _ => {}
                    }
                }
                symbol(a, file, &ag.name.name, CLASS, ag.span, ag.name.span, kids)
            }
            Item::Rule(r) => s(&r.name.name, METHOD, r.name.span),
            Item::Test(t) => s(&t.name.value, METHOD, t.name.span),
            Item::Property(p) => s(&p.name.value, PROPERTY, p.name.span),
            Item::Script(sc) => s(&sc.name.value, MODULE, sc.name.span),
        });
    }
    Ok(json!(out))
}

fn kind_of(sym: &Sym) -> u32 {
    match sym {
        Sym::State(_) | Sym::Symbol { .. } => ENUM_MEMBER,
        Sym::Agent(_) => CLASS,
        Sym::Event(_) => EVENT,
        Sym::Field { .. } => FIELD,
        Sym::Function { .. } => FUNCTION,
        Sym::Rule(_) => METHOD,
        Sym::FsmState { .. } => ENUM_MEMBER,
        Sym::Variable { .. } => 13,
    }
}

fn container(sym: &Sym) -> Option<String> {
    match sym {
        Sym::Field { event, .. } => Some(event.clone()),
        Sym::Symbol { event, field, .. } => Some(format!("{event}.{field}")),
        Sym::Function { agent, .. } | Sym::FsmState { agent, .. } => Some(agent.clone()),
        _ => None,
    }
}

/// The declarations of every analysis whose name contains the query (any case).
pub fn workspace_symbols(world: &World, params: &Value) -> Answer {
    let query = params.get("query").and_then(Value::as_str).unwrap_or("").to_lowercase();
    let mut seen = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for a in world.analyses.values() {
        for o in a.index.occurrences.iter().filter(|o| o.def && !matches!(o.sym, Sym::Variable { .. })) {
            if !o.sym.name().to_lowercase().contains(&query) || !seen.insert((a.uri(o.file), o.span.start)) {
                continue;
            }
            let mut v = json!({ "name": o.sym.name(), "kind": kind_of(&o.sym), "location": location(a, o) });
            if let Some(c) = container(&o.sym) {
                v["containerName"] = json!(c);
            }
            out.push(v);
            if out.len() >= 1000 {
                return Ok(json!(out));
            }
        }
    }
    Ok(json!(out))
}
