//! W0311 and W0312: look-up tables that do not say exactly once what the
//! agent does in each state. A state with no entry, in a table without `_`,
//! leaves the agent sleeping there without anyone having written so; a state
//! named in two entries (or twice in one) gets the first, and the second
//! reads as if it applied.

use super::transitions::Transitions;
use crate::codes;
use crate::model::{Agent, Behaviour, Model, StateId, Table, TableEntry};
use serde_json::json;
use situ_grammar::ast::Span;
use situ_grammar::diag::Diagnostic;
use std::collections::{BTreeMap, BTreeSet};

pub fn check(model: &Model, _tr: &Transitions) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for agent in &model.agents {
        if let Behaviour::Table(t) = &agent.behaviour {
            out.extend(missing(model, agent, t));
            out.extend(duplicates(model, agent, t));
        }
    }
    out
}

fn names(model: &Model, states: &[StateId]) -> Vec<String> {
    states.iter().map(|&s| model.state(s).name.clone()).collect()
}

/// W0311: the states a table without `_` does not name.
fn missing(model: &Model, agent: &Agent, table: &Table) -> Option<Diagnostic> {
    let mut named = BTreeSet::new();
    for e in &table.entries {
        match &e.states {
            None => return None,
            Some(states) => named.extend(states.iter().copied()),
        }
    }
    let missing: Vec<StateId> = model.state_ids().filter(|s| !named.contains(s)).collect();
    if missing.is_empty() {
        return None;
    }
    let list = names(model, &missing).join(", ");
    let start = table.origin.span.start;
    Some(
        Diagnostic::warning(
            codes::NO_TABLE_ENTRY,
            format!("the table of `{}` has no entry for {list}", agent.name),
            table.origin.file,
            Span::new(start, start + "table".len()),
            format!("no entry for {list}"),
        )
        .with_help(format!(
            "add an entry for {list} (`{list} => sleep` if that is meant), or a `_` entry; with none, `{}` sleeps there",
            agent.name
        ))
        .with_witness(json!({ "agent": agent.name, "missing": names(model, &missing) })),
    )
}

/// A table entry's selector, one key per state it names (`None` for `_`).
fn keys(entry: &TableEntry) -> Vec<Option<StateId>> {
    match &entry.states {
        None => vec![None],
        Some(states) => states.iter().copied().map(Some).collect(),
    }
}

/// W0312: per entry, the states that an earlier entry, or the entry itself
/// before, already names.
fn duplicates(model: &Model, agent: &Agent, table: &Table) -> Vec<Diagnostic> {
    let mut first: BTreeMap<Option<StateId>, usize> = BTreeMap::new();
    let mut out = Vec::new();
    for (i, entry) in table.entries.iter().enumerate() {
        let mut repeated = Vec::new();
        for key in keys(entry) {
            match first.get(&key) {
                Some(&j) => repeated.push((key, j)),
                None => {
                    first.insert(key, i);
                }
            }
        }
        if !repeated.is_empty() {
            out.push(duplicate(model, agent, table, i, &repeated));
        }
    }
    out
}

fn duplicate(
    model: &Model,
    agent: &Agent,
    table: &Table,
    i: usize,
    repeated: &[(Option<StateId>, usize)],
) -> Diagnostic {
    let name = |key: &Option<StateId>| key.map_or("_".to_string(), |s| model.state(s).name.clone());
    let quoted: Vec<String> = repeated.iter().map(|(k, _)| format!("`{}`", name(k))).collect();
    let what = quoted.join(", ");
    let entry = &table.entries[i];
    let earlier: BTreeSet<usize> = repeated.iter().map(|(_, j)| *j).filter(|&j| j != i).collect();
    let label = if earlier.is_empty() {
        format!("{what} twice in this entry")
    } else {
        format!("{what} again: not applied here")
    };
    let mut d = Diagnostic::warning(
        codes::DUPLICATE_ENTRY,
        format!("the table of `{}` names {what} a second time", agent.name),
        entry.origin.file,
        entry.origin.span,
        label,
    );
    for e in earlier.iter().map(|&j| &table.entries[j]) {
        d = d.with_label(e.origin.file, e.origin.span, "named first here: this entry applies");
    }
    let dups: Vec<_> =
        repeated.iter().map(|(k, j)| json!({ "state": name(k), "entry": i + 1, "first_entry": j + 1 })).collect();
    d.with_help(format!(
        "name each state in one entry only: the first entry that names a state applies, so remove {what} from this entry"
    ))
    .with_witness(json!({ "agent": agent.name, "duplicates": dups }))
}
