//! The checked model: what a situ program means once every name is resolved
//! and every literal is typed. Later phases (static checks, the Rete network,
//! the bundle) start from here and never look at the AST again.
//!
//! Ids are indices into the vectors of [`Model`]. Every element keeps its
//! [`Origin`] so that any finding or runtime explanation can point at source.

use serde::Serialize;
use situ_grammar::ast::{CmpOp, Mode, Span};
use situ_grammar::diag::FileId;
use std::collections::BTreeSet;

/// Where something was written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
pub struct Origin {
    pub file: FileId,
    pub span: Span,
}

macro_rules! id {
    ($($(#[$m:meta])* $name:ident),*) => {$(
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize)]
        pub struct $name(pub u32);
        impl $name {
            pub fn index(self) -> usize { self.0 as usize }
        }
    )*};
}

id! {
    /// A system state.
    StateId,
    /// An agent.
    AgentId,
    /// An event (names are global, so an event belongs to one agent).
    EventId,
    /// A situation rule.
    RuleId
}

/// A whole checked program.
#[derive(Debug, Clone, Default, Serialize)]
pub struct Model {
    pub states: Vec<State>,
    /// The one initial state.
    pub initial: Option<StateId>,
    pub agents: Vec<Agent>,
    pub events: Vec<Event>,
    /// Rules in declaration order (the last tie-breaker of conflict resolution).
    pub rules: Vec<Rule>,
    pub tests: Vec<Test>,
    pub properties: Vec<Property>,
    /// `script` blocks, for `situ run --script`.
    pub scripts: Vec<Script>,
}

impl Model {
    pub fn state(&self, id: StateId) -> &State {
        &self.states[id.index()]
    }
    pub fn agent(&self, id: AgentId) -> &Agent {
        &self.agents[id.index()]
    }
    pub fn event(&self, id: EventId) -> &Event {
        &self.events[id.index()]
    }
    pub fn state_id(&self, name: &str) -> Option<StateId> {
        self.states.iter().position(|s| s.name == name).map(|i| StateId(i as u32))
    }
    pub fn agent_id(&self, name: &str) -> Option<AgentId> {
        self.agents.iter().position(|a| a.name == name).map(|i| AgentId(i as u32))
    }
    pub fn event_id(&self, name: &str) -> Option<EventId> {
        self.events.iter().position(|e| e.name == name).map(|i| EventId(i as u32))
    }
    /// Every state id, in declaration order.
    pub fn state_ids(&self) -> impl Iterator<Item = StateId> {
        (0..self.states.len() as u32).map(StateId)
    }
}

/// A system state.
#[derive(Debug, Clone, Serialize)]
pub struct State {
    pub name: String,
    pub is_final: bool,
    pub description: Option<String>,
    pub origin: Origin,
}

pub use situ_grammar::ast::AgentKind;

/// An agent of the stack.
#[derive(Debug, Clone, Serialize)]
pub struct Agent {
    pub name: String,
    pub kind: AgentKind,
    pub description: Option<String>,
    /// With no report for this long (nanoseconds), the agent's fact expires.
    pub stale_after: Option<u64>,
    /// How often the runtime steps the agent.
    pub rate_hz: Option<f64>,
    /// The agents it sends commands to (`commands X`), with where each is named.
    pub commands: Vec<(AgentId, Origin)>,
    /// The events it reports.
    pub events: Vec<EventId>,
    /// The functions it offers; [`FunctionRef`] indexes this.
    pub functions: Vec<Function>,
    pub behaviour: Behaviour,
    pub origin: Origin,
}

/// A function an agent offers.
#[derive(Debug, Clone, Serialize)]
pub struct Function {
    pub name: String,
    pub description: Option<String>,
    pub origin: Origin,
}

/// An index into the functions of the agent that owns the action.
pub type FunctionRef = usize;

/// An event an agent reports.
#[derive(Debug, Clone, Serialize)]
pub struct Event {
    pub name: String,
    pub agent: AgentId,
    pub fields: Vec<Field>,
    pub description: Option<String>,
    pub origin: Origin,
}

impl Event {
    pub fn field(&self, name: &str) -> Option<usize> {
        self.fields.iter().position(|f| f.name == name)
    }
}

/// A payload field.
#[derive(Debug, Clone, Serialize)]
pub struct Field {
    pub name: String,
    pub ty: Type,
    pub origin: Origin,
}

/// The type of a payload field.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum Type {
    F64,
    I64,
    Bool,
    /// One of these symbols; a value is an index into the list.
    Symbols(Vec<String>),
}

impl Type {
    /// How the type is written.
    pub fn describe(&self) -> String {
        match self {
            Type::F64 => "f64".into(),
            Type::I64 => "i64".into(),
            Type::Bool => "bool".into(),
            Type::Symbols(s) => format!("{{{}}}", s.join(", ")),
        }
    }
    pub fn is_numeric(&self) -> bool {
        matches!(self, Type::F64 | Type::I64)
    }
    /// Whether values of the two types can be compared with each other.
    pub fn comparable(&self, other: &Type) -> bool {
        (self.is_numeric() && other.is_numeric()) || self == other
    }
}

/// A typed value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Value {
    F64(f64),
    I64(i64),
    Bool(bool),
    /// An index into the symbols of the field's type.
    Symbol(u32),
}

/// What an agent does, per system state.
#[derive(Debug, Clone, Serialize)]
pub enum Behaviour {
    /// No table and no FSM: running in every state, no function, no links.
    Always,
    Table(Table),
    Fsm(Fsm),
}

/// A look-up table: entries in source order.
#[derive(Debug, Clone, Serialize)]
pub struct Table {
    pub entries: Vec<TableEntry>,
    pub origin: Origin,
}

/// One line of a table.
#[derive(Debug, Clone, Serialize)]
pub struct TableEntry {
    /// The states it names; `None` for `_`.
    pub states: Option<Vec<StateId>>,
    pub action: Action,
    pub origin: Origin,
}

/// A mode, a function and links.
#[derive(Debug, Clone, Serialize)]
pub struct Action {
    pub mode: Mode,
    pub function: Option<FunctionRef>,
    /// The agents it reads from.
    pub from: Vec<AgentId>,
    /// The agents it sends to.
    pub to: Vec<AgentId>,
    pub origin: Origin,
}

impl Action {
    /// An agent with no table: running, no function, no links.
    pub fn always(origin: Origin) -> Self {
        Action { mode: Mode::Running, function: None, from: Vec::new(), to: Vec::new(), origin }
    }
}

/// An agent's finite state machine.
#[derive(Debug, Clone, Serialize)]
pub struct Fsm {
    pub states: Vec<FsmState>,
    /// An index into `states`.
    pub initial: usize,
    /// In source order: the first that matches an input fires.
    pub transitions: Vec<FsmTransition>,
    pub origin: Origin,
}

/// A state of an agent's FSM and what the agent does in it.
#[derive(Debug, Clone, Serialize)]
pub struct FsmState {
    pub name: String,
    pub action: Action,
    pub origin: Origin,
}

/// `A -> B on TRIGGER`.
#[derive(Debug, Clone, Serialize)]
pub struct FsmTransition {
    pub from: usize,
    pub to: usize,
    pub trigger: FsmTrigger,
    pub origin: Origin,
}

/// What fires an FSM transition.
#[derive(Debug, Clone, Serialize)]
pub enum FsmTrigger {
    /// The system state becomes one of these.
    State(StateSet),
    /// The agent reports this event.
    Event(EventId),
}

/// A set of system states, as a guard allows them.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct StateSet {
    pub states: BTreeSet<StateId>,
    pub origin: Origin,
}

/// A situation rule.
#[derive(Debug, Clone, Serialize)]
pub struct Rule {
    pub name: String,
    pub salience: i64,
    pub description: Option<String>,
    /// State guards; the rule applies in their intersection.
    pub guards: Vec<StateSet>,
    /// Events that must be their agent's latest.
    pub patterns: Vec<Pattern>,
    /// `not P`: no agent's latest event matches.
    pub negations: Vec<Pattern>,
    pub stale: Vec<StaleTest>,
    /// The variables of the rule; [`VarId`] indexes this.
    pub variables: Vec<Variable>,
    pub target: StateId,
    /// The rule's name.
    pub origin: Origin,
    /// The whole rule, from its attributes to its closing brace.
    pub item: Origin,
}

impl Rule {
    /// The states in which the rule can fire (`None`: every state).
    pub fn allowed_states(&self) -> Option<BTreeSet<StateId>> {
        let mut sets = self.guards.iter().map(|g| &g.states);
        let first = sets.next()?.clone();
        Some(sets.fold(first, |acc, s| acc.intersection(s).copied().collect()))
    }

    /// The number of tests of the rule, for conflict resolution by specificity.
    pub fn specificity(&self) -> usize {
        let pattern_tests =
            |p: &Pattern| 1 + p.tests.len() + usize::from(p.run_length > 1) + usize::from(p.within.is_some());
        self.guards.len()
            + self.stale.len()
            + self.patterns.iter().map(pattern_tests).sum::<usize>()
            + self.negations.iter().map(pattern_tests).sum::<usize>()
    }
}

/// `stale A` / `not stale A`.
#[derive(Debug, Clone, Serialize)]
pub struct StaleTest {
    pub agent: AgentId,
    pub negated: bool,
    pub origin: Origin,
}

/// An index into [`Rule::variables`].
pub type VarId = usize;

/// A variable of a rule.
#[derive(Debug, Clone, Serialize)]
pub struct Variable {
    pub name: String,
    pub ty: Type,
    /// Where it is first bound.
    pub origin: Origin,
}

/// A test on the latest event of one agent.
#[derive(Debug, Clone, Serialize)]
pub struct Pattern {
    pub event: EventId,
    pub tests: Vec<FieldTest>,
    /// At least this many reports in a row (1 when not written).
    pub run_length: u64,
    /// Reported no longer ago than this (nanoseconds).
    pub within: Option<u64>,
    pub origin: Origin,
}

/// A test on one payload field.
#[derive(Debug, Clone, Serialize)]
pub struct FieldTest {
    /// An index into the event's fields.
    pub field: usize,
    pub check: FieldCheck,
    pub origin: Origin,
}

/// What is tested of a field.
#[derive(Debug, Clone, Serialize)]
pub enum FieldCheck {
    /// The binding site of a variable: tests nothing, gives the variable the
    /// field's value. A variable has one binding site, in a positive
    /// pattern (or, for a variable local to a `not` pattern, in that
    /// pattern); every other `field: ?v` is a `Compare` with `==`.
    Bind(VarId),
    Compare {
        op: CmpOp,
        rhs: Operand,
    },
    /// `lo..hi` (`inclusive`: `lo..=hi`).
    Range {
        lo: Operand,
        hi: Operand,
        inclusive: bool,
    },
}

/// A value or a variable.
#[derive(Debug, Clone, Copy, Serialize)]
pub enum Operand {
    Value(Value),
    Var(VarId),
}

/// A `test` block.
#[derive(Debug, Clone, Serialize)]
pub struct Test {
    pub name: String,
    pub steps: Vec<TestStep>,
    pub origin: Origin,
}

/// One clause of a test, in order.
#[derive(Debug, Clone, Serialize)]
pub enum TestStep {
    /// Sets the state (if given) and agent facts without firing rules.
    Given { state: Option<StateId>, facts: Vec<EventFact>, origin: Origin },
    /// Posts events in order.
    On { events: Vec<EventFact>, origin: Origin },
    /// Checks the system.
    Expect { expectations: Vec<Expectation>, origin: Origin },
}

/// A concrete event of a test.
#[derive(Debug, Clone, Serialize)]
pub struct EventFact {
    pub event: EventId,
    /// One value per field of the event, in declaration order.
    pub payload: Vec<Value>,
    /// How many times it is posted (1 when not written).
    pub repeat: u64,
    /// Its timestamp (nanoseconds) if written.
    pub at: Option<u64>,
    pub origin: Origin,
}

/// What a test expects.
#[derive(Debug, Clone, Serialize)]
pub enum Expectation {
    State { state: StateId, origin: Origin },
    Mode { agent: AgentId, mode: Mode, origin: Origin },
    Runs { agent: AgentId, function: FunctionRef, origin: Origin },
    Link { from: AgentId, to: AgentId, present: bool, origin: Origin },
}

/// A `property` block.
#[derive(Debug, Clone, Serialize)]
pub struct Property {
    pub name: String,
    pub quantifier: situ_grammar::ast::Quantifier,
    pub formula: Formula,
    pub origin: Origin,
}

/// The body of a property.
#[derive(Debug, Clone, Serialize)]
pub enum Formula {
    Now(Pred),
    Implies { premise: Pred, consequent: Consequent },
}

/// The right side of an implication.
#[derive(Debug, Clone, Serialize)]
pub enum Consequent {
    Now(Pred),
    Next(Pred),
    Eventually { pred: Pred, bound: Option<Bound> },
}

/// A bound on `eventually`.
#[derive(Debug, Clone, Copy, Serialize)]
pub enum Bound {
    Events(u64),
    Nanos(u64),
}

/// A predicate on the system at one point of a run.
#[derive(Debug, Clone, Serialize)]
pub enum Pred {
    Or(Vec<Pred>),
    And(Vec<Pred>),
    Not(Box<Pred>),
    Bool(bool),
    /// The state is one of these.
    State(StateSet),
    Mode {
        agent: AgentId,
        mode: Mode,
    },
    Link {
        from: AgentId,
        to: AgentId,
    },
    Stale(AgentId),
    /// The latest event of its agent matches; `variables` are local to it.
    Event {
        pattern: Pattern,
        variables: Vec<Variable>,
    },
}

/// A `script` block: a timeline of events (`situ run --script`).
#[derive(Debug, Clone, Serialize)]
pub struct Script {
    pub name: String,
    /// In the order written, which is the order of their start times.
    pub steps: Vec<ScriptStep>,
    pub origin: Origin,
    /// When the last step ends (nanoseconds).
    pub end: u64,
}

/// One step of a script; times in nanoseconds from the start of the run.
#[derive(Debug, Clone, Serialize)]
pub enum ScriptStep {
    /// One event at `time`.
    At { time: u64, event: ScriptEvent, origin: Origin },
    /// The event at `from`, `from + period`, … while before `to`.
    Every { period: u64, from: u64, to: u64, event: ScriptEvent, origin: Origin },
    /// The agent reports nothing in `[from, to)`.
    Silent { agent: AgentId, from: u64, to: u64, origin: Origin },
    /// The guided generator drives every agent in `[from, from + length)`.
    Random { from: u64, length: u64, seed: u64, origin: Origin },
}

/// A concrete event of a script: every field given.
#[derive(Debug, Clone, Serialize)]
pub struct ScriptEvent {
    pub event: EventId,
    pub payload: Vec<Value>,
    pub origin: Origin,
}
