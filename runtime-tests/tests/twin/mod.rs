//! The fast path held to the interpreter: the same operations on an
//! engine built by `Engine::new` (the fast path) and one built by
//! `Engine::interpreted` (the Rete interpreter) must give the same
//! answers — every step's `Step` or refusal or cascade error, its recorded
//! firings with their matched facts (`last_change`), every heartbeat's and
//! settling's change — and leave the same working memory (state, now,
//! each agent's fact, staleness and clock, the activated rules as a set).

// Shared by test binaries that each use a part of it.
#![allow(dead_code)]

use proptest::prelude::*;
use situ_compiler::bundle::{Content, FieldType, Value};
use situ_runtime::rete::{Engine, StepError};
use std::sync::Arc;

/// An operation on an engine: every entry point that changes it.
#[derive(Debug, Clone)]
pub enum Op {
    /// `step` (payload checked, then the event), then `last_change`.
    Post(u32, u64, Vec<Value>),
    /// `set_clock`: the Bulletinboard's clock for the next posts.
    Clock(Option<u64>),
    /// `advance` (a heartbeat).
    Advance(u64),
    Settle,
    Reset,
    ResetIfFinal,
    ForceState(u32),
    ForceFact(u32, u64, Vec<Value>, u64),
    ForceStale(u32),
    AdvanceClock(u64),
    CascadeLimit(usize),
}

/// What an operation answered, as text: `Value`'s `PartialEq` has NaN
/// unequal to itself, its `Debug` does not.
fn apply(e: &mut Engine, op: &Op) -> String {
    match op {
        Op::Post(ev, t, p) => {
            // A refused event records nothing: `last_change` is then the
            // previous step's (and a copy's, `copy_from`, is not copied).
            match e.step(*ev, *t, p) {
                step @ (Ok(_) | Err(StepError::Cascade { .. })) => {
                    format!("{step:?} {:?} {:?}", e.last_change(), step.map_err(|x| e.post_error(x)))
                }
                Err(refused) => format!("{refused:?} {:?}", e.post_error(refused)),
            }
        }
        Op::Clock(c) => {
            e.set_clock(*c);
            String::new()
        }
        Op::Advance(t) => format!("{:?}", e.advance(*t)),
        Op::Settle => format!("{:?}", e.settle()),
        Op::Reset => {
            e.reset();
            String::new()
        }
        Op::ResetIfFinal => format!("{}", e.reset_if_final()),
        Op::ForceState(s) => {
            e.force_state(*s);
            String::new()
        }
        Op::ForceFact(ev, t, p, run) => format!("{:?}", e.force_fact(*ev, *t, p, *run)),
        Op::ForceStale(a) => {
            e.force_stale(*a);
            String::new()
        }
        Op::AdvanceClock(t) => {
            e.advance_clock(*t);
            String::new()
        }
        Op::CascadeLimit(n) => {
            e.set_cascade_limit(*n);
            String::new()
        }
    }
}

/// The working memory as text.
fn memory(e: &Engine, agents: usize) -> String {
    let mut active = e.activated().to_vec();
    active.sort_unstable();
    let mut s = format!("state {} now {} active {active:?}", e.state(), e.now());
    for a in 0..agents as u32 {
        s.push_str(&format!("\n  agent {a}: {:?} stale {} time {}", e.fact_view(a), e.is_stale(a), e.agent_time(a)));
    }
    s
}

/// Runs `ops` on both engines; the number of firings of the fast one, or
/// the first difference. The fast path must not decline the bundle.
pub fn twins(content: &Arc<Content>, ops: &[Op]) -> Result<usize, String> {
    twins_with(content, ops, &|c| Engine::new(c))
}

/// [`twins`] with the engine held to the interpreter built by `make`
/// (the fast path, or native code).
pub fn twins_with(content: &Arc<Content>, ops: &[Op], make: &dyn Fn(Arc<Content>) -> Engine) -> Result<usize, String> {
    let mut fast = make(content.clone());
    let mut slow = Engine::interpreted(content.clone());
    if !fast.is_fast() {
        return Err(format!("the fast path declined the bundle: {:?}", fast.fast_declined()));
    }
    assert!(!slow.is_fast());
    let agents = content.agents.len();
    let mut fired = 0;
    let mut copy = make(content.clone());
    for (i, op) in ops.iter().enumerate() {
        let (a, b) = (apply(&mut fast, op), apply(&mut slow, op));
        if a != b {
            return Err(format!("op {i} {op:?}:\n fast: {a}\n interpreter: {b}"));
        }
        let (ma, mb) = (memory(&fast, agents), memory(&slow, agents));
        if ma != mb {
            return Err(format!("after op {i} {op:?}:\n fast: {ma}\n interpreter: {mb}"));
        }
        if matches!(op, Op::Post(..)) {
            fired += fast.last_change().firings.len();
        }
        // A copy (the explorer's `copy_from`) goes on as the original.
        if i % 7 == 3 {
            copy.copy_from(&fast);
            std::mem::swap(&mut copy, &mut fast);
        }
    }
    Ok(fired)
}

/// Posts only, with a mission reset after each final state.
pub fn posts(events: &[(u32, u64, Vec<Value>)], reset_on_final: bool) -> Vec<Op> {
    let mut ops = Vec::with_capacity(events.len() * 2);
    for (e, t, p) in events {
        ops.push(Op::Post(*e, *t, p.clone()));
        if reset_on_final {
            ops.push(Op::ResetIfFinal);
        }
    }
    ops
}

/// Random operations over `content`, mostly posts; `gaps_ms` the time steps
/// (a negative one: an event stamped before now); payloads from `pool`.
pub fn ops(
    content: Arc<Content>,
    gaps_ms: &'static [i64],
    pool: fn(&Content, usize, usize) -> Vec<Value>,
    max: usize,
) -> impl Strategy<Value = Vec<Op>> {
    let n_events = content.events.len().max(1);
    let n_states = content.states.len() as u32;
    let n_agents = content.agents.len().max(1) as u32;
    prop::collection::vec((0..24u8, 0..n_events, 0..gaps_ms.len(), any::<u16>(), any::<u16>()), 1..max).prop_map(
        move |raw| {
            let mut t: u64 = 0;
            let mut out = Vec::with_capacity(raw.len());
            for (kind, e, gap, a, b) in raw {
                t = (t as i64 + gaps_ms[gap] * 1_000_000).max(0) as u64;
                let payload = |e: usize| -> Vec<Value> {
                    (0..content.events[e].fields.len())
                        .map(|f| {
                            let p = pool(&content, e, f);
                            p[[a, b][f % 2] as usize % p.len()]
                        })
                        .collect()
                };
                let op = match kind {
                    _ if content.events.is_empty() => Op::Advance(t),
                    0 => Op::Clock(if a % 2 == 0 { None } else { Some(t.saturating_sub(u64::from(b) * 1_000_000)) }),
                    1 => Op::Advance(t),
                    2 => Op::Settle,
                    3 => Op::Reset,
                    4 => Op::ResetIfFinal,
                    5 => Op::ForceState(u32::from(a) % (n_states + 1)),
                    6 => Op::ForceFact(e as u32, t, payload(e), u64::from(b % 4)),
                    7 => Op::ForceStale(u32::from(a) % (n_agents + 1)),
                    8 => Op::AdvanceClock(t + u64::from(b % 64) * 1_000_000),
                    9 => Op::CascadeLimit(1 + usize::from(a % 4) * 21),
                    _ => Op::Post(e as u32, t, payload(e)),
                };
                out.push(op);
            }
            out
        },
    )
}

/// Payload values for field `field` of `event`: the edges, and each
/// constant its rules compare the field with, a little below, at and
/// above it.
pub fn pool(content: &Content, event: usize, field: usize) -> Vec<Value> {
    match &content.events[event].fields[field].ty {
        FieldType::F64 => {
            let mut v = vec![Value::F64(f64::NAN), Value::F64(-1.0), Value::F64(0.0), Value::F64(1000.0)];
            for c in thresholds(content, event, field) {
                v.extend([c - 0.5, c, c.next_up(), c + 0.5].map(Value::F64));
            }
            v
        }
        FieldType::I64 => {
            let mut v = vec![Value::I64(-1), Value::I64(0), Value::I64(1000)];
            for c in thresholds(content, event, field) {
                v.extend([c as i64 - 1, c as i64, c as i64 + 1].map(Value::I64));
            }
            v
        }
        FieldType::Bool => vec![Value::Bool(false), Value::Bool(true)],
        FieldType::Symbols(s) => (0..s.len() as u32).map(Value::Symbol).collect(),
    }
}

fn thresholds(content: &Content, event: usize, field: usize) -> Vec<f64> {
    use situ_compiler::bundle::{AlphaNode, Check, Operand};
    let mut out = Vec::new();
    for node in &content.network.alpha {
        let AlphaNode::Event { event: e, tests, .. } = node else { continue };
        if *e as usize != event {
            continue;
        }
        for t in tests.iter().filter(|t| t.field as usize == field) {
            let ops = match &t.check {
                Check::Compare { rhs, .. } => vec![*rhs],
                Check::Range { lo, hi, .. } => vec![*lo, *hi],
            };
            for o in ops {
                match o {
                    Operand::Value(Value::F64(f)) if f.is_finite() => out.push(f),
                    Operand::Value(Value::I64(i)) => out.push(i as f64),
                    _ => {}
                }
            }
        }
    }
    out
}
