//! Text arithmetic of the protocol: LSP positions (lines and UTF-16 code
//! units) to byte offsets and back, document edits, and `file://` URIs.

use lsp_types::{Position, Range};
use situ_grammar::ast::Span;
use std::path::{Path, PathBuf};

/// The start of every line of a text, for position arithmetic.
#[derive(Debug, Clone, Default)]
pub struct LineIndex {
    starts: Vec<usize>,
}

impl LineIndex {
    pub fn new(text: &str) -> Self {
        LineIndex { starts: std::iter::once(0).chain(text.match_indices('\n').map(|(i, _)| i + 1)).collect() }
    }

    /// The position of a byte offset (clamped to the text, and back to a
    /// character boundary).
    pub fn position(&self, text: &str, offset: usize) -> Position {
        let mut offset = offset.min(text.len());
        while !text.is_char_boundary(offset) {
            offset -= 1;
        }
        let line = self.starts.partition_point(|&s| s <= offset).saturating_sub(1);
        let start = self.starts.get(line).copied().unwrap_or(0);
        let col: usize = text[start..offset].chars().map(char::len_utf16).sum();
        Position { line: line as u32, character: col as u32 }
    }

    pub fn range(&self, text: &str, span: Span) -> Range {
        Range { start: self.position(text, span.start), end: self.position(text, span.end.max(span.start)) }
    }

    /// The byte offset of a position, or `None` when its line is past the
    /// end of the text. A character past the end of its line means the end of
    /// the line (as the protocol says); one inside a surrogate pair, the
    /// character's start.
    pub fn offset(&self, text: &str, pos: Position) -> Option<usize> {
        let line = pos.line as usize;
        let start = *self.starts.get(line)?;
        let end = self.starts.get(line + 1).map_or(text.len(), |&s| s - 1);
        let mut units = 0usize;
        for (i, c) in text[start..end].char_indices() {
            units += c.len_utf16();
            if units > pos.character as usize {
                return Some(start + i);
            }
        }
        Some(end)
    }

    /// The byte span of a range, or `None` when it is impossible (outside the
    /// text, or its end before its start).
    pub fn span(&self, text: &str, range: Range) -> Option<Span> {
        let start = self.offset(text, range.start)?;
        let end = self.offset(text, range.end)?;
        (start <= end).then_some(Span::new(start, end))
    }
}

/// `file:///a/b%20c.situ` to `/a/b c.situ`; `None` for another scheme.
pub fn uri_to_path(uri: &str) -> Option<PathBuf> {
    let rest = uri.strip_prefix("file://")?;
    // `file://host/path`: only the local host (empty or `localhost`).
    let rest = rest.strip_prefix("localhost").unwrap_or(rest);
    if !rest.starts_with('/') {
        return None;
    }
    let bytes = rest.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' && i + 2 < bytes.len() {
            let hex = std::str::from_utf8(&bytes[i + 1..i + 3]).ok().and_then(|h| u8::from_str_radix(h, 16).ok());
            if let Some(b) = hex {
                out.push(b);
                i += 3;
                continue;
            }
        }
        out.push(bytes[i]);
        i += 1;
    }
    let path = String::from_utf8(out).ok()?;
    Some(situ_compiler::loader::normalize(Path::new(&path)))
}

/// `/a/b c.situ` to `file:///a/b%20c.situ`.
pub fn path_to_uri(path: &Path) -> String {
    let mut out = String::from("file://");
    for b in path.to_string_lossy().bytes() {
        if b.is_ascii_alphanumeric() || b"/-_.~".contains(&b) {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// Why a text cannot be a name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum NameError {
    #[error("`{0}` is not a name: a letter, then letters, digits and `_`")]
    NotAName(String),
    #[error("`{0}` is a keyword and cannot be a name")]
    Keyword(String),
}

/// Whether `name` can name something: a letter, then letters, digits and `_`,
/// not a keyword.
pub fn valid_name(name: &str) -> Result<(), NameError> {
    let mut chars = name.chars();
    let ok =
        chars.next().is_some_and(|c| c.is_ascii_alphabetic()) && chars.all(|c| c.is_ascii_alphanumeric() || c == '_');
    if !ok {
        return Err(NameError::NotAName(name.to_string()));
    }
    if situ_grammar::parse::KEYWORDS.contains(&name) {
        return Err(NameError::Keyword(name.to_string()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pos(line: u32, character: u32) -> Position {
        Position { line, character }
    }

    #[test]
    fn positions_count_utf16_units() {
        let text = "ab\n// é𝄞x\n";
        let idx = LineIndex::new(text);
        assert_eq!(idx.position(text, 0), pos(0, 0));
        assert_eq!(idx.position(text, 3), pos(1, 0));
        let x = text.find('x').unwrap();
        // `// ` is 3 units, `é` 1, `𝄞` 2.
        assert_eq!(idx.position(text, x), pos(1, 6));
        assert_eq!(idx.offset(text, pos(1, 6)), Some(x));
        assert_eq!(idx.offset(text, pos(1, 5)), Some(x - 4)); // inside the pair: its start
        assert_eq!(idx.offset(text, pos(0, 99)), Some(2)); // past the line: its end
        assert_eq!(idx.offset(text, pos(2, 0)), Some(text.len()));
        assert_eq!(idx.offset(text, pos(3, 0)), None);
        assert_eq!(idx.position(text, 999), pos(2, 0));
    }

    #[test]
    fn impossible_ranges_are_refused() {
        let text = "abc\ndef";
        let idx = LineIndex::new(text);
        let r = |a: Position, b: Position| Range { start: a, end: b };
        assert_eq!(idx.span(text, r(pos(0, 1), pos(1, 2))), Some(Span::new(1, 6)));
        assert_eq!(idx.span(text, r(pos(1, 2), pos(0, 1))), None);
        assert_eq!(idx.span(text, r(pos(0, 0), pos(9, 0))), None);
    }

    #[test]
    fn uris_round_trip() {
        let p = Path::new("/tmp/a b/ç.situ");
        let uri = path_to_uri(p);
        assert_eq!(uri, "file:///tmp/a%20b/%C3%A7.situ");
        assert_eq!(uri_to_path(&uri).as_deref(), Some(p));
        assert_eq!(uri_to_path("untitled:1"), None);
        assert_eq!(uri_to_path("file:///x/%zz").as_deref(), Some(Path::new("/x/%zz")));
        assert_eq!(uri_to_path("file:///x/%"), Some(PathBuf::from("/x/%")));
    }

    #[test]
    fn names_are_checked() {
        assert!(valid_name("RS2").is_ok());
        assert!(valid_name("state").unwrap_err().to_string().contains("keyword"));
        assert!(valid_name("2x").is_err());
        assert!(valid_name("").is_err());
    }
}
