//! What every simulated agent shares, whichever stack it belongs to: the
//! events it reports ([`Event`], [`Value`], [`Plain`], [`Named`], typed
//! for the bundle by [`payload`] and sent by [`report`]) and the handling
//! of the data it reads ([`take`] and [`fresh`] on typed slots, [`hold`]
//! and [`held`] on slots that keep the datum's body; data older than
//! [`FRESH`] is not used), and [`names`] for an agent's functions.
//!
//! The stacks (outdoor, UGV, DLA in `situ-dla`) build their agents on
//! these; none of them borrows helpers from another.

use serde::Serialize;
use situ_compiler::bundle::{Content, FieldType, Value as BundleValue};
use situ_runtime::agent::{Body, Context, Datum};

/// A payload value, as the rules file types it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(untagged)]
pub enum Value {
    /// An `f64` field.
    F64(f64),
    /// An `i64` field.
    I64(i64),
    /// A symbol field (`side: {left, right}`, `reason: {…}`).
    Symbol(&'static str),
}

/// An event of a rules file: its name and payload.
pub trait Event {
    /// The event's name in the rules file (e.g. `LAOBS`).
    fn name(&self) -> &'static str;
    /// The payload, field by field, in the rules file's order.
    fn fields(&self) -> Vec<(&'static str, Value)>;
}

/// The payload of `event` as the bundle declares it: the name and the
/// payload become the `Value`s of the rules file's event, field by field in
/// its declared order, symbols by their index; `None` when the bundle has
/// no such event, or a field is missing or of another type.
pub fn payload(content: &Content, event: &dyn Event) -> Option<Vec<BundleValue>> {
    let id = content.event_id(event.name())?;
    let def = &content.events[id as usize];
    let fields = event.fields();
    def.fields
        .iter()
        .map(|f| {
            let (_, v) = fields.iter().find(|(n, _)| *n == f.name)?;
            match (&f.ty, v) {
                (FieldType::F64, Value::F64(x)) => Some(BundleValue::F64(*x)),
                (FieldType::I64, Value::I64(x)) => Some(BundleValue::I64(*x)),
                (FieldType::Symbols(names), Value::Symbol(s)) => {
                    names.iter().position(|n| n == s).map(|i| BundleValue::Symbol(i as u32))
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
    fn fields(&self) -> Vec<(&'static str, Value)> {
        Vec::new()
    }
}

/// An event with a name and payload given in place.
#[derive(Debug, Clone, PartialEq)]
pub struct Named(pub &'static str, pub Vec<(&'static str, Value)>);

impl Event for Named {
    fn name(&self) -> &'static str {
        self.0
    }
    fn fields(&self) -> Vec<(&'static str, Value)> {
        self.1.clone()
    }
}

/// Data older than this is not used (ns): 300 ms, three periods of the
/// slowest sensor an agent waits for (the UGV's GPS at 10 Hz).
pub const FRESH: u64 = 300_000_000;

/// An agent's function names, as [`situ_runtime::agent::Agent::functions`] returns them.
pub fn names(list: &[&str]) -> Vec<String> {
    list.iter().map(|s| s.to_string()).collect()
}

/// Keeps in `slot` the latest datum of type `T` among `inputs`, if newer
/// than the slot's.
pub fn take<T: Clone + 'static>(inputs: &[Datum], slot: &mut Option<(u64, T)>) {
    for d in inputs {
        if let Some(v) = d.body.get::<T>() {
            if slot.as_ref().is_none_or(|(t, _)| d.time >= *t) {
                *slot = Some((d.time, v.clone()));
            }
        }
    }
}

/// The slot's datum, unless older than [`FRESH`] at `now`.
pub fn fresh<T>(slot: &Option<(u64, T)>, now: u64) -> Option<&T> {
    slot.as_ref().filter(|(t, _)| now.saturating_sub(*t) <= FRESH).map(|(_, v)| v)
}

/// The latest datum of a kind, kept as its body (no copy of the data), and
/// when it was sent.
#[derive(Debug, Clone)]
pub struct Held {
    time: u64,
    body: Body,
}

/// Keeps in `slot` the latest datum of type `T` among `inputs` (its body).
pub fn hold<T: 'static>(inputs: &[Datum], slot: &mut Option<Held>) {
    for d in inputs {
        if d.body.get::<T>().is_some() && slot.as_ref().is_none_or(|l| d.time >= l.time) {
            *slot = Some(Held { time: d.time, body: d.body.clone() });
        }
    }
}

/// The held datum as a `T`, unless older than [`FRESH`] at `now`.
pub fn held<T: 'static>(slot: &Option<Held>, now: u64) -> Option<&T> {
    slot.as_ref().filter(|l| now.saturating_sub(l.time) <= FRESH).and_then(|l| l.body.get::<T>())
}
