//! The formatter behind `situ fmt`: prints a parsed file in one canonical
//! layout and keeps every comment.
//!
//! # Layout
//!
//! Four spaces per level; one blank line between top-level items (consecutive
//! `include`s stay together); one state, agent member, table entry, FSM line
//! and test clause per line, in source order; attributes on their own lines
//! before their item. A rule is
//!
//! ```text
//! rule NAME salience N "description" {
//!     when COND and COND
//!     then STATE
//! }
//! ```
//!
//! with its conditions on one line if that line fits in [`MAX_WIDTH`] columns
//! and no comment stands between the end of the first condition and the end
//! of the last, and otherwise one condition per line, each after the first
//! as `and COND` indented one more level. A test clause longer than
//! [`MAX_WIDTH`] continues after a comma, one level deeper. A property formula
//! is one line, in parentheses, `always (P -> next Q)` (unless they would
//! make it too deep or too long to parse back). A block with nothing inside,
//! not even a comment, is `{}`.
//!
//! # Canonical forms
//!
//! Durations in the largest unit that is exact (`1500ms`, `2s`, `2min`, `0s`);
//! calls with parentheses (`f()`); floats in the shortest text that reads
//! back as the same `f64`, always with a `.` or an exponent (`30.0`, `1e-7`);
//! frequencies in plain decimal (`20Hz`, `2.5Hz`); strings re-escaped (`\"`,
//! `\\`, `\n`, `\t`); sets as `{a, b}`, payloads as `{ a: f64, b: i64 }`;
//! no empty `()` or `{}` after an event; no trailing commas; attribute codes
//! without the `situ::` prefix. Parentheses in predicates are kept only where
//! they change the tree.
//!
//! # Comments
//!
//! The output is a list of lines; each stands for a range of the source, its
//! *anchor*. A comment is attached by position:
//!
//! - inside an anchor (between the tokens of one printed line): it moves to
//!   its own line just before that line;
//! - on the same source line after an anchor's end: it trails that line;
//! - otherwise (a line of its own): it leads the next printed line, at that
//!   line's indentation, or at the inner indentation when the next line is a
//!   closing `}`; after the last line, it goes at the end of the file.
//!
//! One blank line of the source is kept between the elements of a block and
//! between comments and elements; none after `{` or before `}`.
//!
//! # Alignment
//!
//! A run of like lines, at one indentation with no blank or comment line
//! between them, is aligned in columns: the descriptions of states and of
//! functions, the `=>` of a table's entries and of an FSM's states, the `->`
//! and `on` of an FSM's transitions. Trailing comments are aligned when two
//! or more lines of such a run, or of consecutive lines, have one (never on
//! a line that opens or closes a block). Alignment only adds spaces
//! between tokens, so the output still parses to the same tree.

use crate::ast::*;
use crate::diag::{Diagnostic, FileId};
use crate::lex::Comment;

mod text;
use text::*;

/// The column a rule's conditions must fit in to stay on one line, and where
/// test clauses wrap.
pub const MAX_WIDTH: usize = 80;

/// One level of indentation.
const INDENT: &str = "    ";

/// Formats a situ source in the canonical layout.
///
/// Returns the syntax errors instead when the source does not parse: a broken
/// file is never formatted. The result parses to the same AST (spans aside),
/// keeps every comment, and formats to itself.
///
/// ```
/// let out = situ_grammar::format("rule r{when A and B then S}").unwrap();
/// assert_eq!(out, "rule r {\n    when A and B\n    then S\n}\n");
/// ```
pub fn format(src: &str) -> Result<String, Vec<Diagnostic>> {
    let parsed = crate::parse(src, FileId(0));
    if !parsed.errors.is_empty() {
        return Err(parsed.errors);
    }
    let mut layout = Layout { src, comments: &parsed.comments, lines: Vec::new() };
    let mut previous: Option<&Item> = None;
    for item in &parsed.file.items {
        let blank = match (previous, item) {
            (Some(Item::Include(_)), Item::Include(_)) => Blank::Keep,
            _ => Blank::Always,
        };
        layout.item(item, blank);
        previous = Some(item);
    }
    let mut lines = layout.lines;
    let at_end = attach(src, &mut lines, &parsed.comments);
    align(src, &mut lines);
    Ok(render(src, &lines, &at_end, &parsed.comments))
}

// ─── The line model ──────────────────────────────────────────────────────────

/// Whether a blank line may come before a line (or its first comment).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Blank {
    /// Never: inside rules and properties, and between an attribute and its item.
    Never,
    /// If the source has one there.
    Keep,
    /// Always before the line's first comment or the line: top-level items.
    Always,
}

/// A comment that leads a line.
#[derive(Debug, Clone, Copy)]
struct Lead {
    /// The index of the comment.
    comment: usize,
    /// The comment stood inside the line's anchor and was moved before it.
    hoisted: bool,
}

/// One printed line (a test clause may continue on more physical lines).
#[derive(Debug)]
struct Line {
    indent: usize,
    text: String,
    /// The source range this line stands for; anchors are in source order and
    /// do not overlap.
    anchor: Span,
    blank: Blank,
    /// The line opens a block (ends with `{`).
    opens: bool,
    /// The line is a block's closing `}`.
    closes: bool,
    leading: Vec<Lead>,
    trailing: Option<usize>,
    /// The line as columns, for lines that are aligned with their like
    /// neighbours (states, functions, table and FSM lines); `text` is them
    /// joined with one space until [`align`] pads them.
    cells: Vec<String>,
    /// What kind of line it is: only lines of one kind align (0: none).
    kind: u8,
}

/// Kinds of aligned lines.
const STATE: u8 = 1;
const FUNCTION: u8 = 2;
const ENTRY: u8 = 3;
const FSM_STATE: u8 = 4;
const TRANSITION: u8 = 5;

/// Builds the lines of a file from its AST and its source.
struct Layout<'a> {
    src: &'a str,
    comments: &'a [Comment],
    lines: Vec<Line>,
}

impl Layout<'_> {
    fn push(&mut self, indent: usize, text: String, anchor: Span, blank: Blank) {
        let line = Line {
            indent,
            text,
            anchor,
            blank,
            opens: false,
            closes: false,
            leading: Vec::new(),
            trailing: None,
            cells: Vec::new(),
            kind: 0,
        };
        self.lines.push(line);
    }

    /// Pushes a line made of columns that align with the lines of the same
    /// kind around it.
    fn push_cells(&mut self, indent: usize, kind: u8, cells: Vec<String>, anchor: Span, blank: Blank) {
        self.push(indent, cells.join(" "), anchor, blank);
        if let Some(line) = self.lines.last_mut() {
            line.cells = cells;
            line.kind = kind;
        }
    }

    /// Pushes the header of the block `block` (from its keyword to its `}`),
    /// `text {`, whose `{` follows `after`; or, with no children and no
    /// comments inside, the whole block as `text {}`. Returns the indentation
    /// of the children, or `None` for an empty block.
    fn open(
        &mut self,
        indent: usize,
        text: String,
        block: Span,
        after: usize,
        blank: Blank,
        no_children: bool,
    ) -> Option<usize> {
        let brace = skip_trivia(self.src, after);
        if no_children && !self.has_comment_in(brace, block.end) {
            self.push(indent, format!("{text} {{}}"), block, blank);
            return None;
        }
        self.push(indent, format!("{text} {{"), Span::new(block.start, brace + 1), blank);
        if let Some(line) = self.lines.last_mut() {
            line.opens = true;
        }
        Some(indent + 1)
    }

    /// Pushes the `}` that ends the block spanning `span`.
    fn close(&mut self, indent: usize, span: Span) {
        self.push(indent, "}".into(), Span::new(span.end - 1, span.end), Blank::Never);
        if let Some(line) = self.lines.last_mut() {
            line.closes = true;
        }
    }

    /// `span` without the whitespace and comments pest leaves at its end.
    fn tight(&self, span: Span) -> Span {
        Span::new(span.start, code_end(self.src, span))
    }

    /// Whether a comment starts in `start..end`.
    fn has_comment_in(&self, start: usize, end: usize) -> bool {
        let first = self.comments.partition_point(|c| c.span.start < start);
        self.comments.get(first).is_some_and(|c| c.span.start < end)
    }

    fn item(&mut self, item: &Item, blank: Blank) {
        match item {
            Item::Include(i) => self.push(0, format!("include {}", string(&i.path.value)), i.span, blank),
            Item::States(s) => {
                let header = "states".to_string();
                let after = s.span.start + "states".len();
                if let Some(inner) = self.open(0, header, s.span, after, blank, s.states.is_empty()) {
                    for decl in &s.states {
                        self.push_cells(inner, STATE, state_decl(decl), self.tight(decl.span), Blank::Keep);
                    }
                    self.close(0, s.span);
                }
            }
            Item::Agent(a) => self.agent(a, blank),
            Item::Rule(r) => self.rule(r, blank),
            Item::Test(t) => {
                let header = format!("test {}", string(&t.name.value));
                if let Some(inner) = self.open(0, header, t.span, t.name.span.end, blank, t.clauses.is_empty()) {
                    for clause in &t.clauses {
                        let (head, parts) = test_clause(clause);
                        self.push(inner, fill(inner, head, &parts), self.tight(clause.span()), Blank::Keep);
                    }
                    self.close(0, t.span);
                }
            }
            Item::Script(t) => {
                let header = format!("script {}", string(&t.name.value));
                if let Some(inner) = self.open(0, header, t.span, t.name.span.end, blank, t.steps.is_empty()) {
                    for step in &t.steps {
                        let text = crate::script::step_text(step, duration, literal);
                        self.push(inner, text, self.tight(step.span()), Blank::Keep);
                    }
                    self.close(0, t.span);
                }
            }
            Item::Property(p) => {
                let header = format!("property {}", string(&p.name.value));
                self.open(0, header, p.span, p.name.span.end, blank, false);
                let brace = skip_trivia(self.src, p.name.span.end);
                let start = skip_trivia(self.src, brace + 1);
                let anchor = self.tight(Span::new(start, p.span.end - 1));
                let quantifier = match p.quantifier {
                    Quantifier::Always => "always",
                    Quantifier::Never => "never",
                };
                self.push(1, format!("{quantifier} {}", parenthesized(quantifier, &p.formula)), anchor, Blank::Never);
                self.close(0, p.span);
            }
        }
    }

    /// Pushes the attributes of an item; returns where its keyword starts.
    fn attributes(&mut self, attributes: &[Attribute], start: usize, blank: Blank) -> (usize, Blank) {
        let mut blank = blank;
        let mut next = start;
        for a in attributes {
            let codes: Vec<&str> = a.allow.iter().map(|c| c.name.as_str()).collect();
            self.push(0, format!("#[allow({})]", codes.join(", ")), a.span, blank);
            blank = Blank::Never;
            next = skip_trivia(self.src, a.span.end);
        }
        (next, blank)
    }

    fn agent(&mut self, a: &Agent, blank: Blank) {
        let (start, blank) = self.attributes(&a.attributes, a.span.start, blank);
        let mut header = format!("agent {} {}", a.name.name, a.kind.keyword());
        let mut after = a.kind_span.end;
        if let Some(d) = &a.description {
            header = format!("{header} {}", string(&d.value));
            after = d.span.end;
        }
        let Some(inner) = self.open(0, header, Span::new(start, a.span.end), after, blank, a.members.is_empty()) else {
            return;
        };
        for member in &a.members {
            let anchor = self.tight(member.span());
            match member {
                AgentMember::Stale(s) => {
                    self.push(inner, format!("stale after {}", duration(s.after.nanos)), anchor, Blank::Keep)
                }
                AgentMember::Rate(r) => self.push(inner, format!("rate {}Hz", r.hertz), anchor, Blank::Keep),
                AgentMember::Commands(c) => {
                    let names: Vec<&str> = c.targets.iter().map(|t| t.name.as_str()).collect();
                    self.push(inner, format!("commands {}", names.join(", ")), anchor, Blank::Keep)
                }
                AgentMember::Event(e) => self.push(inner, event_decl(e), anchor, Blank::Keep),
                AgentMember::Function(f) => {
                    let mut cells = vec![format!("function {}", f.name.name)];
                    cells.extend(f.description.as_ref().map(|d| string(&d.value)));
                    self.push_cells(inner, FUNCTION, cells, anchor, Blank::Keep)
                }
                AgentMember::Table(t) => {
                    let after = t.span.start + "table".len();
                    if let Some(deeper) =
                        self.open(inner, "table".into(), t.span, after, Blank::Keep, t.entries.is_empty())
                    {
                        for entry in &t.entries {
                            self.push_cells(deeper, ENTRY, table_entry(entry), self.tight(entry.span), Blank::Keep);
                        }
                        self.close(inner, t.span);
                    }
                }
                AgentMember::Fsm(f) => {
                    let after = f.span.start + "fsm".len();
                    if let Some(deeper) = self.open(inner, "fsm".into(), f.span, after, Blank::Keep, f.lines.is_empty())
                    {
                        for line in &f.lines {
                            let (kind, cells) = fsm_line(line);
                            self.push_cells(deeper, kind, cells, self.tight(line.span()), Blank::Keep);
                        }
                        self.close(inner, f.span);
                    }
                }
            }
        }
        self.close(0, a.span);
    }

    fn rule(&mut self, r: &Rule, blank: Blank) {
        let (start, blank) = self.attributes(&r.attributes, r.span.start, blank);
        let mut header = format!("rule {}", r.name.name);
        let mut after = r.name.span.end;
        if let Some(s) = &r.salience {
            header = format!("{header} salience {}", s.value);
            after = s.span.end;
        }
        if let Some(d) = &r.description {
            header = format!("{header} {}", string(&d.value));
            after = d.span.end;
        }
        self.open(0, header, Span::new(start, r.span.end), after, blank, false);
        let anchors: Vec<Span> = r.conditions.iter().map(|c| self.tight(c.span())).collect();
        let texts: Vec<String> = r.conditions.iter().map(condition).collect();
        if let (Some(first), Some(last)) = (anchors.first(), anchors.last()) {
            let one_line = format!("when {}", texts.join(" and "));
            // A comment inside the first condition moves before `when` in
            // both forms; any other among the conditions needs one per line.
            if INDENT.len() + one_line.len() <= MAX_WIDTH && !self.has_comment_in(first.end, last.end) {
                self.push(1, one_line, Span::new(first.start, last.end), Blank::Never);
            } else {
                for (i, (text, anchor)) in texts.iter().zip(&anchors).enumerate() {
                    let (indent, word) = if i == 0 { (1, "when") } else { (2, "and") };
                    self.push(indent, format!("{word} {text}"), *anchor, Blank::Never);
                }
            }
        }
        self.push(1, format!("then {}", r.target.name), r.target.span, Blank::Never);
        self.close(0, r.span);
    }
}

// ─── Source positions ─────────────────────────────────────────────────────────

/// The first position at or after `at` that is neither whitespace nor in a
/// comment.
fn skip_trivia(src: &str, mut at: usize) -> usize {
    let bytes = src.as_bytes();
    while at < bytes.len() {
        if bytes[at].is_ascii_whitespace() {
            at += 1;
        } else if bytes[at..].starts_with(b"//") {
            at = bytes[at..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |p| at + p);
        } else {
            break;
        }
    }
    at
}

/// The end of the last token in `span`: pest spans of rules that end with an
/// optional part also cover the whitespace and comments after it.
fn code_end(src: &str, span: Span) -> usize {
    let bytes = &src.as_bytes()[..span.end.min(src.len())];
    let mut end = span.start;
    let mut i = span.start;
    while i < bytes.len() {
        match bytes[i] {
            b'/' if bytes.get(i + 1) == Some(&b'/') => {
                i = bytes[i..].iter().position(|&b| b == b'\n').map_or(bytes.len(), |p| i + p);
                continue;
            }
            b'"' => {
                i = crate::lex::skip_string(bytes, i);
                end = i;
                continue;
            }
            b if b.is_ascii_whitespace() => {}
            _ => end = i + 1,
        }
        i += 1;
    }
    end.max(span.start + 1).min(span.end)
}

/// Whether `src[from..to]` holds an empty line.
fn has_blank_line(src: &str, from: usize, to: usize) -> bool {
    if from >= to {
        return false;
    }
    let mut newlines = 0;
    for b in src.as_bytes()[from..to].iter() {
        match b {
            b'\n' => {
                newlines += 1;
                if newlines == 2 {
                    return true;
                }
            }
            b' ' | b'\t' | b'\r' => {}
            _ => newlines = 0,
        }
    }
    false
}

// ─── Comments ─────────────────────────────────────────────────────────────────

/// Attaches every comment to a line (see the module documentation); returns
/// the comments that come after the last line.
fn attach(src: &str, lines: &mut [Line], comments: &[Comment]) -> Vec<usize> {
    debug_assert!(lines.windows(2).all(|w| w[0].anchor.end <= w[1].anchor.start), "anchors overlap");
    let mut at_end = Vec::new();
    for (index, comment) in comments.iter().enumerate() {
        let at = comment.span.start;
        let next = lines.partition_point(|l| l.anchor.start <= at);
        if let Some(line) = next.checked_sub(1).map(|p| &mut lines[p]) {
            if at < line.anchor.end {
                line.leading.push(Lead { comment: index, hoisted: true });
                continue;
            }
            if line.trailing.is_none() && !src[line.anchor.end..at].contains('\n') {
                line.trailing = Some(index);
                continue;
            }
        }
        match lines.get_mut(next) {
            Some(line) => line.leading.push(Lead { comment: index, hoisted: false }),
            None => at_end.push(index),
        }
    }
    at_end
}

/// Prints the lines with their comments.
fn render(src: &str, lines: &[Line], at_end: &[usize], comments: &[Comment]) -> String {
    let mut out = Printer { src, out: String::new(), cursor: 0, after_open: true };
    for line in lines {
        let comment_indent = line.indent + usize::from(line.closes);
        for (i, lead) in line.leading.iter().enumerate() {
            let comment = &comments[lead.comment];
            let start = if lead.hoisted { line.anchor.start } else { comment.span.start };
            out.blank(line.blank, i == 0, start);
            out.line(comment_indent, &format!("//{}", comment.text));
            out.cursor = if lead.hoisted { out.cursor.max(line.anchor.start) } else { comment.span.end };
        }
        let blank = if line.closes { Blank::Never } else { line.blank };
        out.blank(blank, line.leading.is_empty(), line.anchor.start);
        match line.trailing {
            Some(t) => {
                out.line(line.indent, &format!("{} //{}", line.text, comments[t].text));
                out.cursor = comments[t].span.end;
            }
            None => {
                out.line(line.indent, &line.text);
                out.cursor = line.anchor.end;
            }
        }
        out.after_open = line.opens;
    }
    for &index in at_end {
        let comment = &comments[index];
        out.blank(Blank::Keep, false, comment.span.start);
        out.line(0, &format!("//{}", comment.text));
        out.cursor = comment.span.end;
    }
    out.out
}

/// The output being written, and where the source has been read up to.
struct Printer<'a> {
    src: &'a str,
    out: String,
    /// The end in the source of what was printed last.
    cursor: usize,
    /// Nothing yet, or a `{`, was printed last: no blank line here.
    after_open: bool,
}

impl Printer<'_> {
    /// Prints a blank line before something that starts at `start` in the
    /// source if `rule` asks for one.
    fn blank(&mut self, rule: Blank, first: bool, start: usize) {
        let wanted = match rule {
            Blank::Never => false,
            Blank::Always if first => true,
            Blank::Always | Blank::Keep => has_blank_line(self.src, self.cursor, start),
        };
        if wanted && !self.after_open {
            self.out.push('\n');
        }
        self.after_open = false;
    }

    fn line(&mut self, indent: usize, text: &str) {
        for _ in 0..indent {
            self.out.push_str(INDENT);
        }
        self.out.push_str(text);
        self.out.push('\n');
    }
}

// ─── Text of the elements ─────────────────────────────────────────────────────

/// Whether `next` continues the run of `prev`: at the same indentation,
/// with no comment line and no blank line between them.
fn continues(src: &str, prev: &Line, next: &Line) -> bool {
    next.indent == prev.indent
        && !prev.opens
        && !next.closes
        && next.leading.is_empty()
        && !(next.blank == Blank::Keep && has_blank_line(src, prev.anchor.end, next.anchor.start))
}

/// Aligns columns of consecutive lines of one kind (a table's `=>`, the
/// descriptions of states and functions), then their trailing comments,
/// and those of consecutive commented lines.
fn align(src: &str, lines: &mut [Line]) {
    let mut i = 0;
    while i < lines.len() {
        let mut j = i + 1;
        while j < lines.len()
            && lines[i].kind != 0
            && lines[j].kind == lines[i].kind
            && continues(src, &lines[j - 1], &lines[j])
        {
            j += 1;
        }
        if j - i > 1 {
            let columns = lines[i..j].iter().map(|l| l.cells.len()).max().unwrap_or(0);
            for c in 0..columns.saturating_sub(1) {
                let width =
                    lines[i..j].iter().filter(|l| l.cells.len() > c + 1).map(|l| l.cells[c].chars().count()).max();
                let Some(width) = width else { continue };
                for l in &mut lines[i..j] {
                    if l.cells.len() > c + 1 {
                        let pad = width - l.cells[c].chars().count();
                        l.cells[c].push_str(&" ".repeat(pad));
                    }
                }
            }
            for l in &mut lines[i..j] {
                l.text = l.cells.join(" ");
            }
        }
        i = j;
    }
    // Trailing comments: in a run of like lines (a table, the states), or of
    // consecutive commented lines; never on a line that opens or closes a
    // block.
    let plain = |l: &Line| !l.opens && !l.closes && !l.text.contains('\n');
    let commented = |l: &Line| l.trailing.is_some() && plain(l);
    let mut i = 0;
    while i < lines.len() {
        let mut j = i + 1;
        while j < lines.len()
            && plain(&lines[j - 1])
            && plain(&lines[j])
            && continues(src, &lines[j - 1], &lines[j])
            && ((commented(&lines[j - 1]) && commented(&lines[j]))
                || (lines[j].kind != 0 && lines[j].kind == lines[j - 1].kind))
        {
            j += 1;
        }
        let width = lines[i..j].iter().filter(|l| commented(l)).map(|l| l.text.chars().count()).max();
        if lines[i..j].iter().filter(|l| commented(l)).count() > 1 {
            let width = width.unwrap_or(0);
            for l in lines[i..j].iter_mut().filter(|l| l.trailing.is_some()) {
                let pad = width - l.text.chars().count();
                l.text.push_str(&" ".repeat(pad));
            }
        }
        i = j;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn durations_take_the_largest_exact_unit() {
        assert_eq!(duration(1_500_000_000), "1500ms");
        assert_eq!(duration(2_000_000_000), "2s");
        assert_eq!(duration(120_000_000_000), "2min");
        assert_eq!(duration(1_500), "1500ns");
        assert_eq!(duration(3_000), "3us");
        assert_eq!(duration(0), "0s");
    }

    #[test]
    fn floats_stay_floats() {
        assert_eq!(float(30.0), "30.0");
        assert_eq!(float(1e-7), "1e-7");
        assert_eq!(float(-0.5), "-0.5");
        assert_eq!(float(1e16), "1e16");
        for v in [0.1, 1e300, -2.5e-300, 123456789.123] {
            assert_eq!(float(v).parse::<f64>().unwrap(), v);
        }
        assert_eq!((float(f64::NAN).as_str(), float(f64::INFINITY).as_str()), ("NaN", "inf"));
        assert_eq!(float(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn strings_are_escaped() {
        assert_eq!(string("a\"b\\c\nd\te"), r#""a\"b\\c\nd\te""#);
    }

    #[test]
    fn finds_the_end_of_code() {
        let src = "A initial // c\n  B";
        assert_eq!(code_end(src, Span::new(0, 17)), 9);
        assert_eq!(code_end("x \"//\" // y", Span::new(0, 11)), 6);
    }

    #[test]
    fn fills_clauses() {
        let parts: Vec<String> = (0..12).map(|i| format!("state S{i}")).collect();
        let text = fill(1, "expect", &parts);
        assert!(text.lines().all(|l| l.len() + 4 <= MAX_WIDTH), "{text}");
        assert!(text.contains("\n        state"));
    }

    #[test]
    fn keeps_deep_formulas_parseable() {
        for depth in [crate::parse::MAX_NESTING - 2, crate::parse::MAX_NESTING - 1] {
            let body = format!("{}A and A{}", "A and (".repeat(depth), ")".repeat(depth));
            let src = format!("property \"p\" {{ always {body} -> B }}");
            let out = format(&src).unwrap();
            assert!(crate::parse(&out, FileId(0)).errors.is_empty(), "{out}");
            assert_eq!(out.contains("always (A and"), depth < crate::parse::MAX_NESTING - 1);
        }
    }

    #[test]
    fn keeps_long_implications_parseable() {
        let premise = vec!["A"; 3_000].join(" and ");
        let out = format(&format!("property \"p\" {{ always {premise} -> B }}")).unwrap();
        assert!(crate::parse(&out, FileId(0)).errors.is_empty());
        let out = format(&format!("property \"p\" {{ always {} -> B }}", ["A"; 10].join(" and "))).unwrap();
        assert!(out.contains("always (A and"));
    }

    #[test]
    fn refuses_broken_files() {
        assert!(format("rule r { when }").is_err());
    }
}
