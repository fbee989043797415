//! Showing findings: miette reports for people, JSON lines and SARIF 2.1.0
//! for tools. Rendering is pure: it returns strings.

use crate::codes;
use crate::source::SourceMap;
use crate::Checked;
use miette::{GraphicalReportHandler, GraphicalTheme, LabeledSpan, NamedSource, SourceSpan};
use serde_json::{json, Value};
use situ_grammar::diag::{Diagnostic, FileId, Label, Severity};
use std::fmt;

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
    let theme = if style.colour { GraphicalTheme::unicode() } else { GraphicalTheme::unicode_nocolor() };
    let handler = GraphicalReportHandler::new_themed(theme).with_width(style.width).with_links(false);
    let mut out = String::new();
    let report = Report::new(sources, d);
    if handler.render_report(&mut out, &report).is_err() {
        out = format!("{}: {} [situ::{}]\n", d.severity.as_str(), d.message, d.code);
    }
    out
}

/// Every visible finding of a check, then a summary line.
pub fn human_all(checked: &Checked, style: Style) -> String {
    let mut out = String::new();
    for d in checked.visible() {
        out.push_str(&human(&checked.sources, d, style));
        out.push('\n');
    }
    out
}

/// A miette view of one [`Diagnostic`]: labels in the primary file are drawn
/// on its source; labels in other files become related notes.
struct Report {
    d: Diagnostic,
    source: NamedSource<String>,
    labels: Vec<LabeledSpan>,
    related: Vec<Report>,
}

impl Report {
    fn new(sources: &SourceMap, d: &Diagnostic) -> Report {
        let file = sources.get(d.primary.file);
        let mut labels = vec![labeled(&d.primary, file.text.len(), true)];
        let mut related = Vec::new();
        for l in &d.secondary {
            if l.file == d.primary.file {
                labels.push(labeled(l, file.text.len(), false));
            } else {
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
                related.push(Report::new(sources, &note));
            }
        }
        // The witness is structured data for tools (JSON, SARIF); for people
        // each check writes it into its message, labels and help.
        let d = d.clone();
        Report { d, source: NamedSource::new(file.name.clone(), file.text.clone()), labels, related }
    }
}

fn labeled(l: &Label, len: usize, primary: bool) -> LabeledSpan {
    let start = l.span.start.min(len);
    let span = SourceSpan::new(start.into(), l.span.end.min(len).saturating_sub(start));
    let text = (!l.text.is_empty()).then(|| l.text.clone());
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
    let rules: Vec<Value> = codes::ALL
        .iter()
        .map(|c| {
            json!({
                "id": format!("situ::{}", c.code),
                "name": c.title,
                "shortDescription": { "text": c.title },
                "fullDescription": { "text": c.explain },
                "help": { "text": c.explain, "markdown": c.explain },
                "defaultConfiguration": { "level": level(c.severity) },
            })
        })
        .collect();
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
    let log = json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": {
                "name": "situ",
                "version": env!("CARGO_PKG_VERSION"),
                "informationUri": "https://example.invalid/situ",
                "rules": rules,
            }},
            "columnKind": "unicodeCodePoints",
            "results": results,
        }],
    });
    serde_json::to_string_pretty(&log).expect("JSON values always serialize")
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
            "artifactLocation": { "uri": file.name.replace('\\', "/") },
            "region": { "startLine": line, "startColumn": column, "endLine": end_line, "endColumn": end_column },
        },
        "message": { "text": l.text },
    })
}

/// Which file a finding is in, for grouping.
pub fn file_of(d: &Diagnostic) -> FileId {
    d.primary.file
}
