//! From a checked program to a bundle's [`Content`].

use super::*;
use crate::checks::behaviour::action_in;
use crate::model::{self, Model};
use crate::{rete, Checked};
use petgraph::graphmap::DiGraphMap;

/// The content of the bundle of a checked program. The program must have no
/// errors (the caller checks: a model with errors is incomplete).
pub fn build(checked: &Checked) -> Content {
    let model = &checked.model;
    let states = model
        .states
        .iter()
        .map(|s| StateDef { name: s.name.clone(), is_final: s.is_final, description: s.description.clone() })
        .collect();
    let agents = model.agents.iter().map(|a| agent(model, a)).collect();
    let events = model
        .events
        .iter()
        .map(|e| EventDef {
            name: e.name.clone(),
            agent: e.agent.0,
            fields: e.fields.iter().map(|f| FieldDef { name: f.name.clone(), ty: field_type(&f.ty) }).collect(),
            description: e.description.clone(),
        })
        .collect();
    let rules = model.rules.iter().map(|r| rule(checked, r)).collect();
    let source = checked.sources.iter().next().map(|(_, f)| f.name.clone()).unwrap_or_default();
    Content {
        source,
        states,
        initial: model.initial.map_or(0, |s| s.0),
        agents,
        events,
        rules,
        network: rete::build(model),
        wiring: wiring(model),
    }
}

fn agent(model: &Model, a: &model::Agent) -> AgentDef {
    let behaviour = match &a.behaviour {
        model::Behaviour::Always => Behaviour::Always,
        model::Behaviour::Table(_) => Behaviour::Table {
            actions: model.state_ids().map(|s| action_in(a, s, 0).map(|act| action(&act))).collect(),
        },
        model::Behaviour::Fsm(f) => Behaviour::Fsm(Fsm {
            states: f.states.iter().map(|s| FsmState { name: s.name.clone(), action: action(&s.action) }).collect(),
            initial: f.initial as u32,
            transitions: f
                .transitions
                .iter()
                .map(|t| FsmTransition {
                    from: t.from as u32,
                    to: t.to as u32,
                    trigger: match &t.trigger {
                        model::FsmTrigger::State(set) => Trigger::States(set.states.iter().map(|s| s.0).collect()),
                        model::FsmTrigger::Event(e) => Trigger::Event(e.0),
                    },
                })
                .collect(),
        }),
    };
    AgentDef {
        name: a.name.clone(),
        kind: match a.kind {
            model::AgentKind::Sensor => AgentKind::Sensor,
            model::AgentKind::Actuator => AgentKind::Actuator,
            model::AgentKind::Processing => AgentKind::Processing,
            model::AgentKind::Interface => AgentKind::Interface,
        },
        description: a.description.clone(),
        stale_after_ns: a.stale_after,
        rate_hz: a.rate_hz,
        events: a.events.iter().map(|e| e.0).collect(),
        functions: a
            .functions
            .iter()
            .map(|f| FunctionDef { name: f.name.clone(), description: f.description.clone() })
            .collect(),
        behaviour,
    }
}

fn action(a: &model::Action) -> Action {
    Action {
        mode: mode(a.mode),
        function: a.function.map(|f| f as u32),
        from: a.from.iter().map(|x| x.0).collect(),
        to: a.to.iter().map(|x| x.0).collect(),
    }
}

pub(crate) fn mode(m: situ_grammar::ast::Mode) -> Mode {
    match m {
        situ_grammar::ast::Mode::Running => Mode::Running,
        situ_grammar::ast::Mode::Waiting => Mode::Waiting,
        situ_grammar::ast::Mode::Sleeping => Mode::Sleeping,
    }
}

fn field_type(t: &model::Type) -> FieldType {
    match t {
        model::Type::F64 => FieldType::F64,
        model::Type::I64 => FieldType::I64,
        model::Type::Bool => FieldType::Bool,
        model::Type::Symbols(s) => FieldType::Symbols(s.clone()),
    }
}

fn rule(checked: &Checked, r: &model::Rule) -> RuleDef {
    let model = &checked.model;
    let file = checked.sources.get(r.item.file);
    let (line, column) = file.line_col(r.item.span.start);
    let (end_line, end_column) = file.line_col(r.item.span.end);
    RuleDef {
        name: r.name.clone(),
        salience: r.salience,
        specificity: r.specificity() as u32,
        target: r.target.0,
        description: r.description.clone(),
        matches: r.patterns.iter().map(|p| model.event(p.event).agent.0).collect(),
        stale: r.stale.iter().map(|s| s.agent.0).collect(),
        source: SourceRef {
            file: file.name.clone(),
            line: line as u32,
            column: column as u32,
            end_line: end_line as u32,
            end_column: end_column as u32,
            text: file.slice(r.item.span).to_string(),
        },
    }
}

/// The wiring graph of a state, built with petgraph: a link for every
/// `from`/`to` of an agent running there. An FSM agent's links depend on
/// its FSM state, so they are kept apart, with the FSM state that writes them.
pub fn wiring_graph(model: &Model, state: model::StateId) -> (DiGraphMap<u32, ()>, Vec<FsmLink>) {
    let mut graph = DiGraphMap::new();
    let mut fsm_links = Vec::new();
    for (i, a) in model.agents.iter().enumerate() {
        let id = model::AgentId(i as u32);
        graph.add_node(id.0);
        match &a.behaviour {
            model::Behaviour::Fsm(f) => {
                for (k, s) in f.states.iter().enumerate() {
                    if s.action.mode == situ_grammar::ast::Mode::Running {
                        for (from, to) in crate::checks::behaviour::links(id, &s.action) {
                            fsm_links.push(FsmLink { from: from.0, to: to.0, agent: id.0, fsm_state: k as u32 });
                        }
                    }
                }
            }
            _ => {
                if let Some(act) = action_in(a, state, 0).filter(|a| a.mode == situ_grammar::ast::Mode::Running) {
                    for (from, to) in crate::checks::behaviour::links(id, &act) {
                        graph.add_edge(from.0, to.0, ());
                    }
                }
            }
        }
    }
    (graph, fsm_links)
}

fn wiring(model: &Model) -> Vec<Wiring> {
    model
        .state_ids()
        .map(|s| {
            let (graph, fsm_links) = wiring_graph(model, s);
            let mut links: Vec<(u32, u32)> = graph.all_edges().map(|(a, b, _)| (a, b)).collect();
            links.sort_unstable();
            Wiring { state: s.0, links, fsm_links }
        })
        .collect()
}
