//! Help for syntax errors: the mistakes people make, recognised from the
//! tokens around the place where pest stopped, each with a message that says
//! what to write instead and, where the change is mechanical, a fix.
//!
//! A fix is only offered when it works: it is applied to the item's text and
//! the item parsed again, and the fix is kept when the item then parses, or
//! fails only after the edited text. Guesses whose fix does not work are
//! dropped, so that a detector can never make a message worse than pest's.

use super::{Rule, SituParser};
use crate::ast::Span;
use pest::Parser as _;

/// Items longer than this get no verified fixes (each check is a parse).
const MAX_VERIFIED_LEN: usize = 64 * 1024;

/// What the parser could have accepted where it stopped.
pub(super) struct Expected {
    /// Literal tokens, as written: `}`, `and`, `ms`.
    pub literals: Vec<String>,
    /// Grammar rules that were tried there.
    pub rules: Vec<Rule>,
}

impl Expected {
    fn lit(&self, s: &str) -> bool {
        self.literals.iter().any(|l| l == s)
    }
    fn rule(&self, r: Rule) -> bool {
        self.rules.contains(&r)
    }
    fn name(&self) -> bool {
        self.rule(Rule::ident)
    }
    fn duration(&self) -> bool {
        self.rule(Rule::duration) || self.lit("ms")
    }
    fn frequency(&self) -> bool {
        self.rule(Rule::frequency) || self.lit("Hz")
    }
    fn variable(&self) -> bool {
        self.rule(Rule::variable) || self.lit("?")
    }
}

/// A fix in the item's coordinates.
pub(super) struct ItemFix {
    pub title: String,
    pub edits: Vec<(Span, String)>,
}

/// What to say instead of (or in addition to) pest's expected tokens.
#[derive(Default)]
pub(super) struct Advice {
    /// The whole message after `syntax error: `.
    pub message: Option<String>,
    /// The primary place, in the item's coordinates.
    pub span: Option<Span>,
    pub label: Option<String>,
    pub help: Option<String>,
    /// Further places, in the item's coordinates.
    pub secondary: Vec<(Span, String)>,
    pub fixes: Vec<ItemFix>,
    /// A guess that only stands if one of its fixes works.
    speculative: bool,
}

impl Advice {
    fn new(message: impl Into<String>, span: Span, label: impl Into<String>, help: impl Into<String>) -> Self {
        Advice {
            message: Some(message.into()),
            span: Some(span),
            label: Some(label.into()),
            help: Some(help.into()),
            ..Advice::default()
        }
    }
    fn help_only(help: impl Into<String>) -> Self {
        Advice { help: Some(help.into()), ..Advice::default() }
    }
    fn fix(mut self, title: impl Into<String>, span: Span, text: impl Into<String>) -> Self {
        self.fixes.push(ItemFix { title: title.into(), edits: vec![(span, text.into())] });
        self
    }
    fn fix_edits(mut self, title: impl Into<String>, edits: Vec<(Span, String)>) -> Self {
        self.fixes.push(ItemFix { title: title.into(), edits });
        self
    }
    fn speculative(mut self) -> Self {
        self.speculative = true;
        self
    }
}

// ─── Tokens ─────────────────────────────────────────────────────────────────

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
enum Kind {
    Word,
    Number,
    Str,
    Var,
    Punct,
}

#[derive(Clone, Copy, Debug)]
struct Tok<'a> {
    kind: Kind,
    text: &'a str,
    start: usize,
    end: usize,
}

impl Tok<'_> {
    fn span(&self) -> Span {
        Span::new(self.start, self.end)
    }
    fn is(&self, s: &str) -> bool {
        self.text == s
    }
    fn word(&self) -> bool {
        self.kind == Kind::Word
    }
}

const PUNCTS: [&str; 14] = ["..=", "..", "==", "!=", "<=", ">=", "=>", "->", "&&", "||", "#[", "::", "<>", "=<"];

/// A rough lexer for the item's text, enough to read the mistakes around an
/// error: words, numbers (digits with an optional fraction), strings,
/// variables and punctuation; comments and spaces are skipped.
fn tokens(text: &str) -> Vec<Tok<'_>> {
    let bytes = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    while i < bytes.len() {
        let b = bytes[i];
        let start = i;
        let kind = if b.is_ascii_whitespace() {
            i += 1;
            continue;
        } else if bytes[i..].starts_with(b"//") {
            i = bytes[i..].iter().position(|&c| c == b'\n').map_or(bytes.len(), |p| i + p);
            continue;
        } else if b.is_ascii_digit() {
            while i < bytes.len() && bytes[i].is_ascii_digit() {
                i += 1;
            }
            if bytes.get(i) == Some(&b'.') && bytes.get(i + 1).is_some_and(u8::is_ascii_digit) {
                i += 1;
                while i < bytes.len() && bytes[i].is_ascii_digit() {
                    i += 1;
                }
            }
            Kind::Number
        } else if b.is_ascii_alphabetic() || b == b'_' {
            while i < bytes.len() && word(bytes[i]) {
                i += 1;
            }
            Kind::Word
        } else if b == b'?' && bytes.get(i + 1).is_some_and(|c| c.is_ascii_alphabetic()) {
            i += 1;
            while i < bytes.len() && word(bytes[i]) {
                i += 1;
            }
            Kind::Var
        } else if b == b'"' {
            i += 1;
            while i < bytes.len() && bytes[i] != b'"' && bytes[i] != b'\n' {
                i += if bytes[i] == b'\\' { 2 } else { 1 };
            }
            i = (i + usize::from(bytes.get(i) == Some(&b'"'))).min(bytes.len());
            Kind::Str
        } else {
            let p = PUNCTS.iter().find(|p| bytes[i..].starts_with(p.as_bytes()));
            i += p.map_or_else(|| text[i..].chars().next().map_or(1, char::len_utf8), |p| p.len());
            Kind::Punct
        };
        out.push(Tok { kind, text: &text[start..i], start, end: i });
    }
    out
}

// ─── The context of an error ──────────────────────────────────────────────────

struct Cx<'a> {
    text: &'a str,
    pos: usize,
    exp: &'a Expected,
    toks: Vec<Tok<'a>>,
    /// The item's keyword: `rule`, `agent`, `states`, `test`, `property`, `script`, `include`.
    item: &'a str,
}

impl<'a> Cx<'a> {
    /// The index of the first token at or after the error.
    fn at(&self) -> Option<usize> {
        self.toks.iter().position(|t| t.end > self.pos)
    }
    fn tok(&self, i: usize) -> Option<Tok<'a>> {
        self.toks.get(i).copied()
    }
    /// The token at the error.
    fn found(&self) -> Option<Tok<'a>> {
        self.at().and_then(|i| self.tok(i))
    }
    /// The token before the error.
    fn before(&self) -> Option<Tok<'a>> {
        let i = self.at().unwrap_or(self.toks.len());
        i.checked_sub(1).and_then(|i| self.tok(i))
    }
    /// The item's keyword as a noun: `rule`, `agent`.
    fn noun(&self) -> &'a str {
        match self.item {
            "states" => "states block",
            "" => "item",
            other => other,
        }
    }
    /// Whether only spaces separate the end of `a` from `b`, on one line.
    fn same_line(&self, a: &Tok, b: &Tok) -> bool {
        !self.text[a.end..b.start].contains('\n')
    }

    /// Whether the fix makes the item parse, or move its first error past
    /// the edited text.
    fn works(&self, fix: &ItemFix, strict: bool) -> bool {
        if self.text.len() > MAX_VERIFIED_LEN || fix.edits.is_empty() {
            return false;
        }
        let mut edits: Vec<&(Span, String)> = fix.edits.iter().collect();
        edits.sort_by_key(|(s, _)| s.start);
        let mut out = String::with_capacity(self.text.len() + 16);
        let mut at = 0;
        let mut edited_end = 0;
        for (span, new) in edits {
            if span.start < at || span.end > self.text.len() || span.start > span.end {
                return false;
            }
            out.push_str(&self.text[at..span.start]);
            out.push_str(new);
            edited_end = out.len();
            at = span.end;
        }
        out.push_str(&self.text[at..]);
        match SituParser::parse(Rule::item, &out) {
            Ok(_) => true,
            Err(_) if strict => false,
            Err(e) => {
                let p = match e.location {
                    pest::error::InputLocation::Pos(p) => p,
                    pest::error::InputLocation::Span((s, _)) => s,
                };
                p > edited_end && !out[edited_end..p].trim().is_empty()
            }
        }
    }
}

/// The keyword of an item, after its attributes.
fn item_keyword<'a>(toks: &[Tok<'a>]) -> &'a str {
    let mut depth = 0i32;
    for t in toks {
        match t.text {
            "#[" | "[" => depth += 1,
            "]" => depth -= 1,
            w if depth <= 0 && t.word() => {
                return match w {
                    "rule" | "agent" | "states" | "test" | "property" | "script" | "include" => w,
                    _ => "",
                };
            }
            _ => {}
        }
    }
    ""
}

mod forms;
mod items;
mod numbers;
mod words;

use forms::*;
use items::*;
use numbers::*;
use words::*;

/// Advice for a syntax error at `pos` of one item's `text`, if a known
/// mistake is recognised.
pub(super) fn advise(text: &str, pos: usize, exp: &Expected) -> Option<Advice> {
    let toks = tokens(text);
    let item = item_keyword(&toks);
    let cx = Cx { text, pos, exp, toks, item };
    let detectors: [fn(&Cx) -> Option<Advice>; 21] = [
        unclosed_brace,
        stray_brace,
        semicolon,
        links_without_function,
        set_of_values,
        quantities,
        float_forms,
        run_length,
        rule_target,
        colon_for_equals,
        logic_words,
        arrows,
        agent_kind,
        declarations,
        test_forms,
        wrong_word,
        doubled,
        missing_words,
        commas,
        quotes,
        insert_expected,
    ];
    for detect in detectors {
        let Some(mut advice) = detect(&cx) else { continue };
        let strict = advice.speculative;
        advice.fixes.retain(|f| cx.works(f, strict));
        if advice.speculative && advice.fixes.is_empty() {
            continue;
        }
        return Some(advice);
    }
    None
}
