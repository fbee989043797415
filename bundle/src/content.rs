//! The bundle's content: the types of the format. They use their own small
//! enums rather than the AST's, so that the format changes only when
//! [`FORMAT_VERSION`] does. Every id is an index into a vector of
//! [`Content`].

use serde::{Deserialize, Serialize};

/// The version of the bundle format this compiler writes and reads.
/// Raise it on any change of the types of this module.
pub const FORMAT_VERSION: u32 = 1;

/// The value of the envelope's `format` field.
pub const FORMAT_NAME: &str = "situ-bundle";

/// The highest `rate` an agent may declare, in Hz (a period of 1 ms).
///
/// The Bulletinboard sees time in 10 ms heartbeats, the real-time
/// scheduler sleeps with the operating system's millisecond granularity,
/// and the boundary's per-agent event limit is derived from the rate: a
/// faster rate buys nothing but a flood licence and, in simulated time, a
/// run that takes longer than the time it simulates. (`docs/language.md`,
/// 5.3.)
pub const MAX_RATE_HZ: f64 = 1000.0;

/// The lowest `rate` an agent may declare, in Hz (a period of 1000 s).
/// Slower than that, an agent is better stepped on input (no `rate`); the
/// bound also keeps every period, in nanoseconds, far from overflow.
pub const MIN_RATE_HZ: f64 = 0.001;

/// Whether `hz` is a rate an agent may have: finite, within
/// [`MIN_RATE_HZ`]..=[`MAX_RATE_HZ`].
pub fn rate_in_range(hz: f64) -> bool {
    (MIN_RATE_HZ..=MAX_RATE_HZ).contains(&hz)
}

/// A checked, compiled program: states, agents, events, rules, the Rete
/// network and the wiring of every state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Content {
    /// The root source file it was built from, as named on the command line.
    pub source: String,
    pub states: Vec<StateDef>,
    /// The initial state (an index into `states`).
    pub initial: u32,
    pub agents: Vec<AgentDef>,
    pub events: Vec<EventDef>,
    /// In declaration order (the last tie-breaker of conflict resolution).
    pub rules: Vec<RuleDef>,
    pub network: Network,
    /// One per state, in the order of `states`.
    pub wiring: Vec<Wiring>,
}

impl Content {
    pub fn state_id(&self, name: &str) -> Option<u32> {
        self.states.iter().position(|s| s.name == name).map(|i| i as u32)
    }
    pub fn agent_id(&self, name: &str) -> Option<u32> {
        self.agents.iter().position(|a| a.name == name).map(|i| i as u32)
    }
    pub fn event_id(&self, name: &str) -> Option<u32> {
        self.events.iter().position(|e| e.name == name).map(|i| i as u32)
    }
}

/// A system state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StateDef {
    pub name: String,
    #[serde(rename = "final")]
    pub is_final: bool,
    pub description: Option<String>,
}

/// An agent.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AgentDef {
    pub name: String,
    pub kind: AgentKind,
    pub description: Option<String>,
    /// Nanoseconds without a report after which its fact expires.
    pub stale_after_ns: Option<u64>,
    pub rate_hz: Option<f64>,
    /// The events it reports (indexes into [`Content::events`]).
    pub events: Vec<u32>,
    pub functions: Vec<FunctionDef>,
    pub behaviour: Behaviour,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AgentKind {
    Sensor,
    Actuator,
    Processing,
    Interface,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FunctionDef {
    pub name: String,
    pub description: Option<String>,
}

/// What an agent does per system state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Behaviour {
    /// No table and no FSM: running in every state, no function, no links.
    Always,
    /// The action of every state (indexed like [`Content::states`]), the
    /// table already applied: `None` means the table has no entry (sleeping).
    Table {
        actions: Vec<Option<Action>>,
    },
    Fsm(Fsm),
}

/// An agent's mode, function and links.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Action {
    pub mode: Mode,
    /// An index into the agent's functions.
    pub function: Option<u32>,
    /// The agents it reads from.
    pub from: Vec<u32>,
    /// The agents it sends to.
    pub to: Vec<u32>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    Running,
    Waiting,
    Sleeping,
}

impl Mode {
    pub fn adjective(self) -> &'static str {
        match self {
            Mode::Running => "running",
            Mode::Waiting => "waiting",
            Mode::Sleeping => "sleeping",
        }
    }
}

/// An agent's finite state machine (language reference §10.6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Fsm {
    pub states: Vec<FsmState>,
    pub initial: u32,
    /// In source order: for each input, the first that matches fires.
    pub transitions: Vec<FsmTransition>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FsmState {
    pub name: String,
    pub action: Action,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FsmTransition {
    pub from: u32,
    pub to: u32,
    pub trigger: Trigger,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Trigger {
    /// The system state (at rest) becomes one of these.
    States(Vec<u32>),
    /// The agent reports this event.
    Event(u32),
}

/// An event and its payload schema.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EventDef {
    pub name: String,
    pub agent: u32,
    pub fields: Vec<FieldDef>,
    pub description: Option<String>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FieldDef {
    pub name: String,
    pub ty: FieldType,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldType {
    F64,
    I64,
    Bool,
    /// One of these symbols; a value is an index into the list.
    Symbols(Vec<String>),
}

impl FieldType {
    /// How the type is written in situ.
    pub fn describe(&self) -> String {
        match self {
            FieldType::F64 => "f64".into(),
            FieldType::I64 => "i64".into(),
            FieldType::Bool => "bool".into(),
            FieldType::Symbols(s) => format!("{{{}}}", s.join(", ")),
        }
    }
}

/// A payload value.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Value {
    /// In JSON, NaN and the infinities are `"NaN"`, `"inf"`, `"-inf"`.
    F64(#[serde(with = "crate::float")] f64),
    I64(i64),
    Bool(bool),
    /// An index into the symbols of the field's type.
    Symbol(u32),
}

/// A rule as the runtime reports it: what it does, and where it was written.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RuleDef {
    pub name: String,
    pub salience: i64,
    /// The number of tests, for conflict resolution (§10.4).
    pub specificity: u32,
    pub target: u32,
    pub description: Option<String>,
    /// The agents whose facts its positive patterns match (for recency and
    /// explanations), in the order of the patterns.
    pub matches: Vec<u32>,
    /// The agents it tests for staleness.
    pub stale: Vec<u32>,
    pub source: SourceRef,
}

/// A place in the source, with the text there.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SourceRef {
    pub file: String,
    /// 1-based, columns in characters.
    pub line: u32,
    pub column: u32,
    pub end_line: u32,
    pub end_column: u32,
    pub text: String,
}

impl std::fmt::Display for SourceRef {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

// ─── The Rete network ──────────────────────────────────────────────────────

/// A Rete network (Forgy 1982), for a working memory of one state fact and
/// at most one fact per agent (its latest event).
///
/// - **Alpha nodes** test one fact alone: the state fact against a set of
///   states, an agent's fact against an event name, constant payload tests,
///   a run length and a window, or an agent's staleness. Identical tests are
///   one node, shared by every rule that has them. Each has an alpha memory:
///   whether the one fact it can hold passes.
/// - **Beta nodes** form one chain per rule from the top: a *join* adds a
///   fact from its alpha memory to the parent's token when the join tests
///   (comparisons with variables bound in earlier facts) pass; a *negative*
///   node passes the parent's token only when no fact of its alpha memory
///   passes its join tests (`not P`, `not stale A`). Chains with identical
///   prefixes share them. Nodes are in topological order: a parent comes
///   before its children.
/// - **Terminal nodes** are the rules: a rule is activated when the token
///   of its last beta node exists.
///
/// Every rule's chain starts with a join on the state fact (its guard minus
/// its own target), so rules for other states cost nothing on an event, and
/// a state change re-activates the rules guarded on the state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Network {
    pub alpha: Vec<AlphaNode>,
    pub beta: Vec<BetaNode>,
    /// One per rule, in the order of [`Content::rules`].
    pub terminals: Vec<Terminal>,
    pub stats: NetworkStats,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum AlphaNode {
    /// The state fact is one of these states (sorted).
    State { states: Vec<u32> },
    /// The agent of `event` has a live fact of this event that passes the
    /// tests, was reported at least `min_run` times in a row, and, with a
    /// window, no longer than `within_ns` ago.
    Event { event: u32, tests: Vec<Test>, min_run: u64, within_ns: Option<u64> },
    /// The agent is stale.
    Stale { agent: u32 },
}

/// A test on one field of a fact.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Test {
    pub field: u32,
    pub check: Check,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Check {
    Compare {
        op: Cmp,
        rhs: Operand,
    },
    /// `lo <= x < hi`, or `<= hi` when inclusive.
    Range {
        lo: Operand,
        hi: Operand,
        inclusive: bool,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Cmp {
    Eq,
    Ne,
    Lt,
    Le,
    Gt,
    Ge,
}

impl Cmp {
    pub fn symbol(self) -> &'static str {
        match self {
            Cmp::Eq => "==",
            Cmp::Ne => "!=",
            Cmp::Lt => "<",
            Cmp::Le => "<=",
            Cmp::Gt => ">",
            Cmp::Ge => ">=",
        }
    }
}

/// The right side of a test.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Operand {
    Value(Value),
    /// Another field of the same fact (a variable bound in the same pattern).
    Own {
        field: u32,
    },
    /// A field of another agent's fact, matched earlier in the token (a
    /// variable bound in another pattern). Only in beta tests.
    Fact {
        agent: u32,
        field: u32,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BetaNode {
    /// `None`: a child of the top node (the empty token).
    pub parent: Option<u32>,
    pub kind: BetaKind,
    /// Its right input.
    pub alpha: u32,
    /// Tests between the right fact and the token's facts.
    pub tests: Vec<Test>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BetaKind {
    Join,
    Negative,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Terminal {
    pub rule: u32,
    /// The last beta node of the rule's chain.
    pub beta: u32,
}

/// What sharing saved: the nodes the rules would need one by one, and the
/// nodes of the network.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct NetworkStats {
    pub alpha_unshared: u32,
    pub alpha: u32,
    pub beta_unshared: u32,
    pub beta: u32,
    pub terminals: u32,
}

impl NetworkStats {
    pub fn nodes(&self) -> u32 {
        self.alpha + self.beta + self.terminals
    }
    pub fn saved(&self) -> u32 {
        (self.alpha_unshared + self.beta_unshared) - (self.alpha + self.beta)
    }
}

// ─── Wiring ────────────────────────────────────────────────────────────────

/// The wiring graph of one system state (§10.6): the union of the links of
/// the agents running in it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Wiring {
    pub state: u32,
    /// Links of agents whose action is fixed in this state (tables and
    /// agents without one), sorted.
    pub links: Vec<(u32, u32)>,
    /// Links that depend on an FSM agent's current FSM state.
    pub fsm_links: Vec<FsmLink>,
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FsmLink {
    pub from: u32,
    pub to: u32,
    /// Present when this agent …
    pub agent: u32,
    /// … is in this FSM state.
    pub fsm_state: u32,
}
