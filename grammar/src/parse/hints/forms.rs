//! Things written in a form situ does not have, where the keyword message
//! would name the wrong fix: links after `run` with no function, a set of
//! values tested on a payload field.

use super::{Advice, Cx, Kind, Tok};
use crate::ast::Span;

/// `run from IMU, GPS` (or `run to Drive`): the function is missing, and
/// `from` is no name. The writer wanted the agent's links: say how an entry
/// writes them, and offer the agent's own functions.
pub(super) fn links_without_function(cx: &Cx) -> Option<Advice> {
    let i = cx.at()?;
    let t = cx.tok(i)?;
    let b = cx.before()?;
    if cx.item != "agent" || t.start != cx.pos || !b.is("run") || !matches!(t.text, "from" | "to") || !cx.exp.name() {
        return None;
    }
    let functions = declared_functions(cx);
    let f = match functions.as_slice() {
        [only] => (*only).to_string(),
        _ => "f".to_string(),
    };
    let place = if enclosing_block(cx, t.start) == Some("fsm") { "an FSM" } else { "a table" };
    let links = links_text(cx, i);
    let help = match functions.as_slice() {
        [] => format!(
            "`run` requires a function: declare one in the agent (`function {f}`) and write `run {f}() {links}`; `wait {links}` needs none, but drops the agent's outputs"
        ),
        [_] => format!("write `run {f}() {links}`"),
        many => format!("write the function before the links; this agent's functions are {}", list(many)),
    };
    let mut advice = Advice::new(
        format!("in {place}, an agent's links are written after the function it runs: `run {f}() {links}`"),
        t.span(),
        "expected the function here",
        help,
    );
    let at = Span::new(t.start, t.start);
    for name in functions {
        advice = advice.fix(format!("run `{name}()`"), at, format!("{name}() "));
    }
    Some(advice)
}

/// The functions the agent declares: the names after `function`.
fn declared_functions<'a>(cx: &Cx<'a>) -> Vec<&'a str> {
    cx.toks.windows(2).filter(|w| w[0].is("function") && w[1].kind == Kind::Word).map(|w| w[1].text).fold(
        Vec::new(),
        |mut v, f| {
            if !v.contains(&f) {
                v.push(f);
            }
            v
        },
    )
}

/// `table` or `fsm`: the block the position is in, if any.
fn enclosing_block<'a>(cx: &Cx<'a>, at: usize) -> Option<&'a str> {
    cx.toks.iter().take_while(|t| t.start < at).filter(|t| t.is("table") || t.is("fsm")).last().map(|t| t.text)
}

/// The links as written from token `i` (`from A, B to C`), on its line, up to
/// the next entry.
fn links_text(cx: &Cx, i: usize) -> String {
    let first = cx.toks[i];
    let mut last = first;
    for (k, t) in cx.toks.iter().enumerate().skip(i + 1) {
        let next_is_entry = cx.tok(k + 1).is_some_and(|n: Tok| n.is("=>") || n.is(","));
        let ends_entry = t.word() && next_is_entry && !matches!(cx.toks[k - 1].text, "," | "from" | "to");
        if !cx.same_line(&last, t) || !(t.word() || t.is(",")) || ends_entry {
            break;
        }
        last = *t;
    }
    cx.text[first.start..last.end].to_string()
}

/// `a`, `a` and `b`, `a`, `b` and `c`, each in backquotes.
fn list(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} and {last}", rest.join(", ")),
        _ => quoted.concat(),
    }
}

/// `GPFIX(quality in {fix3d, rtk})`: a payload field tested against a set.
/// Only system states have `in {…}`; say how to write it today.
pub(super) fn set_of_values(cx: &Cx) -> Option<Advice> {
    let i = cx.at()?;
    let t = cx.tok(i)?;
    if t.start != cx.pos || !t.is("{") || !matches!(cx.item, "rule" | "property") || i < 3 {
        return None;
    }
    let (field, kw, open) = (cx.tok(i - 2)?, cx.tok(i - 1)?, cx.tok(i - 3)?);
    if !kw.is("in") || !field.word() || !(open.is("(") || open.is(",")) {
        return None;
    }
    let close = cx.toks[i..].iter().position(|c| c.is("}") || c.is(")")).map(|p| p + i)?;
    let end = cx.tok(close).filter(|c| c.is("}"))?;
    let values: Vec<&str> = cx.toks[i + 1..close].iter().filter(|v| v.word()).map(|v| v.text).collect();
    let (first, second) = match values.as_slice() {
        [a, b, ..] => (*a, *b),
        [a] => (*a, "…"),
        [] => ("a", "b"),
    };
    let f = field.text;
    let mut advice = Advice::new(
        "a payload field cannot be tested against a set of values: only `state in {…}` can",
        Span::new(kw.start, end.end),
        "not a payload constraint",
        format!(
            "a constraint tests one value: write one rule per value (`{f} == {first}`, `{f} == {second}`), or exclude every other symbol of `{f}` (`{f} != s, …`: all of a pattern's constraints must hold)"
        ),
    );
    if values.len() == 1 {
        advice = advice.fix(format!("write `{f} == {first}`"), Span::new(kw.start, end.end), format!("== {first}"));
    }
    Some(advice)
}
