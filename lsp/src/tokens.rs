//! A lexer for the editor (every token, comments included), semantic tokens
//! classified by the name index, and folding ranges.

use crate::index::Sym;
use crate::nav::analysis;
use crate::server::Answer;
use serde_json::{json, Value};
use situ_grammar::ast::{AgentMember, Item, Span};
use situ_grammar::parse::KEYWORDS;
use std::collections::HashMap;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tok {
    Name,
    Keyword,
    /// A number, with its unit if it has one (`200ms`, `10Hz`).
    Number,
    Str,
    Comment,
    /// `?name`.
    Variable,
    Punct,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Token {
    pub kind: Tok,
    pub span: Span,
}

/// Every token of `text`; what is not a token of the language is one
/// punctuation character.
pub fn lex(text: &str) -> Vec<Token> {
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let word = |mut j: usize| {
        while j < b.len() && (b[j].is_ascii_alphanumeric() || b[j] == b'_') {
            j += 1;
        }
        j
    };
    while i < b.len() {
        let c = b[i];
        let start = i;
        let kind = if c.is_ascii_whitespace() {
            i += 1;
            continue;
        } else if c == b'/' && b.get(i + 1) == Some(&b'/') {
            i = b[i..].iter().position(|&c| c == b'\n').map_or(b.len(), |p| i + p);
            Tok::Comment
        } else if c == b'"' {
            i += 1;
            while i < b.len() && b[i] != b'"' && b[i] != b'\n' {
                i += if b[i] == b'\\' && i + 1 < b.len() && b[i + 1] != b'\n' { 2 } else { 1 };
            }
            if i < b.len() && b[i] == b'"' {
                i += 1;
            }
            Tok::Str
        } else if c.is_ascii_digit() || (c == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
            i += 1;
            while i < b.len()
                && (b[i].is_ascii_digit() || (b[i] == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)))
            {
                i += 1;
            }
            if i < b.len()
                && (b[i] == b'e' || b[i] == b'E')
                && b.get(i + 1).is_some_and(|d| d.is_ascii_digit() || *d == b'-')
            {
                i += 2;
                while i < b.len() && b[i].is_ascii_digit() {
                    i += 1;
                }
            }
            i = word(i); // a unit
            Tok::Number
        } else if c == b'?' && b.get(i + 1).is_some_and(u8::is_ascii_alphabetic) {
            i = word(i + 1);
            Tok::Variable
        } else if c.is_ascii_alphabetic() || c == b'_' {
            i = word(i);
            if KEYWORDS.contains(&&text[start..i]) {
                Tok::Keyword
            } else {
                Tok::Name
            }
        } else if b"=!<>.-".contains(&c) {
            while i < b.len()
                && b"=!<>.-".contains(&b[i])
                && !(b[i] == b'-' && b.get(i + 1).is_some_and(u8::is_ascii_digit))
            {
                i += 1;
            }
            i = i.max(start + 1);
            Tok::Punct
        } else {
            i += text[i..].chars().next().map_or(1, char::len_utf8);
            Tok::Punct
        };
        out.push(Token { kind, span: Span::new(start, i) });
    }
    out
}

const TYPES: [&str; 12] = [
    "keyword",
    "string",
    "number",
    "comment",
    "enumMember",
    "class",
    "event",
    "property",
    "function",
    "method",
    "variable",
    "type",
];

pub fn legend() -> Value {
    json!({ "tokenTypes": TYPES, "tokenModifiers": ["declaration"] })
}

fn type_of(sym: &Sym) -> usize {
    match sym {
        Sym::State(_) | Sym::Symbol { .. } | Sym::FsmState { .. } => 4,
        Sym::Agent(_) => 5,
        Sym::Event(_) => 6,
        Sym::Field { .. } => 7,
        Sym::Function { .. } => 8,
        Sym::Rule(_) => 9,
        Sym::Variable { .. } => 10,
    }
}

pub fn semantic_tokens(world: &crate::world::World, params: &Value) -> Answer {
    let (a, file) = analysis(world, params)?;
    let text = a.text(file);
    let lines = &a.lines[file.0 as usize];
    let names: HashMap<usize, (usize, bool)> = a
        .index
        .occurrences
        .iter()
        .filter(|o| o.file == file)
        .map(|o| (o.span.start, (type_of(&o.sym), o.def)))
        .collect();
    let mut data = Vec::new();
    let (mut last_line, mut last_col) = (0u32, 0u32);
    for t in lex(text) {
        let (span, ty, def) = match t.kind {
            Tok::Keyword if ["f64", "i64", "bool"].contains(&&text[t.span.start..t.span.end]) => (t.span, 11, false),
            Tok::Keyword => (t.span, 0, false),
            Tok::Str => (t.span, 1, false),
            Tok::Number => (t.span, 2, false),
            Tok::Comment => (t.span, 3, false),
            Tok::Variable => {
                let span = Span::new(t.span.start + 1, t.span.end);
                (span, 10, names.get(&span.start).is_some_and(|n| n.1))
            }
            Tok::Name => match names.get(&t.span.start) {
                Some(&(ty, def)) => (t.span, ty, def),
                None => continue,
            },
            Tok::Punct => continue,
        };
        let start = lines.position(text, span.start);
        let end = lines.position(text, span.end);
        if end.line != start.line || end.character <= start.character {
            continue;
        }
        let delta_line = start.line - last_line;
        let delta_col = if delta_line == 0 { start.character - last_col } else { start.character };
        data.extend([delta_line, delta_col, end.character - start.character, ty as u32, u32::from(def)]);
        (last_line, last_col) = (start.line, start.character);
    }
    Ok(json!({ "data": data }))
}

pub fn folding(world: &crate::world::World, params: &Value) -> Answer {
    let (a, file) = analysis(world, params)?;
    let text = a.text(file);
    let lines = &a.lines[file.0 as usize];
    let mut spans = Vec::new();
    for item in &a.asts[file.0 as usize].items {
        spans.push(item.span());
        if let Item::Agent(ag) = item {
            for m in &ag.members {
                if matches!(m, AgentMember::Table(_) | AgentMember::Fsm(_) | AgentMember::Event(_)) {
                    spans.push(m.span());
                }
            }
        }
    }
    let mut out = Vec::new();
    for span in spans {
        let (s, e) = (lines.position(text, span.start).line, lines.position(text, span.end).line);
        if e > s {
            out.push(json!({ "startLine": s, "endLine": e }));
        }
    }
    // Runs of whole-line comments.
    let mut run: Option<(u32, u32)> = None;
    for t in lex(text).into_iter().filter(|t| t.kind == Tok::Comment) {
        let line = lines.position(text, t.span.start).line;
        run = match run {
            Some((s, e)) if e + 1 == line => Some((s, line)),
            Some((s, e)) => {
                if e > s {
                    out.push(json!({ "startLine": s, "endLine": e, "kind": "comment" }));
                }
                Some((line, line))
            }
            None => Some((line, line)),
        };
    }
    if let Some((s, e)) = run.filter(|(s, e)| e > s) {
        out.push(json!({ "startLine": s, "endLine": e, "kind": "comment" }));
    }
    Ok(json!(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_lexer_sees_every_kind_of_token() {
        let text = "rule r { when OBS(d < -1.5e3, x: ?v) within 200ms then RS } // c\n\"s\\\"\"";
        let kinds: Vec<(Tok, &str)> = lex(text).iter().map(|t| (t.kind, &text[t.span.start..t.span.end])).collect();
        assert!(kinds.contains(&(Tok::Keyword, "rule")));
        assert!(kinds.contains(&(Tok::Number, "-1.5e3")));
        assert!(kinds.contains(&(Tok::Number, "200ms")));
        assert!(kinds.contains(&(Tok::Variable, "?v")));
        assert!(kinds.contains(&(Tok::Comment, "// c")));
        assert!(kinds.contains(&(Tok::Str, "\"s\\\"\"")));
        assert!(kinds.contains(&(Tok::Name, "OBS")));
    }

    #[test]
    fn the_lexer_ends_on_any_input() {
        for text in ["\"", "?", "-", "1e", "é", "\"\\", "//"] {
            let toks = lex(text);
            assert!(toks.iter().all(|t| t.span.end <= text.len() && t.span.start < t.span.end), "{text:?}");
        }
    }
}
