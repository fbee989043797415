//! The sim's events as the bundle types them: the name and the payload of a
//! [`crate::sensors::Event`] become the `Value`s of the rules file's event,
//! field by field in its declared order, symbols by their index.

use crate::sensors::{Event, Value as SimValue};
use situ_compiler::bundle::{Content, FieldType, Value};
use situ_runtime::agent::Context;

/// The payload of `event` as the bundle declares it; `None` when the
/// bundle has no such event, or a field is missing or of another type.
pub fn payload(content: &Content, event: &dyn Event) -> Option<Vec<Value>> {
    let id = content.event_id(event.name())?;
    let def = &content.events[id as usize];
    let fields = event.fields();
    def.fields
        .iter()
        .map(|f| {
            let (_, v) = fields.iter().find(|(n, _)| *n == f.name)?;
            match (&f.ty, v) {
                (FieldType::F64, SimValue::F64(x)) => Some(Value::F64(*x)),
                (FieldType::I64, SimValue::I64(x)) => Some(Value::I64(*x)),
                (FieldType::Symbols(names), SimValue::Symbol(s)) => {
                    names.iter().position(|n| n == s).map(|i| Value::Symbol(i as u32))
                }
                _ => None,
            }
        })
        .collect()
}

/// Reports `event` to the Bulletinboard; returns whether the bundle knows
/// it (an event the rules do not declare is not sent).
pub fn report(cx: &mut Context<'_>, content: &Content, event: &dyn Event) -> bool {
    match payload(content, event) {
        Some(p) => cx.report(event.name(), &p).is_ok(),
        None => false,
    }
}

/// An event with a name and no payload (the heartbeat `TCHB`, `SVRDY`, …).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Plain(pub &'static str);

impl Event for Plain {
    fn name(&self) -> &'static str {
        self.0
    }
    fn fields(&self) -> Vec<(&'static str, SimValue)> {
        Vec::new()
    }
}

/// An event with a name and payload given in place.
#[derive(Debug, Clone, PartialEq)]
pub struct Named(pub &'static str, pub Vec<(&'static str, SimValue)>);

impl Event for Named {
    fn name(&self) -> &'static str {
        self.0
    }
    fn fields(&self) -> Vec<(&'static str, SimValue)> {
        self.1.clone()
    }
}
