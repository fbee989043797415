//! Keywords, operators and the parts of a rule.

use super::{Advice, Cx, ItemFix, Kind, Tok};
use crate::ast::Span;
use crate::parse::Rule;

/// What follows `then` in a rule: exactly one state.
pub(super) fn rule_target(cx: &Cx) -> Option<Advice> {
    if cx.item != "rule" {
        return None;
    }
    let ti = cx.toks.iter().rposition(|t| t.is("then"))?;
    let then = cx.tok(ti)?;
    if cx.pos < then.start {
        return None;
    }
    let close = cx.toks.iter().skip(ti).position(|t| t.is("}")).map(|p| p + ti);
    let after: Vec<Tok> = cx.toks[ti + 1..close.unwrap_or(cx.toks.len())].to_vec();
    match after.as_slice() {
        [] => Some(Advice::new(
            "a rule needs a state after `then`",
            then.span(),
            "then what?",
            "write the state the rule sets: `then RO`",
        )),
        [s, rest @ ..] if s.is("state") => {
            let name = rest.iter().find(|t| t.word())?;
            let span = Span::new(s.start, name.start);
            Some(
                Advice::new(
                    format!("a rule's target is a state name: `then {}`", name.text),
                    Span::new(s.start, name.end),
                    "not a state test",
                    format!("write `then {}`: `then` names the state the rule sets", name.text),
                )
                .fix(format!("write `then {}`", name.text), span, ""),
            )
        }
        [first, second, ..] if first.word() => {
            let last = after.last()?;
            let names: Vec<&str> =
                after[1..].iter().filter(|t| t.word() && !matches!(t.text, "and" | "or")).map(|t| t.text).collect();
            let span = Span::new(first.end, last.end);
            let message = if matches!(second.text, "," | "and" | "or" | "|" | "||") || !names.is_empty() {
                let count = match names.len() + 1 {
                    2 => "two",
                    3 => "three",
                    _ => "several",
                };
                format!("a rule sets one state, but `then {}` names {count}", cx.text[first.start..last.end].trim())
            } else {
                format!("expected `}}` after `then {}`, found `{}`", first.text, second.text)
            };
            Some(
                Advice::new(
                    message,
                    Span::new(second.start, last.end),
                    "only one state after `then`",
                    format!(
                        "keep `then {}`; for another target, write another rule with its own conditions",
                        first.text
                    ),
                )
                .fix(format!("keep only `then {}`", first.text), span, "")
                .speculative(),
            )
        }
        _ => None,
    }
}

/// `side: left` in a rule (`==`), `side == left` in a test (`:`), `=` for
/// `==`, and the operators of other languages.
pub(super) fn colon_for_equals(cx: &Cx) -> Option<Advice> {
    let i = cx.at()?;
    let t = cx.tok(i)?;
    let b = cx.before();
    // `field: value` in a rule or a property: `:` only binds a variable.
    if cx.exp.variable() && b.is_some_and(|b| b.is(":")) && t.start == cx.pos {
        let colon = b?;
        let field = i.checked_sub(2).and_then(|j| cx.tok(j))?;
        let value = &cx.text[t.start..t.end];
        let good = format!("{} == {value}", field.text);
        return Some(
            Advice::new(
                format!("`:` binds a variable; to compare `{}` with `{value}`, write `{good}`", field.text),
                Span::new(field.start, t.end),
                "`:` takes a variable here",
                format!("write `{good}`; `{}: ?v` would bind the field's value to the variable `?v`", field.text),
            )
            .fix(format!("write `{good}`"), Span::new(colon.start, t.start), " == "),
        );
    }
    // `field == value` in a test or script event: a value is given with `:`.
    if cx.exp.lit(":") && matches!(t.text, "==" | "=") && t.start == cx.pos {
        let field = b?;
        if cx.item == "agent" {
            return Some(
                Advice::new(
                    format!("a payload field is declared with `:`: `{}: f64`", field.text),
                    t.span(),
                    "expected `:`",
                    format!("write `{}:` and the field's type", field.text),
                )
                .fix("write `:`", Span::new(field.end, t.end), ":"),
            );
        }
        return Some(
            Advice::new(
                format!("an event in a {} gives its fields with `:`: `{}: …`", cx.noun(), field.text),
                t.span(),
                "expected `:`",
                format!("write `{}:` and the value; `==` compares, in rules and properties", field.text),
            )
            .fix("write `:`", Span::new(field.end, t.end), ":"),
        );
    }
    if cx.exp.lit(":") && matches!(t.text, "<" | "<=" | ">" | ">=" | "!=") && t.start == cx.pos {
        return Some(Advice::new(
            format!("an event in a {} has values, not conditions", cx.noun()),
            t.span(),
            "expected `:`",
            "give every field one value: `distance: 12.0`",
        ));
    }
    // An operator of another language where `==`, `!=`, `<=`, `>=` would do.
    let wants_cmp = cx.exp.lit("==") || cx.exp.rule(Rule::cmp_op) || t.is("<>") && t.start < cx.pos;
    if wants_cmp && t.start <= cx.pos {
        let good = match t.text {
            "=" => "==",
            "<>" => "!=",
            "=<" => "<=",
            "=>" => ">=",
            ":" if cx.exp.lit("==") && b.is_some_and(|b| b.is("state")) => "==",
            _ => "",
        };
        let next = cx.tok(i + 1);
        if t.is("=") && next.is_some_and(|n| n.is("=") && n.start == t.end) {
            return None;
        }
        if !good.is_empty() {
            return Some(
                Advice::new(
                    format!("`{}` is not a comparison; write `{good}`", t.text),
                    t.span(),
                    format!("write `{good}`"),
                    "the comparisons are `==`, `!=`, `<`, `<=`, `>` and `>=`",
                )
                .fix(format!("write `{good}`"), t.span(), good),
            );
        }
    }
    None
}

/// `&&`, `||`, `!`, and `or` or `,` between a rule's conditions.
pub(super) fn logic_words(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    if t.start != cx.pos || !matches!(cx.item, "rule" | "property") {
        return None;
    }
    let rule = cx.item == "rule";
    let and_expected = cx.exp.lit("and");
    match t.text {
        "&&" | "&" => Some(
            Advice::new(format!("`{}` is written `and` in situ", t.text), t.span(), "write `and`", "write `and`")
                .fix("write `and`", t.span(), "and"),
        ),
        "||" | "|" | "or" if rule => Some(states_or(cx).unwrap_or_else(|| {
            Advice::new(
                "a rule's conditions cannot be joined with `or`",
                t.span(),
                "no `or` in a rule",
                "conditions are joined with `and`; for one condition or another, write two rules with the same `then`, one with each",
            )
        })),
        "||" | "|" => Some(
            Advice::new(format!("`{}` is written `or` in situ", t.text), t.span(), "write `or`", "write `or`")
                .fix("write `or`", t.span(), "or"),
        ),
        "," if rule && and_expected => Some(
            Advice::new(
                "conditions are joined with `and`, not `,`",
                t.span(),
                "write `and`",
                "write `and` between conditions",
            )
            .fix("write `and`", t.span(), " and")
            .speculative(),
        ),
        "!" => Some(
            Advice::new("`!` is written `not` in situ", t.span(), "write `not`", "write `not` and a space: `not LAOBN`")
                .fix("write `not`", t.span(), "not ")
                .speculative(),
        ),
        _ => None,
    }
}

/// `->` for `=>` (tables, FSM states) and `=>` for `->` (transitions, links,
/// implications).
pub(super) fn arrows(cx: &Cx) -> Option<Advice> {
    let i = cx.at()?;
    let t = cx.tok(i)?;
    if t.start != cx.pos {
        return None;
    }
    if cx.exp.lit("=>") && matches!(t.text, "->" | "=" | ":" | ">" | "→" | "⇒") {
        return Some(
            Advice::new(
                format!("expected `=>`, found `{}`", t.text),
                t.span(),
                "write `=>`",
                "a table entry or an FSM state gives its action after `=>`: `RS => run f()`; `->` is for FSM transitions",
            )
            .fix("write `=>`", t.span(), "=>")
            .speculative(),
        );
    }
    if cx.exp.lit("->") && matches!(t.text, "=>" | "-" | ">" | "→" | "=" | "-->") {
        return Some(
            Advice::new(
                format!("expected `->`, found `{}`", t.text),
                t.span(),
                "write `->`",
                "links, FSM transitions and implications are written with `->`",
            )
            .fix("write `->`", t.span(), "->")
            .speculative(),
        );
    }
    // `A => B on X` in an FSM: a transition written with `=>`.
    if cx.exp.rule(Rule::action) && t.word() {
        let b = cx.before()?;
        let on = cx.tok(i + 1)?;
        if b.is("=>") && on.is("on") {
            return Some(
                Advice::new(
                    "an FSM transition is written with `->`",
                    b.span(),
                    "write `->`",
                    format!("write `-> {} on …`; `=>` gives an FSM state its action", t.text),
                )
                .fix("write `->`", b.span(), "->")
                .speculative(),
            );
        }
    }
    None
}

/// Words that were left out: `when`, `then`, a property's quantifier.
pub(super) fn missing_words(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    if t.start != cx.pos {
        return None;
    }
    let at = Span::new(t.start, t.start);
    if cx.item == "rule" && cx.exp.lit("when") && !t.is("when") {
        return Some(
            Advice::new(
                "a rule's conditions start with `when`",
                at,
                "expected `when`",
                "write `{ when CONDITIONS then STATE }`",
            )
            .fix("insert `when`", at, "when ")
            .speculative(),
        );
    }
    if cx.item == "property" && cx.exp.rule(Rule::quantifier) {
        return Some(
            Advice::new(
                "a property starts with `always` or `never`",
                at,
                "expected `always` or `never`",
                "write `always P` (P holds at every point) or `never P` (at none)",
            )
            .fix("insert `always`", at, "always ")
            .fix("insert `never`", at, "never ")
            .speculative(),
        );
    }
    // `when A and B RO }`: `then` is missing before the target.
    if cx.item == "rule" && cx.exp.lit("then") && t.word() {
        let next = cx.toks.iter().find(|n| n.start > t.start)?;
        if next.is("}") {
            return Some(
                Advice::new(
                    format!("expected `then` before the target `{}`", t.text),
                    at,
                    "expected `then`",
                    format!("write `then {}`", t.text),
                )
                .fix("insert `then`", at, "then ")
                .speculative(),
            );
        }
    }
    None
}

/// Edit distance, for "did you mean".
pub(super) fn distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != *cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

/// A word where a keyword was expected: wrong case, another language's word,
/// a typo; or a keyword where a name was expected.
pub(super) fn wrong_word(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    if !t.word() || t.start != cx.pos {
        return None;
    }
    let implied = cx.exp.rules.iter().flat_map(|r| crate::parse::vocab::implied(*r).iter().copied());
    let words: Vec<&str> = cx
        .exp
        .literals
        .iter()
        .map(String::as_str)
        .chain(implied)
        .filter(|l| l.len() > 1 && l.bytes().all(|b| b.is_ascii_alphabetic()))
        .fold(Vec::new(), |mut v, w| {
            if !v.contains(&w) {
                v.push(w);
            }
            v
        });
    if words.contains(&t.text) {
        return None;
    }
    if crate::parse::KEYWORDS.contains(&t.text) && cx.exp.name() {
        let mut cap = t.text.to_string();
        cap[..1].make_ascii_uppercase();
        return Some(Advice::help_only(format!(
            "`{}` is a keyword and cannot be used as a name: choose another, such as `{cap}` or `{}_`",
            t.text, t.text
        )));
    }
    let lower = t.text.to_ascii_lowercase();
    let alias = match t.text {
        "running" => "run",
        "sleeping" => "sleep",
        "waiting" => "wait",
        "run" | "runs" => "running",
        "sleep" | "sleeps" => "sleeping",
        "wait" | "waits" => "waiting",
        "if" => "when",
        "priority" => "salience",
        "AND" => "and",
        "event" => "events",
        _ => "",
    };
    let good = if words.contains(&lower.as_str()) {
        Some((lower.as_str(), "keywords are lowercase"))
    } else if words.contains(&alias) {
        Some((alias, "the word here is"))
    } else {
        let mut best: Vec<(&str, usize)> = words.iter().map(|w| (*w, distance(t.text, w))).collect();
        best.sort_by_key(|(_, d)| *d);
        match best.as_slice() {
            [(w, d), rest @ ..]
                if *d <= if t.text.len() >= 5 { 2 } else { 1 } && rest.first().is_none_or(|r| r.1 > *d) =>
            {
                Some((*w, "did you mean"))
            }
            _ => None,
        }
    };
    let (good, why) = good?;
    let help = match why {
        "did you mean" => format!("did you mean `{good}`?"),
        "keywords are lowercase" => format!("keywords are lowercase: write `{good}`"),
        _ => format!("write `{good}` here"),
    };
    Some(Advice::help_only(help).fix(format!("write `{good}`"), t.span(), good))
}

/// A token written twice: `and and`, `,,`, `then then`.
pub(super) fn doubled(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    let b = cx.before()?;
    if t.start != cx.pos || t.text != b.text || t.kind == Kind::Word && !crate::parse::KEYWORDS.contains(&t.text) {
        return None;
    }
    if !matches!(t.kind, Kind::Word | Kind::Punct) || matches!(t.text, "{" | "}" | "(" | ")") {
        return None;
    }
    Some(
        Advice::new(
            format!("`{}` is written twice", t.text),
            t.span(),
            "remove this",
            format!("remove the second `{}`", t.text),
        )
        .fix(format!("remove the second `{}`", t.text), Span::new(b.end, t.end), "")
        .speculative(),
    )
}

/// The last resort: a token that pest expected and that, inserted where it
/// stopped, makes the item parse (`RS run f()` lacks `=>`, `A B` an `and`).
pub(super) fn insert_expected(cx: &Cx) -> Option<Advice> {
    let t = cx.found()?;
    if t.start != cx.pos {
        return None;
    }
    const INSERTABLE: [&str; 11] = ["=>", "->", "and", "then", "{", "(", ")", "}", ",", ":", "on"];
    let at = Span::new(t.start, t.start);
    for token in INSERTABLE.iter().filter(|k| cx.exp.lit(k)).take(4) {
        let text = match *token {
            "(" | ")" | "," | ":" => token.to_string(),
            _ => format!("{token} "),
        };
        let fix = ItemFix { title: format!("insert `{token}`"), edits: vec![(at, text.clone())] };
        if !cx.works(&fix, true) {
            continue;
        }
        let help = match *token {
            "and" if cx.item == "rule" => "conditions are joined with `and`".to_string(),
            "=>" => "a table entry or an FSM state gives its action after `=>`: `RS => run f()`".to_string(),
            "(" if cx.item == "rule" || cx.item == "property" => {
                "payload constraints are written in parentheses after the event: `LAOBS(distance < 30.0)`".to_string()
            }
            _ => format!("insert `{token}`"),
        };
        let found = if t.kind == Kind::Str { "the string".to_string() } else { format!("`{}`", t.text) };
        return Some(
            Advice::new(
                format!("expected `{token}` before {found}"),
                t.span(),
                format!("expected `{token}` before this"),
                help,
            )
            .fix(format!("insert `{token}`"), at, text),
        );
    }
    // `LAOBS distance < 30.0)`: the `(` belongs before the field.
    let b = cx.before().filter(|b| b.word())?;
    if cx.exp.lit("(") && matches!(t.text, "<" | "<=" | ">" | ">=" | "==" | "!=" | ":" | "in") {
        let at = Span::new(b.start, b.start);
        let fix = ItemFix { title: "insert `(`".into(), edits: vec![(at, "(".into())] };
        if cx.works(&fix, true) {
            return Some(
                Advice::new(
                    format!("expected `(` before `{}`", b.text),
                    b.span(),
                    "expected `(` before this",
                    "payload constraints are written in parentheses after the event: `LAOBS(distance < 30.0)`",
                )
                .fix("insert `(`", at, "("),
            );
        }
    }
    None
}

/// `state == A or state == B` in a rule: one state test with a set.
fn states_or(cx: &Cx) -> Option<Advice> {
    let i = cx.at()?;
    let or = cx.tok(i)?;
    let left = cx.toks.get(i.checked_sub(3)?..i)?;
    let right = cx.toks.get(i + 1..i + 4)?;
    let is_eq = |t: &[Tok]| t[0].is("state") && t[1].is("==") && t[2].word();
    if !is_eq(left) || !is_eq(right) {
        return None;
    }
    let good = format!("state in {{{}, {}}}", left[2].text, right[2].text);
    let span = Span::new(left[0].start, right[2].end);
    Some(
        Advice::new(
            "a rule's conditions cannot be joined with `or`",
            or.span(),
            "no `or` in a rule",
            format!("for one state or another, write `{good}`"),
        )
        .fix(format!("write `{good}`"), span, good),
    )
}
