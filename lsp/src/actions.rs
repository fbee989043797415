//! Edits the server proposes: formatting (whole document and range), code
//! actions (the diagnostics' fixes, the missing table row, `#[allow(code)]`),
//! and inlay hints.

use crate::diagnostics::{of_file, to_lsp};
use crate::nav::analysis;
use crate::server::{invalid_params, Answer};
use crate::world::{Analysis, World};
use serde_json::{json, Value};
use situ_compiler::codes;
use situ_grammar::ast::{self, AgentMember, Item, Span};
use situ_grammar::diag::{Diagnostic, FileId, Severity};
use std::collections::BTreeMap;

/// The smallest edit that turns `old` into `new`: one replacement of what
/// lies between their common prefix and suffix.
fn minimal_edit(old: &str, new: &str) -> Option<(Span, String)> {
    if old == new {
        return None;
    }
    let mut pre = old.bytes().zip(new.bytes()).take_while(|(a, b)| a == b).count();
    while !old.is_char_boundary(pre) || !new.is_char_boundary(pre) {
        pre -= 1;
    }
    let max_suf = old.len().min(new.len()) - pre;
    let mut suf = old.bytes().rev().zip(new.bytes().rev()).take(max_suf).take_while(|(a, b)| a == b).count();
    while !old.is_char_boundary(old.len() - suf) || !new.is_char_boundary(new.len() - suf) {
        suf -= 1;
    }
    Some((Span::new(pre, old.len() - suf), new[pre..new.len() - suf].to_string()))
}

fn text_edit(a: &Analysis, file: FileId, span: Span, text: &str) -> Value {
    json!({ "range": a.range(file, span), "newText": text })
}

/// The whole document, formatted; no edit when it has syntax errors.
pub fn formatting(world: &World, params: &Value) -> Answer {
    let (a, file) = analysis(world, params)?;
    let text = a.text(file);
    let Ok(formatted) = situ_grammar::format(text) else { return Ok(Value::Null) };
    Ok(json!(minimal_edit(text, &formatted).map(|(s, t)| vec![text_edit(a, file, s, &t)]).unwrap_or_default()))
}

/// The items the range touches, formatted.
pub fn range_formatting(world: &World, params: &Value) -> Answer {
    let (a, file) = analysis(world, params)?;
    let text = a.text(file);
    let range = params.get("range").cloned().and_then(|r| serde_json::from_value(r).ok());
    let span = range
        .and_then(|r| a.lines[file.0 as usize].span(text, r))
        .ok_or_else(|| invalid_params("no range, or a range outside the document"))?;
    let items: Vec<Span> = a.asts[file.0 as usize]
        .items
        .iter()
        .map(Item::span)
        .filter(|s| s.start <= span.end && span.start <= s.end)
        .collect();
    let (Some(first), Some(last)) = (items.first(), items.last()) else { return Ok(json!([])) };
    let whole = Span::new(first.start, last.end);
    let Some(slice) = text.get(whole.start..whole.end) else { return Ok(json!([])) };
    let Ok(formatted) = situ_grammar::format(slice) else { return Ok(Value::Null) };
    let formatted = formatted.trim_end_matches('\n');
    Ok(json!(minimal_edit(slice, formatted)
        .map(|(s, t)| vec![text_edit(a, file, Span::new(whole.start + s.start, whole.start + s.end), &t)])
        .unwrap_or_default()))
}

fn action(a: &Analysis, d: &Diagnostic, title: String, edits: Vec<(FileId, Span, String)>, preferred: bool) -> Value {
    let mut changes: BTreeMap<String, Vec<Value>> = BTreeMap::new();
    for (file, span, text) in edits {
        changes.entry(a.uri(file)).or_default().push(text_edit(a, file, span, &text));
    }
    json!({
        "title": title,
        "kind": "quickfix",
        "diagnostics": [to_lsp(a, d)],
        "isPreferred": preferred,
        "edit": { "changes": changes },
    })
}

pub fn code_actions(world: &World, params: &Value) -> Answer {
    let (a, file) = analysis(world, params)?;
    let text = a.text(file);
    let range = params.get("range").cloned().and_then(|r| serde_json::from_value(r).ok());
    let span = range
        .and_then(|r| a.lines[file.0 as usize].span(text, r))
        .ok_or_else(|| invalid_params("no range, or a range outside the document"))?;
    let mut out = Vec::new();
    for d in of_file(a, file).filter(|d| d.primary.span.start <= span.end && span.start <= d.primary.span.end) {
        for (i, fix) in d.fixes.iter().enumerate() {
            let edits = fix
                .edits
                .iter()
                .filter(|e| (e.file.0 as usize) < a.paths.len())
                .map(|e| (e.file, e.span, e.text.clone()))
                .collect();
            out.push(action(a, d, fix.title.clone(), edits, i == 0));
        }
        if d.code == codes::NO_TABLE_ENTRY {
            if let Some(v) = missing_row(a, file, d) {
                out.push(v);
            }
        }
        if d.severity == Severity::Warning {
            if let Some((name, start)) = attributable(a, file, d.primary.span.start) {
                let title = format!("allow `{}` on `{name}`", d.code);
                out.push(action(
                    a,
                    d,
                    title,
                    vec![(file, Span::new(start, start), format!("#[allow({})]\n", d.code))],
                    false,
                ));
            }
        }
    }
    Ok(json!(out))
}

/// The agent or rule around `offset`: its name and where its first line starts.
fn attributable(a: &Analysis, file: FileId, offset: usize) -> Option<(String, usize)> {
    a.asts[file.0 as usize].items.iter().find_map(|item| match item {
        Item::Agent(ag) if ag.span.start <= offset && offset <= ag.span.end => {
            Some((ag.name.name.clone(), ag.span.start))
        }
        Item::Rule(r) if r.span.start <= offset && offset <= r.span.end => Some((r.name.name.clone(), r.span.start)),
        _ => None,
    })
}

/// `STATES => sleep`, before the closing brace of the table W0311 is about.
fn missing_row(a: &Analysis, file: FileId, d: &Diagnostic) -> Option<Value> {
    let missing: Vec<&str> = d.witness.as_ref()?.get("missing")?.as_array()?.iter().filter_map(Value::as_str).collect();
    if missing.is_empty() {
        return None;
    }
    let at = d.primary.span.start;
    let table = a.asts[file.0 as usize].items.iter().find_map(|item| match item {
        Item::Agent(ag) => ag.members.iter().find_map(|m| match m {
            AgentMember::Table(t) if t.span.start <= at && at < t.span.end => Some(t),
            _ => None,
        }),
        _ => None,
    })?;
    let text = a.text(file);
    let close = table.span.end.checked_sub(1).filter(|&c| text.as_bytes().get(c) == Some(&b'}'))?;
    let row = format!("{} => sleep", missing.join(", "));
    let line_start = text[..close].rfind('\n').map_or(0, |i| i + 1);
    let (span, insert) = if text[line_start..close].trim().is_empty() && line_start > table.span.start {
        let indent = table
            .entries
            .first()
            .map(|e| {
                let ls = text[..e.span.start].rfind('\n').map_or(0, |i| i + 1);
                text[ls..e.span.start].to_string()
            })
            .filter(|i| i.trim().is_empty())
            .unwrap_or_else(|| format!("{}    ", &text[line_start..close]));
        (Span::new(line_start, line_start), format!("{indent}{row}\n"))
    } else {
        (Span::new(close, close), format!(" {row} "))
    };
    Some(action(a, d, format!("add the missing table row `{row}`"), vec![(file, span, insert)], false))
}

pub fn inlay_hints(world: &World, params: &Value) -> Answer {
    let (a, file) = analysis(world, params)?;
    let text = a.text(file);
    let lines = &a.lines[file.0 as usize];
    let range = params
        .get("range")
        .cloned()
        .and_then(|r| serde_json::from_value(r).ok())
        .and_then(|r| lines.span(text, r))
        .unwrap_or(Span::new(0, text.len()));
    let inside = |o: usize| range.start <= o && o <= range.end;
    let states: Vec<String> = a
        .index
        .occurrences
        .iter()
        .filter_map(|o| match (&o.sym, o.def) {
            (crate::index::Sym::State(n), true) => Some(n.clone()),
            _ => None,
        })
        .collect();
    let mut out = Vec::new();
    for w in a.index.wildcards.iter().filter(|w| w.file == file && inside(w.span.end)) {
        let covered: Vec<&str> = states.iter().filter(|s| !w.named.contains(s)).map(String::as_str).collect();
        let shown = if covered.len() > 8 {
            format!("{}, … ({} states)", covered[..8].join(", "), covered.len())
        } else if covered.is_empty() {
            "no state".to_string()
        } else {
            covered.join(", ")
        };
        out.push(json!({
            "position": lines.position(text, w.span.end),
            "label": format!(": {shown}"),
            "kind": 1,
            "tooltip": "the states `_` stands for",
        }));
    }
    for item in &a.asts[file.0 as usize].items {
        let Item::Rule(r) = item else { continue };
        if !inside(r.name.span.end) {
            continue;
        }
        let runs: u64 = r
            .conditions
            .iter()
            .filter_map(|c| match c {
                ast::Condition::Pattern(p) => Some(p.run_length.as_ref().map_or(1, |r| r.count)),
                _ => None,
            })
            .fold(0u64, u64::saturating_add);
        if runs == 0 {
            continue;
        }
        out.push(json!({
            "position": lines.position(text, r.name.span.end),
            "label": format!("needs {runs} event{}", if runs == 1 { "" } else { "s" }),
            "paddingLeft": true,
            "tooltip": "the fewest reports that can fire this rule: each pattern's run length, added",
        }));
    }
    Ok(json!(out))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_edits_keep_what_is_common() {
        assert_eq!(minimal_edit("abc", "abc"), None);
        assert_eq!(minimal_edit("a  b", "a b"), Some((Span::new(2, 3), String::new())));
        assert_eq!(minimal_edit("xé", "xè"), Some((Span::new(1, 3), "è".into())));
        assert_eq!(minimal_edit("aa", "aaa"), Some((Span::new(2, 2), "a".into())));
    }
}
