//! The rules a map is read against, from a bundle: a bundle has no source,
//! but it has what the map needs — the agents, their events and the events'
//! fields. [`model_of`] builds that part of a [`Model`]; every place in it is
//! the start of `file` (a finding's label on the rules then names the bundle).

use situ_compiler::bundle::{self, Content, FieldType};
use situ_compiler::model::{Agent, AgentId, AgentKind, Behaviour, Event, EventId, Field, Model, Origin, Type};
use situ_grammar::ast::Span;
use situ_grammar::diag::FileId;

fn kind(k: bundle::AgentKind) -> AgentKind {
    match k {
        bundle::AgentKind::Sensor => AgentKind::Sensor,
        bundle::AgentKind::Actuator => AgentKind::Actuator,
        bundle::AgentKind::Processing => AgentKind::Processing,
        bundle::AgentKind::Interface => AgentKind::Interface,
    }
}

fn ty(t: &FieldType) -> Type {
    match t {
        FieldType::F64 => Type::F64,
        FieldType::I64 => Type::I64,
        FieldType::Bool => Type::Bool,
        FieldType::Symbols(s) => Type::Symbols(s.clone()),
    }
}

/// The agents and events of `content`, as a [`Model`] with nothing else.
pub fn model_of(content: &Content, file: FileId) -> Model {
    let origin = Origin { file, span: Span::new(0, 0) };
    let agents = content
        .agents
        .iter()
        .map(|a| Agent {
            name: a.name.clone(),
            kind: kind(a.kind),
            description: a.description.clone(),
            stale_after: a.stale_after_ns,
            rate_hz: a.rate_hz,
            commands: Vec::new(),
            events: a.events.iter().map(|&e| EventId(e)).collect(),
            functions: Vec::new(),
            behaviour: Behaviour::Always,
            origin,
        })
        .collect();
    let events = content
        .events
        .iter()
        .map(|e| Event {
            name: e.name.clone(),
            agent: AgentId(e.agent),
            fields: e.fields.iter().map(|f| Field { name: f.name.clone(), ty: ty(&f.ty), origin }).collect(),
            description: e.description.clone(),
            origin,
        })
        .collect();
    Model { agents, events, ..Model::default() }
}

#[cfg(test)]
mod tests {
    use super::*;
    use situ_compiler::check_source;

    #[test]
    fn a_map_reads_the_same_against_a_bundle_as_against_its_source() {
        let rules = include_str!("../../tests/ros2/amr.situ");
        let map = include_str!("../../tests/ros2/amr.toml");
        let checked = check_source("amr.situ", rules);
        let content = bundle::build(&checked);
        let skeleton = model_of(&content, FileId(0));
        assert!(crate::check_map(&skeleton, map, &crate::Registry::carried(), FileId(1)).is_empty());
        // A mistake is found the same way.
        let bad = map.replace("pose.position.x", "pose.position.q");
        let codes = |m: &Model| {
            crate::check_map(m, &bad, &crate::Registry::carried(), FileId(1))
                .into_iter()
                .map(|d| d.code)
                .collect::<Vec<_>>()
        };
        assert_eq!(codes(&skeleton), codes(&checked.model));
        assert!(!codes(&skeleton).is_empty());
    }
}
