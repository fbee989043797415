//! Name resolution and type checking: from the parsed files to the [`Model`].
//!
//! The phases run in order, each one small and each reporting every finding
//! it has (none stops at the first):
//! 1. [`declare`]: states, agents, events, fields and functions get ids;
//!    duplicates and the initial state are checked.
//! 2. [`behaviour`]: every agent's table or FSM.
//! 3. [`rules`]: every rule's conditions, with payload types and variables.
//! 4. [`scenarios`]: tests and properties.
//! 5. [`allow`] (called by the pipeline after the static checks):
//!    `#[allow(...)]` attributes mark the findings they silence.

pub(crate) mod allow;
mod behaviour;
mod declare;
mod rules;
mod scenarios;
mod script;
mod types;

use crate::codes;
use crate::model::*;
use crate::suggest::suggest;
use situ_grammar::ast::{self, Span};
use situ_grammar::diag::{Diagnostic, FileId};
use std::collections::HashMap;

/// Resolves the parsed files of one compilation. The model is complete only
/// when no error was found; otherwise it holds what could be resolved.
pub fn resolve(files: &[(FileId, ast::File)]) -> (Model, Vec<Diagnostic>) {
    let mut cx = Cx::default();
    let root = files.last().map_or(FileId(0), |(id, _)| *id);
    declare::declare(&mut cx, files, root);
    for (file, item) in items(files) {
        match item {
            ast::Item::Agent(agent) => behaviour::agent(&mut cx, file, agent),
            ast::Item::Rule(rule) => rules::rule(&mut cx, file, rule),
            ast::Item::Test(test) => scenarios::test(&mut cx, file, test),
            ast::Item::Property(prop) => scenarios::property(&mut cx, file, prop),
            ast::Item::Script(s) => script::script(&mut cx, file, s),
            ast::Item::Include(_) | ast::Item::States(_) => {}
        }
    }
    (cx.model, cx.diags)
}

/// Every item of every file, in declaration order.
fn items(files: &[(FileId, ast::File)]) -> impl Iterator<Item = (FileId, &ast::Item)> {
    files.iter().flat_map(|(id, f)| f.items.iter().map(move |i| (*id, i)))
}

/// The resolution context: the model being built, the name tables, the findings.
#[derive(Default)]
struct Cx {
    model: Model,
    diags: Vec<Diagnostic>,
    states: HashMap<String, StateId>,
    agents: HashMap<String, AgentId>,
    events: HashMap<String, EventId>,
    rule_names: HashMap<String, Origin>,
    test_names: HashMap<String, Origin>,
    property_names: HashMap<String, Origin>,
    script_names: HashMap<String, Origin>,
}

impl Cx {
    fn origin(file: FileId, span: Span) -> Origin {
        Origin { file, span }
    }

    fn state(&mut self, file: FileId, name: &ast::Ident) -> Option<StateId> {
        let found = self.states.get(&name.name).copied();
        if found.is_none() {
            let mut d = Diagnostic::error(
                codes::UNDEFINED_STATE,
                format!("undefined state `{}`", name.name),
                file,
                name.span,
                "no state of this name",
            );
            if let Some(s) = suggest(&name.name, self.model.states.iter().map(|s| s.name.as_str())) {
                d = d.with_help(format!("a state with a similar name exists: `{s}`")).with_fix(
                    format!("change to `{s}`"),
                    file,
                    name.span,
                    s,
                );
            } else {
                d = d.with_help("declare it in the `states { ... }` block");
            }
            self.diags.push(d);
        }
        found
    }

    fn agent(&mut self, file: FileId, name: &ast::Ident) -> Option<AgentId> {
        let found = self.agents.get(&name.name).copied();
        if found.is_none() {
            let mut d = Diagnostic::error(
                codes::UNDEFINED_AGENT,
                format!("undefined agent `{}`", name.name),
                file,
                name.span,
                "no agent of this name",
            );
            if let Some(s) = suggest(&name.name, self.model.agents.iter().map(|a| a.name.as_str())) {
                d = d.with_help(format!("an agent with a similar name exists: `{s}`")).with_fix(
                    format!("change to `{s}`"),
                    file,
                    name.span,
                    s,
                );
            }
            self.diags.push(d);
        }
        found
    }

    fn event(&mut self, file: FileId, name: &ast::Ident) -> Option<EventId> {
        let found = self.events.get(&name.name).copied();
        if found.is_none() {
            let mut d = Diagnostic::error(
                codes::UNDEFINED_EVENT,
                format!("undefined event `{}`", name.name),
                file,
                name.span,
                "no agent reports an event of this name",
            );
            if let Some(s) = suggest(&name.name, self.model.events.iter().map(|e| e.name.as_str())) {
                d = d.with_help(format!("an event with a similar name exists: `{s}`")).with_fix(
                    format!("change to `{s}`"),
                    file,
                    name.span,
                    s,
                );
            } else {
                d = d.with_help("declare it in the agent that reports it: `event NAME { ... }`");
            }
            self.diags.push(d);
        }
        found
    }

    /// A function of `agent`, by name.
    fn function(&mut self, file: FileId, agent: AgentId, name: &ast::Ident) -> Option<FunctionRef> {
        let a = &self.model.agents[agent.index()];
        let found = a.functions.iter().position(|f| f.name == name.name);
        if found.is_none() {
            let agent_name = a.name.clone();
            let mut d = Diagnostic::error(
                codes::UNDEFINED_FUNCTION,
                format!("agent `{agent_name}` has no function `{}`", name.name),
                file,
                name.span,
                "not a function of this agent",
            );
            d = match suggest(&name.name, a.functions.iter().map(|f| f.name.as_str())) {
                Some(s) => {
                    d.with_help(format!("did you mean `{s}`?")).with_fix(format!("change to `{s}`"), file, name.span, s)
                }
                None => d.with_help(format!("declare it in agent `{agent_name}`: `function {}`", name.name)),
            };
            self.diags.push(d);
        }
        found
    }

    /// A field of `event`, by name.
    fn field(&mut self, file: FileId, event: EventId, name: &ast::Ident) -> Option<usize> {
        let e = &self.model.events[event.index()];
        let found = e.field(&name.name);
        if found.is_none() {
            let fields: Vec<&str> = e.fields.iter().map(|f| f.name.as_str()).collect();
            let help = if fields.is_empty() {
                format!("`{}` has no payload", e.name)
            } else {
                format!("the fields of `{}` are: {}", e.name, fields.join(", "))
            };
            let mut d = Diagnostic::error(
                codes::UNDEFINED_FIELD,
                format!("event `{}` has no field `{}`", e.name, name.name),
                file,
                name.span,
                "no such field",
            )
            .with_help(help);
            if let Some(s) = suggest(&name.name, fields.iter().copied()) {
                d = d.with_fix(format!("change to `{s}`"), file, name.span, s);
            }
            self.diags.push(d);
        }
        found
    }

    /// A state test as a set of allowed states.
    fn state_set(&mut self, file: FileId, test: &ast::StateTest) -> StateSet {
        let named: std::collections::BTreeSet<StateId> =
            test.states.iter().filter_map(|s| self.state(file, s)).collect();
        let states = if test.negated { self.model.state_ids().filter(|s| !named.contains(s)).collect() } else { named };
        StateSet { states, origin: Cx::origin(file, test.span) }
    }

    /// A count that must be positive.
    fn positive(&mut self, file: FileId, value: u64, span: Span, what: &str) -> bool {
        if value == 0 {
            // Durations and rates are told what to write; counts, the least count.
            let help = match what {
                "a window" => "a window says how recent the event must be: write a positive duration, such as `within 500ms`, or leave the window out",
                "a stale time" => "write a positive duration, such as `stale after 300ms`, or leave `stale after` out",
                "a time bound" => "write a positive duration, such as `within 2s`",
                "a period" => "write a positive period, such as `every 100ms`",
                "a random section's length" => "write a positive length, such as `random 30s`",
                "a rate" => "write a positive frequency, such as `rate 10Hz`, or leave `rate` out",
                _ => "use at least 1 (or leave it out)",
            };
            self.diags.push(
                Diagnostic::error(codes::ZERO, format!("{what} must be positive"), file, span, "zero").with_help(help),
            );
        }
        value > 0
    }

    fn duplicate(&mut self, what: &str, name: &str, file: FileId, span: Span, first: Origin) {
        self.diags.push(
            Diagnostic::error(
                codes::DUPLICATE,
                format!("{what} `{name}` is defined twice"),
                file,
                span,
                "defined again here",
            )
            .with_label(first.file, first.span, "first defined here")
            .with_help("rename one of them or remove the duplicate"),
        );
    }
}
