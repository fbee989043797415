//! The source text miette draws from, indexed once per file.
//!
//! miette's own `SourceCode for str` scans the text from its start for every
//! span it reads, and a report owns its source: drawing N findings of a
//! large file copied and scanned the file N times. A [`Text`] is shared by
//! every report of a file and knows where each line starts, so that reading
//! a span looks only at the lines it shows. It answers exactly as miette's
//! implementation would (the same data, line, column and line count), so
//! reports are drawn to the byte as before.
//!
//! A line longer than [`LONG_LINE`] bytes is not drawn whole: a report whose
//! labels sit on such a line is drawn on a window of it around the primary
//! label (see [`Window`]), so that a finding at column 70,000 is drawn as
//! one at column 70 would be, with its true line and column in the header.

use miette::{MietteError, MietteSpanContents, SourceCode, SourceSpan, SpanContents};
use std::sync::Arc;

/// Lines longer than this (in bytes) are shown as a window around a label.
pub(super) const LONG_LINE: usize = 1024;
/// Bytes of a long line shown before the primary label's start, and after its end.
const MARGIN: usize = 64;
/// At most this many bytes of a long primary label are shown.
const MAX_LABEL: usize = 256;
/// What marks the cut ends of a window.
const CUT: &str = "…";

/// A text and the byte offset where each of its lines starts, counting line
/// ends as miette does (`\n`, `\r\n`, and a lone `\r`).
#[derive(Debug, Clone)]
pub(super) struct Text {
    text: Arc<str>,
    starts: Arc<[usize]>,
    /// The file's line number of this text's first line (0-based).
    line_base: usize,
    /// Added to the column of a span read without context (a window's cut).
    column_shift: usize,
}

impl Text {
    pub(super) fn new(text: &str) -> Text {
        Text { text: Arc::from(text), starts: line_starts(text).into(), line_base: 0, column_shift: 0 }
    }

    /// The line (0-based) that holds byte `offset`.
    pub(super) fn line_of(&self, offset: usize) -> usize {
        self.starts.partition_point(|&s| s <= offset).saturating_sub(1)
    }

    /// The byte range of a line, without its line end.
    pub(super) fn line_range(&self, line: usize) -> (usize, usize) {
        let start = self.starts[line];
        let next = self.starts.get(line + 1).copied().unwrap_or(self.text.len());
        let bytes = self.text.as_bytes();
        let mut end = next;
        if end > start && bytes[end - 1] == b'\n' {
            end -= 1;
        }
        if end > start && bytes[end - 1] == b'\r' {
            end -= 1;
        }
        (start, end)
    }

    /// Whether the line holding `offset` is longer than [`LONG_LINE`].
    pub(super) fn on_long_line(&self, offset: usize) -> bool {
        let (start, end) = self.line_range(self.line_of(offset.min(self.text.len())));
        end - start > LONG_LINE
    }

    /// A window of the long line holding `primary`, as a text of its own
    /// that keeps the file's line number and the line's columns.
    pub(super) fn window(&self, primary: (usize, usize)) -> Window {
        let (p_start, p_end) = (primary.0.min(self.text.len()), primary.1.min(self.text.len()));
        let line = self.line_of(p_start);
        let (line_start, line_end) = self.line_range(line);
        let mut from = floor_boundary(&self.text, p_start.saturating_sub(MARGIN).max(line_start));
        if from - line_start <= CUT.len() {
            from = line_start; // no shorter to cut than to show
        }
        let label_end = p_end.max(p_start).min(p_start + MAX_LABEL);
        let to = ceil_boundary(&self.text, (label_end + MARGIN).min(line_end)).max(from);
        let prefix = if from > line_start { CUT } else { "" };
        let suffix = if to < line_end { CUT } else { "" };
        let shown = format!("{prefix}{}{suffix}", &self.text[from..to]);
        let text = Text {
            starts: line_starts(&shown).into(),
            text: Arc::from(shown),
            line_base: line,
            column_shift: from - line_start - prefix.len(),
        };
        Window { text, from, to, offset: prefix.len() }
    }
}

/// A window of a long line: its text, the bytes `from..to` of the file it
/// shows, and where they start in the window's text.
pub(super) struct Window {
    pub(super) text: Text,
    from: usize,
    to: usize,
    offset: usize,
}

impl Window {
    /// A file span in the window's offsets, clipped to it; `None` when the
    /// span does not start in the window.
    pub(super) fn map(&self, start: usize, end: usize) -> Option<(usize, usize)> {
        if start < self.from || start > self.to {
            return None;
        }
        let end = end.clamp(start, self.to);
        Some((start - self.from + self.offset, end - self.from + self.offset))
    }
}

fn floor_boundary(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i -= 1;
    }
    i
}

fn ceil_boundary(text: &str, mut i: usize) -> usize {
    while !text.is_char_boundary(i) {
        i += 1;
    }
    i
}

fn line_starts(text: &str) -> Vec<usize> {
    let bytes = text.as_bytes();
    let mut starts = vec![0];
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'\r' if bytes.get(i + 1) == Some(&b'\n') => {
                i += 1;
                starts.push(i + 1);
            }
            b'\r' | b'\n' => starts.push(i + 1),
            _ => {}
        }
        i += 1;
    }
    starts
}

/// How many lines a context spans. miette's own reading answers the line
/// number where its scan stopped instead, and its renderer merges two
/// labels' contexts when `line + line_count` reaches the second one: deep in
/// a file every pair of labels within twice the first one's line number was
/// drawn as one snippet with every line between them. With the count of the
/// context's own lines plus a few ([`MERGE_GAP`]), contexts separated by at
/// most that many lines are merged and the others drawn apart.
fn lines_in(data: &[u8]) -> usize {
    line_count(data) + MERGE_GAP
}

/// How many unlabelled lines may lie between two contexts that are still
/// drawn as one snippet (fewer lines than a second snippet's frame).
const MERGE_GAP: usize = 1;

fn line_count(data: &[u8]) -> usize {
    let mut lines = 1;
    let mut bytes = data.iter().peekable();
    while let Some(&b) = bytes.next() {
        let end = b == b'\n' || (b == b'\r' && bytes.peek() != Some(&&b'\n'));
        if end && bytes.peek().is_some() {
            lines += 1;
        }
    }
    lines
}

impl SourceCode for Text {
    fn read_span<'a>(
        &'a self,
        span: &SourceSpan,
        context_lines_before: usize,
        context_lines_after: usize,
    ) -> Result<Box<dyn SpanContents<'a> + 'a>, MietteError> {
        let len = self.text.len();
        if span.offset() + span.len() > len {
            // Reports clamp their labels to the text; miette's own reading
            // may panic past the end.
            return Err(MietteError::OutOfBounds);
        }
        // The lines miette's scan would look at: from one line more than
        // `before` above the span's first line (an empty span is found at
        // the byte before it) to two lines past `after` below its last. From
        // any line start before the span, the scan goes the same way.
        let first = self.line_of(span.offset()).saturating_sub(context_lines_before + 1);
        let last_byte = (span.offset() + span.len()).saturating_sub(1).max(span.offset());
        let last = self.line_of(last_byte.min(len)) + context_lines_after + 2;
        let from = self.starts[first];
        let to = self.starts.get(last).copied().unwrap_or(len);
        let slice = &self.text.as_bytes()[from..to];
        let inner = SourceSpan::new((span.offset() - from).into(), span.len());
        let found = slice.read_span(&inner, context_lines_before, context_lines_after)?;
        let column = if context_lines_before == 0 { found.column() + self.column_shift } else { found.column() };
        Ok(Box::new(MietteSpanContents::new(
            found.data(),
            SourceSpan::new((found.span().offset() + from).into(), found.span().len()),
            found.line() + first + self.line_base,
            column,
            lines_in(found.data()),
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn same(text: &str, span: SourceSpan, before: usize, after: usize) {
        let indexed = Text::new(text);
        let theirs = text.read_span(&span, before, after);
        let ours = indexed.read_span(&span, before, after);
        match (theirs, ours) {
            (Ok(t), Ok(o)) => {
                let at = format!("{text:?} {span:?} {before} {after}");
                assert_eq!(t.data(), o.data(), "{at}");
                assert_eq!(t.span(), o.span(), "{at}");
                assert_eq!(t.line(), o.line(), "{at}");
                assert_eq!(t.column(), o.column(), "{at}");
                // Not `line_count`: ours is the context's own (`lines_in`).
            }
            (Err(_), Err(_)) => {}
            (t, o) => panic!("{text:?} {span:?}: miette {:?}, ours {:?}", t.is_ok(), o.is_ok()),
        };
    }

    #[test]
    fn a_context_counts_its_own_lines() {
        assert_eq!(line_count(b""), 1);
        assert_eq!(line_count(b"a"), 1);
        assert_eq!(line_count(b"a\n"), 1);
        assert_eq!(line_count(b"a\nb"), 2);
        assert_eq!(line_count(b"a\r\nb\r\nc\n"), 3);
        assert_eq!(line_count(b"a\rb\n\nc"), 4);
        let text = Text::new(&"line\n".repeat(100));
        let deep = text.read_span(&SourceSpan::new(250.into(), 2), 1, 1).unwrap();
        assert_eq!((deep.line(), deep.line_count()), (49, 3 + MERGE_GAP));
    }

    #[test]
    fn reads_every_span_as_miette_does() {
        let texts = [
            "",
            "a",
            "ab\ncd\n",
            "ab\r\ncd\r\n\r\nef",
            "x\ry\n\nz\n",
            "\n\n\n",
            "çé\nλx\n  y",
            "one\ntwo",
            "a\nb\nc\nd\ne\nf\ng\n",
            "\r\n\r\nx\r\ny\n\rz",
        ];
        for text in texts {
            for start in 0..=text.len() {
                for len in 0..=text.len() - start {
                    for (before, after) in [(0, 0), (1, 1), (2, 2), (0, 1), (3, 0)] {
                        same(text, SourceSpan::new(start.into(), len), before, after);
                    }
                }
            }
        }
    }

    #[test]
    fn reads_only_the_lines_it_shows() {
        // 100,000 lines: a span near the end comes back with its context
        // only, and the right line number, without looking at the rest.
        let text: String = (0..100_000).map(|i| format!("rule r{i} {{}}\n")).collect();
        let source = Text::new(&text);
        let at = text.rfind("r99999").unwrap();
        let found = source.read_span(&SourceSpan::new(at.into(), 6), 1, 1).unwrap();
        assert_eq!(found.line(), 99_998);
        assert!(found.data().len() < 64, "{} bytes", found.data().len());
        // The index is shared, not copied, between the reports of a file.
        let copy = source.clone();
        assert!(Arc::ptr_eq(&copy.text, &source.text) && Arc::ptr_eq(&copy.starts, &source.starts));
    }

    #[test]
    fn a_window_keeps_the_line_and_the_column() {
        let text = format!("states {{ A initial }}\n{}x\n", "\t".repeat(70_000));
        let source = Text::new(&text);
        let at = text.find('x').unwrap();
        assert!(source.on_long_line(at) && !source.on_long_line(0));
        let window = source.window((at, at + 1));
        let (start, end) = window.map(at, at + 1).unwrap();
        assert_eq!(&window.text.text[start..end], "x");
        assert!(window.text.text.len() < 2 * MARGIN + 8);
        let found = window.text.read_span(&SourceSpan::new(start.into(), 1), 0, 0).unwrap();
        assert_eq!((found.line(), found.column()), (1, 70_000));
        assert!(window.map(0, 3).is_none(), "a label on another line is not in the window");
    }
}
