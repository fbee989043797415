//! From source text to the AST, with recovery: the file is split into items
//! (`lex::split_items`), each item is parsed alone, and every item that fails
//! gives one diagnostic while the others still produce their AST.

use crate::ast::*;
use crate::diag::{Diagnostic, FileId};
use crate::lex::{self, Comment};
use pest::iterators::Pair;
use pest::Parser as _;
use std::num::NonZeroUsize;
use std::sync::{Mutex, Once};

pub mod cache;
mod declarations;
mod hints;
mod report;
mod rules;
mod scenarios;
mod vocab;

use report::syntax_error;

/// The pest parser generated from `situ.pest`.
#[derive(pest_derive::Parser)]
#[grammar = "situ.pest"]
pub struct SituParser;

/// The syntax error code: the input does not follow the grammar.
pub const SYNTAX: &str = "E0001";
/// The nesting code: an item is nested deeper than [`MAX_NESTING`].
pub const TOO_DEEP: &str = "E0006";
/// The literal code: a number or duration that does not fit.
pub const BAD_LITERAL: &str = "E0007";
/// The code given once a file has more than [`MAX_SYNTAX_ERRORS`] errors.
pub const TOO_MANY_ERRORS: &str = "E0008";

/// Items nested deeper than this are refused before the grammar sees them.
pub const MAX_NESTING: usize = 64;
/// A file reports at most this many syntax errors.
pub const MAX_SYNTAX_ERRORS: usize = 50;

/// The result of parsing one file: everything that parsed, every comment, and
/// every error.
#[derive(Debug, Clone)]
pub struct Parsed {
    pub file: File,
    pub comments: Vec<Comment>,
    pub errors: Vec<Diagnostic>,
}

fn configure_pest() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // Error detail (what was expected at the furthest place reached) is
        // collected only when an item is parsed again to report its error:
        // see `parse_item`.
        pest::set_error_detail(false);
        // A bound on the work per item, so that no input can make it hang.
        pest::set_call_limit(NonZeroUsize::new(5_000_000));
    });
}

/// Held while an item is parsed with pest's error detail on: the only code
/// that turns the flag on, and it turns it off again before letting go.
static DETAIL: Mutex<()> = Mutex::new(());

/// Parses one item with the `item` rule; a failure comes with the expected
/// tokens that `syntax_error` reports.
///
/// pest's error detail costs a string per literal tried (most of a parse),
/// and only a failure uses it, so the item is parsed without it first and,
/// only when that fails, once more with it. Neither the outcome of a parse
/// nor its error's position and rules depend on the flag: it only turns on
/// the bookkeeping of `ParseAttempts`, which no decision of the parser reads,
/// and pest reads it once, when a parse starts. The second parse therefore
/// fails exactly as the first and yields the error that a parse with the flag
/// always on gave. The flag is process-wide, and other threads parse at the
/// same time: it is turned on only here, under `DETAIL`, and off again before
/// the lock is released, so the detailed parse always sees it on; a parse on
/// another thread that starts meanwhile also collects the detail, which
/// changes nothing but its speed.
fn parse_item(text: &str) -> Result<pest::iterators::Pairs<'_, Rule>, pest::error::Error<Rule>> {
    match SituParser::parse(Rule::item, text) {
        Ok(pairs) => Ok(pairs),
        Err(_) => {
            /// Turns the flag off on every way out, a panic included.
            struct Off;
            impl Drop for Off {
                fn drop(&mut self) {
                    pest::set_error_detail(false);
                }
            }
            let _lock = DETAIL.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
            pest::set_error_detail(true);
            let _off = Off;
            SituParser::parse(Rule::item, text)
        }
    }
}

/// Parses a whole source, recovering at item boundaries.
pub fn parse(src: &str, file: FileId) -> Parsed {
    parse_items(src, file, |text, offset| parse_one(text, offset, file))
}

/// One item's parse: its AST (none when it failed) and its errors.
#[derive(Debug, Clone)]
pub(crate) struct ItemParse {
    pub(crate) item: Option<Item>,
    pub(crate) errors: Vec<Diagnostic>,
}

/// Parses a whole source, each item by `item` (its text and where it starts);
/// the errors of the items in order, at most [`MAX_SYNTAX_ERRORS`] and then
/// one more to say so.
pub(crate) fn parse_items(src: &str, file: FileId, mut item: impl FnMut(&str, usize) -> ItemParse) -> Parsed {
    configure_pest();
    let mut items = Vec::new();
    let mut errors = Vec::new();
    for span in lex::split_items(src) {
        if errors.len() >= MAX_SYNTAX_ERRORS {
            errors.push(
                Diagnostic::error(
                    TOO_MANY_ERRORS,
                    format!("too many syntax errors; stopped after {MAX_SYNTAX_ERRORS}"),
                    file,
                    Span::new(span.start, span.start),
                    "stopped here",
                )
                .with_help("is this a situ source file?"),
            );
            break;
        }
        let parsed = item(&src[span.start..span.end], span.start);
        items.extend(parsed.item);
        errors.extend(parsed.errors);
    }
    Parsed { file: File { items }, comments: lex::comments(src), errors }
}

/// Parses the item `text`, which starts at `offset` of `file`. What it gives
/// depends on the text alone, but for its spans (shifted by `offset`) and
/// the file its errors name.
pub(crate) fn parse_one(text: &str, offset: usize, file: FileId) -> ItemParse {
    configure_pest();
    let mut errors = Vec::new();
    let (depth, at) = lex::max_nesting(text);
    if depth > MAX_NESTING {
        let at = offset + at;
        errors.push(
            Diagnostic::error(
                TOO_DEEP,
                format!("this item is nested {depth} levels deep; at most {MAX_NESTING} are allowed"),
                file,
                Span::new(at, at + 1),
                "too deep from here",
            )
            .with_help("split the expression into several rules or properties"),
        );
        return ItemParse { item: None, errors };
    }
    let item = match parse_item(text) {
        Ok(mut pairs) => pairs.next().and_then(|p| p.into_inner().next()).and_then(|pair| {
            let mut builder = Builder { offset, file, errors: &mut errors };
            builder.item(pair)
        }),
        Err(err) => {
            errors.push(syntax_error(&err, text, offset, file));
            None
        }
    };
    ItemParse { item, errors }
}

/// The reserved words of the language (mirrors `keyword` in the grammar).
pub const KEYWORDS: &[&str] = &[
    "states",
    "agent",
    "rule",
    "test",
    "property",
    "include",
    "initial",
    "final",
    "sensor",
    "actuator",
    "processing",
    "interface",
    "stale",
    "after",
    "event",
    "function",
    "table",
    "fsm",
    "rate",
    "when",
    "then",
    "salience",
    "and",
    "or",
    "not",
    "in",
    "state",
    "within",
    "run",
    "sleep",
    "wait",
    "from",
    "to",
    "on",
    "given",
    "expect",
    "at",
    "link",
    "no",
    "always",
    "never",
    "next",
    "eventually",
    "events",
    "true",
    "false",
    "runs",
    "running",
    "sleeping",
    "waiting",
    "f64",
    "i64",
    "bool",
];

/// Builds AST nodes from pest pairs of one item, shifting spans by `offset`.
pub(crate) struct Builder<'e> {
    offset: usize,
    file: FileId,
    errors: &'e mut Vec<Diagnostic>,
}

pub(crate) type P<'i> = Pair<'i, Rule>;

impl Builder<'_> {
    pub(crate) fn span(&self, pair: &P) -> Span {
        let s = pair.as_span();
        Span::new(self.offset + s.start(), self.offset + s.end())
    }

    pub(crate) fn ident(&self, pair: P) -> Ident {
        Ident { name: pair.as_str().to_string(), span: self.span(&pair) }
    }

    pub(crate) fn string(&self, pair: P) -> StrLit {
        let span = self.span(&pair);
        let inner = pair.into_inner().next().map(|p| p.as_str()).unwrap_or("");
        let mut value = String::with_capacity(inner.len());
        let mut chars = inner.chars();
        while let Some(c) = chars.next() {
            if c == '\\' {
                match chars.next() {
                    Some('n') => value.push('\n'),
                    Some('t') => value.push('\t'),
                    Some(other) => value.push(other),
                    None => {}
                }
            } else {
                value.push(c);
            }
        }
        StrLit { value, span }
    }

    fn literal_error(&mut self, span: Span, what: &str) {
        self.errors.push(Diagnostic::error(
            BAD_LITERAL,
            format!("{what} does not fit"),
            self.file,
            span,
            "out of range",
        ));
    }

    fn int(&mut self, pair: P) -> Option<i64> {
        let span = self.span(&pair);
        match pair.as_str().parse() {
            Ok(v) => Some(v),
            Err(_) => {
                self.literal_error(span, "this integer");
                None
            }
        }
    }

    pub(crate) fn uint(&mut self, pair: P) -> Option<u64> {
        let span = self.span(&pair);
        match pair.as_str().parse() {
            Ok(v) => Some(v),
            Err(_) => {
                self.literal_error(span, "this count");
                None
            }
        }
    }

    fn float(&mut self, pair: P) -> Option<f64> {
        let span = self.span(&pair);
        match pair.as_str().parse::<f64>() {
            Ok(v) if v.is_finite() => Some(v),
            _ => {
                self.literal_error(span, "this number");
                None
            }
        }
    }

    pub(crate) fn duration(&mut self, pair: P) -> Option<Duration> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let value = inner.next()?.as_str();
        let unit = inner.next()?.as_str();
        let scale: u64 = match unit {
            "ns" => 1,
            "us" => 1_000,
            "ms" => 1_000_000,
            "s" => 1_000_000_000,
            _ => 60_000_000_000,
        };
        let nanos = parse_scaled(value, scale);
        match nanos {
            Some(nanos) => Some(Duration { nanos, span }),
            None => {
                self.literal_error(span, "this duration");
                None
            }
        }
    }

    fn item(&mut self, pair: P) -> Option<Item> {
        Some(match pair.as_rule() {
            Rule::include => {
                let span = self.span(&pair);
                let path = self.string(pair.into_inner().next()?);
                Item::Include(Include { path, span })
            }
            Rule::states_block => Item::States(self.states_block(pair)),
            Rule::agent => Item::Agent(self.agent(pair)?),
            Rule::rule => Item::Rule(self.rule(pair)?),
            Rule::test => Item::Test(self.test(pair)?),
            Rule::property => Item::Property(self.property(pair)?),
            Rule::script => Item::Script(self.script(pair)?),
            _ => return None,
        })
    }

    fn attribute(&self, pair: P) -> Attribute {
        let span = self.span(&pair);
        let allow = pair
            .into_inner()
            .map(|p| {
                let span = self.span(&p);
                let name = p.as_str().trim_start_matches("situ::").to_string();
                Ident { name, span }
            })
            .collect();
        Attribute { allow, span }
    }
}

/// The AST rule type, named apart from pest's `Rule` enum.
type Rule_ = crate::ast::Rule;

fn mode_word(s: &str) -> Mode {
    match s {
        "running" => Mode::Running,
        "sleeping" => Mode::Sleeping,
        _ => Mode::Waiting,
    }
}

/// `value × scale` for a decimal `value` such as `1.5`, exactly, in integers.
fn parse_scaled(value: &str, scale: u64) -> Option<u64> {
    let (int, frac) = value.split_once('.').unwrap_or((value, ""));
    let whole = int.parse::<u64>().ok()?.checked_mul(scale)?;
    let mut frac_part = 0u64;
    let mut unit = scale;
    for d in frac.bytes() {
        unit /= 10;
        if unit == 0 {
            // Finer than a nanosecond: only zeros are allowed.
            if d != b'0' {
                return None;
            }
            continue;
        }
        frac_part += u64::from(d - b'0') * unit;
    }
    whole.checked_add(frac_part)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_decimal_durations_exactly() {
        assert_eq!(parse_scaled("1.5", 1_000_000_000), Some(1_500_000_000));
        assert_eq!(parse_scaled("200", 1_000_000), Some(200_000_000));
        assert_eq!(parse_scaled("0.0000000001", 1_000_000_000), None);
        assert_eq!(parse_scaled("99999999999999999999", 1), None);
    }

    /// The arguments of the first `on` of the first test of `src`.
    fn arguments(src: &str) -> Vec<LiteralValue> {
        let parsed = parse(src, crate::diag::FileId(0));
        assert!(parsed.errors.is_empty(), "{:?}", parsed.errors);
        let Some(crate::ast::Item::Test(t)) = parsed.file.items.first() else { panic!("a test") };
        let Some(TestClause::On { events, .. }) = t.clauses.first() else { panic!("an on clause") };
        events[0].arguments.iter().map(|a| a.value.value.clone()).collect()
    }

    #[test]
    fn non_finite_floats_are_literals() {
        let values = arguments("test \"t\" { on E(a: NaN, b: inf, c: -inf, d: nan, e: infinity, f: info) }");
        assert!(matches!(values[0], LiteralValue::Float(f) if f.is_nan()));
        assert_eq!(values[1], LiteralValue::Float(f64::INFINITY));
        assert_eq!(values[2], LiteralValue::Float(f64::NEG_INFINITY));
        for (v, name) in values[3..].iter().zip(["nan", "infinity", "info"]) {
            assert_eq!(*v, LiteralValue::Symbol(name.into()), "other spellings are names");
        }
        // An overflowing number is still an error, not infinity.
        assert!(!parse("test \"t\" { on E(a: 1e999) }", crate::diag::FileId(0)).errors.is_empty());
    }

    /// `ident` compares a name with the keywords only when it starts with a
    /// small letter: every keyword must, and `KEYWORDS` must be the grammar's.
    #[test]
    fn keywords_start_with_a_small_letter() {
        let grammar = include_str!("situ.pest");
        let start = grammar.find("keyword = _{").expect("the keyword rule");
        let body = &grammar[start..start + grammar[start..].find("~ !ident_char").expect("its end")];
        let mut words: Vec<&str> = body.split('"').skip(1).step_by(2).collect();
        let mut listed = KEYWORDS.to_vec();
        words.sort_unstable();
        listed.sort_unstable();
        assert_eq!(words, listed);
        for w in KEYWORDS {
            assert!(w.starts_with(|c: char| c.is_ascii_lowercase()), "{w}");
            let capital = format!("{}{}", w[..1].to_ascii_uppercase(), &w[1..]);
            let src = format!("rule {w} {{ when A then B }}\nrule {capital} {{ when A then B }}");
            let parsed = parse(&src, crate::diag::FileId(0));
            assert_eq!(parsed.errors.len(), 1, "{w}: {:?}", parsed.errors);
            assert_eq!(parsed.file.items.len(), 1, "{capital} is a name");
        }
    }
}
