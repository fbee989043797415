//! Edits the server proposes: formatting (whole document and range), code
//! actions (the diagnostics' fixes, the missing table row, `#[allow(code)]`),
//! and inlay hints.

pub use crate::data::CodeAction;
use crate::data::{TextEdit, WorkspaceEdit};
use crate::diagnostics::{finding, of_file};
use crate::world::Analysis;
use lsp_types::{InlayHintKind, Position};
use situ_compiler::codes;
use situ_grammar::ast::{self, AgentMember, Item, Span};
use situ_grammar::diag::{Diagnostic, FileId, Severity};

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

fn text_edit(a: &Analysis, file: FileId, span: Span, text: &str) -> TextEdit {
    TextEdit { range: a.range(file, span), new_text: text.to_string() }
}

/// The whole document, formatted: one edit, or none when it is formatted
/// already; `None` when it has syntax errors.
pub fn formatting(a: &Analysis, file: FileId) -> Option<Vec<TextEdit>> {
    let text = a.text(file);
    let formatted = situ_grammar::format(text).ok()?;
    Some(minimal_edit(text, &formatted).map(|(s, t)| vec![text_edit(a, file, s, &t)]).unwrap_or_default())
}

/// The items `span` touches, formatted; `None` when they have syntax errors.
pub fn range_formatting(a: &Analysis, file: FileId, span: Span) -> Option<Vec<TextEdit>> {
    let text = a.text(file);
    let items: Vec<Span> = a.asts[file.0 as usize]
        .items
        .iter()
        .map(Item::span)
        .filter(|s| s.start <= span.end && span.start <= s.end)
        .collect();
    let (Some(first), Some(last)) = (items.first(), items.last()) else { return Some(Vec::new()) };
    let whole = Span::new(first.start, last.end);
    let Some(slice) = text.get(whole.start..whole.end) else { return Some(Vec::new()) };
    let formatted = situ_grammar::format(slice).ok()?;
    let formatted = formatted.trim_end_matches('\n');
    Some(
        minimal_edit(slice, formatted)
            .map(|(s, t)| vec![text_edit(a, file, Span::new(whole.start + s.start, whole.start + s.end), &t)])
            .unwrap_or_default(),
    )
}

fn action(
    a: &Analysis,
    d: &Diagnostic,
    title: String,
    edits: Vec<(FileId, Span, String)>,
    preferred: bool,
) -> CodeAction {
    let mut edit = WorkspaceEdit::new();
    for (file, span, text) in edits {
        edit.entry(a.uri(file)).or_default().push(text_edit(a, file, span, &text));
    }
    CodeAction { title, finding: finding(a, d), preferred, edit }
}

/// The fixes of the findings `span` touches: the compiler's own, the missing
/// table row, and `#[allow(code)]` for a warning.
pub fn code_actions(a: &Analysis, file: FileId, span: Span) -> Vec<CodeAction> {
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
    out
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
fn missing_row(a: &Analysis, file: FileId, d: &Diagnostic) -> Option<CodeAction> {
    let missing: Vec<&str> =
        d.witness.as_ref()?.get("missing")?.as_array()?.iter().filter_map(|v| v.as_str()).collect();
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

/// A note the editor shows inside the text.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct InlayHint {
    pub position: Position,
    pub label: String,
    /// `Some(TYPE)` for what `_` stands for; none for a rule's length.
    pub kind: Option<InlayHintKind>,
    pub padding_left: bool,
    pub tooltip: &'static str,
}

/// In `range` (the whole document when `None`): the states each table's `_`
/// stands for, and the fewest events each rule needs.
pub fn inlay_hints(a: &Analysis, file: FileId, range: Option<Span>) -> Vec<InlayHint> {
    let text = a.text(file);
    let lines = &a.lines[file.0 as usize];
    let range = range.unwrap_or(Span::new(0, text.len()));
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
        out.push(InlayHint {
            position: lines.position(text, w.span.end),
            label: format!(": {shown}"),
            kind: Some(InlayHintKind::TYPE),
            padding_left: false,
            tooltip: "the states `_` stands for",
        });
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
        out.push(InlayHint {
            position: lines.position(text, r.name.span.end),
            label: format!("needs {runs} event{}", if runs == 1 { "" } else { "s" }),
            kind: None,
            padding_left: true,
            tooltip: "the fewest reports that can fire this rule: each pattern's run length, added",
        });
    }
    out
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

    #[test]
    fn formatting_is_one_edit_or_none() {
        let (w, path) = crate::world::world_of("actions-fmt", "states {   IT initial }\n");
        let (a, file) = w.primary(&path).unwrap();
        let edits = formatting(a, file).unwrap();
        assert_eq!(edits.len(), 1);
        assert_eq!(
            (edits[0].range.start.character, edits[0].range.end.character, edits[0].new_text.as_str()),
            (8, 22, "\n    IT initial\n")
        );
        let (w, path) = crate::world::world_of("actions-fmt-bad", "states { IT initial ");
        let (a, file) = w.primary(&path).unwrap();
        assert_eq!(formatting(a, file), None, "a syntax error: no edit");
    }

    #[test]
    fn a_missing_row_and_an_allow_are_offered() {
        let (w, path) = crate::world::world_of("actions-fix", crate::world::SMALL);
        let (a, file) = w.primary(&path).unwrap();
        let all = code_actions(a, file, Span::new(0, a.text(file).len()));
        let row = all.iter().find(|c| c.title == "add the missing table row `RD => sleep`").expect("row");
        assert_eq!(row.finding.code, codes::NO_TABLE_ENTRY);
        let edit = &row.edit[&a.uri(file)][0];
        assert_eq!((edit.range.start.line, edit.new_text.as_str()), (9, "        RD => sleep\n"));
        assert!(all.iter().any(|c| c.title == format!("allow `{}` on `A`", codes::NO_TABLE_ENTRY)));
        assert!(code_actions(a, file, Span::new(0, 3)).is_empty(), "nothing found in the comment");
    }

    #[test]
    fn inlay_hints_count_events_and_name_wildcards() {
        let text = "states { IT initial RD }\nagent A sensor { event E function f table { IT => run f() _ => sleep } }\nrule r { when E then RD }\n";
        let (w, path) = crate::world::world_of("actions-hints", text);
        let (a, file) = w.primary(&path).unwrap();
        let hints = inlay_hints(a, file, None);
        let labels: Vec<&str> = hints.iter().map(|h| h.label.as_str()).collect();
        assert_eq!(labels, [": RD", "needs 1 event"]);
        assert_eq!(hints[0].kind, Some(InlayHintKind::TYPE));
        assert!(hints[1].padding_left && hints[1].kind.is_none());
        assert!(inlay_hints(a, file, Some(Span::new(0, 5))).is_empty());
    }
}
