//! A lexer for the editor (every token, comments included), semantic tokens
//! classified by the name index, and folding ranges.

use crate::index::Sym;
use crate::world::Analysis;
use situ_grammar::ast::{AgentMember, Item, Span};
use situ_grammar::diag::FileId;
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

/// The semantic token types, in the order of [`TokenType`]: the legend the
/// server announces in its capabilities.
pub const TOKEN_TYPES: [&str; 12] = [
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

/// The semantic token modifiers: bit 0 marks a declaration.
pub const TOKEN_MODIFIERS: [&str; 1] = ["declaration"];

/// What a token is shown as; its number is its place in [`TOKEN_TYPES`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TokenType {
    Keyword,
    String,
    Number,
    Comment,
    EnumMember,
    Class,
    Event,
    Property,
    Function,
    Method,
    Variable,
    Type,
}

impl TokenType {
    /// Its index in the legend.
    pub fn index(self) -> u32 {
        self as u32
    }
}

/// One classified token, on one line.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SemanticToken {
    pub line: u32,
    /// The first UTF-16 column.
    pub start: u32,
    /// In UTF-16 code units.
    pub length: u32,
    pub ty: TokenType,
    pub declaration: bool,
}

fn type_of(sym: &Sym) -> TokenType {
    match sym {
        Sym::State(_) | Sym::Symbol { .. } | Sym::FsmState { .. } => TokenType::EnumMember,
        Sym::Agent(_) => TokenType::Class,
        Sym::Event(_) => TokenType::Event,
        Sym::Field { .. } => TokenType::Property,
        Sym::Function { .. } => TokenType::Function,
        Sym::Rule(_) => TokenType::Method,
        Sym::Variable { .. } => TokenType::Variable,
    }
}

/// The tokens of `file` worth colouring, in the order of the text: keywords,
/// literals, comments, and the names the index knows.
pub fn semantic_tokens(a: &Analysis, file: FileId) -> Vec<SemanticToken> {
    let text = a.text(file);
    let lines = &a.lines[file.0 as usize];
    let names: HashMap<usize, (TokenType, bool)> = a
        .index
        .occurrences
        .iter()
        .filter(|o| o.file == file)
        .map(|o| (o.span.start, (type_of(&o.sym), o.def)))
        .collect();
    let mut out = Vec::new();
    for t in lex(text) {
        let (span, ty, def) = match t.kind {
            Tok::Keyword if ["f64", "i64", "bool"].contains(&&text[t.span.start..t.span.end]) => {
                (t.span, TokenType::Type, false)
            }
            Tok::Keyword => (t.span, TokenType::Keyword, false),
            Tok::Str => (t.span, TokenType::String, false),
            Tok::Number => (t.span, TokenType::Number, false),
            Tok::Comment => (t.span, TokenType::Comment, false),
            Tok::Variable => {
                let span = Span::new(t.span.start + 1, t.span.end);
                (span, TokenType::Variable, names.get(&span.start).is_some_and(|n| n.1))
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
        out.push(SemanticToken {
            line: start.line,
            start: start.character,
            length: end.character - start.character,
            ty,
            declaration: def,
        });
    }
    out
}

/// A range of lines the editor may fold.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fold {
    pub start_line: u32,
    pub end_line: u32,
    /// A run of whole-line comments.
    pub comment: bool,
}

/// The items, tables, FSMs and events of more than one line, then the runs of
/// comments.
pub fn folding(a: &Analysis, file: FileId) -> Vec<Fold> {
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
            out.push(Fold { start_line: s, end_line: e, comment: false });
        }
    }
    // Runs of whole-line comments.
    let comments = |s, e| Fold { start_line: s, end_line: e, comment: true };
    let mut run: Option<(u32, u32)> = None;
    for t in lex(text).into_iter().filter(|t| t.kind == Tok::Comment) {
        let line = lines.position(text, t.span.start).line;
        run = match run {
            Some((s, e)) if e + 1 == line => Some((s, line)),
            Some((s, e)) => {
                if e > s {
                    out.push(comments(s, e));
                }
                Some((line, line))
            }
            None => Some((line, line)),
        };
    }
    if let Some((s, e)) = run.filter(|(s, e)| e > s) {
        out.push(comments(s, e));
    }
    out
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

    #[test]
    fn semantic_tokens_classify_names_by_the_index() {
        let (w, path) = crate::world::world_of("tokens", crate::world::SMALL);
        let (a, file) = w.primary(&path).unwrap();
        let tokens = semantic_tokens(a, file);
        let at = |line, start| tokens.iter().find(|t| t.line == line && t.start == start).copied();
        let t = |line, start, length, ty, declaration| Some(SemanticToken { line, start, length, ty, declaration });
        assert_eq!(at(0, 0), t(0, 0, 4, TokenType::Comment, false));
        assert_eq!(at(2, 0), t(2, 0, 6, TokenType::Keyword, false));
        assert_eq!(at(2, 9), t(2, 9, 2, TokenType::EnumMember, true));
        assert_eq!(at(3, 6), t(3, 6, 1, TokenType::Class, true));
        assert_eq!(at(11, 5), t(11, 5, 1, TokenType::Method, true));
        assert!(tokens.windows(2).all(|p| (p[0].line, p[0].start) < (p[1].line, p[1].start)), "in order");
        assert_eq!(TOKEN_TYPES[TokenType::EnumMember.index() as usize], "enumMember");
    }

    #[test]
    fn folds_cover_items_tables_and_comment_runs() {
        let (w, path) = crate::world::world_of("folding", crate::world::SMALL);
        let (a, file) = w.primary(&path).unwrap();
        let folds: Vec<(u32, u32, bool)> =
            folding(a, file).into_iter().map(|f| (f.start_line, f.end_line, f.comment)).collect();
        // An event's span runs to the next member: `event E` folds down to `event F`.
        assert_eq!(folds, [(3, 10, false), (4, 5, false), (5, 6, false), (7, 9, false), (0, 1, true)]);
    }
}
