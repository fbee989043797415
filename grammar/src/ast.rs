//! The abstract syntax tree of a situ file. Every node carries the [`Span`] it
//! was parsed from, so that every later phase can point back at the source.

use serde::Serialize;

/// A range of bytes in one source file, `start..end`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Default)]
pub struct Span {
    pub start: usize,
    pub end: usize,
}

impl Span {
    pub fn new(start: usize, end: usize) -> Self {
        Span { start, end }
    }
    /// The smallest span covering both.
    pub fn join(self, other: Span) -> Span {
        Span::new(self.start.min(other.start), self.end.max(other.end))
    }
    pub fn len(self) -> usize {
        self.end - self.start
    }
    pub fn is_empty(self) -> bool {
        self.end == self.start
    }
}

/// A name as written, with its place.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Ident {
    pub name: String,
    pub span: Span,
}

/// A string literal, unescaped.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StrLit {
    pub value: String,
    pub span: Span,
}

/// A length of time, in nanoseconds.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize)]
pub struct Duration {
    pub nanos: u64,
    pub span: Span,
}

/// One parsed file.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct File {
    pub items: Vec<Item>,
}

/// A top-level item.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Item {
    Include(Include),
    States(StatesBlock),
    Agent(Agent),
    Rule(Rule),
    Test(Test),
    Property(Property),
    Script(Script),
}

impl Item {
    pub fn span(&self) -> Span {
        match self {
            Item::Include(i) => i.span,
            Item::States(i) => i.span,
            Item::Agent(i) => i.span,
            Item::Rule(i) => i.span,
            Item::Test(i) => i.span,
            Item::Property(i) => i.span,
            Item::Script(i) => i.span,
        }
    }
}

/// `include "path.situ"`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Include {
    pub path: StrLit,
    pub span: Span,
}

/// `#[allow(W0301)]`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Attribute {
    /// The codes as written, without a `situ::` prefix.
    pub allow: Vec<Ident>,
    pub span: Span,
}

/// `states { ... }`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StatesBlock {
    pub states: Vec<StateDecl>,
    pub span: Span,
}

/// One system state.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StateDecl {
    pub name: Ident,
    /// The span of the `initial` flag, if present.
    pub initial: Option<Span>,
    /// The span of the `final` flag, if present.
    pub is_final: Option<Span>,
    pub description: Option<StrLit>,
    pub span: Span,
}

/// What an agent is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum AgentKind {
    Sensor,
    Actuator,
    Processing,
    Interface,
}

impl AgentKind {
    pub fn keyword(self) -> &'static str {
        match self {
            AgentKind::Sensor => "sensor",
            AgentKind::Actuator => "actuator",
            AgentKind::Processing => "processing",
            AgentKind::Interface => "interface",
        }
    }
}

/// `agent NAME KIND { ... }`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Agent {
    pub attributes: Vec<Attribute>,
    pub name: Ident,
    pub kind: AgentKind,
    pub kind_span: Span,
    pub description: Option<StrLit>,
    pub members: Vec<AgentMember>,
    pub span: Span,
}

/// A member of an agent body, in source order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum AgentMember {
    Stale(StaleDecl),
    Rate(RateDecl),
    Commands(CommandsDecl),
    Event(EventDecl),
    Function(FunctionDecl),
    Table(Table),
    Fsm(Fsm),
}

impl AgentMember {
    pub fn span(&self) -> Span {
        match self {
            AgentMember::Stale(m) => m.span,
            AgentMember::Rate(m) => m.span,
            AgentMember::Commands(m) => m.span,
            AgentMember::Event(m) => m.span,
            AgentMember::Function(m) => m.span,
            AgentMember::Table(m) => m.span,
            AgentMember::Fsm(m) => m.span,
        }
    }
}

/// `stale after 200ms`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StaleDecl {
    pub after: Duration,
    pub span: Span,
}

/// `rate 20Hz`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RateDecl {
    pub hertz: f64,
    pub span: Span,
}

/// `commands Vehicle, Arm`: the agents this one sends commands to.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CommandsDecl {
    pub targets: Vec<Ident>,
    pub span: Span,
}

/// `event LAOBS { distance: f64 } "description"`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventDecl {
    pub name: Ident,
    pub fields: Vec<FieldDecl>,
    pub description: Option<StrLit>,
    pub span: Span,
}

/// `distance: f64`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FieldDecl {
    pub name: Ident,
    pub ty: FieldType,
    pub ty_span: Span,
    pub span: Span,
}

/// The type of a payload field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum FieldType {
    F64,
    I64,
    Bool,
    /// One of these symbols.
    Symbols(Vec<Ident>),
}

/// `function plrs "straight road plan"`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FunctionDecl {
    pub name: Ident,
    pub description: Option<StrLit>,
    pub span: Span,
}

/// `table { ... }`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Table {
    pub entries: Vec<TableEntry>,
    pub span: Span,
}

/// `RO, CO => run fuse() from A to B`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableEntry {
    pub selector: Selector,
    pub action: Action,
    pub span: Span,
}

/// The states a table entry is for.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Selector {
    /// These states.
    States(Vec<Ident>),
    /// `_`: every state without an entry of its own.
    Wildcard(Span),
}

/// The mode of an agent in a system state.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Mode {
    Running,
    Waiting,
    Sleeping,
}

impl Mode {
    /// The verb used in tables and FSMs.
    pub fn verb(self) -> &'static str {
        match self {
            Mode::Running => "run",
            Mode::Waiting => "wait",
            Mode::Sleeping => "sleep",
        }
    }
    /// The adjective used in tests and properties.
    pub fn adjective(self) -> &'static str {
        match self {
            Mode::Running => "running",
            Mode::Waiting => "waiting",
            Mode::Sleeping => "sleeping",
        }
    }
}

/// `run fuse() from A, B to C`, `wait`, `sleep`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Action {
    pub mode: Mode,
    pub function: Option<Ident>,
    pub from: Vec<Ident>,
    pub to: Vec<Ident>,
    pub span: Span,
}

/// `fsm { ... }`: lines in source order.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Fsm {
    pub lines: Vec<FsmLine>,
    pub span: Span,
}

/// A line of an FSM.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum FsmLine {
    State(FsmState),
    Transition(FsmTransition),
}

impl FsmLine {
    pub fn span(&self) -> Span {
        match self {
            FsmLine::State(s) => s.span,
            FsmLine::Transition(t) => t.span,
        }
    }
}

/// `Following initial => run follow() from LPL`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FsmState {
    pub name: Ident,
    pub initial: Option<Span>,
    pub action: Action,
    pub span: Span,
}

/// `Following -> Braking on state == EM`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FsmTransition {
    pub from: Ident,
    pub to: Ident,
    pub trigger: Trigger,
    pub span: Span,
}

/// What fires an FSM transition.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Trigger {
    /// The system state passes this test.
    State(StateTest),
    /// The agent reports this event of its own.
    Event(Ident),
}

/// `rule NAME salience N { when ... then STATE }`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Rule {
    pub attributes: Vec<Attribute>,
    pub name: Ident,
    pub salience: Option<Salience>,
    pub description: Option<StrLit>,
    pub conditions: Vec<Condition>,
    pub target: Ident,
    pub span: Span,
}

/// `salience 10`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Salience {
    pub value: i64,
    pub span: Span,
}

/// One condition of a rule; a rule's conditions are joined by `and`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Condition {
    /// A test on the system state.
    State(StateTest),
    /// Some agent's latest event matches.
    Pattern(Pattern),
    /// No agent's latest event matches; the span covers `not`.
    Not { pattern: Pattern, span: Span },
    /// `stale AGENT` (or, `negated`, `not stale AGENT`).
    Stale { agent: Ident, negated: bool, span: Span },
}

impl Condition {
    pub fn span(&self) -> Span {
        match self {
            Condition::State(s) => s.span,
            Condition::Pattern(p) => p.span,
            Condition::Not { span, .. } | Condition::Stale { span, .. } => *span,
        }
    }
}

/// `state in {RD, RS}` and the like: whether the state is (not) one of these.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct StateTest {
    /// `!=` or `not in`.
    pub negated: bool,
    /// Written as a set `{...}` (rather than `==` / `!=`).
    pub set_syntax: bool,
    pub states: Vec<Ident>,
    pub span: Span,
}

/// `LAOBS(distance < 30.0) x3 within 500ms`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Pattern {
    pub event: Ident,
    pub constraints: Vec<Constraint>,
    pub run_length: Option<RunLength>,
    pub within: Option<Duration>,
    pub span: Span,
}

/// `x3`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RunLength {
    pub count: u64,
    pub span: Span,
}

/// A test on one payload field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Constraint {
    pub field: Ident,
    pub test: FieldTest,
    pub span: Span,
}

/// What is tested of a field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum FieldTest {
    /// `field: ?var`.
    Bind(Ident),
    /// `field OP operand`.
    Compare { op: CmpOp, op_span: Span, rhs: Operand },
    /// `field in lo..hi` or `lo..=hi`.
    Range { lo: Operand, hi: Operand, inclusive: bool },
}

/// A comparison operator.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum CmpOp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl CmpOp {
    pub fn symbol(self) -> &'static str {
        match self {
            CmpOp::Eq => "==",
            CmpOp::Ne => "!=",
            CmpOp::Lt => "<",
            CmpOp::Le => "<=",
            CmpOp::Gt => ">",
            CmpOp::Ge => ">=",
        }
    }
    /// Whether this operator needs an ordered type.
    pub fn is_ordering(self) -> bool {
        !matches!(self, CmpOp::Eq | CmpOp::Ne)
    }
}

/// A literal or a variable.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Operand {
    Literal(Literal),
    /// `?d`, without the `?`.
    Variable(Ident),
}

impl Operand {
    pub fn span(&self) -> Span {
        match self {
            Operand::Literal(l) => l.span,
            Operand::Variable(v) => v.span,
        }
    }
}

/// A literal value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Literal {
    pub value: LiteralValue,
    pub span: Span,
}

/// The value of a literal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum LiteralValue {
    Float(f64),
    Int(i64),
    Bool(bool),
    Symbol(String),
}

/// `test "name" { ... }`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Test {
    pub name: StrLit,
    pub clauses: Vec<TestClause>,
    pub span: Span,
}

/// A clause of a test.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum TestClause {
    Given { items: Vec<GivenItem>, span: Span },
    On { events: Vec<EventInstance>, span: Span },
    Expect { expectations: Vec<Expectation>, span: Span },
}

impl TestClause {
    pub fn span(&self) -> Span {
        match self {
            TestClause::Given { span, .. } | TestClause::On { span, .. } | TestClause::Expect { span, .. } => *span,
        }
    }
}

/// A fact that holds before a test's first event.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum GivenItem {
    /// `state RS`.
    State { state: Ident, span: Span },
    /// `LAOBN x3`: this event was the agent's latest report.
    Event(EventInstance),
}

/// `LAOBS(distance: 12.0) x2 at 1.5s`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct EventInstance {
    pub event: Ident,
    pub arguments: Vec<Argument>,
    pub repeat: Option<RunLength>,
    pub at: Option<Duration>,
    pub span: Span,
}

/// `distance: 12.0`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Argument {
    pub field: Ident,
    pub value: Literal,
    pub span: Span,
}

/// What a test expects after its latest `on`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Expectation {
    /// `state RO`.
    State { state: Ident, span: Span },
    /// `Fusion running`.
    Mode { agent: Ident, mode: Mode, span: Span },
    /// `LPL runs plro`.
    Runs { agent: Ident, function: Ident, span: Span },
    /// `link A -> B` (`present`) or `no link A -> B`.
    Link { from: Ident, to: Ident, present: bool, span: Span },
}

impl Expectation {
    pub fn span(&self) -> Span {
        match self {
            Expectation::State { span, .. }
            | Expectation::Mode { span, .. }
            | Expectation::Runs { span, .. }
            | Expectation::Link { span, .. } => *span,
        }
    }
}

/// `property "name" { always ... }`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Property {
    pub name: StrLit,
    pub quantifier: Quantifier,
    pub formula: Formula,
    pub span: Span,
}

/// `always` or `never`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub enum Quantifier {
    Always,
    Never,
}

/// The body of a property.
// One per property: the size of the variants does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Formula {
    /// A predicate that must hold (or never hold) after every event.
    Now(Predicate),
    /// `P -> Q`, `P -> next Q`, `P -> eventually Q within B`.
    Implies { premise: Predicate, consequent: Consequent, span: Span },
}

/// The right side of an implication.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Consequent {
    /// Q holds at the same point.
    Now(Predicate),
    /// Q holds after the next event.
    Next { predicate: Predicate, span: Span },
    /// Q holds at some point, within the bound if there is one.
    Eventually { predicate: Predicate, bound: Option<Bound>, span: Span },
}

/// A bound on `eventually`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Bound {
    Events { count: u64, span: Span },
    Time(Duration),
}

/// A predicate on the system at one point of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Predicate {
    Or(Vec<Predicate>, Span),
    And(Vec<Predicate>, Span),
    Not(Box<Predicate>, Span),
    Bool(bool, Span),
    State(StateTest),
    Mode {
        agent: Ident,
        mode: Mode,
        span: Span,
    },
    Link {
        from: Ident,
        to: Ident,
        span: Span,
    },
    /// `stale LADAR`.
    Stale {
        agent: Ident,
        span: Span,
    },
    /// The latest event of its agent matches.
    Event(Pattern),
}

impl Predicate {
    pub fn span(&self) -> Span {
        match self {
            Predicate::Or(_, s) | Predicate::And(_, s) | Predicate::Not(_, s) => *s,
            Predicate::Bool(_, s) => *s,
            Predicate::State(t) => t.span,
            Predicate::Mode { span, .. } | Predicate::Link { span, .. } | Predicate::Stale { span, .. } => *span,
            Predicate::Event(p) => p.span,
        }
    }
}

/// `script "name" { ... }`: a timeline of events for `situ run --script`.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Script {
    pub name: StrLit,
    pub steps: Vec<ScriptStep>,
    pub span: Span,
}

/// One step of a script.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum ScriptStep {
    /// `at 2.5s Bumper.BPHIT(side: left)`.
    At { time: Duration, event: ScriptEvent, span: Span },
    /// `every 100ms GPS.GPFIX(error: 0.3) from 0s to 60s`.
    Every { period: Duration, event: ScriptEvent, from: Duration, to: Duration, span: Span },
    /// `silent Rain from 10s to 12s`.
    Silent { agent: Ident, from: Duration, to: Duration, span: Span },
    /// `random 30s seed 7 [from 40s]`.
    Random { length: Duration, seed: u64, seed_span: Span, from: Option<Duration>, span: Span },
}

impl ScriptStep {
    pub fn span(&self) -> Span {
        match self {
            ScriptStep::At { span, .. }
            | ScriptStep::Every { span, .. }
            | ScriptStep::Silent { span, .. }
            | ScriptStep::Random { span, .. } => *span,
        }
    }
}

/// `Bumper.BPHIT(side: left)`: an event of a script, every field given.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ScriptEvent {
    /// The agent, when written (`Bumper.`).
    pub agent: Option<Ident>,
    pub event: Ident,
    pub arguments: Vec<Argument>,
    pub span: Span,
}

/// A file's AST as JSON with its places left out: every `span` and `*_span`
/// key dropped, every other span (as in `initial: Some(span)`) replaced by a
/// marker so that its presence still counts. Two texts that mean the same
/// have the same shape; the formatter's round trip and the layout tests
/// compare it.
pub fn shape(file: &File) -> serde_json::Value {
    let mut v = serde_json::to_value(file).expect("the AST serializes to JSON");
    strip_spans(&mut v);
    v
}

/// Whether a JSON value is a serialized `Span`.
fn is_span(v: &serde_json::Value) -> bool {
    use serde_json::Value;
    matches!(v, Value::Object(m) if m.len() == 2 && m.get("start").is_some_and(Value::is_u64) && m.get("end").is_some_and(Value::is_u64))
}

fn strip_spans(v: &mut serde_json::Value) {
    use serde_json::Value;
    if is_span(v) {
        *v = Value::String("<span>".into());
        return;
    }
    match v {
        Value::Object(m) => {
            m.retain(|k, _| k != "span" && !k.ends_with("_span"));
            m.values_mut().for_each(strip_spans);
        }
        Value::Array(a) => a.iter_mut().for_each(strip_spans),
        _ => {}
    }
}
