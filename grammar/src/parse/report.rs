//! Syntax errors as people read them: what was expected, in the words of
//! the language, what was found, and, for a known mistake, what to write
//! instead (see `hints`).

use super::vocab::{describe, implied};
use super::{hints, Rule, SYNTAX};
use crate::ast::Span;
use crate::diag::{Diagnostic, Edit, FileId, Fix};

/// Turns a pest error into a diagnostic that says what was expected, and
/// where, in the words of the language; a known mistake gets its own message,
/// help and fixes (see `hints`).
pub(super) fn syntax_error(err: &pest::error::Error<Rule>, text: &str, offset: usize, file: FileId) -> Diagnostic {
    use pest::error::{ErrorVariant, InputLocation};
    let mut pos = match err.location {
        InputLocation::Pos(p) => p,
        InputLocation::Span((s, _)) => s,
    };
    let mut literals: Vec<String> = Vec::new();
    let mut tokens_at = pos;
    if let Some(attempts) = err.parse_attempts() {
        tokens_at = attempts.max_position;
        for token in attempts.expected_tokens() {
            // `ParsingToken` is not exported by name; only literal tokens help a reader.
            let text = token.to_string();
            if format!("{token:?}").starts_with("Sensitive") && !text.trim().is_empty() && text != "//" && text != "_" {
                push_unique(&mut literals, text);
            }
        }
    }
    let mut custom = None;
    let mut rules = Vec::new();
    match &err.variant {
        ErrorVariant::ParsingError { positives, .. } => rules.clone_from(positives),
        ErrorVariant::CustomError { message } => custom = Some(message.clone()),
    }
    // pest places the error where the last rule started, but the literal
    // tokens it expected are those of the furthest place it reached: the
    // place of the mistake. The rules tried where the error is placed are
    // not alternatives there.
    if tokens_at > pos && tokens_at <= text.len() && !literals.is_empty() {
        pos = tokens_at;
        rules.clear();
    }
    let mut expected: Vec<String> = Vec::new();
    for l in &literals {
        // A token that a described rule already names (`sensor` of an agent
        // kind, `x` of a run length) is said once, by the rule.
        if !rules.iter().any(|r| describe(*r).is_some() && implied(*r).contains(&l.as_str())) {
            push_unique(&mut expected, format!("`{l}`"));
        }
    }
    for r in &rules {
        if let Some(name) = describe(*r) {
            push_unique(&mut expected, name.to_string());
        }
    }
    let item = item_noun(text);
    let found = describe_found(text, pos, item);
    let at = offset + pos;
    let end = at + found.1;
    let message = match (&custom, expected.is_empty()) {
        (Some(m), _) => format!("syntax error: {m}"),
        (None, true) => format!("syntax error: unexpected {}", found.0),
        (None, false) => format!("syntax error: expected {}, found {}", one_of(&expected), found.0),
    };
    let label =
        if expected.is_empty() { "unexpected here".to_string() } else { format!("expected {}", one_of(&expected)) };
    let mut diag = Diagnostic::error(SYNTAX, message, file, Span::new(at, end), label);
    if custom.is_some() {
        return diag;
    }
    let shift = |s: Span| Span::new(offset + s.start, offset + s.end);
    if let Some(advice) = hints::advise(text, pos, &hints::Expected { literals, rules }) {
        if let Some(m) = advice.message {
            diag.message = format!("syntax error: {m}");
        }
        if let Some(s) = advice.span {
            diag.primary.span = shift(s);
        }
        if let Some(l) = advice.label {
            diag.primary.text = l;
        }
        diag.help = advice.help;
        for (s, text) in advice.secondary {
            diag = diag.with_label(file, shift(s), text);
        }
        for fix in advice.fixes {
            diag.fixes.push(Fix {
                title: fix.title,
                edits: fix.edits.into_iter().map(|(s, text)| Edit { file, span: shift(s), text }).collect(),
            });
        }
    }
    diag
}

fn push_unique(list: &mut Vec<String>, s: String) {
    if !list.contains(&s) {
        list.push(s);
    }
}

fn one_of(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => {
            let mut init = init.to_vec();
            init.truncate(8);
            format!("{} or {}", init.join(", "), last)
        }
    }
}

/// The item's keyword as a noun, for "the end of the rule".
fn item_noun(text: &str) -> &'static str {
    let body = text.trim_start();
    let body = if body.starts_with("#[") { body.split_once(']').map_or("", |(_, r)| r.trim_start()) } else { body };
    let word: String = body.chars().take_while(|c| c.is_ascii_alphabetic()).collect();
    match word.as_str() {
        "rule" => "rule",
        "agent" => "agent",
        "states" => "states block",
        "test" => "test",
        "property" => "property",
        "script" => "script",
        "include" => "include",
        _ => "item",
    }
}

/// What stands at `pos`: a description and its length in bytes.
fn describe_found(text: &str, pos: usize, item: &str) -> (String, usize) {
    let rest = &text[pos.min(text.len())..];
    let Some(c) = rest.chars().next() else { return (format!("the end of the {item}"), 0) };
    if c.is_alphanumeric() || c == '_' {
        let word: String = rest.chars().take_while(|c| c.is_alphanumeric() || *c == '_').take(40).collect();
        (format!("`{word}`"), word.len())
    } else if c == ' ' || c == '\t' {
        ("a space".into(), 1)
    } else if c == '\n' || c == '\r' {
        ("the end of the line".into(), 1)
    } else if c.is_control() {
        (format!("the character U+{:04X}", c as u32), c.len_utf8())
    } else {
        (format!("`{c}`"), c.len_utf8())
    }
}
