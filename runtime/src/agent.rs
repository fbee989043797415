//! The agent SDK: what an agent is to the runtime, what it sees in one step
//! of its running cycle, and how the functions a bundle names are bound to
//! implementations before anything runs.
//!
//! The running cycle of Zhang & Zhu (2005, §2): get the status from the
//! Bulletinboard → look the state up in the table or FSM → choose the
//! function and the mode → take the inputs of the links active in this
//! state → process → send the outputs along the active links → report
//! events to the Bulletinboard. The runtime does every step but "process":
//! [`Agent::step`] gets a [`Context`] with the status, the mode, the
//! function and the inputs, and leaves its outputs and events in it.

use situ_bundle::{Content, Mode, Value};
use std::any::Any;
use std::fmt;
use std::sync::Arc;

/// The body of a data message.
#[derive(Clone)]
pub enum Body {
    /// Any Rust value, for agents of one process (shared, never copied).
    Local(Arc<dyn Any + Send + Sync>),
    /// JSON, for agents anywhere: other processes, other languages.
    Json(Arc<serde_json::Value>),
}

impl Body {
    pub fn local<T: Any + Send + Sync>(value: T) -> Body {
        Body::Local(Arc::new(value))
    }

    pub fn json(value: serde_json::Value) -> Body {
        Body::Json(Arc::new(value))
    }

    /// The value, if it is a local one of type `T`.
    pub fn get<T: Any>(&self) -> Option<&T> {
        match self {
            Body::Local(v) => v.downcast_ref(),
            Body::Json(_) => None,
        }
    }

    /// The value as JSON, if it is JSON.
    pub fn as_json(&self) -> Option<&serde_json::Value> {
        match self {
            Body::Json(v) => Some(v),
            Body::Local(_) => None,
        }
    }

    /// An estimate of its size in bytes (JSON: the text; local: unknown, 0).
    pub fn size(&self) -> usize {
        match self {
            Body::Json(v) => v.to_string().len(),
            Body::Local(_) => 0,
        }
    }
}

impl fmt::Debug for Body {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Body::Local(_) => f.write_str("Body::Local(..)"),
            Body::Json(v) => write!(f, "Body::Json({v})"),
        }
    }
}

/// A data message, as an agent receives it.
#[derive(Debug, Clone)]
pub struct Datum {
    pub from: u32,
    pub time: u64,
    pub urgent: bool,
    pub body: Body,
}

/// What an agent leaves in its context: a datum to send.
#[derive(Debug, Clone)]
pub struct Outgoing {
    /// `None`: along every active link out of the agent.
    pub to: Option<u32>,
    pub urgent: bool,
    pub body: Body,
}

/// What an agent leaves in its context: an event to report.
#[derive(Debug, Clone)]
pub struct Report {
    pub event: u32,
    pub payload: Vec<Value>,
    pub urgent: bool,
}

/// Why a report or a send was not taken.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ContextError {
    /// No event of this name, or it is another agent's.
    NotMyEvent(String),
    /// No agent of this name.
    UnknownAgent(String),
}

impl fmt::Display for ContextError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ContextError::NotMyEvent(e) => write!(f, "`{e}` is not an event of this agent"),
            ContextError::UnknownAgent(a) => write!(f, "no agent `{a}`"),
        }
    }
}

impl std::error::Error for ContextError {}

/// What an agent sees and does in one step.
pub struct Context<'a> {
    pub(crate) content: &'a Content,
    pub(crate) agent: u32,
    pub(crate) now: u64,
    pub(crate) state: u32,
    pub(crate) mode: Mode,
    pub(crate) safe: bool,
    pub(crate) function: Option<&'a str>,
    pub(crate) inputs: &'a [Datum],
    pub(crate) receivers: &'a [u32],
    pub(crate) outputs: &'a mut Vec<Outgoing>,
    pub(crate) reports: &'a mut Vec<Report>,
}

impl<'a> Context<'a> {
    /// The time of this step (nanoseconds; simulated or wall clock).
    pub fn now(&self) -> u64 {
        self.now
    }

    /// The system state, as the last status broadcast said.
    pub fn state(&self) -> &'a str {
        &self.content.states[self.state as usize].name
    }

    /// Running or waiting (sleeping agents are not stepped).
    pub fn mode(&self) -> Mode {
        self.mode
    }

    /// Whether the stack is in safe mode (the Bulletinboard fell silent):
    /// the agent waits whatever its table says; an actuator should stop.
    pub fn safe_mode(&self) -> bool {
        self.safe
    }

    /// The function the table or FSM chose for this state.
    pub fn function(&self) -> Option<&'a str> {
        self.function
    }

    /// The data received on the active links since the previous step, in
    /// the order it arrived (urgent data first).
    pub fn inputs(&self) -> &'a [Datum] {
        self.inputs
    }

    /// The agents a datum sent now reaches: the links of the moment out of
    /// this agent (empty when it waits: its outputs are dropped).
    pub fn receivers(&self) -> &'a [u32] {
        self.receivers
    }

    /// The name of an agent (of a datum's sender, say).
    pub fn agent_name(&self, agent: u32) -> &'a str {
        self.content.agents.get(agent as usize).map_or("?", |a| a.name.as_str())
    }

    /// Sends a datum along every link out of this agent that is active now.
    /// A waiting agent's data is dropped by the runtime (and counted).
    pub fn send(&mut self, body: Body) {
        self.outputs.push(Outgoing { to: None, urgent: false, body });
    }

    /// Sends a datum to one agent, if a link to it is active now.
    pub fn send_to(&mut self, agent: &str, body: Body) -> Result<(), ContextError> {
        let to = self.content.agent_id(agent).ok_or_else(|| ContextError::UnknownAgent(agent.into()))?;
        self.outputs.push(Outgoing { to: Some(to), urgent: false, body });
        Ok(())
    }

    /// Sends a datum that overtakes the receivers' queues and wakes them.
    pub fn send_urgent(&mut self, body: Body) {
        self.outputs.push(Outgoing { to: None, urgent: true, body });
    }

    /// Reports one of this agent's events to the Bulletinboard.
    pub fn report(&mut self, event: &str, payload: &[Value]) -> Result<(), ContextError> {
        self.report_with(event, payload, false)
    }

    /// Reports an event that overtakes the Bulletinboard's queue.
    pub fn report_urgent(&mut self, event: &str, payload: &[Value]) -> Result<(), ContextError> {
        self.report_with(event, payload, true)
    }

    fn report_with(&mut self, event: &str, payload: &[Value], urgent: bool) -> Result<(), ContextError> {
        let id = self
            .content
            .event_id(event)
            .filter(|&e| self.content.events[e as usize].agent == self.agent)
            .ok_or_else(|| ContextError::NotMyEvent(event.into()))?;
        self.reports.push(Report { event: id, payload: payload.to_vec(), urgent });
        Ok(())
    }
}

/// An agent of the stack.
pub trait Agent: Send {
    /// Its name, as the rules call it.
    fn name(&self) -> &str;

    /// The functions it offers, by the names the rules use. An agent whose
    /// table or FSM names a function it does not offer is refused at start.
    fn functions(&self) -> Vec<String> {
        Vec::new()
    }

    /// One step of the running cycle.
    fn step(&mut self, cx: &mut Context<'_>);
}

/// Why the agents do not fit the bundle.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum BindError {
    /// Functions the bundle names that the registered agent does not offer:
    /// (agent, function).
    MissingFunctions(Vec<(String, String)>),
    /// Agents registered under names the bundle does not declare.
    UnknownAgents(Vec<String>),
    /// Two implementations for one agent.
    Duplicate(String),
    /// Agents of the bundle with no implementation (when all are required).
    Unimplemented(Vec<String>),
}

impl fmt::Display for BindError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BindError::MissingFunctions(m) => {
                let list: Vec<String> = m.iter().map(|(a, f)| format!("{a}.{f}")).collect();
                write!(f, "the bundle names functions no registered agent offers: {}", list.join(", "))
            }
            BindError::UnknownAgents(a) => write!(f, "agents the bundle does not declare: {}", a.join(", ")),
            BindError::Duplicate(a) => write!(f, "agent `{a}` is registered twice"),
            BindError::Unimplemented(a) => {
                write!(f, "agents of the bundle without an implementation: {}", a.join(", "))
            }
        }
    }
}

impl std::error::Error for BindError {}

/// Agent implementations indexed by the bundle's agent ids.
pub type Bound = Vec<Option<Box<dyn Agent>>>;

/// Binds implementations to the bundle's agents by name, and checks that
/// every function the bundle's tables and FSMs name for them is offered.
/// With `all`, every agent of the bundle must have an implementation.
pub fn bind(content: &Content, agents: Vec<Box<dyn Agent>>, all: bool) -> Result<Bound, BindError> {
    let mut bound: Bound = (0..content.agents.len()).map(|_| None).collect();
    let mut unknown = Vec::new();
    for agent in agents {
        match content.agent_id(agent.name()) {
            Some(id) if bound[id as usize].is_some() => return Err(BindError::Duplicate(agent.name().into())),
            Some(id) => bound[id as usize] = Some(agent),
            None => unknown.push(agent.name().to_string()),
        }
    }
    if !unknown.is_empty() {
        return Err(BindError::UnknownAgents(unknown));
    }
    let mut missing = Vec::new();
    let mut unimplemented = Vec::new();
    for (def, imp) in content.agents.iter().zip(&bound) {
        let Some(imp) = imp else {
            unimplemented.push(def.name.clone());
            continue;
        };
        let offered = imp.functions();
        for f in &def.functions {
            let named = named_functions(def).contains(&f.name.as_str());
            if named && !offered.contains(&f.name) {
                missing.push((def.name.clone(), f.name.clone()));
            }
        }
    }
    if !missing.is_empty() {
        return Err(BindError::MissingFunctions(missing));
    }
    if all && !unimplemented.is_empty() {
        return Err(BindError::Unimplemented(unimplemented));
    }
    Ok(bound)
}

/// The functions an agent's table or FSM names.
fn named_functions(a: &situ_bundle::AgentDef) -> Vec<&str> {
    use situ_bundle::Behaviour;
    let actions: Vec<&situ_bundle::Action> = match &a.behaviour {
        Behaviour::Always => Vec::new(),
        Behaviour::Table { actions } => actions.iter().flatten().collect(),
        Behaviour::Fsm(f) => f.states.iter().map(|s| &s.action).collect(),
    };
    actions.iter().filter_map(|act| act.function).map(|f| a.functions[f as usize].name.as_str()).collect()
}
