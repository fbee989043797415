//! Moving a parsed item to another place in its file: every span of the item
//! (and of its syntax errors) shifted by the same number of bytes. The item
//! cache (`parse::cache`) keeps items parsed at offset 0 and shifts a copy to
//! where the item is now.

use crate::ast::*;
use crate::diag::{Diagnostic, FileId};

/// Adds `by` to every span inside.
pub(crate) trait Shift {
    fn shift(&mut self, by: usize);
}

impl Shift for Span {
    fn shift(&mut self, by: usize) {
        self.start += by;
        self.end += by;
    }
}

impl<T: Shift> Shift for Option<T> {
    fn shift(&mut self, by: usize) {
        if let Some(x) = self {
            x.shift(by);
        }
    }
}

impl<T: Shift> Shift for Vec<T> {
    fn shift(&mut self, by: usize) {
        self.iter_mut().for_each(|x| x.shift(by));
    }
}

impl<T: Shift> Shift for Box<T> {
    fn shift(&mut self, by: usize) {
        (**self).shift(by);
    }
}

/// `Shift` for a struct: the listed fields.
macro_rules! shift_fields {
    ($($ty:ty { $($field:ident),* $(,)? })*) => {$(
        impl Shift for $ty {
            fn shift(&mut self, by: usize) {
                $(self.$field.shift(by);)*
            }
        }
    )*};
}

shift_fields! {
    Ident { span }
    StrLit { span }
    Duration { span }
    Include { path, span }
    Attribute { allow, span }
    StatesBlock { states, span }
    StateDecl { name, initial, is_final, description, span }
    Agent { attributes, name, kind_span, description, members, span }
    StaleDecl { after, span }
    RateDecl { span }
    CommandsDecl { targets, span }
    EventDecl { name, fields, description, span }
    FieldDecl { name, ty, ty_span, span }
    FunctionDecl { name, description, span }
    Table { entries, span }
    TableEntry { selector, action, span }
    Action { function, from, to, span }
    Fsm { lines, span }
    FsmState { name, initial, action, span }
    FsmTransition { from, to, trigger, span }
    Rule { attributes, name, salience, description, conditions, target, span }
    Salience { span }
    StateTest { states, span }
    Pattern { event, constraints, run_length, within, span }
    RunLength { span }
    Constraint { field, test, span }
    Literal { span }
    Test { name, clauses, span }
    EventInstance { event, arguments, repeat, at, span }
    Argument { field, value, span }
    Property { name, formula, span }
    Script { name, steps, span }
    ScriptEvent { agent, event, arguments, span }
}

impl Shift for Item {
    fn shift(&mut self, by: usize) {
        match self {
            Item::Include(i) => i.shift(by),
            Item::States(i) => i.shift(by),
            Item::Agent(i) => i.shift(by),
            Item::Rule(i) => i.shift(by),
            Item::Test(i) => i.shift(by),
            Item::Property(i) => i.shift(by),
            Item::Script(i) => i.shift(by),
        }
    }
}

impl Shift for AgentMember {
    fn shift(&mut self, by: usize) {
        match self {
            AgentMember::Stale(m) => m.shift(by),
            AgentMember::Rate(m) => m.shift(by),
            AgentMember::Commands(m) => m.shift(by),
            AgentMember::Event(m) => m.shift(by),
            AgentMember::Function(m) => m.shift(by),
            AgentMember::Table(m) => m.shift(by),
            AgentMember::Fsm(m) => m.shift(by),
        }
    }
}

impl Shift for FieldType {
    fn shift(&mut self, by: usize) {
        match self {
            FieldType::F64 | FieldType::I64 | FieldType::Bool => {}
            FieldType::Symbols(symbols) => symbols.shift(by),
        }
    }
}

impl Shift for Selector {
    fn shift(&mut self, by: usize) {
        match self {
            Selector::States(states) => states.shift(by),
            Selector::Wildcard(span) => span.shift(by),
        }
    }
}

impl Shift for FsmLine {
    fn shift(&mut self, by: usize) {
        match self {
            FsmLine::State(s) => s.shift(by),
            FsmLine::Transition(t) => t.shift(by),
        }
    }
}

impl Shift for Trigger {
    fn shift(&mut self, by: usize) {
        match self {
            Trigger::State(t) => t.shift(by),
            Trigger::Event(e) => e.shift(by),
        }
    }
}

impl Shift for Condition {
    fn shift(&mut self, by: usize) {
        match self {
            Condition::State(t) => t.shift(by),
            Condition::Pattern(p) => p.shift(by),
            Condition::Not { pattern, span } => {
                pattern.shift(by);
                span.shift(by);
            }
            Condition::Stale { agent, span, .. } => {
                agent.shift(by);
                span.shift(by);
            }
        }
    }
}

impl Shift for FieldTest {
    fn shift(&mut self, by: usize) {
        match self {
            FieldTest::Bind(v) => v.shift(by),
            FieldTest::Compare { op_span, rhs, .. } => {
                op_span.shift(by);
                rhs.shift(by);
            }
            FieldTest::Range { lo, hi, .. } => {
                lo.shift(by);
                hi.shift(by);
            }
        }
    }
}

impl Shift for Operand {
    fn shift(&mut self, by: usize) {
        match self {
            Operand::Literal(l) => l.shift(by),
            Operand::Variable(v) => v.shift(by),
        }
    }
}

impl Shift for TestClause {
    fn shift(&mut self, by: usize) {
        match self {
            TestClause::Given { items, span } => {
                items.shift(by);
                span.shift(by);
            }
            TestClause::On { events, span } => {
                events.shift(by);
                span.shift(by);
            }
            TestClause::Expect { expectations, span } => {
                expectations.shift(by);
                span.shift(by);
            }
        }
    }
}

impl Shift for GivenItem {
    fn shift(&mut self, by: usize) {
        match self {
            GivenItem::State { state, span } => {
                state.shift(by);
                span.shift(by);
            }
            GivenItem::Event(e) => e.shift(by),
        }
    }
}

impl Shift for Expectation {
    fn shift(&mut self, by: usize) {
        match self {
            Expectation::State { state, span } => {
                state.shift(by);
                span.shift(by);
            }
            Expectation::Mode { agent, span, .. } => {
                agent.shift(by);
                span.shift(by);
            }
            Expectation::Runs { agent, function, span } => {
                agent.shift(by);
                function.shift(by);
                span.shift(by);
            }
            Expectation::Link { from, to, span, .. } => {
                from.shift(by);
                to.shift(by);
                span.shift(by);
            }
        }
    }
}

impl Shift for Formula {
    fn shift(&mut self, by: usize) {
        match self {
            Formula::Now(p) => p.shift(by),
            Formula::Implies { premise, consequent, span } => {
                premise.shift(by);
                consequent.shift(by);
                span.shift(by);
            }
        }
    }
}

impl Shift for Consequent {
    fn shift(&mut self, by: usize) {
        match self {
            Consequent::Now(p) => p.shift(by),
            Consequent::Next { predicate, span } => {
                predicate.shift(by);
                span.shift(by);
            }
            Consequent::Eventually { predicate, bound, span } => {
                predicate.shift(by);
                bound.shift(by);
                span.shift(by);
            }
        }
    }
}

impl Shift for Bound {
    fn shift(&mut self, by: usize) {
        match self {
            Bound::Events { span, .. } => span.shift(by),
            Bound::Time(d) => d.shift(by),
        }
    }
}

impl Shift for Predicate {
    fn shift(&mut self, by: usize) {
        match self {
            Predicate::Or(ps, span) | Predicate::And(ps, span) => {
                ps.shift(by);
                span.shift(by);
            }
            Predicate::Not(p, span) => {
                p.shift(by);
                span.shift(by);
            }
            Predicate::Bool(_, span) => span.shift(by),
            Predicate::State(t) => t.shift(by),
            Predicate::Mode { agent, span, .. } | Predicate::Stale { agent, span } => {
                agent.shift(by);
                span.shift(by);
            }
            Predicate::Link { from, to, span } => {
                from.shift(by);
                to.shift(by);
                span.shift(by);
            }
            Predicate::Event(p) => p.shift(by),
        }
    }
}

impl Shift for ScriptStep {
    fn shift(&mut self, by: usize) {
        match self {
            ScriptStep::At { time, event, span } => {
                time.shift(by);
                event.shift(by);
                span.shift(by);
            }
            ScriptStep::Every { period, event, from, to, span } => {
                period.shift(by);
                event.shift(by);
                from.shift(by);
                to.shift(by);
                span.shift(by);
            }
            ScriptStep::Silent { agent, from, to, span } => {
                agent.shift(by);
                from.shift(by);
                to.shift(by);
                span.shift(by);
            }
            ScriptStep::Random { length, seed_span, from, span, .. } => {
                length.shift(by);
                seed_span.shift(by);
                from.shift(by);
                span.shift(by);
            }
        }
    }
}

/// A syntax error moved with its item, and into `file`.
pub(crate) fn move_diagnostic(d: &mut Diagnostic, by: usize, file: FileId) {
    let labels = std::iter::once(&mut d.primary).chain(d.secondary.iter_mut());
    for label in labels {
        label.span.shift(by);
        label.file = file;
    }
    for edit in d.fixes.iter_mut().flat_map(|f| f.edits.iter_mut()) {
        edit.span.shift(by);
        edit.file = file;
    }
}
