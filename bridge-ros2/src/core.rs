//! The bridge without DDS: the Bulletinboard, the organisation, the map's
//! translator and the lifecycle nodes' bookkeeping, driven by what arrives
//! (a message, an answer, the clock) and answering with what to send
//! ([`Output`]). The DDS shell ([`crate::dds`]) only carries bytes both
//! ways, so everything the bridge decides is tested here without a socket.
//!
//! Time is nanoseconds since the Unix epoch, as in the real-time stack.

use crate::msgs::{level, DiagnosticArray, DiagnosticStatus, Header, KeyValue, Time};
use crate::xcdr2;
use situ_compiler::bundle::{Content, Mode, Value};
use situ_compiler::model::Model;
use situ_grammar::diag::{Diagnostic, FileId};
use situ_ros2_map::lifecycle::{self, NodeState, Target, Transition};
use situ_ros2_map::map;
use situ_ros2_map::{Registry, Translator};
use situ_runtime::bulletinboard::Bulletinboard;
use situ_runtime::organise::Organisation;
use situ_runtime::rete::{PostError, StateChange};
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Duration;

/// How often the bridge's own status goes to `/diagnostics`, and the
/// problems of the messages with it (not one diagnostic per bad message:
/// a flood of them must not become a flood on `/diagnostics`).
pub const DIAGNOSTICS_EVERY: Duration = Duration::from_secs(1);

/// Something the DDS shell sends.
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    /// The state, on `/situ/state`.
    State(String),
    /// Every agent's mode, function and links, on `/situ/agents`.
    Agents(DiagnosticArray),
    /// On `/diagnostics`.
    Diagnostics(DiagnosticArray),
    /// A `change_state` request to node number `node` of the map.
    ChangeState { node: usize, transition: Transition },
    /// A `get_state` request to node number `node`.
    GetState { node: usize },
}

/// What the bridge counted since it started.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Counters {
    pub messages: u64,
    /// Messages that did not decode, or entries that could not be evaluated.
    pub refused: u64,
    pub events: u64,
    /// Events the Bulletinboard refused (out of order, from the future).
    pub rejected: u64,
    pub changes: u64,
    pub requests: u64,
    /// Transitions that failed or were not answered in time.
    pub failures: u64,
}

/// A lifecycle node of the map.
#[derive(Debug, Clone)]
pub struct Node {
    pub agent: u32,
    /// Its fully qualified name, `/planner`.
    pub name: String,
    pub failed_event: Option<u32>,
    pub timeout: Duration,
    pub state: NodeState,
    /// The target its last request failed for: not insisted on until the
    /// table asks for something else.
    held_for: Option<Target>,
    /// When its `get_state` request is due again (while its state is unknown).
    ask_at: u64,
}

/// The request the bridge waits an answer for (one `change_state` at a
/// time: that is what orders them).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct InFlight {
    node: usize,
    transition: Transition,
    deadline: u64,
}

/// Why a bridge cannot start on a rules file and a map.
#[derive(Debug)]
pub enum SetupError {
    /// The map's findings (errors only).
    Map(Vec<Diagnostic>),
}

pub struct Core {
    board: Bulletinboard,
    org: Organisation,
    translator: Translator,
    /// The message definitions the map is read with.
    msgs: Registry,
    nodes: Vec<Node>,
    /// Node number by agent id.
    node_of: BTreeMap<u32, usize>,
    in_flight: Option<InFlight>,
    /// The links between nodes of the situations left since the nodes
    /// were last where their tables want them.
    left: Vec<(usize, usize)>,
    counters: Counters,
    /// The last problem seen on each topic since the last diagnostics, and
    /// how many.
    problems: BTreeMap<String, (u64, String)>,
    next_diagnostics: u64,
}

impl Core {
    /// A bridge for the compiled rules `content` (whose checked `model` the
    /// map `map_text`, file `map_file`, is read against, its message types
    /// as `msgs` defines them).
    pub fn new(
        content: Arc<Content>,
        model: &Model,
        map_text: &str,
        msgs: &Registry,
        map_file: FileId,
    ) -> Result<Core, SetupError> {
        let parsed = map::parse(map_text, map_file).map_err(|d| SetupError::Map(vec![*d]))?;
        let translator = Translator::of(model, &parsed, msgs, map_file).map_err(SetupError::Map)?;
        let mut nodes = Vec::new();
        let mut node_of = BTreeMap::new();
        for n in &parsed.nodes {
            let Some(agent) = content.agent_id(&n.agent.value) else { continue };
            node_of.insert(agent, nodes.len());
            nodes.push(Node {
                agent,
                name: n.node.value.clone(),
                failed_event: n.failed.as_ref().and_then(|f| content.event_id(&f.value)),
                timeout: n.timeout().unwrap_or(map::DEFAULT_NODE_TIMEOUT),
                state: NodeState::Unknown,
                held_for: None,
                ask_at: 0,
            });
        }
        Ok(Core {
            board: Bulletinboard::new(content.clone()),
            org: Organisation::new(content),
            translator,
            msgs: msgs.clone(),
            nodes,
            node_of,
            in_flight: None,
            left: Vec::new(),
            counters: Counters::default(),
            problems: BTreeMap::new(),
            next_diagnostics: 0,
        })
    }

    /// The message definitions the map is read with.
    pub fn msgs(&self) -> &Registry {
        &self.msgs
    }

    pub fn content(&self) -> &Arc<Content> {
        self.board.content()
    }

    /// The map's warnings (W04xx): the bridge runs, and says them first.
    pub fn map_warnings(&self) -> &[Diagnostic] {
        self.translator.warnings()
    }

    /// The topics to subscribe to, with the full names of their types.
    pub fn topics(&self) -> Vec<(String, &'static str)> {
        self.translator.topics().map(|(t, ty)| (t.to_string(), ty)).collect()
    }

    pub fn nodes(&self) -> &[Node] {
        &self.nodes
    }

    pub fn state_name(&self) -> &str {
        self.board.state_name()
    }

    pub fn counters(&self) -> Counters {
        self.counters
    }

    /// The first outputs: the state at rest and the agents, and a
    /// `get_state` to every node.
    pub fn start(&mut self, now: u64) -> Vec<Output> {
        let mut out = Vec::new();
        self.board.set_clock(now);
        let change = self.board.settle();
        self.after(change, now, &mut out);
        self.org.set_state(self.board.state());
        self.org.on_state(self.board.state());
        out.push(Output::State(self.state_name().to_string()));
        out.push(self.agents(now));
        self.next_diagnostics = now;
        self.tick(now, &mut out);
        out
    }

    /// One message of `topic` (its CDR bytes, encapsulation header included)
    /// that arrived at `now`. XCDR2 is read into plain CDR first
    /// ([`crate::xcdr2`]).
    pub fn on_message(&mut self, topic: &str, cdr: &[u8], now: u64) -> Vec<Output> {
        let mut out = Vec::new();
        self.counters.messages += 1;
        let ty = self.translator.topics().find(|(t, _)| *t == topic).map(|(_, ty)| ty);
        let plain;
        let cdr = match ty {
            Some(ty) if xcdr2::is_xcdr2(cdr) => match xcdr2::to_xcdr1(&self.msgs, ty, cdr) {
                Ok(bytes) => {
                    plain = bytes;
                    &plain[..]
                }
                Err(e) => {
                    let short = ty.rsplit('/').next().unwrap_or(ty);
                    self.counters.refused += 1;
                    self.problem(topic, format!("{short}: XCDR2: {e}"));
                    return out;
                }
            },
            _ => cdr,
        };
        let outcome = self.translator.on_message(topic, cdr);
        if !outcome.problems.is_empty() {
            self.counters.refused += outcome.problems.len() as u64;
            for p in outcome.problems {
                let what = match &p.event {
                    Some(e) => format!("{e}: {}", p.message),
                    None => p.message,
                };
                self.problem(&p.topic, what);
            }
        }
        for e in outcome.produced {
            self.post(e.agent, e.event, &e.payload, now, &mut out);
        }
        out
    }

    /// A sample of `topic` that the middleware could not hand over (an
    /// encapsulation it does not name): counted as a message refused, its
    /// `reason` reported with the topic's problems.
    pub fn on_unreadable(&mut self, topic: &str, reason: &str) {
        self.counters.messages += 1;
        self.counters.refused += 1;
        self.problem(topic, reason.to_string());
    }

    /// One more problem of `topic`, the last one `what`.
    fn problem(&mut self, topic: &str, what: String) {
        let slot = self.problems.entry(topic.to_string()).or_insert((0, String::new()));
        slot.0 += 1;
        slot.1 = what;
    }

    /// The clock: staleness, the timeout of the request in flight, the
    /// `get_state` retries and the periodic diagnostics.
    pub fn on_tick(&mut self, now: u64) -> Vec<Output> {
        let mut out = Vec::new();
        self.tick(now, &mut out);
        out
    }

    /// The answer of node `node` to the `change_state` request in flight.
    pub fn on_change_state(&mut self, node: usize, success: bool, now: u64) -> Vec<Output> {
        let mut out = Vec::new();
        let Some(f) = self.in_flight.filter(|f| f.node == node) else { return out };
        self.in_flight = None;
        if success {
            self.nodes[node].state = f.transition.goal();
            out.push(self.agents(now));
        } else {
            let why = format!("{} refused to {}", self.nodes[node].name, f.transition.label());
            self.fail(node, why, now, &mut out);
        }
        self.drive(now, &mut out);
        out
    }

    /// The answer of node `node` to a `get_state` request.
    pub fn on_get_state(&mut self, node: usize, state_id: u8, now: u64) -> Vec<Output> {
        let mut out = Vec::new();
        let Some(n) = self.nodes.get_mut(node) else { return out };
        // While a change is in flight its answer tells the state.
        if self.in_flight.is_some_and(|f| f.node == node) || n.state != NodeState::Unknown {
            return out;
        }
        n.state = NodeState::from_id(state_id);
        if n.state == NodeState::Unknown {
            // A transition state: ask again soon.
            n.ask_at = now + n.timeout.as_nanos() as u64 / 4;
            return out;
        }
        out.push(self.agents(now));
        self.drive(now, &mut out);
        out
    }

    fn tick(&mut self, now: u64, out: &mut Vec<Output>) {
        let change = self.board.advance(now);
        self.after(change, now, out);
        if let Some(f) = self.in_flight.filter(|f| now >= f.deadline) {
            self.in_flight = None;
            let n = &self.nodes[f.node];
            let why = format!("{} did not answer {} within {:?}", n.name, f.transition.label(), n.timeout);
            self.nodes[f.node].state = NodeState::Unknown;
            self.fail(f.node, why, now, out);
        }
        for (i, n) in self.nodes.iter_mut().enumerate() {
            if n.state == NodeState::Unknown && now >= n.ask_at && self.in_flight.is_none_or(|f| f.node != i) {
                n.ask_at = now + n.timeout.as_nanos() as u64;
                out.push(Output::GetState { node: i });
            }
        }
        self.drive(now, out);
        if now >= self.next_diagnostics {
            self.next_diagnostics = now + DIAGNOSTICS_EVERY.as_nanos() as u64;
            out.push(self.diagnostics(now));
        }
    }

    fn post(&mut self, agent: u32, event: u32, payload: &[Value], now: u64, out: &mut Vec<Output>) {
        self.counters.events += 1;
        let moved = self.org.on_event(agent, event).is_some();
        let result = self.board.post_at(now, event, now, payload);
        if matches!(&result, Err(e) if !matches!(e, PostError::Cascade { .. })) {
            self.counters.rejected += 1;
        }
        let changed = self.after(result, now, out);
        if moved && !changed {
            out.push(self.agents(now));
            self.drive(now, out);
        }
    }

    /// Follows what a post or an advance gave; whether the state changed.
    fn after(&mut self, result: Result<Option<StateChange>, PostError>, now: u64, out: &mut Vec<Output>) -> bool {
        let to = match result {
            Ok(Some(c)) if c.changed() => c.to,
            Ok(_) => return false,
            Err(PostError::Cascade { .. }) if self.board.state() != self.org.state() => {
                let status = self.status(level::ERROR, "situ: rules", "a cascade of rules did not come to rest");
                out.push(self.array(now, vec![status]));
                self.board.state()
            }
            Err(e) => {
                let message = e.describe(self.board.content());
                let status = self.status(level::WARN, "situ: refused event", &message);
                out.push(self.array(now, vec![status]));
                return false;
            }
        };
        self.counters.changes += 1;
        let before = self.node_links();
        self.left.extend(before);
        self.left.sort_unstable();
        self.left.dedup();
        self.org.on_state(to);
        out.push(Output::State(self.state_name().to_string()));
        out.push(self.agents(now));
        self.drive(now, out);
        true
    }

    /// What every node's table wants now.
    fn target(&self, node: usize) -> Target {
        match self.org.mode(self.nodes[node].agent) {
            Mode::Running | Mode::Waiting => Target::Active,
            Mode::Sleeping => Target::Inactive,
        }
    }

    /// The links between nodes now, as node numbers.
    fn node_links(&self) -> Vec<(usize, usize)> {
        self.org
            .links()
            .into_iter()
            .filter_map(|(w, r)| Some((*self.node_of.get(&w)?, *self.node_of.get(&r)?)))
            .collect()
    }

    /// Sends the next request when none is in flight.
    fn drive(&mut self, now: u64, out: &mut Vec<Output>) {
        if self.in_flight.is_some() {
            return;
        }
        let planned: Vec<lifecycle::Node> = (0..self.nodes.len())
            .map(|i| {
                let target = self.target(i);
                let n = &mut self.nodes[i];
                if n.held_for.is_some_and(|t| t != target) {
                    n.held_for = None;
                }
                lifecycle::Node { state: n.state, target, held: n.held_for.is_some() }
            })
            .collect();
        let entered = self.node_links();
        match lifecycle::next_step(&planned, &self.left, &entered) {
            Some(step) => {
                let deadline = now + self.nodes[step.node].timeout.as_nanos() as u64;
                self.in_flight = Some(InFlight { node: step.node, transition: step.transition, deadline });
                self.counters.requests += 1;
                out.push(Output::ChangeState { node: step.node, transition: step.transition });
            }
            None => {
                if planned.iter().all(|n| n.state != NodeState::Unknown) {
                    self.left.clear();
                }
            }
        }
    }

    fn fail(&mut self, node: usize, why: String, now: u64, out: &mut Vec<Output>) {
        self.counters.failures += 1;
        let target = self.target(node);
        self.nodes[node].held_for = Some(target);
        let status = self.status(level::ERROR, &format!("situ: {}", self.nodes[node].name), &why);
        out.push(self.array(now, vec![status]));
        if let Some(ev) = self.nodes[node].failed_event {
            let agent = self.nodes[node].agent;
            self.post(agent, ev, &[], now, out);
        }
        out.push(self.agents(now));
    }

    fn status(&self, level: u8, name: &str, message: &str) -> DiagnosticStatus {
        DiagnosticStatus {
            level,
            name: name.to_string(),
            message: message.to_string(),
            hardware_id: "situ".to_string(),
            values: Vec::new(),
        }
    }

    fn array(&self, now: u64, status: Vec<DiagnosticStatus>) -> Output {
        Output::Diagnostics(DiagnosticArray { header: header(now), status })
    }

    /// The bridge's counters, and the problems of each topic since the last time.
    fn diagnostics(&mut self, now: u64) -> Output {
        let c = self.counters;
        let kv = |k: &str, v: u64| KeyValue { key: k.to_string(), value: v.to_string() };
        let mut bridge = self.status(level::OK, "situ: bridge", &format!("state {}", self.state_name()));
        bridge.values = vec![
            kv("messages", c.messages),
            kv("refused", c.refused),
            kv("events", c.events),
            kv("rejected events", c.rejected),
            kv("state changes", c.changes),
            kv("lifecycle requests", c.requests),
            kv("lifecycle failures", c.failures),
        ];
        let mut status = vec![bridge];
        for (topic, (count, last)) in std::mem::take(&mut self.problems) {
            let mut s = self.status(level::WARN, &format!("situ: {topic}"), &last);
            s.values = vec![kv("refused since last report", count)];
            status.push(s);
        }
        Output::Diagnostics(DiagnosticArray { header: header(now), status })
    }

    /// Every agent: its mode and function as the message, its links, and
    /// its node and that node's lifecycle state when it has one.
    fn agents(&self, now: u64) -> Output {
        let content = self.board.content();
        let links = self.org.links();
        let names =
            |ids: Vec<u32>| ids.iter().map(|&i| content.agents[i as usize].name.as_str()).collect::<Vec<_>>().join(",");
        let status = (0..content.agents.len() as u32)
            .map(|a| {
                let mode = self.org.mode(a);
                let function = self.org.function(a);
                let message = match function {
                    Some(f) => format!("{} {f}()", mode.adjective()),
                    None => mode.adjective().to_string(),
                };
                let kv = |k: &str, v: String| KeyValue { key: k.to_string(), value: v };
                let mut values = vec![
                    kv("mode", mode.adjective().to_string()),
                    kv("function", function.unwrap_or("").to_string()),
                    kv("reads", names(links.iter().filter(|l| l.1 == a).map(|l| l.0).collect())),
                    kv("sends", names(links.iter().filter(|l| l.0 == a).map(|l| l.1).collect())),
                ];
                let node = self.node_of.get(&a).map(|&n| &self.nodes[n]);
                if let Some(n) = node {
                    values.push(kv("lifecycle", n.state.label().to_string()));
                }
                DiagnosticStatus {
                    level: level::OK,
                    name: content.agents[a as usize].name.clone(),
                    message,
                    hardware_id: node.map_or(String::new(), |n| n.name.clone()),
                    values,
                }
            })
            .collect();
        Output::Agents(DiagnosticArray { header: header(now), status })
    }
}

fn header(now: u64) -> Header {
    Header { stamp: Time::from_nanos(now), frame_id: String::new() }
}

#[cfg(test)]
#[path = "core_tests.rs"]
mod tests;
