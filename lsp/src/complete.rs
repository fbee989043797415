//! Completion that knows the place: the tokens before the cursor say which
//! block it is in (`state in {…}`, a table, an FSM, a pattern's
//! parentheses, a test, a script) and what came just before.

use crate::data::TextEdit;
use crate::index::{Index, Sym};
use crate::tokens::{lex, Tok, Token};
use crate::world::Analysis;
use lsp_types::CompletionItemKind as Kind;
use situ_grammar::ast::Span;
use situ_grammar::diag::FileId;

const FUNCTION: Kind = Kind::FUNCTION;
const FIELD: Kind = Kind::FIELD;
const CLASS: Kind = Kind::CLASS;
const UNIT: Kind = Kind::UNIT;
const KEYWORD: Kind = Kind::KEYWORD;
const SNIPPET: Kind = Kind::SNIPPET;
const ENUM_MEMBER: Kind = Kind::ENUM_MEMBER;
const EVENT: Kind = Kind::EVENT;

/// One proposal: the edit puts `label` (or, for a snippet, its body) in place
/// of the word being typed.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Item {
    pub label: String,
    pub kind: Kind,
    pub detail: Option<String>,
    pub edit: TextEdit,
    /// The edit's text is a snippet, with `${1:…}` placeholders.
    pub snippet: bool,
}

/// The block the cursor is in.
#[derive(Debug, Clone, PartialEq)]
enum Frame {
    StateSet,
    States,
    Agent(String),
    Payload,
    Table(String),
    Fsm(String),
    Rule,
    Test,
    Property,
    Script,
    /// The parentheses of an event (a pattern, an instance).
    Event(String),
    Attribute,
    Other,
}

struct Items<'a> {
    out: Vec<Item>,
    replace: lsp_types::Range,
    index: &'a Index,
}

impl Items<'_> {
    fn add(&mut self, label: &str, kind: Kind, detail: Option<&str>) {
        if self.out.iter().any(|i| i.label == label) {
            return;
        }
        self.out.push(Item {
            label: label.into(),
            kind,
            detail: detail.map(str::to_string),
            edit: TextEdit { range: self.replace, new_text: label.into() },
            snippet: false,
        });
    }

    fn keywords(&mut self, words: &[&str]) {
        for w in words {
            self.add(w, KEYWORD, None);
        }
    }

    fn defs(&mut self, pick: impl Fn(&Sym) -> bool, kind: Kind, detail: &str) {
        let names: Vec<String> =
            self.index.occurrences.iter().filter(|o| o.def && pick(&o.sym)).map(|o| o.sym.name().to_string()).collect();
        for n in names {
            self.add(&n, kind, Some(detail));
        }
    }

    fn states(&mut self) {
        self.defs(|s| matches!(s, Sym::State(_)), ENUM_MEMBER, "state");
    }
    fn agents(&mut self) {
        self.defs(|s| matches!(s, Sym::Agent(_)), CLASS, "agent");
    }
    fn events(&mut self) {
        let mut events: Vec<(String, String)> =
            self.index.events.iter().map(|(e, (a, _))| (e.clone(), format!("event of {a}"))).collect();
        events.sort();
        for (e, d) in events {
            self.add(&e, EVENT, Some(&d));
        }
    }
    fn events_of(&mut self, agent: &str) {
        let mut events: Vec<String> =
            self.index.events.iter().filter(|(_, (a, _))| a == agent).map(|(e, _)| e.clone()).collect();
        events.sort();
        for e in events {
            self.add(&e, EVENT, Some(&format!("event of {agent}")));
        }
    }
    fn functions_of(&mut self, agent: &str) {
        self.defs(|s| matches!(s, Sym::Function { agent: a, .. } if a == agent), FUNCTION, "function");
    }
    fn fsm_states_of(&mut self, agent: &str) {
        self.defs(|s| matches!(s, Sym::FsmState { agent: a, .. } if a == agent), ENUM_MEMBER, "FSM state");
    }
    fn fields_of(&mut self, event: &str) {
        let fields = self.index.events.get(event).map(|(_, f)| f.clone()).unwrap_or_default();
        for (f, ty) in fields {
            self.add(&f, FIELD, Some(&ty));
        }
    }
    fn values_of(&mut self, event: &str, field: &str) {
        if let Some(syms) = self.index.symbols_of(event, field).map(<[String]>::to_vec) {
            for s in syms {
                self.add(&s, ENUM_MEMBER, Some(&format!("symbol of {event}.{field}")));
            }
        }
        let is_bool =
            self.index.events.get(event).is_some_and(|(_, f)| f.iter().any(|(n, t)| n == field && t == "bool"));
        if is_bool {
            self.keywords(&["true", "false"]);
        }
    }
    fn snippet(&mut self, label: &str, body: &str) {
        self.out.push(Item {
            label: label.into(),
            kind: SNIPPET,
            detail: None,
            edit: TextEdit { range: self.replace, new_text: body.into() },
            snippet: true,
        });
    }
}

fn word<'t>(text: &'t str, t: Option<&Token>) -> &'t str {
    t.map_or("", |t| &text[t.span.start..t.span.end])
}

/// The blocks open at the end of `toks`, outermost first.
fn frames(text: &str, toks: &[Token]) -> Vec<Frame> {
    let mut stack: Vec<Frame> = Vec::new();
    let mut item: Option<(String, String)> = None; // keyword, name
    for (i, t) in toks.iter().enumerate() {
        let w = word(text, Some(t));
        let back = |k: usize| if i >= k { word(text, toks.get(i - k)) } else { "" };
        if stack.is_empty() && t.kind == Tok::Keyword {
            if let "states" | "agent" | "rule" | "test" | "property" | "include" = w {
                let name = toks.get(i + 1).filter(|n| n.kind == Tok::Name).map(|n| word(text, Some(n)).to_string());
                item = Some((w.to_string(), name.unwrap_or_default()));
            }
        }
        if stack.is_empty() && t.kind == Tok::Name && w == "script" {
            item = Some(("script".into(), String::new()));
        }
        match w {
            "{" => {
                let agent =
                    || match stack.iter().rev().find_map(|f| if let Frame::Agent(a) = f { Some(a) } else { None }) {
                        Some(a) => a.clone(),
                        None => String::new(),
                    };
                let f = if back(1) == "in" {
                    Frame::StateSet
                } else if back(1) == "table" {
                    Frame::Table(agent())
                } else if back(1) == "fsm" {
                    Frame::Fsm(agent())
                } else if back(2) == "event" {
                    Frame::Payload
                } else if stack.is_empty() {
                    match item.as_ref().map(|(k, n)| (k.as_str(), n.clone())) {
                        Some(("states", _)) => Frame::States,
                        Some(("agent", n)) => Frame::Agent(n),
                        Some(("rule", _)) => Frame::Rule,
                        Some(("test", _)) => Frame::Test,
                        Some(("property", _)) => Frame::Property,
                        Some(("script", _)) => Frame::Script,
                        _ => Frame::Other,
                    }
                } else {
                    Frame::Other
                };
                stack.push(f);
            }
            "(" if t.kind == Tok::Punct => {
                let f = match toks.get(i.wrapping_sub(1)) {
                    Some(p) if p.kind == Tok::Name => Frame::Event(word(text, Some(p)).to_string()),
                    _ if back(1) == "allow" => Frame::Attribute,
                    _ => Frame::Other,
                };
                stack.push(f);
            }
            "}" | ")" => {
                stack.pop();
            }
            _ => {}
        }
    }
    stack
}

/// The list of names the cursor is in (`from A, B, |`): the keyword before it.
fn list_head<'t>(text: &'t str, toks: &[Token]) -> &'t str {
    let mut i = toks.len();
    while i > 0 {
        i -= 1;
        let w = word(text, toks.get(i));
        if w == "," || toks[i].kind == Tok::Name {
            continue;
        }
        return w;
    }
    ""
}

/// What may be typed at `offset`, for the block it is in and the tokens
/// before it.
pub fn completion(a: &Analysis, file: FileId, offset: usize) -> Vec<Item> {
    let text = a.text(file);
    let mut offset = offset.min(text.len());
    while !text.is_char_boundary(offset) {
        offset -= 1;
    }
    let mut toks = lex(&text[..offset]);
    let lines = &a.lines[file.0 as usize];
    let mut replace = Span::new(offset, offset);
    let mut number_unit = None;
    if let Some(last) = toks.last().copied().filter(|t| t.span.end == offset) {
        match last.kind {
            Tok::Comment | Tok::Str => return Vec::new(),
            Tok::Name | Tok::Keyword => {
                replace = last.span;
                toks.pop();
            }
            Tok::Number => {
                let digits = text[last.span.start..offset]
                    .find(|c: char| c.is_ascii_alphabetic() && c != 'e' && c != 'E')
                    .map_or(offset, |i| last.span.start + i);
                replace = Span::new(digits, offset);
                number_unit = Some(());
            }
            Tok::Variable => return Vec::new(),
            Tok::Punct => {}
        }
    }
    let mut it = Items { out: Vec::new(), replace: lines.range(text, replace), index: &a.index };
    if number_unit.is_some() {
        for (u, d) in [
            ("ms", "milliseconds"),
            ("s", "seconds"),
            ("min", "minutes"),
            ("us", "microseconds"),
            ("ns", "nanoseconds"),
            ("Hz", "hertz"),
        ] {
            it.add(u, UNIT, Some(d));
        }
        return it.out;
    }
    let stack = frames(text, &toks);
    let prev = word(text, toks.last());
    let prev2 = if toks.len() >= 2 { word(text, toks.get(toks.len() - 2)) } else { "" };
    let head = list_head(text, &toks);
    match stack.last().cloned() {
        None => {
            it.keywords(&["states", "agent", "rule", "test", "property", "script", "include"]);
            it.snippet("rule …", "rule ${1:name} salience ${2:0} {\n    when state == ${3:STATE} and ${4:EVENT}\n    then ${5:TARGET}\n}");
            it.snippet("agent …", "agent ${1:Name} ${2|sensor,actuator,processing,interface|} \"${3:description}\" {\n    event ${4:EVENT} \"${5:description}\"\n    function ${6:work} \"${7:description}\"\n    table {\n        _ => run ${6:work}()\n    }\n}");
            it.snippet(
                "test …",
                "test \"${1:name}\" {\n    given state ${2:STATE}\n    on ${3:EVENT}\n    expect state ${4:STATE}\n}",
            );
        }
        Some(Frame::StateSet) => it.states(),
        Some(Frame::States) => it.keywords(&["initial", "final"]),
        Some(Frame::Payload) => it.keywords(&["f64", "i64", "bool"]),
        Some(Frame::Attribute) => {
            // A map's warnings are not allowed in rules: only the rules' own.
            let rules_warnings =
                |c: &&situ_compiler::codes::Code| c.code.starts_with('W') && !situ_compiler::codes::is_ros2_map(c.code);
            for c in situ_compiler::codes::ALL.iter().filter(rules_warnings) {
                it.add(c.code, KEYWORD, Some(c.title));
            }
        }
        Some(Frame::Agent(_)) => {
            it.keywords(&["event", "function", "table", "fsm", "rate", "stale", "commands"]);
            it.snippet("table …", "table {\n    ${1:STATE} => run ${2:work}()\n    _ => sleep\n}");
        }
        Some(Frame::Table(agent)) | Some(Frame::Fsm(agent)) => {
            let fsm = matches!(stack.last(), Some(Frame::Fsm(_)));
            match prev {
                "=>" => it.keywords(&["run", "wait", "sleep"]),
                "run" | "wait" => {
                    it.functions_of(&agent);
                    // The agent being written may not parse yet: its functions as written so far.
                    let start = toks.iter().rposition(|t| word(text, Some(t)) == "agent").unwrap_or(0);
                    for w in toks[start..].windows(2) {
                        if word(text, Some(&w[0])) == "function" && w[1].kind == Tok::Name {
                            it.add(word(text, Some(&w[1])), FUNCTION, Some("function"));
                        }
                    }
                }
                "on" if fsm => {
                    it.events_of(&agent);
                    it.keywords(&["state"]);
                }
                "->" if fsm => it.fsm_states_of(&agent),
                "==" | "!=" => it.states(),
                _ if head == "from" || head == "to" => {
                    it.agents();
                    if !agent.is_empty() {
                        it.add(&agent, CLASS, Some("agent"));
                    }
                }
                ")" => it.keywords(&["from", "to"]),
                _ if fsm => {
                    it.fsm_states_of(&agent);
                    it.keywords(&["initial"]);
                }
                _ => {
                    it.states();
                    it.add("_", KEYWORD, Some("every other state"));
                }
            }
        }
        Some(Frame::Event(event)) => {
            if ["==", "!=", ":"].contains(&prev) {
                it.values_of(&event, prev2);
            } else if prev == "(" || prev == "," {
                it.fields_of(&event);
            }
        }
        Some(Frame::Rule) | Some(Frame::Property) => match prev {
            "then" | "==" | "!=" => it.states(),
            "stale" => it.agents(),
            "salience" => {}
            "state" => it.keywords(&["in", "not"]),
            _ if prev2 == "state" && prev == "not" => it.keywords(&["in"]),
            _ if matches!(stack.last(), Some(Frame::Property)) && prev == "link" => it.agents(),
            _ => {
                it.keywords(&["state", "not", "stale", "and"]);
                if matches!(stack.last(), Some(Frame::Rule)) {
                    it.keywords(&["when", "then", "within"]);
                } else {
                    it.keywords(&["always", "never", "next", "eventually", "within", "or", "link"]);
                    it.agents();
                }
                it.events();
            }
        },
        Some(Frame::Test) => match prev {
            "state" => it.states(),
            "runs" => it.functions_of(prev2),
            "link" | "->" => it.agents(),
            _ if head == "on" || head == "given" => {
                it.events();
                if head == "given" {
                    it.keywords(&["state"]);
                }
            }
            _ if head == "expect" => {
                it.keywords(&["state", "link", "no"]);
                it.agents();
            }
            _ if toks.last().is_some_and(|t| t.kind == Tok::Name)
                && a.index.definition(&Sym::Agent(prev.into())).is_some() =>
            {
                it.keywords(&["running", "sleeping", "waiting", "runs"])
            }
            _ => it.keywords(&["given", "on", "expect"]),
        },
        Some(Frame::Script) => match prev {
            "." => it.events_of(prev2),
            "silent" => it.agents(),
            _ if toks.last().is_some_and(|t| t.kind == Tok::Number) => {
                it.agents();
                it.events();
            }
            _ => it.keywords(&["at", "every", "silent", "random", "seed", "from", "to"]),
        },
        Some(Frame::Other) => it.keywords(&[]),
    }
    it.out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::{Doc, World};
    use std::path::PathBuf;

    fn labels(src: &str) -> Vec<String> {
        let at = src.find('|').unwrap();
        let text = src.replace('|', "");
        let path = PathBuf::from("/tmp/situ-lsp-complete.situ");
        let mut w = World::default();
        w.open(path.clone(), Doc::new("file:///tmp/situ-lsp-complete.situ".into(), text, 1));
        w.refresh_fully();
        let (a, file) = w.primary(&path).unwrap();
        completion(a, file, at).into_iter().map(|i| i.label).collect()
    }

    const DECLS: &str = "states { IT initial RS RO }\n\
        agent L sensor { event OBS { d: f64, side: {left, right} } event NOB function f function g\n\
          table { RS => run f() _ => sleep } }\n";

    #[test]
    fn completion_knows_the_place() {
        let at = |tail: &str| labels(&format!("{DECLS}{tail}"));
        assert_eq!(at("rule r { when state in {RS, |} then RO }"), ["IT", "RS", "RO"]);
        assert_eq!(at("rule r { when OBS(|) then RO }"), ["d", "side"]);
        assert_eq!(at("rule r { when OBS(side == |) then RO }"), ["left", "right"]);
        assert_eq!(at("rule r { when OBS(side == le|) then RO }"), ["left", "right"]);
        assert_eq!(at("rule r { when OBS within 20|"), ["ms", "s", "min", "us", "ns", "Hz"]);
        assert_eq!(at("rule r { when NOB then |"), ["IT", "RS", "RO"]);
        assert!(at("rule r { when |").contains(&"OBS".to_string()));
        assert!(at("|").contains(&"agent".to_string()));
        assert_eq!(at("agent M processing { function h table { RS => run |"), ["h"]);
        assert_eq!(at("agent M processing { table { RS => run h() from |"), ["L", "M"]);
        assert!(at("rule r { when NOB then RO } // |").is_empty());
    }

    #[test]
    fn an_item_replaces_the_word_being_typed() {
        let text = format!("{DECLS}rule r {{ when OBS(side == le");
        let (w, path) = crate::world::world_of("complete-edit", &text);
        let (a, file) = w.primary(&path).unwrap();
        let items = completion(a, file, text.len());
        let left = items.iter().find(|i| i.label == "left").expect("a symbol of side");
        assert_eq!((left.kind, left.detail.as_deref(), left.snippet), (ENUM_MEMBER, Some("symbol of OBS.side"), false));
        let r = left.edit.range;
        assert_eq!((r.start.line, r.start.character, r.end.character), (3, 26, 28));
        assert_eq!(left.edit.new_text, "left");
        let (w, path) = crate::world::world_of("complete-top", "");
        let (a, file) = w.primary(&path).unwrap();
        let top = completion(a, file, 0);
        let rule = top.iter().find(|i| i.label == "rule …").expect("a snippet");
        assert!(rule.snippet && rule.kind == SNIPPET && rule.detail.is_none());
        assert!(rule.edit.new_text.starts_with("rule ${1:name}"), "{}", rule.edit.new_text);
    }
}
