//! Phase 4 (continued): `script` blocks, the timelines `situ run --script`
//! plays. Events are resolved and type-checked as a test's are; the steps'
//! times are checked against each other (order, overlaps, silences).

use super::scenarios::event_fact;
use super::Cx;
use crate::codes;
use crate::model::*;
use situ_grammar::ast;
use situ_grammar::diag::{Diagnostic, FileId};

/// The most events one script may post (periodic steps counted out), so
/// that a run of any script ends in bounded time and memory.
pub const MAX_SCRIPT_EVENTS: u64 = 50_000_000;

pub(super) fn script(cx: &mut Cx, file: FileId, script: &ast::Script) {
    let origin = Cx::origin(file, script.name.span);
    if let Some(first) = cx.script_names.get(&script.name.value).copied() {
        cx.duplicate("script", &script.name.value, file, script.name.span, first);
    } else {
        cx.script_names.insert(script.name.value.clone(), origin);
    }
    let mut steps = Vec::new();
    let mut ok = true;
    // Where the script stands: the start of the previous step and its place.
    let mut cursor: Option<(u64, ast::Span)> = None;
    let mut total: u64 = 0;
    for step in &script.steps {
        let here = cursor.map_or(0, |c| c.0);
        // The start is known from the text, even when the step has errors.
        let start = match step {
            ast::ScriptStep::At { time, .. } => time.nanos,
            ast::ScriptStep::Every { from, .. } | ast::ScriptStep::Silent { from, .. } => from.nanos,
            ast::ScriptStep::Random { from, .. } => from.map_or(here, |f| f.nanos),
        };
        if let Some((previous, span)) = cursor {
            if start < previous {
                time_order(cx, file, step.span(), start, previous, span);
                ok = false;
            }
        }
        cursor = Some((start, step.span()));
        let Some(resolved) = self::step(cx, file, step, here) else {
            ok = false;
            continue;
        };
        total = total.saturating_add(count(&resolved));
        steps.push(resolved);
    }
    ok &= overlaps(cx, &steps);
    ok &= silences(cx, &steps);
    if total > MAX_SCRIPT_EVENTS {
        cx.diags.push(
            Diagnostic::error(
                codes::BAD_INTERVAL,
                format!("script `{}` posts {total} events, more than {MAX_SCRIPT_EVENTS}", script.name.value),
                file,
                script.name.span,
                "too many events",
            )
            .with_help("use longer periods or shorter intervals; `random` sections are bounded by their length"),
        );
        ok = false;
    }
    if ok {
        let end = steps.iter().map(end_of).max().unwrap_or(0);
        cx.model.scripts.push(Script { name: script.name.value.clone(), steps, origin, end });
    }
}

fn step(cx: &mut Cx, file: FileId, step: &ast::ScriptStep, cursor: u64) -> Option<ScriptStep> {
    let origin = Cx::origin(file, step.span());
    match step {
        ast::ScriptStep::At { time, event, .. } => {
            let event = script_event(cx, file, event)?;
            Some(ScriptStep::At { time: time.nanos, event, origin })
        }
        ast::ScriptStep::Every { period, event, from, to, .. } => {
            let event = script_event(cx, file, event);
            let mut ok = cx.positive(file, period.nanos, period.span, "a period");
            ok &= interval(cx, file, from, to);
            if ok && (to.nanos - from.nanos) / period.nanos > MAX_SCRIPT_EVENTS {
                cx.diags.push(
                    Diagnostic::error(
                        codes::BAD_INTERVAL,
                        format!("`every` posts more than {MAX_SCRIPT_EVENTS} events"),
                        file,
                        period.span,
                        "too short a period for this interval",
                    )
                    .with_help("a longer period, or a shorter interval"),
                );
                ok = false;
            }
            let event = event?;
            ok.then_some(ScriptStep::Every { period: period.nanos, from: from.nanos, to: to.nanos, event, origin })
        }
        ast::ScriptStep::Silent { agent, from, to, .. } => {
            let agent = cx.agent(file, agent);
            let ok = interval(cx, file, from, to);
            let agent = agent?;
            ok.then_some(ScriptStep::Silent { agent, from: from.nanos, to: to.nanos, origin })
        }
        ast::ScriptStep::Random { length, seed, from, .. } => {
            let ok = cx.positive(file, length.nanos, length.span, "a random section's length");
            let from = from.map_or(cursor, |f| f.nanos);
            ok.then_some(ScriptStep::Random { from, length: length.nanos, seed: *seed, origin })
        }
    }
}

/// `Agent.EVENT(field: value, …)`: the event, its payload, and the agent if
/// written must be the event's.
fn script_event(cx: &mut Cx, file: FileId, e: &ast::ScriptEvent) -> Option<ScriptEvent> {
    let instance = ast::EventInstance {
        event: e.event.clone(),
        arguments: e.arguments.clone(),
        repeat: None,
        at: None,
        span: e.span,
    };
    let agent = match &e.agent {
        Some(a) => Some((cx.agent(file, a)?, a)),
        None => None,
    };
    let fact = event_fact(cx, file, &instance)?;
    let owner = cx.model.event(fact.event).agent;
    if let Some((agent, ident)) = agent {
        if agent != owner {
            let owner_name = cx.model.agent(owner).name.clone();
            cx.diags.push(
                Diagnostic::error(
                    codes::FOREIGN_SCRIPT_EVENT,
                    format!("`{}` is an event of `{owner_name}`, not of `{}`", e.event.name, ident.name),
                    file,
                    ident.span.join(e.event.span),
                    "another agent's event",
                )
                .with_help(format!(
                    "write `{owner_name}.{}`, or the event of `{}` you meant",
                    e.event.name, ident.name
                )),
            );
            return None;
        }
    }
    Some(ScriptEvent { event: fact.event, payload: fact.payload, origin: Cx::origin(file, e.span) })
}

/// E0121: `from A to B` with `B <= A`.
fn interval(cx: &mut Cx, file: FileId, from: &ast::Duration, to: &ast::Duration) -> bool {
    if to.nanos > from.nanos {
        return true;
    }
    cx.diags.push(
        Diagnostic::error(
            codes::BAD_INTERVAL,
            format!("the interval from {} to {} is empty", show(from.nanos), show(to.nanos)),
            file,
            from.span.join(to.span),
            "ends before it starts",
        )
        .with_help("the interval is `from START to END`, END after START (END excluded)"),
    );
    false
}

/// E0119: a step that starts before the one written before it.
fn time_order(cx: &mut Cx, file: FileId, span: ast::Span, start: u64, previous: u64, previous_span: ast::Span) {
    cx.diags.push(
        Diagnostic::error(
            codes::SCRIPT_TIME_ORDER,
            format!("this step starts at {}, before the previous step ({})", show(start), show(previous)),
            file,
            span,
            "earlier than the step before",
        )
        .with_label(file, previous_span, format!("starts at {}", show(previous)))
        .with_help("write a script's steps in the order of their start times"),
    );
}

/// E0120: two `every` of one event whose intervals overlap.
fn overlaps(cx: &mut Cx, steps: &[ScriptStep]) -> bool {
    let mut ok = true;
    for (i, a) in steps.iter().enumerate() {
        let ScriptStep::Every { from: af, to: at, event: ae, origin: ao, .. } = a else { continue };
        for b in &steps[..i] {
            let ScriptStep::Every { from: bf, to: bt, event: be, origin: bo, .. } = b else { continue };
            if ae.event == be.event && af < bt && bf < at {
                let name = cx.model.event(ae.event).name.clone();
                cx.diags.push(
                    Diagnostic::error(
                        codes::OVERLAPPING_EVERY,
                        format!("two `every` steps post `{name}` at once"),
                        ao.file,
                        ao.span,
                        "overlaps the other",
                    )
                    .with_label(bo.file, bo.span, "this one")
                    .with_help("one periodic step per event at a time: end the first where the second starts"),
                );
                ok = false;
            }
        }
    }
    ok
}

/// E0122: an `at` event of an agent that the script silences then.
fn silences(cx: &mut Cx, steps: &[ScriptStep]) -> bool {
    let mut ok = true;
    for a in steps {
        let ScriptStep::At { time, event, origin } = a else { continue };
        let agent = cx.model.event(event.event).agent;
        for b in steps {
            let ScriptStep::Silent { agent: silent, from, to, origin: so } = b else { continue };
            if *silent == agent && from <= time && time < to {
                let name = cx.model.agent(agent).name.clone();
                cx.diags.push(
                    Diagnostic::error(
                        codes::EVENT_IN_SILENCE,
                        format!("`{name}` reports an event at a time the script says it is silent"),
                        origin.file,
                        origin.span,
                        "an event of a silent agent",
                    )
                    .with_label(so.file, so.span, "silent here")
                    .with_help("move the event out of the silence, or shorten the silence"),
                );
                ok = false;
            }
        }
    }
    ok
}

fn end_of(step: &ScriptStep) -> u64 {
    match step {
        ScriptStep::At { time, .. } => *time,
        ScriptStep::Every { to, .. } | ScriptStep::Silent { to, .. } => *to,
        ScriptStep::Random { from, length, .. } => from.saturating_add(*length),
    }
}

/// How many events a step posts (random sections: none counted here).
fn count(step: &ScriptStep) -> u64 {
    match step {
        ScriptStep::At { .. } => 1,
        ScriptStep::Every { period, from, to, .. } => (to - from).div_ceil(*period),
        ScriptStep::Silent { .. } | ScriptStep::Random { .. } => 0,
    }
}

/// A time as a person writes it in a script: `60s`, `2.5s`, `100ms`.
fn show(ns: u64) -> String {
    if ns >= 1_000_000_000 {
        format!("{}s", ns as f64 / 1e9)
    } else {
        format!("{}ms", ns as f64 / 1e6)
    }
}
