//! Lexical scans that run before the grammar: splitting a file into top-level
//! items (the unit of error recovery) and collecting comments (which the
//! grammar skips but the formatter keeps).

use crate::ast::Span;

/// The words that start a top-level item.
const ITEM_KEYWORDS: [&str; 7] = ["states", "agent", "rule", "test", "property", "script", "include"];

/// A `//` comment: its text without the slashes, and where it is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Comment {
    pub text: String,
    pub span: Span,
}

/// Whether an item keyword (or an attribute) starts at `at`.
///
/// `script` is not reserved (a state or a field may be called so): it starts
/// an item only as `script "name" {`, which no member of an item can be.
fn item_starts_at(bytes: &[u8], at: usize) -> bool {
    let rest = &bytes[at..];
    if rest.starts_with(b"#[") {
        return true;
    }
    ITEM_KEYWORDS.iter().any(|kw| {
        rest.starts_with(kw.as_bytes())
            && rest.get(kw.len()).is_none_or(|c| !(c.is_ascii_alphanumeric() || *c == b'_'))
            && (*kw != "script" || script_head_at(bytes, at + kw.len()))
    })
}

/// Whether `"name" {` follows `at`, trivia aside: the rest of a script's head.
fn script_head_at(bytes: &[u8], at: usize) -> bool {
    let skip_blank = |mut i: usize| loop {
        match bytes.get(i) {
            Some(c) if c.is_ascii_whitespace() => i += 1,
            Some(b'/') if bytes.get(i + 1) == Some(&b'/') => i = skip_comment(bytes, i),
            _ => return i,
        }
    };
    let i = skip_blank(at);
    if bytes.get(i) != Some(&b'"') {
        return false;
    }
    let end = skip_string(bytes, i);
    bytes.get(end - 1) == Some(&b'"') && end - 1 > i && bytes.get(skip_blank(end)) == Some(&b'{')
}

/// Whether the line after the newline at `newline` starts with an item, at
/// any indentation.
fn next_line_starts_item(bytes: &[u8], newline: usize) -> bool {
    let mut at = newline + 1;
    while bytes.get(at).is_some_and(|c| matches!(c, b' ' | b'\t' | b'\r')) {
        at += 1;
    }
    at < bytes.len() && item_starts_at(bytes, at)
}

/// Skips a string literal that starts at `i` (a `"`); returns the index after
/// its closing quote, or after the end of the line if it is not closed.
pub(crate) fn skip_string(bytes: &[u8], mut i: usize) -> usize {
    i += 1;
    while i < bytes.len() {
        match bytes[i] {
            b'\\' => i += 2,
            b'"' => return i + 1,
            b'\n' => return i,
            _ => i += 1,
        }
    }
    bytes.len()
}

/// Skips a comment that starts at `i` (`//`); returns the index of the newline
/// that ends it, or the end of the input.
fn skip_comment(bytes: &[u8], i: usize) -> usize {
    bytes[i..].iter().position(|&c| c == b'\n').map_or(bytes.len(), |p| i + p)
}

/// Splits a source into the spans of its top-level items.
///
/// An item ends at the `}` that closes its first brace, or where a line starts
/// with an item keyword (so that a missing `}` costs one item and not the
/// rest of the file, and an item without braces, `include "a.situ"`, ends
/// where the next begins). The keyword may stand at any column: layout never
/// changes what a file means. No item keyword but `script` can appear in an
/// item, and `script` starts one only as `script "name" {` (see
/// `item_starts_at`). Trivia between items belongs to no item.
pub fn split_items(src: &str) -> Vec<Span> {
    let bytes = src.as_bytes();
    let mut items = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        // Skip trivia before an item.
        match bytes[i] {
            c if c.is_ascii_whitespace() => {
                i += 1;
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = skip_comment(bytes, i);
                continue;
            }
            _ => {}
        }
        let start = i;
        let mut depth = 0usize;
        let mut opened = false;
        let mut end = bytes.len();
        while i < bytes.len() {
            match bytes[i] {
                b'"' => {
                    i = skip_string(bytes, i);
                    continue;
                }
                b'/' if bytes.get(i + 1) == Some(&b'/') => {
                    i = skip_comment(bytes, i);
                    continue;
                }
                b'{' => {
                    depth += 1;
                    opened = true;
                }
                b'}' => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 && opened {
                        end = i + 1;
                        i += 1;
                        break;
                    }
                }
                // Attributes stand on their own lines before the item they annotate.
                b'\n' if (opened || bytes[start] != b'#') && next_line_starts_item(bytes, i) => {
                    // A new item starts the next line: this one ends here, closed or not.
                    end = i;
                    i += 1;
                    break;
                }
                _ => {}
            }
            i += 1;
        }
        if i >= bytes.len() && end > bytes.len() {
            end = bytes.len();
        }
        items.push(Span::new(start, end.min(bytes.len())));
    }
    items
}

/// Collects every `//` comment of a source, in order.
pub fn comments(src: &str) -> Vec<Comment> {
    let bytes = src.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => i = skip_string(bytes, i),
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                let end = skip_comment(bytes, i);
                let text = src[i + 2..end].trim_end().to_string();
                out.push(Comment { text, span: Span::new(i, end) });
                i = end;
            }
            _ => i += 1,
        }
    }
    out
}

/// The deepest nesting of `(`, `{` and `[` in a source, outside strings and
/// comments. The parser refuses items nested deeper than it can recurse into.
pub fn max_nesting(src: &str) -> (usize, usize) {
    let bytes = src.as_bytes();
    let (mut depth, mut max, mut at) = (0usize, 0usize, 0usize);
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'"' => {
                i = skip_string(bytes, i);
                continue;
            }
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = skip_comment(bytes, i);
                continue;
            }
            b'(' | b'{' | b'[' => {
                depth += 1;
                if depth > max {
                    max = depth;
                    at = i;
                }
            }
            b')' | b'}' | b']' => depth = depth.saturating_sub(1),
            _ => {}
        }
        i += 1;
    }
    (max, at)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn texts(src: &str) -> Vec<&str> {
        split_items(src).into_iter().map(|s| &src[s.start..s.end]).collect()
    }

    #[test]
    fn splits_on_closing_braces_and_includes() {
        let src = "include \"a.situ\"\nstates { A initial }\n// c\nrule r { when X then A }\n";
        assert_eq!(texts(src), vec!["include \"a.situ\"", "states { A initial }", "rule r { when X then A }"]);
    }

    #[test]
    fn a_missing_brace_costs_one_item() {
        let src = "rule r { when X then A\nrule s { when Y then B }";
        assert_eq!(texts(src), vec!["rule r { when X then A", "rule s { when Y then B }"]);
    }

    #[test]
    fn attributes_stay_with_their_item() {
        let src = "#[allow(W0301)]\nrule r { when X then A }\nrule s { when Y then B }";
        assert_eq!(texts(src), vec!["#[allow(W0301)]\nrule r { when X then A }", "rule s { when Y then B }"]);
    }

    #[test]
    fn an_item_may_start_at_any_column() {
        // What `situ test` prints for a counterexample, pasted after an include.
        let src = "include \"x.situ\"\n    test \"t\" {\n        on A\n    }\n\t rule r { when X then A\n\tproperty \"p\" { always true }";
        assert_eq!(
            texts(src),
            vec![
                "include \"x.situ\"",
                "test \"t\" {\n        on A\n    }",
                "rule r { when X then A",
                "property \"p\" { always true }"
            ]
        );
    }

    #[test]
    fn script_starts_an_item_only_with_its_head() {
        // `script` is not reserved: a state may be called so.
        let src = "states {\n    script \"a state\"\n    B initial\n}\ninclude \"x.situ\"\n  script \"s\" // c\n  { at 1s E }";
        assert_eq!(
            texts(src),
            vec![
                "states {\n    script \"a state\"\n    B initial\n}",
                "include \"x.situ\"",
                "script \"s\" // c\n  { at 1s E }"
            ]
        );
    }

    #[test]
    fn braces_in_strings_and_comments_do_not_count() {
        let src = "agent A sensor \"{\" { // }\n event E }\nrule r { when E then S }";
        assert_eq!(texts(src), vec!["agent A sensor \"{\" { // }\n event E }", "rule r { when E then S }"]);
    }

    #[test]
    fn collects_comments_but_not_slashes_in_strings() {
        let src = "states { A \"a // b\" } // end\n// next";
        let c = comments(src);
        assert_eq!(c.iter().map(|c| c.text.as_str()).collect::<Vec<_>>(), vec![" end", " next"]);
    }

    #[test]
    fn measures_nesting() {
        assert_eq!(max_nesting("a ( { [ ] } ) ( )").0, 3);
        assert_eq!(max_nesting("\"(((\" // ((((").0, 0);
    }
}
