//! Every name of a compilation, where it is defined and where it is used:
//! the ground of definition, references, highlights, rename, hover and
//! semantic tokens. Built from the ASTs (spans on every node), so that it is
//! there also when the program has errors.

use situ_grammar::ast::{self, FieldType, Item, Span};
use situ_grammar::diag::FileId;
use std::collections::HashMap;

/// What a name names. Names are global for states, agents, events and
/// rules; fields belong to their event, symbols to their field, functions
/// and FSM states to their agent, variables to their rule or pattern.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sym {
    State(String),
    Agent(String),
    Event(String),
    Field {
        event: String,
        field: String,
    },
    Symbol {
        event: String,
        field: String,
        symbol: String,
    },
    Function {
        agent: String,
        function: String,
    },
    Rule(String),
    FsmState {
        agent: String,
        state: String,
    },
    /// A variable; its scope is the item (rule or property pattern) where it is.
    Variable {
        scope: (FileId, usize),
        name: String,
    },
}

impl Sym {
    /// The name as written.
    pub fn name(&self) -> &str {
        match self {
            Sym::State(n) | Sym::Agent(n) | Sym::Event(n) | Sym::Rule(n) => n,
            Sym::Field { field, .. } => field,
            Sym::Symbol { symbol, .. } => symbol,
            Sym::Function { function, .. } => function,
            Sym::FsmState { state, .. } => state,
            Sym::Variable { name, .. } => name,
        }
    }

    /// A word for the kind of thing, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            Sym::State(_) => "state",
            Sym::Agent(_) => "agent",
            Sym::Event(_) => "event",
            Sym::Field { .. } => "field",
            Sym::Symbol { .. } => "symbol",
            Sym::Function { .. } => "function",
            Sym::Rule(_) => "rule",
            Sym::FsmState { .. } => "FSM state",
            Sym::Variable { .. } => "variable",
        }
    }

    /// The same kind of thing, in the same scope, under another name.
    pub fn renamed(&self, new: &str) -> Sym {
        let n = new.to_string();
        match self.clone() {
            Sym::State(_) => Sym::State(n),
            Sym::Agent(_) => Sym::Agent(n),
            Sym::Event(_) => Sym::Event(n),
            Sym::Rule(_) => Sym::Rule(n),
            Sym::Field { event, .. } => Sym::Field { event, field: n },
            Sym::Symbol { event, field, .. } => Sym::Symbol { event, field, symbol: n },
            Sym::Function { agent, .. } => Sym::Function { agent, function: n },
            Sym::FsmState { agent, .. } => Sym::FsmState { agent, state: n },
            Sym::Variable { scope, .. } => Sym::Variable { scope, name: n },
        }
    }
}

/// One place where a name is written.
#[derive(Debug, Clone, PartialEq)]
pub struct Occurrence {
    pub file: FileId,
    pub span: Span,
    pub sym: Sym,
    /// The declaration (for a variable: its binding `field: ?v`).
    pub def: bool,
}

/// A `_` entry of a table: the states it does not cover are those named.
#[derive(Debug, Clone, PartialEq)]
pub struct Wildcard {
    pub file: FileId,
    pub span: Span,
    pub agent: String,
    /// The states named by the other entries of the table.
    pub named: Vec<String>,
}

/// The names of one compilation.
#[derive(Debug, Clone, Default)]
pub struct Index {
    pub occurrences: Vec<Occurrence>,
    pub wildcards: Vec<Wildcard>,
    /// The symbols of each enumerated field, by (event, field).
    symbols: HashMap<(String, String), Vec<String>>,
    /// Each event's agent and fields (name, type as written), by event.
    pub events: HashMap<String, (String, Vec<(String, String)>)>,
}

impl Index {
    pub fn build(files: &[(FileId, &ast::File)]) -> Index {
        let mut index = Index::default();
        for (_, file) in files {
            for item in &file.items {
                if let Item::Agent(a) = item {
                    for m in &a.members {
                        if let ast::AgentMember::Event(e) = m {
                            let fields = e.fields.iter().map(|f| (f.name.name.clone(), type_text(&f.ty))).collect();
                            index.events.insert(e.name.name.clone(), (a.name.name.clone(), fields));
                            for f in &e.fields {
                                if let FieldType::Symbols(s) = &f.ty {
                                    let names = s.iter().map(|s| s.name.clone()).collect();
                                    index.symbols.insert((e.name.name.clone(), f.name.name.clone()), names);
                                }
                            }
                        }
                    }
                }
            }
        }
        for (id, file) in files {
            let mut w = Walker { index: &mut index, file: *id };
            for item in &file.items {
                w.item(item);
            }
        }
        index
    }

    /// The name written at `offset` of `file` (a cursor just after a name counts).
    pub fn at(&self, file: FileId, offset: usize) -> Option<&Occurrence> {
        let hit = |o: &&Occurrence| o.file == file && o.span.start <= offset && offset <= o.span.end;
        let mut found = self.occurrences.iter().filter(hit);
        let first = found.next()?;
        // Two names touch (`A,B` never does, but be exact): prefer the one that starts at the cursor.
        Some(found.find(|o| o.span.start == offset).unwrap_or(first))
    }

    pub fn wildcard_at(&self, file: FileId, offset: usize) -> Option<&Wildcard> {
        self.wildcards.iter().find(|w| w.file == file && w.span.start <= offset && offset <= w.span.end)
    }

    /// Every place of `sym`, declarations first.
    pub fn references<'a>(&'a self, sym: &'a Sym) -> impl Iterator<Item = &'a Occurrence> + 'a {
        let defs = self.occurrences.iter().filter(move |o| o.def && &o.sym == sym);
        defs.chain(self.occurrences.iter().filter(move |o| !o.def && &o.sym == sym))
    }

    pub fn definition(&self, sym: &Sym) -> Option<&Occurrence> {
        self.occurrences.iter().find(|o| o.def && &o.sym == sym)
    }

    /// Whether something of the kind and scope of `sym` is declared as `name`.
    pub fn is_declared(&self, sym: &Sym, name: &str) -> bool {
        let other = sym.renamed(name);
        match &other {
            // A variable is declared by its binding site, or used at all.
            Sym::Variable { .. } => self.occurrences.iter().any(|o| o.sym == other),
            _ => self.definition(&other).is_some(),
        }
    }

    pub fn symbols_of(&self, event: &str, field: &str) -> Option<&[String]> {
        self.symbols.get(&(event.to_string(), field.to_string())).map(Vec::as_slice)
    }
}

fn type_text(ty: &FieldType) -> String {
    match ty {
        FieldType::F64 => "f64".into(),
        FieldType::I64 => "i64".into(),
        FieldType::Bool => "bool".into(),
        FieldType::Symbols(s) => format!("{{{}}}", s.iter().map(|s| s.name.as_str()).collect::<Vec<_>>().join(", ")),
    }
}

struct Walker<'a> {
    index: &'a mut Index,
    file: FileId,
}

impl Walker<'_> {
    fn push(&mut self, span: Span, sym: Sym, def: bool) {
        self.index.occurrences.push(Occurrence { file: self.file, span, sym, def });
    }

    fn state(&mut self, id: &ast::Ident) {
        self.push(id.span, Sym::State(id.name.clone()), false);
    }

    fn agent(&mut self, id: &ast::Ident) {
        self.push(id.span, Sym::Agent(id.name.clone()), false);
    }

    fn item(&mut self, item: &Item) {
        match item {
            Item::Include(_) => {}
            Item::States(b) => {
                for s in &b.states {
                    self.push(s.name.span, Sym::State(s.name.name.clone()), true);
                }
            }
            Item::Agent(a) => self.agent_item(a),
            Item::Rule(r) => {
                self.push(r.name.span, Sym::Rule(r.name.name.clone()), true);
                let scope = (self.file, r.span.start);
                for c in &r.conditions {
                    match c {
                        ast::Condition::State(t) => self.state_test(t),
                        ast::Condition::Pattern(p) => self.pattern(p, scope),
                        ast::Condition::Not { pattern, .. } => self.pattern(pattern, scope),
                        ast::Condition::Stale { agent, .. } => self.agent(agent),
                    }
                }
                self.state(&r.target);
            }
            Item::Test(t) => {
                for c in &t.clauses {
                    match c {
                        ast::TestClause::Given { items, .. } => {
                            for g in items {
                                match g {
                                    ast::GivenItem::State { state, .. } => self.state(state),
                                    ast::GivenItem::Event(e) => self.instance(&e.event, &e.arguments),
                                }
                            }
                        }
                        ast::TestClause::On { events, .. } => {
                            for e in events {
                                self.instance(&e.event, &e.arguments);
                            }
                        }
                        ast::TestClause::Expect { expectations, .. } => {
                            for e in expectations {
                                self.expectation(e);
                            }
                        }
                    }
                }
            }
            Item::Property(p) => match &p.formula {
                ast::Formula::Now(q) => self.predicate(q),
                ast::Formula::Implies { premise, consequent, .. } => {
                    self.predicate(premise);
                    match consequent {
                        ast::Consequent::Now(q)
                        | ast::Consequent::Next { predicate: q, .. }
                        | ast::Consequent::Eventually { predicate: q, .. } => self.predicate(q),
                    }
                }
            },
            Item::Script(s) => {
                for step in &s.steps {
                    match step {
                        ast::ScriptStep::At { event, .. } | ast::ScriptStep::Every { event, .. } => {
                            if let Some(a) = &event.agent {
                                self.agent(a);
                            }
                            self.instance(&event.event, &event.arguments);
                        }
                        ast::ScriptStep::Silent { agent, .. } => self.agent(agent),
                        ast::ScriptStep::Random { .. } => {}
                    }
                }
            }
        }
    }

    fn agent_item(&mut self, a: &ast::Agent) {
        let agent = a.name.name.clone();
        self.push(a.name.span, Sym::Agent(agent.clone()), true);
        for m in &a.members {
            match m {
                ast::AgentMember::Stale(_) | ast::AgentMember::Rate(_) => {}
                ast::AgentMember::Commands(c) => c.targets.iter().for_each(|t| self.agent(t)),
                ast::AgentMember::Event(e) => {
                    let event = e.name.name.clone();
                    self.push(e.name.span, Sym::Event(event.clone()), true);
                    for f in &e.fields {
                        let field = f.name.name.clone();
                        self.push(f.name.span, Sym::Field { event: event.clone(), field: field.clone() }, true);
                        if let FieldType::Symbols(syms) = &f.ty {
                            for s in syms {
                                let sym =
                                    Sym::Symbol { event: event.clone(), field: field.clone(), symbol: s.name.clone() };
                                self.push(s.span, sym, true);
                            }
                        }
                    }
                }
                ast::AgentMember::Function(f) => {
                    let sym = Sym::Function { agent: agent.clone(), function: f.name.name.clone() };
                    self.push(f.name.span, sym, true);
                }
                ast::AgentMember::Table(t) => {
                    let named: Vec<String> = t
                        .entries
                        .iter()
                        .filter_map(|e| match &e.selector {
                            ast::Selector::States(s) => Some(s.iter().map(|s| s.name.clone())),
                            ast::Selector::Wildcard(_) => None,
                        })
                        .flatten()
                        .collect();
                    for e in &t.entries {
                        match &e.selector {
                            ast::Selector::States(s) => s.iter().for_each(|s| self.state(s)),
                            ast::Selector::Wildcard(span) => self.index.wildcards.push(Wildcard {
                                file: self.file,
                                span: *span,
                                agent: agent.clone(),
                                named: named.clone(),
                            }),
                        }
                        self.action(&agent, &e.action);
                    }
                }
                ast::AgentMember::Fsm(f) => {
                    for line in &f.lines {
                        match line {
                            ast::FsmLine::State(s) => {
                                let sym = Sym::FsmState { agent: agent.clone(), state: s.name.name.clone() };
                                self.push(s.name.span, sym, true);
                                self.action(&agent, &s.action);
                            }
                            ast::FsmLine::Transition(t) => {
                                for end in [&t.from, &t.to] {
                                    let sym = Sym::FsmState { agent: agent.clone(), state: end.name.clone() };
                                    self.push(end.span, sym, false);
                                }
                                match &t.trigger {
                                    ast::Trigger::State(test) => self.state_test(test),
                                    ast::Trigger::Event(e) => self.push(e.span, Sym::Event(e.name.clone()), false),
                                }
                            }
                        }
                    }
                }
            }
        }
    }

    fn action(&mut self, agent: &str, a: &ast::Action) {
        if let Some(f) = &a.function {
            self.push(f.span, Sym::Function { agent: agent.to_string(), function: f.name.clone() }, false);
        }
        for x in a.from.iter().chain(&a.to) {
            self.agent(x);
        }
    }

    fn state_test(&mut self, t: &ast::StateTest) {
        for s in &t.states {
            self.state(s);
        }
    }

    fn pattern(&mut self, p: &ast::Pattern, scope: (FileId, usize)) {
        let event = p.event.name.clone();
        self.push(p.event.span, Sym::Event(event.clone()), false);
        for c in &p.constraints {
            let field = c.field.name.clone();
            self.push(c.field.span, Sym::Field { event: event.clone(), field: field.clone() }, false);
            match &c.test {
                ast::FieldTest::Bind(v) => self.variable(v, scope, true),
                ast::FieldTest::Compare { rhs, .. } => self.operand(rhs, &event, &field, scope),
                ast::FieldTest::Range { lo, hi, .. } => {
                    self.operand(lo, &event, &field, scope);
                    self.operand(hi, &event, &field, scope);
                }
            }
        }
    }

    fn variable(&mut self, v: &ast::Ident, scope: (FileId, usize), def: bool) {
        // The span covers the `?`; the name is after it.
        let span = Span::new((v.span.start + 1).min(v.span.end), v.span.end);
        let sym = Sym::Variable { scope, name: v.name.clone() };
        // A variable bound twice is bound once: its first binding is the declaration.
        let def = def && !self.index.occurrences.iter().rev().any(|o| o.def && o.sym == sym);
        self.push(span, sym, def);
    }

    fn operand(&mut self, o: &ast::Operand, event: &str, field: &str, scope: (FileId, usize)) {
        match o {
            ast::Operand::Variable(v) => self.variable(v, scope, false),
            ast::Operand::Literal(l) => self.literal(l, event, field),
        }
    }

    fn literal(&mut self, l: &ast::Literal, event: &str, field: &str) {
        if let ast::LiteralValue::Symbol(s) = &l.value {
            let sym = Sym::Symbol { event: event.to_string(), field: field.to_string(), symbol: s.clone() };
            self.push(l.span, sym, false);
        }
    }

    fn instance(&mut self, event: &ast::Ident, arguments: &[ast::Argument]) {
        self.push(event.span, Sym::Event(event.name.clone()), false);
        for a in arguments {
            let field = a.field.name.clone();
            self.push(a.field.span, Sym::Field { event: event.name.clone(), field: field.clone() }, false);
            self.literal(&a.value, &event.name, &field);
        }
    }

    fn expectation(&mut self, e: &ast::Expectation) {
        match e {
            ast::Expectation::State { state, .. } => self.state(state),
            ast::Expectation::Mode { agent, .. } => self.agent(agent),
            ast::Expectation::Runs { agent, function, .. } => {
                self.agent(agent);
                let sym = Sym::Function { agent: agent.name.clone(), function: function.name.clone() };
                self.push(function.span, sym, false);
            }
            ast::Expectation::Link { from, to, .. } => {
                self.agent(from);
                self.agent(to);
            }
        }
    }

    fn predicate(&mut self, p: &ast::Predicate) {
        match p {
            ast::Predicate::Or(ps, _) | ast::Predicate::And(ps, _) => ps.iter().for_each(|q| self.predicate(q)),
            ast::Predicate::Not(q, _) => self.predicate(q),
            ast::Predicate::Bool(..) => {}
            ast::Predicate::State(t) => self.state_test(t),
            ast::Predicate::Mode { agent, .. } | ast::Predicate::Stale { agent, .. } => self.agent(agent),
            ast::Predicate::Link { from, to, .. } => {
                self.agent(from);
                self.agent(to);
            }
            ast::Predicate::Event(pat) => self.pattern(pat, (self.file, pat.span.start)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const SRC: &str = "states { IT initial RS RO }\n\
        agent L sensor { event OBS { d: f64, side: {left, right} } function f\n\
          table { RS => run f() _ => sleep } }\n\
        rule r { when state == RS and OBS(d: ?x, side == left) and OBS(d < ?x) then RO }\n";

    fn index() -> Index {
        let parsed = situ_grammar::parse(SRC, FileId(0));
        assert!(parsed.errors.is_empty(), "{:?}", parsed.errors);
        Index::build(&[(FileId(0), &parsed.file)])
    }

    #[test]
    fn names_resolve_to_their_declarations() {
        let idx = index();
        let at = |needle: &str, nth: usize| {
            let off = SRC.match_indices(needle).nth(nth).unwrap().0;
            idx.at(FileId(0), off).unwrap().sym.clone()
        };
        assert_eq!(at("RS", 1), Sym::State("RS".into()));
        assert_eq!(idx.references(&Sym::State("RS".into())).count(), 3);
        assert!(matches!(at("left", 1), Sym::Symbol { ref field, .. } if field == "side"));
        let x = at("x", 0);
        assert!(matches!(&x, Sym::Variable { name, .. } if name == "x"));
        assert_eq!(idx.references(&x).count(), 2);
        assert_eq!(idx.definition(&x).unwrap().span.len(), 1);
        assert_eq!(at("f()", 0), Sym::Function { agent: "L".into(), function: "f".into() });
        assert_eq!(idx.wildcards[0].named, ["RS"]);
        assert!(idx.is_declared(&Sym::State("IT".into()), "RO"));
        assert!(!idx.is_declared(&Sym::State("IT".into()), "XX"));
        assert_eq!(idx.symbols_of("OBS", "side").unwrap(), ["left", "right"]);
    }
}
