//! Navigation: hover, definition, references, highlights, rename, and the
//! document's and the workspace's symbols.

use crate::data::{Location, Refusal, TextEdit, WorkspaceEdit};
use crate::index::{Occurrence, Sym};
use crate::text::valid_name;
use crate::world::{Analysis, World};
use lsp_types::{Range, SymbolKind};
use situ_compiler::model::{Behaviour, Model, StateId};
use situ_grammar::ast::{self, Item, Span};
use situ_grammar::diag::FileId;

/// What the name (or the table's `_`) under the cursor is: markdown.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Hover {
    pub markdown: String,
    pub range: Range,
}

pub fn hover(a: &Analysis, file: FileId, offset: usize) -> Option<Hover> {
    let m = &a.checked.model;
    if let Some(w) = a.index.wildcard_at(file, offset) {
        let covered: Vec<&str> = declared_states(a).into_iter().filter(|s| !w.named.iter().any(|n| n == s)).collect();
        let text = format!("`_` in the table of `{}` covers {}", w.agent, list(&covered, "no state"));
        return Some(Hover { markdown: text, range: a.range(file, w.span) });
    }
    let o = a.index.at(file, offset)?;
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
    Some(Hover { markdown: text, range: a.range(o.file, o.span) })
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

fn location(a: &Analysis, o: &Occurrence) -> Location {
    a.location(o.file, o.span)
}

/// Where the name under the cursor is declared.
pub fn definition(a: &Analysis, file: FileId, offset: usize) -> Option<Location> {
    let o = a.index.at(file, offset)?;
    a.index.definition(&o.sym).map(|d| location(a, d))
}

/// Every place of the name under the cursor (`with_declaration`: its
/// declaration too).
pub fn references(a: &Analysis, file: FileId, offset: usize, with_declaration: bool) -> Vec<Location> {
    let Some(o) = a.index.at(file, offset) else { return Vec::new() };
    a.index.references(&o.sym).filter(|r| with_declaration || !r.def).map(|r| location(a, r)).collect()
}

/// A place of the name under the cursor in the same document.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Highlight {
    pub range: Range,
    /// Its declaration (shown as a write), not a use (a read).
    pub declaration: bool,
}

pub fn highlight(a: &Analysis, file: FileId, offset: usize) -> Vec<Highlight> {
    let Some(o) = a.index.at(file, offset) else { return Vec::new() };
    a.index
        .references(&o.sym)
        .filter(|r| r.file == file)
        .map(|r| Highlight { range: a.range(file, r.span), declaration: r.def })
        .collect()
}

/// The name a rename would change, and its text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RenamePlace {
    pub range: Range,
    pub placeholder: String,
}

pub fn prepare_rename(a: &Analysis, file: FileId, offset: usize) -> Result<RenamePlace, Refusal> {
    let o = a.index.at(file, offset).ok_or_else(|| Refusal("no name to rename here".into()))?;
    Ok(RenamePlace { range: a.range(file, o.span), placeholder: o.sym.name().to_string() })
}

/// Every place of the name under the cursor, renamed `new`; refused where
/// there is no name, where `new` is not a name, or where it is taken.
pub fn rename(a: &Analysis, file: FileId, offset: usize, new: &str) -> Result<WorkspaceEdit, Refusal> {
    let o = a.index.at(file, offset).ok_or_else(|| Refusal("no name to rename here".into()))?;
    valid_name(new).map_err(|e| Refusal(e.to_string()))?;
    if new != o.sym.name() && a.index.is_declared(&o.sym, new) {
        let what = o.sym.kind();
        let place = a.index.definition(&o.sym.renamed(new)).map(|d| {
            let (line, col) = a.checked.sources.get(d.file).line_col(d.span.start);
            format!(" at {}:{line}:{col}", a.checked.sources.get(d.file).name)
        });
        return Err(Refusal(format!("there is already a {what} `{new}`{}", place.unwrap_or_default())));
    }
    let mut changes = WorkspaceEdit::new();
    for r in a.index.references(&o.sym) {
        changes
            .entry(a.uri(r.file))
            .or_default()
            .push(TextEdit { range: a.range(r.file, r.span), new_text: new.into() });
    }
    Ok(changes)
}

/// A declaration of the document, with those it holds.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Symbol {
    pub name: String,
    pub kind: SymbolKind,
    /// The whole declaration.
    pub range: Range,
    /// Its name.
    pub selection: Range,
    pub children: Vec<Symbol>,
}

fn symbol(
    a: &Analysis,
    file: FileId,
    name: &str,
    kind: SymbolKind,
    span: Span,
    sel: Span,
    children: Vec<Symbol>,
) -> Symbol {
    let name = if name.is_empty() { "?" } else { name };
    Symbol { name: name.to_string(), kind, range: a.range(file, span), selection: a.range(file, sel), children }
}

const FILE: SymbolKind = SymbolKind::FILE;
const MODULE: SymbolKind = SymbolKind::MODULE;
const NAMESPACE: SymbolKind = SymbolKind::NAMESPACE;
const CLASS: SymbolKind = SymbolKind::CLASS;
const METHOD: SymbolKind = SymbolKind::METHOD;
const PROPERTY: SymbolKind = SymbolKind::PROPERTY;
const FIELD: SymbolKind = SymbolKind::FIELD;
const FUNCTION: SymbolKind = SymbolKind::FUNCTION;
const ENUM_MEMBER: SymbolKind = SymbolKind::ENUM_MEMBER;
const EVENT: SymbolKind = SymbolKind::EVENT;
const OPERATOR: SymbolKind = SymbolKind::OPERATOR;

/// The document's declarations, as a tree.
pub fn document_symbols(a: &Analysis, file: FileId) -> Vec<Symbol> {
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
    out
}

fn kind_of(sym: &Sym) -> SymbolKind {
    match sym {
        Sym::State(_) | Sym::Symbol { .. } => ENUM_MEMBER,
        Sym::Agent(_) => CLASS,
        Sym::Event(_) => EVENT,
        Sym::Field { .. } => FIELD,
        Sym::Function { .. } => FUNCTION,
        Sym::Rule(_) => METHOD,
        Sym::FsmState { .. } => ENUM_MEMBER,
        Sym::Variable { .. } => SymbolKind::VARIABLE,
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

/// A declaration found by a workspace search.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WorkspaceSymbol {
    pub name: String,
    pub kind: SymbolKind,
    pub location: Location,
    /// The event, field or agent it belongs to.
    pub container: Option<String>,
}

/// The declarations of every analysis whose name contains the query (any
/// case); at most 1,000.
pub fn workspace_symbols(world: &World, query: &str) -> Vec<WorkspaceSymbol> {
    let query = query.to_lowercase();
    let mut seen = std::collections::BTreeSet::new();
    let mut out = Vec::new();
    for a in world.analyses.values() {
        for o in a.index.occurrences.iter().filter(|o| o.def && !matches!(o.sym, Sym::Variable { .. })) {
            if !o.sym.name().to_lowercase().contains(&query) || !seen.insert((a.uri(o.file), o.span.start)) {
                continue;
            }
            out.push(WorkspaceSymbol {
                name: o.sym.name().to_string(),
                kind: kind_of(&o.sym),
                location: location(a, o),
                container: container(&o.sym),
            });
            if out.len() >= 1000 {
                return out;
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{world_of, SMALL};

    /// The offset of the `nth` `needle` of `SMALL`, `into` bytes in.
    fn offset(needle: &str, nth: usize, into: usize) -> usize {
        SMALL.match_indices(needle).nth(nth).unwrap().0 + into
    }

    #[test]
    fn hover_says_what_a_name_is() {
        let (w, path) = world_of("nav-hover", SMALL);
        let (a, file) = w.primary(&path).unwrap();
        let h = hover(a, file, offset("IT", 0, 1)).unwrap();
        assert!(h.markdown.starts_with("**state** `IT` (initial)"), "{}", h.markdown);
        assert_eq!((h.range.start.line, h.range.start.character, h.range.end.character), (2, 9, 11));
        assert!(hover(a, file, offset("event F", 0, 7)).unwrap().markdown.starts_with("**event** `F` of `A`"));
        assert_eq!(hover(a, file, offset("rule", 0, 4)), None, "a space is no name");
    }

    #[test]
    fn definition_references_and_highlights_of_a_name() {
        let (w, path) = world_of("nav-refs", SMALL);
        let (a, file) = w.primary(&path).unwrap();
        let use_of_e = offset(" E then", 0, 1);
        let def = definition(a, file, use_of_e).unwrap();
        assert_eq!((def.range.start.line, def.range.start.character), (4, 10));
        assert!(def.uri.ends_with("/nav-refs.situ"), "{}", def.uri);
        assert_eq!(references(a, file, use_of_e, true).len(), 2);
        assert_eq!(references(a, file, use_of_e, false).len(), 1);
        let marks = highlight(a, file, use_of_e);
        assert_eq!(marks.iter().filter(|h| h.declaration).count(), 1);
        assert_eq!(marks.len(), 2);
        assert!(references(a, file, offset("//", 0, 1), true).is_empty());
    }

    #[test]
    fn rename_edits_every_place_or_refuses() {
        let (w, path) = world_of("nav-rename", SMALL);
        let (a, file) = w.primary(&path).unwrap();
        let it = offset("IT", 1, 0);
        assert_eq!(prepare_rename(a, file, it).unwrap().placeholder, "IT");
        let edit = rename(a, file, it, "IDLE").unwrap();
        let edits = &edit[&a.uri(file)];
        assert_eq!(edits.len(), 3, "{edits:?}");
        assert!(edits.iter().all(|e| e.new_text == "IDLE"));
        let taken = rename(a, file, it, "RD").unwrap_err();
        assert!(taken.0.starts_with("there is already a state `RD` at "), "{}", taken.0);
        assert!(rename(a, file, it, "state").unwrap_err().0.contains("keyword"));
        assert_eq!(rename(a, file, offset("//", 0, 0), "X"), Err(Refusal("no name to rename here".into())));
    }

    #[test]
    fn the_document_symbols_are_a_tree() {
        let (w, path) = world_of("nav-symbols", SMALL);
        let (a, file) = w.primary(&path).unwrap();
        let symbols = document_symbols(a, file);
        let names: Vec<(&str, SymbolKind)> = symbols.iter().map(|s| (s.name.as_str(), s.kind)).collect();
        assert_eq!(names, [("states", NAMESPACE), ("A", CLASS), ("r", METHOD)]);
        let states: Vec<&str> = symbols[0].children.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(states, ["IT", "RD"]);
        let agent: Vec<&str> = symbols[1].children.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(agent, ["E", "F", "f", "table"]);
        assert_eq!((symbols[1].range.start.line, symbols[1].range.end.line), (3, 10));
        assert_eq!(symbols[1].selection.start.character, 6);
    }

    #[test]
    fn workspace_symbols_match_any_case() {
        let (w, _) = world_of("nav-workspace", SMALL);
        let found: Vec<(String, Option<String>)> =
            workspace_symbols(&w, "f").into_iter().map(|s| (s.name, s.container)).collect();
        assert_eq!(found, [("F".to_string(), None), ("f".to_string(), Some("A".to_string()))]);
    }
}
