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

mod hints;
mod report;
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
        let text = &src[span.start..span.end];
        let (depth, at) = lex::max_nesting(text);
        if depth > MAX_NESTING {
            let at = span.start + at;
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
            continue;
        }
        match parse_item(text) {
            Ok(mut pairs) => {
                let item = pairs.next().and_then(|p| p.into_inner().next());
                let Some(pair) = item else { continue };
                let mut builder = Builder { offset: span.start, file, errors: &mut errors };
                if let Some(item) = builder.item(pair) {
                    items.push(item);
                }
            }
            Err(err) => errors.push(syntax_error(&err, text, span.start, file)),
        }
    }
    Parsed { file: File { items }, comments: lex::comments(src), errors }
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

    fn states_block(&mut self, pair: P) -> StatesBlock {
        let span = self.span(&pair);
        let states = pair.into_inner().map(|p| self.state_decl(p)).collect();
        StatesBlock { states, span }
    }

    fn state_decl(&mut self, pair: P) -> StateDecl {
        let span = self.span(&pair);
        let mut decl = StateDecl {
            name: Ident { name: String::new(), span },
            initial: None,
            is_final: None,
            description: None,
            span,
        };
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => decl.name = self.ident(p),
                Rule::state_flag => {
                    let flag_span = self.span(&p);
                    if p.into_inner().next().map(|f| f.as_rule()) == Some(Rule::initial_kw) {
                        decl.initial = Some(flag_span);
                    } else {
                        decl.is_final = Some(flag_span);
                    }
                }
                Rule::string => decl.description = Some(self.string(p)),
                _ => {}
            }
        }
        decl
    }

    fn agent(&mut self, pair: P) -> Option<Agent> {
        let span = self.span(&pair);
        let mut attributes = Vec::new();
        let mut name = None;
        let mut kind = None;
        let mut description = None;
        let mut members = Vec::new();
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::attribute => attributes.push(self.attribute(p)),
                Rule::ident => name = Some(self.ident(p)),
                Rule::agent_kind => {
                    let k = match p.as_str() {
                        "sensor" => AgentKind::Sensor,
                        "actuator" => AgentKind::Actuator,
                        "processing" => AgentKind::Processing,
                        _ => AgentKind::Interface,
                    };
                    kind = Some((k, self.span(&p)));
                }
                Rule::string => description = Some(self.string(p)),
                Rule::stale_decl => {
                    let s = self.span(&p);
                    if let Some(after) = p.into_inner().next().and_then(|d| self.duration(d)) {
                        members.push(AgentMember::Stale(StaleDecl { after, span: s }));
                    }
                }
                Rule::rate_decl => {
                    let s = self.span(&p);
                    let f = p.into_inner().next()?;
                    let fs = self.span(&f);
                    let text = f.into_inner().next()?.as_str();
                    match text.parse::<f64>() {
                        Ok(hertz) if hertz.is_finite() => members.push(AgentMember::Rate(RateDecl { hertz, span: s })),
                        _ => self.literal_error(fs, "this frequency"),
                    }
                }
                Rule::commands_decl => {
                    let s = self.span(&p);
                    let targets = p.into_inner().map(|t| self.ident(t)).collect();
                    members.push(AgentMember::Commands(CommandsDecl { targets, span: s }));
                }
                Rule::event_decl => members.push(AgentMember::Event(self.event_decl(p))),
                Rule::function_decl => {
                    let s = self.span(&p);
                    let mut inner = p.into_inner();
                    let name = self.ident(inner.next()?);
                    let description = inner.next().map(|d| self.string(d));
                    members.push(AgentMember::Function(FunctionDecl { name, description, span: s }));
                }
                Rule::table => {
                    let s = self.span(&p);
                    let entries = p.into_inner().filter_map(|e| self.table_entry(e)).collect();
                    members.push(AgentMember::Table(Table { entries, span: s }));
                }
                Rule::fsm => members.push(AgentMember::Fsm(self.fsm(p)?)),
                _ => {}
            }
        }
        let (kind, kind_span) = kind?;
        Some(Agent { attributes, name: name?, kind, kind_span, description, members, span })
    }

    fn event_decl(&mut self, pair: P) -> EventDecl {
        let span = self.span(&pair);
        let mut decl =
            EventDecl { name: Ident { name: String::new(), span }, fields: Vec::new(), description: None, span };
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => decl.name = self.ident(p),
                Rule::field_list => {
                    for f in p.into_inner() {
                        let fspan = self.span(&f);
                        let mut inner = f.into_inner();
                        let (Some(n), Some(t)) = (inner.next(), inner.next()) else { continue };
                        let name = self.ident(n);
                        let ty_span = self.span(&t);
                        let Some(t) = t.into_inner().next() else { continue };
                        let ty = match t.as_rule() {
                            Rule::type_f64 => FieldType::F64,
                            Rule::type_i64 => FieldType::I64,
                            Rule::type_bool => FieldType::Bool,
                            _ => FieldType::Symbols(t.into_inner().map(|s| self.ident(s)).collect()),
                        };
                        decl.fields.push(FieldDecl { name, ty, ty_span, span: fspan });
                    }
                }
                Rule::string => decl.description = Some(self.string(p)),
                _ => {}
            }
        }
        decl
    }

    fn table_entry(&mut self, pair: P) -> Option<TableEntry> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let sel = inner.next()?;
        let first = sel.clone().into_inner().next()?;
        let selector = if first.as_rule() == Rule::wildcard {
            Selector::Wildcard(self.span(&first))
        } else {
            Selector::States(sel.into_inner().map(|p| self.ident(p)).collect())
        };
        let action = self.action(inner.next()?)?;
        Some(TableEntry { selector, action, span })
    }

    fn action(&mut self, pair: P) -> Option<Action> {
        let span = self.span(&pair);
        let a = pair.into_inner().next()?;
        let mode = match a.as_rule() {
            Rule::run_action => Mode::Running,
            Rule::wait_action => Mode::Waiting,
            _ => Mode::Sleeping,
        };
        let mut action = Action { mode, function: None, from: Vec::new(), to: Vec::new(), span };
        for p in a.into_inner() {
            match p.as_rule() {
                Rule::call => action.function = Some(self.ident(p.into_inner().next()?)),
                Rule::links => {
                    for l in p.into_inner() {
                        let names: Vec<Ident> = l.clone().into_inner().map(|i| self.ident(i)).collect();
                        if l.as_rule() == Rule::from_links {
                            action.from = names;
                        } else {
                            action.to = names;
                        }
                    }
                }
                _ => {}
            }
        }
        Some(action)
    }

    fn fsm(&mut self, pair: P) -> Option<Fsm> {
        let span = self.span(&pair);
        let mut lines = Vec::new();
        for p in pair.into_inner() {
            let lspan = self.span(&p);
            match p.as_rule() {
                Rule::fsm_state => {
                    let mut name = None;
                    let mut initial = None;
                    let mut action = None;
                    for q in p.into_inner() {
                        match q.as_rule() {
                            Rule::ident => name = Some(self.ident(q)),
                            Rule::initial_kw => initial = Some(self.span(&q)),
                            Rule::action => action = self.action(q),
                            _ => {}
                        }
                    }
                    lines.push(FsmLine::State(FsmState { name: name?, initial, action: action?, span: lspan }));
                }
                Rule::fsm_transition => {
                    let mut inner = p.into_inner();
                    let from = self.ident(inner.next()?);
                    let to = self.ident(inner.next()?);
                    let t = inner.next()?.into_inner().next()?;
                    let trigger = match t.as_rule() {
                        Rule::state_test => Trigger::State(self.state_test(t)?),
                        _ => Trigger::Event(self.ident(t)),
                    };
                    lines.push(FsmLine::Transition(FsmTransition { from, to, trigger, span: lspan }));
                }
                _ => {}
            }
        }
        Some(Fsm { lines, span })
    }

    fn rule(&mut self, pair: P) -> Option<Rule_> {
        let span = self.span(&pair);
        let mut attributes = Vec::new();
        let mut idents = Vec::new();
        let mut salience = None;
        let mut description = None;
        let mut conditions = Vec::new();
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::attribute => attributes.push(self.attribute(p)),
                Rule::ident => idents.push(self.ident(p)),
                Rule::salience => {
                    let s = self.span(&p);
                    let value = self.int(p.into_inner().next()?)?;
                    salience = Some(Salience { value, span: s });
                }
                Rule::string => description = Some(self.string(p)),
                Rule::condition => {
                    for term in p.into_inner() {
                        if let Some(c) = self.cond_term(term) {
                            conditions.push(c);
                        }
                    }
                }
                _ => {}
            }
        }
        let mut idents = idents.into_iter();
        let name = idents.next()?;
        let target = idents.next()?;
        Some(Rule_ { attributes, name, salience, description, conditions, target, span })
    }

    fn cond_term(&mut self, pair: P) -> Option<Condition> {
        let inner = pair.into_inner().next()?;
        Some(match inner.as_rule() {
            Rule::state_test => Condition::State(self.state_test(inner)?),
            Rule::stale_test => {
                let span = self.span(&inner);
                let mut negated = false;
                let mut agent = None;
                for p in inner.into_inner() {
                    match p.as_rule() {
                        Rule::not_kw => negated = true,
                        _ => agent = Some(self.ident(p)),
                    }
                }
                Condition::Stale { agent: agent?, negated, span }
            }
            Rule::negation => {
                let span = self.span(&inner);
                Condition::Not { pattern: self.pattern(inner.into_inner().next()?)?, span }
            }
            _ => Condition::Pattern(self.pattern(inner)?),
        })
    }

    fn state_test(&mut self, pair: P) -> Option<StateTest> {
        let span = self.span(&pair);
        let t = pair.into_inner().next()?;
        let (negated, set_syntax) = match t.as_rule() {
            Rule::state_in => (false, true),
            Rule::state_not_in => (true, true),
            Rule::state_eq => (false, false),
            _ => (true, false),
        };
        let states = t
            .into_inner()
            .flat_map(|p| if p.as_rule() == Rule::state_set { p.into_inner().collect::<Vec<_>>() } else { vec![p] })
            .map(|p| self.ident(p))
            .collect();
        Some(StateTest { negated, set_syntax, states, span })
    }

    fn pattern(&mut self, pair: P) -> Option<Pattern> {
        let span = self.span(&pair);
        let mut event = None;
        let mut constraints = Vec::new();
        let mut run_length = None;
        let mut within = None;
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => event = Some(self.ident(p)),
                Rule::constraints => {
                    for c in p.into_inner() {
                        if let Some(c) = self.constraint(c) {
                            constraints.push(c);
                        }
                    }
                }
                Rule::run_length => run_length = self.run_length(p),
                Rule::window => within = self.duration(p.into_inner().next()?),
                _ => {}
            }
        }
        Some(Pattern { event: event?, constraints, run_length, within, span })
    }

    fn run_length(&mut self, pair: P) -> Option<RunLength> {
        let span = self.span(&pair);
        let count = self.uint(pair.into_inner().next()?)?;
        Some(RunLength { count, span })
    }

    fn constraint(&mut self, pair: P) -> Option<Constraint> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let field = self.ident(inner.next()?);
        let t = inner.next()?;
        let test = match t.as_rule() {
            Rule::binding => {
                let v = t.into_inner().next()?;
                let s = self.span(&v);
                FieldTest::Bind(Ident { name: v.as_str()[1..].to_string(), span: s })
            }
            Rule::range_test => {
                let mut r = t.into_inner();
                let lo = self.operand(r.next()?)?;
                let inclusive = r.next()?.as_str() == "..=";
                let hi = self.operand(r.next()?)?;
                FieldTest::Range { lo, hi, inclusive }
            }
            _ => {
                let mut r = t.into_inner();
                let o = r.next()?;
                let op_span = self.span(&o);
                let op = match o.as_str() {
                    "==" => CmpOp::Eq,
                    "!=" => CmpOp::Ne,
                    "<=" => CmpOp::Le,
                    ">=" => CmpOp::Ge,
                    "<" => CmpOp::Lt,
                    _ => CmpOp::Gt,
                };
                FieldTest::Compare { op, op_span, rhs: self.operand(r.next()?)? }
            }
        };
        Some(Constraint { field, test, span })
    }

    fn operand(&mut self, pair: P) -> Option<Operand> {
        let inner = pair.into_inner().next()?;
        if inner.as_rule() == Rule::variable {
            let span = self.span(&inner);
            return Some(Operand::Variable(Ident { name: inner.as_str()[1..].to_string(), span }));
        }
        Some(Operand::Literal(self.literal(inner)?))
    }

    fn literal(&mut self, pair: P) -> Option<Literal> {
        let span = self.span(&pair);
        let inner = pair.into_inner().next()?;
        let value = match inner.as_rule() {
            Rule::float => LiteralValue::Float(self.float(inner)?),
            Rule::int => LiteralValue::Int(self.int(inner)?),
            Rule::boolean => LiteralValue::Bool(inner.as_str() == "true"),
            Rule::non_finite => LiteralValue::Float(match inner.as_str() {
                "NaN" => f64::NAN,
                "-inf" => f64::NEG_INFINITY,
                _ => f64::INFINITY,
            }),
            _ => LiteralValue::Symbol(inner.as_str().to_string()),
        };
        Some(Literal { value, span })
    }

    fn test(&mut self, pair: P) -> Option<Test> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let name = self.string(inner.next()?);
        let mut clauses = Vec::new();
        for c in inner {
            let cspan = self.span(&c);
            match c.as_rule() {
                Rule::given_clause => {
                    let mut items = Vec::new();
                    for g in c.into_inner() {
                        let g = g.into_inner().next()?;
                        if g.as_rule() == Rule::given_state {
                            let s = self.span(&g);
                            items.push(GivenItem::State { state: self.ident(g.into_inner().next()?), span: s });
                        } else {
                            items.push(GivenItem::Event(self.event_instance(g)?));
                        }
                    }
                    clauses.push(TestClause::Given { items, span: cspan });
                }
                Rule::on_clause => {
                    let events = c.into_inner().filter_map(|e| self.event_instance(e)).collect();
                    clauses.push(TestClause::On { events, span: cspan });
                }
                Rule::expect_clause => {
                    let mut expectations = Vec::new();
                    for e in c.into_inner() {
                        expectations.push(self.expectation(e)?);
                    }
                    clauses.push(TestClause::Expect { expectations, span: cspan });
                }
                _ => {}
            }
        }
        Some(Test { name, clauses, span })
    }

    fn event_instance(&mut self, pair: P) -> Option<EventInstance> {
        let span = self.span(&pair);
        let mut event = None;
        let mut arguments = Vec::new();
        let mut repeat = None;
        let mut at = None;
        for p in pair.into_inner() {
            match p.as_rule() {
                Rule::ident => event = Some(self.ident(p)),
                Rule::arguments => arguments = self.arguments(p)?,
                Rule::run_length => repeat = self.run_length(p),
                Rule::at_time => at = self.duration(p.into_inner().next()?),
                _ => {}
            }
        }
        Some(EventInstance { event: event?, arguments, repeat, at, span })
    }

    /// `(field: value, …)` of an event instance; a literal out of range is
    /// reported and its argument left out.
    pub(crate) fn arguments(&mut self, pair: P) -> Option<Vec<Argument>> {
        let mut arguments = Vec::new();
        for a in pair.into_inner() {
            let span = self.span(&a);
            let mut ai = a.into_inner();
            let field = self.ident(ai.next()?);
            let Some(value) = self.literal(ai.next()?) else { continue };
            arguments.push(Argument { field, value, span });
        }
        Some(arguments)
    }

    fn expectation(&mut self, pair: P) -> Option<Expectation> {
        let e = pair.into_inner().next()?;
        let span = self.span(&e);
        let kind = e.as_rule();
        let mut inner = e.into_inner();
        Some(match kind {
            Rule::expect_state => Expectation::State { state: self.ident(inner.next()?), span },
            Rule::expect_link | Rule::expect_no_link => {
                let from = self.ident(inner.next()?);
                let to = self.ident(inner.next()?);
                Expectation::Link { from, to, present: kind == Rule::expect_link, span }
            }
            Rule::expect_runs => {
                let agent = self.ident(inner.next()?);
                let function = self.ident(inner.next()?);
                Expectation::Runs { agent, function, span }
            }
            _ => {
                let agent = self.ident(inner.next()?);
                let mode = mode_word(inner.next()?.as_str());
                Expectation::Mode { agent, mode, span }
            }
        })
    }

    fn property(&mut self, pair: P) -> Option<Property> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let name = self.string(inner.next()?);
        let quantifier = if inner.next()?.as_str() == "always" { Quantifier::Always } else { Quantifier::Never };
        let formula = self.formula(inner.next()?)?;
        Some(Property { name, quantifier, formula, span })
    }

    fn formula(&mut self, pair: P) -> Option<Formula> {
        let span = self.span(&pair);
        let mut inner = pair.into_inner();
        let first = inner.next()?;
        if first.as_rule() == Rule::formula {
            return self.formula(first);
        }
        let premise = self.predicate(first)?;
        let Some(c) = inner.next() else { return Some(Formula::Now(premise)) };
        let c = c.into_inner().next()?;
        let cspan = self.span(&c);
        let consequent = match c.as_rule() {
            Rule::next_q => Consequent::Next { predicate: self.predicate(c.into_inner().next()?)?, span: cspan },
            Rule::eventually_q => {
                let mut ci = c.into_inner();
                let predicate = self.predicate(ci.next()?)?;
                let bound = match ci.next() {
                    Some(b) => {
                        let b = b.into_inner().next()?;
                        let bspan = self.span(&b);
                        if b.as_rule() == Rule::event_bound {
                            Some(Bound::Events { count: self.uint(b.into_inner().next()?)?, span: bspan })
                        } else {
                            Some(Bound::Time(self.duration(b)?))
                        }
                    }
                    None => None,
                };
                Consequent::Eventually { predicate, bound, span: cspan }
            }
            _ => Consequent::Now(self.predicate(c)?),
        };
        Some(Formula::Implies { premise, consequent, span })
    }

    /// `predicate`, `conjunction`, `negated`, `not_p` and `atom`, flattened so
    /// that a single child does not make a one-element `Or` or `And`.
    fn predicate(&mut self, pair: P) -> Option<Predicate> {
        let span = self.span(&pair);
        let kind = pair.as_rule();
        let mut children: Vec<P> = pair.into_inner().collect();
        match kind {
            Rule::predicate | Rule::conjunction => {
                if children.len() == 1 {
                    return self.predicate(children.pop()?);
                }
                let parts = children.into_iter().map(|c| self.predicate(c)).collect::<Option<Vec<_>>>()?;
                Some(if kind == Rule::predicate { Predicate::Or(parts, span) } else { Predicate::And(parts, span) })
            }
            Rule::negated => self.predicate(children.pop()?),
            Rule::not_p => Some(Predicate::Not(Box::new(self.predicate(children.pop()?)?), span)),
            Rule::atom => {
                let a = children.pop()?;
                let aspan = self.span(&a);
                match a.as_rule() {
                    Rule::predicate => self.predicate(a),
                    Rule::boolean => Some(Predicate::Bool(a.as_str() == "true", aspan)),
                    Rule::state_test => Some(Predicate::State(self.state_test(a)?)),
                    Rule::atom_stale => {
                        Some(Predicate::Stale { agent: self.ident(a.into_inner().next()?), span: aspan })
                    }
                    Rule::atom_link => {
                        let mut i = a.into_inner();
                        let from = self.ident(i.next()?);
                        let to = self.ident(i.next()?);
                        Some(Predicate::Link { from, to, span: aspan })
                    }
                    Rule::atom_mode => {
                        let mut i = a.into_inner();
                        let agent = self.ident(i.next()?);
                        let mode = mode_word(i.next()?.as_str());
                        Some(Predicate::Mode { agent, mode, span: aspan })
                    }
                    _ => Some(Predicate::Event(self.pattern(a)?)),
                }
            }
            _ => None,
        }
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
