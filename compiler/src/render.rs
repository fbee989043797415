//! Showing findings: miette reports for people, JSON lines and SARIF 2.1.0
//! for tools. Rendering is pure: it returns strings.

use crate::codes;
use crate::source::SourceMap;
use crate::{Checked, RootError};
use miette::{GraphicalReportHandler, GraphicalTheme, LabeledSpan, NamedSource, SourceSpan};
use serde_json::{json, Value};
use situ_grammar::diag::{Diagnostic, FileId, Label, Severity};
use snippet::Text;
use std::cell::RefCell;
use std::fmt;

mod snippet;

/// How to draw human reports.
#[derive(Debug, Clone, Copy)]
pub struct Style {
    pub colour: bool,
    pub width: usize,
}

impl Style {
    /// No colour, 80 columns: the form of test snapshots.
    pub const PLAIN: Style = Style { colour: false, width: 80 };
}

/// One finding as a miette report.
pub fn human(sources: &SourceMap, d: &Diagnostic, style: Style) -> String {
    human_with(&Texts::new(sources), d, style)
}

/// Findings as miette reports, one after the other: each file is indexed
/// once for all of them.
pub fn human_list<'a>(sources: &SourceMap, ds: impl IntoIterator<Item = &'a Diagnostic>, style: Style) -> String {
    let texts = Texts::new(sources);
    ds.into_iter().map(|d| human_with(&texts, d, style)).collect()
}

fn human_with(texts: &Texts, d: &Diagnostic, style: Style) -> String {
    let theme = if style.colour { GraphicalTheme::unicode() } else { GraphicalTheme::unicode_nocolor() };
    let handler = GraphicalReportHandler::new_themed(theme).with_width(style.width).with_links(false);
    let mut out = String::new();
    let report = Report::new(texts, d);
    if handler.render_report(&mut out, &report).is_err() {
        out = format!("{}: {} [situ::{}]\n", d.severity.as_str(), d.message, d.code);
    }
    out
}

/// How many findings of one code [`human_all`] draws; the others are
/// counted on one line. JSON and SARIF keep every finding.
pub const SHOWN_PER_CODE: usize = 20;

/// The visible findings of a check, at most [`SHOWN_PER_CODE`] of each code,
/// then a line per code with more: `… and N more CODE (title)`.
pub fn human_all(checked: &Checked, style: Style) -> String {
    let texts = Texts::new(&checked.sources);
    let mut out = String::new();
    let mut shown: std::collections::BTreeMap<&str, usize> = std::collections::BTreeMap::new();
    for d in checked.visible() {
        let n = shown.entry(d.code).or_default();
        *n += 1;
        if *n <= SHOWN_PER_CODE {
            out.push_str(&human_with(&texts, d, style));
            out.push('\n');
        }
    }
    out.push_str(&more_lines(&shown));
    out
}

/// `… and N more CODE (title); --format json lists them all`, per code with
/// more findings than are drawn.
fn more_lines(counts: &std::collections::BTreeMap<&str, usize>) -> String {
    let mut out = String::new();
    for (code, &n) in counts.iter().filter(|(_, &n)| n > SHOWN_PER_CODE) {
        let title = codes::lookup(code).map_or("", |c| c.title);
        out.push_str(&format!(
            "… and {} more situ::{code} ({title}): `--format json` or `--format sarif` lists every finding\n",
            n - SHOWN_PER_CODE
        ));
    }
    out
}

/// The files of a source map as miette sources, each indexed when first
/// drawn and then shared by every report on it.
struct Texts<'a> {
    sources: &'a SourceMap,
    texts: RefCell<Vec<Option<Text>>>,
}

impl<'a> Texts<'a> {
    fn new(sources: &'a SourceMap) -> Self {
        Texts { sources, texts: RefCell::new(vec![None; sources.len()]) }
    }

    fn get(&self, file: FileId) -> Text {
        let mut texts = self.texts.borrow_mut();
        let i = file.0 as usize;
        if texts.len() <= i {
            texts.resize(i + 1, None);
        }
        texts[i].get_or_insert_with(|| Text::new(&self.sources.get(file).text)).clone()
    }
}

/// A miette view of one [`Diagnostic`]: labels in the primary file are drawn
/// on its source; labels in other files become related notes. When the
/// primary label sits on a very long line, the report is drawn on a window
/// of that line, and labels outside the window become related notes too.
struct Report {
    d: Diagnostic,
    source: NamedSource<Text>,
    labels: Vec<LabeledSpan>,
    related: Vec<Report>,
}

impl Report {
    fn new(texts: &Texts, d: &Diagnostic) -> Report {
        let file = texts.sources.get(d.primary.file);
        let len = file.text.len();
        let mut text = texts.get(d.primary.file);
        let same_file = || std::iter::once(&d.primary).chain(d.secondary.iter().filter(|l| l.file == d.primary.file));
        let long = same_file().any(|l| text.on_long_line(l.span.start) || text.on_long_line(l.span.end));
        let window = long.then(|| text.window((d.primary.span.start, d.primary.span.end)));
        let mut labels = Vec::new();
        let mut notes = Vec::new();
        for (i, l) in same_file().enumerate() {
            let (start, end) = (l.span.start.min(len), l.span.end.min(len));
            let span = match &window {
                None => Some((start, end)),
                Some(w) => w.map(start, end),
            };
            match span {
                Some(span) => labels.push(labeled(&l.text, span, i == 0)),
                None => notes.push(l),
            }
        }
        if let Some(w) = window {
            text = w.text;
        }
        let mut related = Vec::new();
        for l in d.secondary.iter().filter(|l| l.file != d.primary.file).chain(notes) {
            let note = Diagnostic {
                code: "",
                severity: Severity::Warning,
                message: l.text.clone(),
                primary: l.clone(),
                secondary: Vec::new(),
                help: None,
                witness: None,
                allowed: false,
                fixes: Vec::new(),
            };
            related.push(Report::new(texts, &note));
        }
        // The witness is structured data for tools (JSON, SARIF); for people
        // each check writes it into its message, labels and help.
        let d = d.clone();
        Report { d, source: NamedSource::new(file.name.clone(), text), labels, related }
    }
}

fn labeled(text: &str, (start, end): (usize, usize), primary: bool) -> LabeledSpan {
    let span = SourceSpan::new(start.into(), end.saturating_sub(start));
    let text = (!text.is_empty()).then(|| text.to_string());
    if primary {
        LabeledSpan::new_primary_with_span(text, span)
    } else {
        LabeledSpan::new_with_span(text, span)
    }
}

impl fmt::Debug for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.d.message)
    }
}

impl fmt::Display for Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.d.message)
    }
}

impl std::error::Error for Report {}

impl miette::Diagnostic for Report {
    fn code<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        (!self.d.code.is_empty()).then(|| Box::new(format!("situ::{}", self.d.code)) as Box<dyn fmt::Display>)
    }
    fn severity(&self) -> Option<miette::Severity> {
        Some(match (self.d.code.is_empty(), self.d.severity) {
            (true, _) => miette::Severity::Advice,
            (false, Severity::Warning) => miette::Severity::Warning,
            (false, Severity::Error) => miette::Severity::Error,
        })
    }
    fn help<'a>(&'a self) -> Option<Box<dyn fmt::Display + 'a>> {
        self.d.help.as_ref().map(|h| Box::new(h) as Box<dyn fmt::Display>)
    }
    fn source_code(&self) -> Option<&dyn miette::SourceCode> {
        Some(&self.source)
    }
    fn labels(&self) -> Option<Box<dyn Iterator<Item = LabeledSpan> + '_>> {
        Some(Box::new(self.labels.iter().cloned()))
    }
    fn related<'a>(&'a self) -> Option<Box<dyn Iterator<Item = &'a dyn miette::Diagnostic> + 'a>> {
        if self.related.is_empty() {
            return None;
        }
        Some(Box::new(self.related.iter().map(|r| r as &dyn miette::Diagnostic)))
    }
}

/// The place of a label as file name, line and column (1-based, in characters).
fn place(sources: &SourceMap, l: &Label) -> Value {
    let file = sources.get(l.file);
    let (line, column) = file.line_col(l.span.start);
    let (end_line, end_column) = file.line_col(l.span.end);
    json!({
        "file": file.name, "line": line, "column": column,
        "end_line": end_line, "end_column": end_column, "label": l.text,
    })
}

/// One finding as a JSON object: `code`, `severity`, `message`, `file`,
/// `line`, `column` (1-based, in characters), `end_line`, `end_column`,
/// `label`, `help`, `related`, `witness` and `allowed`.
pub fn json_object(sources: &SourceMap, d: &Diagnostic) -> Value {
    let mut obj = json!({
        "code": format!("situ::{}", d.code),
        "severity": d.severity.as_str(),
        "message": d.message,
    });
    let map = obj.as_object_mut().expect("an object");
    if let Value::Object(p) = place(sources, &d.primary) {
        map.extend(p);
    }
    map.insert("help".into(), d.help.clone().map_or(Value::Null, Value::String));
    map.insert("related".into(), d.secondary.iter().map(|l| place(sources, l)).collect());
    map.insert("witness".into(), d.witness.clone().unwrap_or(Value::Null));
    map.insert("allowed".into(), Value::Bool(d.allowed));
    obj
}

/// JSON lines: one object per finding (allowed ones included, marked).
pub fn json_lines(checked: &Checked) -> String {
    let mut out = String::new();
    for d in &checked.diagnostics {
        out.push_str(&json_object(&checked.sources, d).to_string());
        out.push('\n');
    }
    out
}

/// A SARIF 2.1.0 log of several checks.
pub fn sarif(checks: &[&Checked]) -> String {
    sarif_with_failures(checks, &[])
}

/// A SARIF 2.1.0 log of several checks and of the roots that could not be
/// read at all. With a failure the run's invocation says
/// `executionSuccessful: false` and names each unread file in a tool
/// execution notification, so that a CI reading only the log does not take
/// an unread file for a clean one.
pub fn sarif_with_failures(checks: &[&Checked], failures: &[&RootError]) -> String {
    let rules: Vec<Value> = codes::ALL.iter().map(sarif_rule).collect();
    let mut results = Vec::new();
    for checked in checks {
        for d in &checked.diagnostics {
            let mut r = json!({
                "ruleId": format!("situ::{}", d.code),
                "ruleIndex": codes::ALL.iter().position(|c| c.code == d.code),
                "level": level(d.severity),
                "message": { "text": match &d.help { Some(h) => format!("{}\nhelp: {h}", d.message), None => d.message.clone() } },
                "locations": [sarif_location(&checked.sources, &d.primary)],
                "relatedLocations": d.secondary.iter().enumerate().map(|(i, l)| {
                    let mut loc = sarif_location(&checked.sources, l);
                    loc["id"] = json!(i);
                    loc
                }).collect::<Vec<_>>(),
            });
            if let Some(w) = &d.witness {
                r["properties"] = json!({ "witness": w });
            }
            if d.allowed {
                r["suppressions"] = json!([{ "kind": "inSource" }]);
            }
            results.push(r);
        }
    }
    let notifications: Vec<Value> = failures
        .iter()
        .map(|f| {
            json!({
                "level": "error",
                "message": { "text": f.to_string() },
                "locations": [{
                    "physicalLocation": { "artifactLocation": { "uri": uri(&f.path.display().to_string()) } },
                }],
            })
        })
        .collect();
    let mut invocation = json!({ "executionSuccessful": failures.is_empty() });
    if !notifications.is_empty() {
        invocation["toolExecutionNotifications"] = json!(notifications);
    }
    let log = json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "situ",
                "version": env!("CARGO_PKG_VERSION"),
                "rules": rules,
            }},
            "invocations": [invocation],
            "columnKind": "unicodeCodePoints",
            "results": results,
        }],
    });
    serde_json::to_string_pretty(&log).expect("JSON values always serialize")
}

/// A root that could not be read, as one JSON line (the `--format json`
/// counterpart of a finding): `{"error": {"kind": "io", "file", "message"}}`.
pub fn json_failure(failure: &RootError) -> String {
    let line = json!({
        "error": {
            "kind": "io",
            "file": failure.path.display().to_string(),
            "message": failure.to_string(),
        }
    });
    format!("{line}\n")
}

/// A code as a SARIF reporting descriptor, documented inline from its page
/// (`docs/codes/CODE.md`, the text of `situ explain`): the project has no
/// public home for a `helpUri`.
fn sarif_rule(c: &codes::Code) -> Value {
    let page = c.explain;
    // The page without its `# CODE: title` line, which the other properties say.
    let body = match page.split_once('\n') {
        Some((first, rest)) if first.starts_with("# ") => rest.trim_start(),
        _ => page,
    };
    let what = section(page, "What it does").unwrap_or(c.title);
    json!({
        "id": format!("situ::{}", c.code),
        "name": c.title,
        "shortDescription": { "text": c.title },
        "fullDescription": { "text": plain(what), "markdown": what },
        "help": { "text": plain(body), "markdown": body },
        "defaultConfiguration": { "level": level(c.severity) },
    })
}

/// The text of a `## heading` section of a Markdown page, trimmed.
fn section<'a>(page: &'a str, heading: &str) -> Option<&'a str> {
    let marker = format!("## {heading}\n");
    let start = page.find(&marker)? + marker.len();
    let rest = &page[start..];
    let end = rest.find("\n## ").map_or(rest.len(), |i| i + 1);
    Some(rest[..end].trim())
}

/// Markdown as plain text: headings lose their `#`s, fenced code is
/// indented by four spaces instead of fenced; the rest reads as it is.
fn plain(markdown: &str) -> String {
    let mut out = String::new();
    let mut fenced = false;
    for line in markdown.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            if !line.is_empty() {
                out.push_str("    ");
                out.push_str(line);
            }
        } else {
            let hashes = line.trim_start_matches('#');
            match hashes.strip_prefix(' ') {
                Some(heading) if hashes.len() < line.len() => out.push_str(heading),
                _ => out.push_str(line),
            }
        }
        out.push('\n');
    }
    out.trim_end().to_string()
}

/// A file name as a SARIF URI reference (forward slashes).
fn uri(name: &str) -> String {
    name.replace('\\', "/")
}

fn level(s: Severity) -> &'static str {
    match s {
        Severity::Error => "error",
        Severity::Warning => "warning",
    }
}

fn sarif_location(sources: &SourceMap, l: &Label) -> Value {
    let file = sources.get(l.file);
    let (line, column) = file.line_col(l.span.start);
    let (end_line, end_column) = file.line_col(l.span.end);
    json!({
        "physicalLocation": {
            "artifactLocation": { "uri": uri(&file.name) },
            "region": { "startLine": line, "startColumn": column, "endLine": end_line, "endColumn": end_column },
        },
        "message": { "text": l.text },
    })
}

/// Which file a finding is in, for grouping.
pub fn file_of(d: &Diagnostic) -> FileId {
    d.primary.file
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sarif_rule_carries_its_documentation_inline() {
        let log: Value = serde_json::from_str(&sarif(&[])).unwrap();
        let driver = &log["runs"][0]["tool"]["driver"];
        assert!(driver.get("informationUri").is_none(), "no made-up home page");
        let rules = driver["rules"].as_array().unwrap();
        assert_eq!(rules.len(), codes::ALL.len());
        for (rule, code) in rules.iter().zip(codes::ALL) {
            let full = rule["fullDescription"]["text"].as_str().unwrap();
            assert!(!full.is_empty() && !full.contains("## "), "{}: {full}", code.code);
            let help = &rule["help"];
            let (text, markdown) = (help["text"].as_str().unwrap(), help["markdown"].as_str().unwrap());
            assert!(markdown.contains("## What it does") && markdown.contains("## Use instead"), "{}", code.code);
            assert!(text.contains("What it does") && !text.contains("```") && !text.contains("## "), "{}", code.code);
        }
        assert_eq!(log["runs"][0]["invocations"][0]["executionSuccessful"], true);
    }

    #[test]
    fn an_unread_root_makes_the_run_unsuccessful() {
        let failure = RootError {
            path: "no/such.situ".into(),
            error: std::io::Error::new(std::io::ErrorKind::NotFound, "not found"),
        };
        let log: Value = serde_json::from_str(&sarif_with_failures(&[], &[&failure])).unwrap();
        let invocation = &log["runs"][0]["invocations"][0];
        assert_eq!(invocation["executionSuccessful"], false);
        let note = &invocation["toolExecutionNotifications"][0];
        assert_eq!(note["level"], "error");
        assert!(note["message"]["text"].as_str().unwrap().contains("no/such.situ"));
        assert_eq!(note["locations"][0]["physicalLocation"]["artifactLocation"]["uri"], "no/such.situ");
        let line: Value = serde_json::from_str(json_failure(&failure).trim_end()).unwrap();
        assert_eq!(line["error"]["file"], "no/such.situ");
    }

    #[test]
    fn labels_far_apart_are_drawn_apart_not_with_every_line_between() {
        let filler: String = (0..30).map(|i| format!("// line {i}\n")).collect();
        // Deep in a file (miette merged any two labels within twice the
        // first one's line number).
        let header: String = (0..60).map(|i| format!("// header {i}\n")).collect();
        let text = format!(
            "{header}states {{ A initial  B  C }}\nagent S sensor {{ event E }}\n\
             rule one {{ when state == A and E then B }}\n{filler}\
             rule two {{ when state == A and E then C }}\n"
        );
        let checked = crate::check_source("far.situ", &text);
        let conflict = checked.diagnostics.iter().find(|d| d.code == codes::CONFLICTING_RULES).expect("a conflict");
        let out = human(&checked.sources, conflict, Style { colour: false, width: 80 });
        assert!(!out.contains("// line 15"), "the lines between the rules are not drawn:\n{out}");
        assert!(out.contains("rule one") && out.contains("rule two"), "both rules are drawn:\n{out}");
        assert_eq!(out.matches("╭─[").count(), 2, "two snippets:\n{out}");
        // Near labels still share one snippet.
        let near = text.replace(&filler, "");
        let checked = crate::check_source("near.situ", &near);
        let conflict = checked.diagnostics.iter().find(|d| d.code == codes::CONFLICTING_RULES).expect("a conflict");
        let out = human(&checked.sources, conflict, Style { colour: false, width: 80 });
        assert_eq!(out.matches("╭─[").count(), 1, "one snippet:\n{out}");
    }

    #[test]
    fn human_output_draws_a_bounded_number_of_findings_per_code() {
        let rules: String =
            (0..SHOWN_PER_CODE + 5).map(|i| format!("rule r{i} {{ when state == A then B }}\n")).collect();
        let checked = crate::check_source("many.situ", &format!("states {{ A initial }}\n{rules}"));
        assert_eq!(checked.errors(), SHOWN_PER_CODE + 5, "every finding is kept");
        let out = human_all(&checked, Style::PLAIN);
        assert_eq!(out.matches("situ::E0101").count(), SHOWN_PER_CODE + 1, "{out}");
        assert!(
            out.ends_with(
                "… and 5 more situ::E0101 (undefined state): `--format json` or `--format sarif` lists every finding\n"
            ),
            "{out}"
        );
        assert_eq!(json_lines(&checked).lines().count(), SHOWN_PER_CODE + 5, "JSON keeps them all");
        // At the bound, nothing is counted.
        let rules: String = (0..SHOWN_PER_CODE).map(|i| format!("rule r{i} {{ when state == A then B }}\n")).collect();
        let checked = crate::check_source("few.situ", &format!("states {{ A initial }}\n{rules}"));
        assert!(!human_all(&checked, Style::PLAIN).contains("more situ::"));
    }

    #[test]
    fn plain_text_unfences_code_and_drops_heading_marks() {
        let md = "## Example\nSome `x`.\n```situ\n#[allow(E0101)]\nrule r {}\n```\n#[not a heading]";
        assert_eq!(plain(md), "Example\nSome `x`.\n    #[allow(E0101)]\n    rule r {}\n#[not a heading]");
    }
}
