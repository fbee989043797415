//! Braces, separators, quotes, and the members of agents, tests and properties.

use super::{Advice, Cx, Kind};
use crate::ast::Span;
use crate::parse::Rule;

/// A `{` that is never closed: the item ends first.
pub(super) fn unclosed_brace(cx: &Cx) -> Option<Advice> {
    let mut open = Vec::new();
    for t in &cx.toks {
        match t.text {
            "{" => open.push(*t),
            "}" => {
                open.pop();
            }
            _ => {}
        }
    }
    let first = *open.first()?;
    let last = cx.toks.last()?;
    let end = Span::new(last.end, last.end);
    let closing = "}".repeat(open.len());
    let mut advice = Advice::new(
        format!("this {}'s `{{` is never closed", cx.noun()),
        end,
        "expected `}` here",
        format!("add `{closing}` at the end of the {}", cx.noun()),
    )
    .fix(format!("add `{closing}`"), end, format!(" {closing}"))
    .speculative();
    advice.secondary.push((first.span(), "opened here".into()));
    Some(advice)
}

/// A `}` with nothing to close (the item is only that brace and what follows).
pub(super) fn stray_brace(cx: &Cx) -> Option<Advice> {
    let first = cx.toks.first()?;
    if !first.is("}") || cx.pos != first.start {
        return None;
    }
    Some(Advice::new("unmatched `}`", first.span(), "nothing to close", "remove it").fix(
        "remove the `}`",
        first.span(),
        "",
    ))
}

/// `;` is no separator in situ.
pub(super) fn semicolon(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    if !t.is(";") || t.start != cx.pos {
        return None;
    }
    if cx.exp.lit(",") {
        return Some(
            Advice::new("expected `,`, found `;`", t.span(), "write `,`", "the items of a list are separated by `,`")
                .fix("write `,`", t.span(), ",")
                .speculative(),
        );
    }
    Some(
        Advice::new(
            "situ has no `;`",
            t.span(),
            "remove this",
            "nothing ends with `;`: members, conditions and entries are separated by spaces or newlines",
        )
        .fix("remove the `;`", t.span(), ""),
    )
}

/// `agent X { … }` without its kind.
pub(super) fn agent_kind(cx: &Cx) -> Option<Advice> {
    if !cx.exp.rule(Rule::agent_kind) {
        return None;
    }
    let t = cx.found()?;
    if t.start != cx.pos || !(t.is("{") || t.kind == Kind::Str) {
        return None;
    }
    let mut advice = Advice::new(
        "an agent needs a kind after its name",
        Span::new(t.start, t.start),
        "expected a kind",
        "write `sensor`, `actuator`, `processing` or `interface` after the name: `agent LADAR sensor { … }`",
    );
    for kind in ["sensor", "actuator", "processing", "interface"] {
        let article = if kind.starts_with(['a', 'i']) { "an" } else { "a" };
        advice = advice.fix(format!("make it {article} `{kind}`"), Span::new(t.start, t.start), format!("{kind} "));
    }
    Some(advice)
}

/// Members of an agent: `event E(a: f64)`, `function f()`, `stale 300ms`,
/// types of other languages.
pub(super) fn declarations(cx: &Cx) -> Option<Advice> {
    if cx.item != "agent" {
        return None;
    }
    let i = cx.at()?;
    let t = cx.tok(i)?;
    if t.start != cx.pos {
        return None;
    }
    let b = cx.before();
    let bb = i.checked_sub(2).and_then(|j| cx.tok(j));
    if t.is("(") && b.is_some_and(|b| b.word()) {
        let close = cx.toks[i..].iter().position(|c| c.is(")")).map(|p| p + i)?;
        let c = cx.tok(close)?;
        if bb.is_some_and(|bb| bb.is("function")) && close == i + 1 {
            return Some(
                Advice::new(
                    "a function is declared by its name, without `()`",
                    Span::new(t.start, c.end),
                    "remove `()`",
                    format!("write `function {}`; the `()` belong to calls in tables", b?.text),
                )
                .fix("remove `()`", Span::new(t.start, c.end), ""),
            );
        }
        if bb.is_some_and(|bb| bb.is("event")) {
            let inner = cx.text[t.end..c.start].trim();
            return Some(
                Advice::new(
                    "an event's payload is written in braces",
                    Span::new(t.start, c.end),
                    "not parentheses",
                    format!("write `{{ {inner} }}`"),
                )
                .fix_edits("write the payload in braces", vec![(t.span(), "{ ".into()), (c.span(), " }".into())])
                .speculative(),
            );
        }
    }
    // `stale 300ms`: `after` is missing.
    if t.kind == Kind::Number && b.is_some_and(|b| b.is("stale")) && cx.exp.lit("after") {
        return Some(
            Advice::new(
                "expected `after`: a stale time is written `stale after 300ms`",
                t.span(),
                "expected `after`",
                "write `stale after` and the duration",
            )
            .fix("insert `after`", Span::new(t.start, t.start), "after "),
        );
    }
    // Types of other languages.
    if cx.exp.rule(Rule::field_type) && t.word() {
        let good = match t.text {
            "float" | "double" | "f32" | "real" | "number" | "Float" | "F64" => "f64",
            "int" | "integer" | "i32" | "u32" | "u64" | "usize" | "isize" | "long" | "Int" | "I64" => "i64",
            "boolean" | "Bool" | "Boolean" => "bool",
            "string" | "str" | "String" => return Some(Advice::new(
                format!("situ has no type `{}`", t.text),
                t.span(),
                "not a field type",
                "a field is `f64`, `i64`, `bool` or a set of symbols such as `{left, right}`; text is for descriptions",
            )),
            _ => return None,
        };
        return Some(
            Advice::new(
                format!("situ has no type `{}`; write `{good}`", t.text),
                t.span(),
                format!("write `{good}`"),
                "the field types are `f64`, `i64`, `bool` and sets of symbols such as `{left, right}`",
            )
            .fix(format!("write `{good}`"), t.span(), good),
        );
    }
    None
}

/// Tests: `expect state == RO`, `expect Drive runs estop()`, `Fusion is running`.
pub(super) fn test_forms(cx: &Cx) -> Option<Advice> {
    if !matches!(cx.item, "test" | "property") {
        return None;
    }
    let i = cx.at()?;
    let t = cx.tok(i)?;
    if t.start != cx.pos {
        return None;
    }
    let b = cx.before()?;
    if cx.item == "test" && b.is("state") && matches!(t.text, "==" | "=" | ":") && cx.exp.name() {
        return Some(
            Advice::new(
                "in a test, a state is written `state RO`, without `==`",
                t.span(),
                "remove this",
                "write `state` and the state's name",
            )
            .fix(format!("remove `{}`", t.text), Span::new(b.end, t.end), ""),
        );
    }
    if t.is("(")
        && cx.tok(i + 1).is_some_and(|c| c.is(")"))
        && cx.tok(i.saturating_sub(2)).is_some_and(|r| r.is("runs"))
    {
        let c = cx.tok(i + 1)?;
        let span = Span::new(t.start, c.end);
        return Some(
            Advice::new(
                "`runs` names a function without `()`",
                span,
                "remove `()`",
                format!("write `{} runs {}`", cx.tok(i.saturating_sub(3)).map_or("", |a| a.text), b.text),
            )
            .fix("remove `()`", span, ""),
        );
    }
    if t.is("is") {
        let next = cx.tok(i + 1)?;
        if matches!(next.text, "running" | "sleeping" | "waiting") {
            let span = Span::new(b.end, next.start);
            return Some(
                Advice::new(
                    format!("write `{} {}`, without `is`", b.text, next.text),
                    t.span(),
                    "remove `is`",
                    format!("a mode is written after the agent: `{} {}`", b.text, next.text),
                )
                .fix("remove `is`", span, " "),
            );
        }
    }
    None
}

/// A `,` where none belongs, or none where one does.
pub(super) fn commas(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    if t.start != cx.pos {
        return None;
    }
    if t.is(",") && !cx.exp.lit(",") {
        let (what, help) = match cx.item {
            "states" => ("states", "write the states one after another, separated by spaces or newlines"),
            "agent" => ("members and table entries", "write one member or entry per line, with no `,` at the end"),
            "test" => ("clauses", "a clause's events and expectations are separated by `,`, but not the clauses"),
            _ => ("these", "remove the `,`"),
        };
        // In a states block, every `,` goes; elsewhere, this one.
        let edits: Vec<(Span, String)> = if cx.item == "states" {
            cx.toks.iter().filter(|c| c.is(",")).map(|c| (c.span(), String::new())).collect()
        } else {
            vec![(t.span(), String::new())]
        };
        let title = if edits.len() > 1 { "remove the commas" } else { "remove the `,`" };
        return Some(
            Advice::new(format!("unexpected `,`: {what} are not separated by commas"), t.span(), "remove this", help)
                .fix_edits(title, edits)
                .speculative(),
        );
    }
    if cx.exp.lit(",") && (t.word() || t.kind == Kind::Number) {
        let b = cx.before()?;
        let at = Span::new(b.end, b.end);
        return Some(
            Advice::new(
                format!("expected `,` before `{}`", t.text),
                Span::new(t.start, t.end),
                "expected `,` before this",
                "the items of a list are separated by `,`",
            )
            .fix("insert `,`", at, ",")
            .speculative(),
        );
    }
    None
}

/// Single quotes, and strings that are not closed.
pub(super) fn quotes(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    if t.start != cx.pos {
        return None;
    }
    if t.is("'") {
        let line_end = cx.text[t.end..].find('\n').map_or(cx.text.len(), |p| t.end + p);
        let close = cx.text[t.end..line_end].find('\'').map(|p| t.end + p);
        let mut advice =
            Advice::new("strings are written in double quotes", t.span(), "not a quote of situ", "write `\"…\"`");
        if let Some(c) = close {
            advice = advice
                .fix_edits("use double quotes", vec![(t.span(), "\"".into()), (Span::new(c, c + 1), "\"".into())]);
        }
        return Some(advice);
    }
    if t.kind == Kind::Str && !t.text.ends_with('"') || t.text == "\"" {
        let end = Span::new(t.end, t.end);
        return Some(
            Advice::new(
                "this string is not closed",
                t.span(),
                "no closing `\"` on this line",
                "close it with `\"` on the same line; a string cannot span lines",
            )
            .fix("close the string", end, "\""),
        );
    }
    None
}
