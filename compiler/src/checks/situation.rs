//! Abstract working memories. A [`Situation`] is the set of working memories
//! in which some conditions hold: the states allowed, and per agent what its
//! latest fact must be (an event with a value set per payload field, a run
//! length range, an age range), or that it is stale. Rules become situations;
//! two rules can fire together when the meet of their situations is
//! satisfiable; a witness is one concrete working memory inside it.

use super::domain::Domain;
use crate::model::*;
use serde_json::{json, Value as Json};
use situ_grammar::ast::CmpOp;
use std::collections::{BTreeMap, BTreeSet};

/// What the latest fact of one agent must be.
#[derive(Debug, Clone, PartialEq)]
pub enum AgentReq {
    /// Anything: no fact, any event, stale or not.
    Free,
    /// Not stale: no fact yet, or a fact younger than the stale time.
    Fresh,
    /// Stale: its latest fact is older than its `stale after`.
    Stale,
    /// This event, with these payload values, run lengths and ages.
    Fact(Fact),
}

/// A required latest fact.
#[derive(Debug, Clone, PartialEq)]
pub struct Fact {
    pub event: EventId,
    /// One value set per payload field.
    pub fields: Vec<Domain>,
    /// Inclusive range of run lengths.
    pub run: (u64, u64),
    /// Inclusive range of ages (now minus the event's time, nanoseconds).
    pub age: (u64, u64),
}

/// Why conditions cannot hold together.
#[derive(Debug, Clone, PartialEq)]
pub struct Unsat {
    pub reason: String,
    /// The conditions that exclude each other.
    pub origins: Vec<Origin>,
}

/// A set of working memories.
#[derive(Debug, Clone)]
pub struct Situation {
    pub states: BTreeSet<StateId>,
    pub agents: BTreeMap<AgentId, AgentReq>,
    /// `not` patterns that must not match.
    pub negations: Vec<Pattern>,
    /// Fields that must hold one value (a variable bound in one and tested
    /// for equality in the others); kept exact by [`propagate`].
    pub equal: Vec<Equality>,
    /// Some condition (a comparison with a variable) was widened: the
    /// situation may contain memories in which the conditions do not hold.
    pub widened: bool,
    /// Where each agent's requirement came from, for reasons.
    origins: BTreeMap<AgentId, Vec<Origin>>,
    state_origins: Vec<Origin>,
}

impl Situation {
    /// Every memory in these states.
    pub fn states(states: BTreeSet<StateId>) -> Situation {
        Situation {
            states,
            agents: BTreeMap::new(),
            negations: Vec::new(),
            equal: Vec::new(),
            widened: false,
            origins: BTreeMap::new(),
            state_origins: Vec::new(),
        }
    }

    /// The memories in which the positive conditions of `rule` hold (its
    /// negations are kept aside, see [`Situation::witness`]).
    pub fn of_rule(model: &Model, rule: &Rule) -> Result<Situation, Unsat> {
        let mut states = rule.allowed_states().unwrap_or_else(|| model.state_ids().collect());
        let guarded = !states.is_empty();
        // A rule is activated only where the state is not already its target.
        states.remove(&rule.target);
        let mut sit = Situation::states(states);
        sit.state_origins = rule.guards.iter().map(|g| g.origin).collect();
        if sit.states.is_empty() {
            let reason = if guarded {
                "it is only allowed in its own target state, where it is never activated"
            } else {
                "its state guards exclude each other"
            };
            return Err(Unsat { reason: reason.into(), origins: sit.state_origins });
        }
        // `?v` tested for equality with its binding site, both on fields of
        // one type: an equality class, decided exactly. Mixed numeric types
        // stay comparisons with a variable (widened).
        let site = |v: VarId| {
            rule.patterns.iter().find_map(|p| {
                p.tests.iter().find(|t| matches!(t.check, FieldCheck::Bind(b) if b == v)).map(|t| (p.event, t.field))
            })
        };
        let mut exact: Vec<Pattern> = Vec::new();
        for p in &rule.patterns {
            let mut p = p.clone();
            p.tests.retain(|t| {
                let FieldCheck::Compare { op: CmpOp::Eq, rhs: Operand::Var(v) } = t.check else { return true };
                let Some((event, field)) = site(v) else { return true };
                let ty = |e: EventId, f: usize| &model.event(e).fields[f].ty;
                if ty(event, field) != ty(p.event, t.field) {
                    return true;
                }
                let members = [(model.event(event).agent, field), (model.event(p.event).agent, t.field)];
                sit.equal.push(Equality { variable: rule.variables[v].name.clone(), members: members.to_vec() });
                false
            });
            exact.push(p);
        }
        merge_classes(&mut sit.equal);
        for p in &exact {
            sit.require_pattern(model, p)?;
        }
        for s in &rule.stale {
            sit.require_stale(model, s.agent, !s.negated, s.origin)?;
        }
        sit.negations = rule.negations.clone();
        sit.widened |= rule.negations.iter().any(has_variable);
        sit.propagate(model)?;
        Ok(sit)
    }

    /// Adds a positive pattern.
    pub fn require_pattern(&mut self, model: &Model, p: &Pattern) -> Result<(), Unsat> {
        let event = model.event(p.event);
        let agent = model.agent(event.agent);
        let mut fields: Vec<Domain> = event.fields.iter().map(|f| Domain::full(&f.ty)).collect();
        for t in &p.tests {
            match Domain::of_check(&event.fields[t.field].ty, &t.check) {
                Some(d) => fields[t.field] = fields[t.field].intersect(&d),
                None => self.widened = true,
            }
        }
        let max_age = agent.stale_after.unwrap_or(u64::MAX).min(p.within.unwrap_or(u64::MAX));
        let fact = Fact { event: p.event, fields, run: (p.run_length, u64::MAX), age: (0, max_age) };
        self.meet_fact(model, event.agent, fact, p.origin)?;
        self.propagate(model)
    }

    /// Narrows the fields of every equality class to the values they can
    /// share, or says why there are none.
    pub fn propagate(&mut self, model: &Model) -> Result<(), Unsat> {
        propagate(model, &mut self.agents, &self.equal)
            .map_err(|reason| Unsat { reason, origins: self.origins.values().flatten().copied().collect() })
    }

    fn meet_fact(&mut self, model: &Model, agent: AgentId, fact: Fact, origin: Origin) -> Result<(), Unsat> {
        let mut origins = self.origins.get(&agent).cloned().unwrap_or_default();
        origins.push(origin);
        let name = |e: EventId| model.event(e).name.clone();
        let merged = match self.agents.get(&agent) {
            None | Some(AgentReq::Free) | Some(AgentReq::Fresh) => fact,
            Some(AgentReq::Stale) => {
                return Err(Unsat {
                    reason: format!("`{}` is required stale, so none of its events matches", model.agent(agent).name),
                    origins,
                })
            }
            Some(AgentReq::Fact(f)) if f.event != fact.event => {
                return Err(Unsat {
                    reason: format!(
                        "`{}` and `{}` are both events of `{}`, which has one latest event",
                        name(f.event),
                        name(fact.event),
                        model.agent(agent).name
                    ),
                    origins,
                })
            }
            Some(AgentReq::Fact(f)) => {
                let fields: Vec<Domain> = f.fields.iter().zip(&fact.fields).map(|(a, b)| a.intersect(b)).collect();
                Fact {
                    event: f.event,
                    fields,
                    run: (f.run.0.max(fact.run.0), f.run.1.min(fact.run.1)),
                    age: (f.age.0.max(fact.age.0), f.age.1.min(fact.age.1)),
                }
            }
        };
        let event = model.event(merged.event);
        if let Some(i) = merged.fields.iter().position(Domain::is_empty) {
            return Err(Unsat {
                reason: format!("no value of `{}.{}` satisfies all its constraints", event.name, event.fields[i].name),
                origins,
            });
        }
        if merged.run.0 > merged.run.1 {
            return Err(Unsat {
                reason: format!("no run length of `{}` satisfies all its bounds", event.name),
                origins,
            });
        }
        if merged.age.0 > merged.age.1 {
            return Err(Unsat { reason: format!("no age of `{}` satisfies all its windows", event.name), origins });
        }
        self.agents.insert(agent, AgentReq::Fact(merged));
        self.origins.insert(agent, origins);
        Ok(())
    }

    /// Requires the agent stale (`stale == true`) or not stale.
    pub fn require_stale(&mut self, model: &Model, agent: AgentId, stale: bool, origin: Origin) -> Result<(), Unsat> {
        let mut origins = self.origins.get(&agent).cloned().unwrap_or_default();
        origins.push(origin);
        let name = &model.agent(agent).name;
        let next = match (self.agents.get(&agent).cloned().unwrap_or(AgentReq::Free), stale) {
            (AgentReq::Free | AgentReq::Stale, true) => AgentReq::Stale,
            (AgentReq::Free | AgentReq::Fresh, false) => AgentReq::Fresh,
            (AgentReq::Fact(f), false) => AgentReq::Fact(f),
            (AgentReq::Fact(_), true) => {
                return Err(Unsat {
                    reason: format!("`{name}` is required stale, so none of its events matches"),
                    origins,
                })
            }
            (AgentReq::Stale, false) | (AgentReq::Fresh, true) => {
                return Err(Unsat { reason: format!("`{name}` is required both stale and not stale"), origins })
            }
        };
        self.agents.insert(agent, next);
        self.origins.insert(agent, origins);
        Ok(())
    }

    /// A quick test that can rule out a meet without building it: some
    /// agent needs two different events, or a fact and staleness.
    pub fn compatible(&self, other: &Situation) -> bool {
        if self.states.is_disjoint(&other.states) {
            return false;
        }
        self.agents.iter().all(|(agent, a)| match (a, other.agents.get(agent)) {
            (AgentReq::Fact(x), Some(AgentReq::Fact(y))) => x.event == y.event,
            (AgentReq::Fact(_), Some(AgentReq::Stale))
            | (AgentReq::Stale, Some(AgentReq::Fact(_) | AgentReq::Fresh)) => false,
            (AgentReq::Fresh, Some(AgentReq::Stale)) => false,
            _ => true,
        })
    }

    /// The memories in both situations.
    pub fn meet(&self, model: &Model, other: &Situation) -> Result<Situation, Unsat> {
        let mut sit = self.clone();
        sit.states = self.states.intersection(&other.states).copied().collect();
        sit.state_origins.extend(other.state_origins.iter().copied());
        if sit.states.is_empty() {
            return Err(Unsat {
                reason: "their state guards have no state in common".into(),
                origins: sit.state_origins,
            });
        }
        for (agent, req) in &other.agents {
            let origin = other.origins.get(agent).and_then(|o| o.first()).copied();
            let origin = origin.unwrap_or(Origin { file: situ_grammar::diag::FileId(0), span: Default::default() });
            match req {
                AgentReq::Free => {}
                AgentReq::Fresh => sit.require_stale(model, *agent, false, origin)?,
                AgentReq::Stale => sit.require_stale(model, *agent, true, origin)?,
                AgentReq::Fact(f) => sit.meet_fact(model, *agent, f.clone(), origin)?,
            }
            if let Some(o) = other.origins.get(agent) {
                let entry = sit.origins.entry(*agent).or_default();
                for x in o.iter().skip(1) {
                    entry.push(*x);
                }
            }
        }
        sit.negations.extend(other.negations.iter().cloned());
        sit.widened |= other.widened;
        if !other.equal.is_empty() {
            sit.equal.extend(other.equal.iter().cloned());
            merge_classes(&mut sit.equal);
        }
        sit.propagate(model)?;
        Ok(sit)
    }

    /// A concrete working memory in the situation that also escapes every
    /// negation, or why there is none. Negations on one agent can each be
    /// escaped in several ways; the ways are tried in turn (at most
    /// `MAX_BRANCHES`; beyond that the answer is widened to "maybe").
    pub fn witness(&self, model: &Model) -> Result<Witness, Unsat> {
        let mut budget = MAX_BRANCHES;
        match escape(model, self.agents.clone(), &self.negations, &self.equal, &mut budget) {
            Some(agents) => Ok(Witness::new(model, &self.states, &agents, self.widened || budget == 0)),
            None if budget == 0 => Ok(Witness::new(model, &self.states, &self.agents, true)),
            None => Err(Unsat {
                reason: "its `not` conditions exclude the events its other conditions need".into(),
                origins: self.negations.iter().map(|n| n.origin).collect(),
            }),
        }
    }
}

const MAX_BRANCHES: usize = 4096;

/// Fields of the agents' latest facts that must hold one value: `(agent,
/// field index)`, the field of the event the agent's fact must be.
#[derive(Debug, Clone, PartialEq)]
pub struct Equality {
    /// The variable that joins them, for reasons.
    pub variable: String,
    pub members: Vec<(AgentId, usize)>,
}

/// Joins classes that share a member, so that each field is in one class.
fn merge_classes(classes: &mut Vec<Equality>) {
    let mut i = 0;
    while i < classes.len() {
        let mut j = i + 1;
        let mut merged = false;
        while j < classes.len() {
            if classes[j].members.iter().any(|m| classes[i].members.contains(m)) {
                let other = classes.swap_remove(j);
                for m in other.members {
                    if !classes[i].members.contains(&m) {
                        classes[i].members.push(m);
                    }
                }
                merged = true;
            } else {
                j += 1;
            }
        }
        if !merged {
            i += 1;
        }
    }
}

/// Narrows every class's fields to their common values. Two fields that
/// must be equal cannot be NaN, which equals nothing.
fn propagate(model: &Model, agents: &mut BTreeMap<AgentId, AgentReq>, equal: &[Equality]) -> Result<(), String> {
    for class in equal {
        let mut common: Option<Domain> = None;
        for (agent, field) in &class.members {
            if let Some(AgentReq::Fact(f)) = agents.get(agent) {
                let d = &f.fields[*field];
                common = Some(match common {
                    None => d.clone(),
                    Some(c) => c.intersect(d),
                });
            }
        }
        let Some(mut common) = common else { continue };
        common.remove_nan();
        let name = |(agent, field): &(AgentId, usize)| match agents.get(agent) {
            Some(AgentReq::Fact(f)) => {
                let e = model.event(f.event);
                format!("`{}.{}`", e.name, e.fields[*field].name)
            }
            _ => format!("a field of `{}`", model.agent(*agent).name),
        };
        if common.is_empty() {
            let fields: Vec<String> = class.members.iter().map(name).collect();
            return Err(format!(
                "`?{}` makes {} equal, and no value satisfies the constraints of all of them",
                class.variable,
                fields.join(" and ")
            ));
        }
        for (agent, field) in &class.members {
            if let Some(AgentReq::Fact(f)) = agents.get_mut(agent) {
                f.fields[*field] = common.clone();
            }
        }
    }
    Ok(())
}

fn has_variable(p: &Pattern) -> bool {
    p.tests.iter().any(|t| match &t.check {
        FieldCheck::Bind(_) => false,
        FieldCheck::Compare { rhs, .. } => matches!(rhs, Operand::Var(_)),
        FieldCheck::Range { lo, hi, .. } => matches!(lo, Operand::Var(_)) || matches!(hi, Operand::Var(_)),
    })
}

/// Narrows the agents' requirements so that no negation matches.
fn escape(
    model: &Model,
    agents: BTreeMap<AgentId, AgentReq>,
    negations: &[Pattern],
    equal: &[Equality],
    budget: &mut usize,
) -> Option<BTreeMap<AgentId, AgentReq>> {
    if *budget == 0 {
        return None;
    }
    *budget -= 1;
    let Some((n, rest)) = negations.split_first() else { return Some(agents) };
    let agent = model.event(n.event).agent;
    let fact = match agents.get(&agent) {
        // No fact, another event, or stale: the negated pattern cannot match.
        None | Some(AgentReq::Free | AgentReq::Fresh | AgentReq::Stale) => {
            return escape(model, agents, rest, equal, budget)
        }
        Some(AgentReq::Fact(f)) if f.event != n.event => return escape(model, agents, rest, equal, budget),
        Some(AgentReq::Fact(f)) => f.clone(),
    };
    if has_variable(n) {
        // Beyond exact: assume it can be escaped (the caller marks it widened).
        return escape(model, agents, rest, equal, budget);
    }
    let event = model.event(n.event);
    // The ways out: a field outside the negated constraint, a shorter run, an older fact.
    let mut ways: Vec<Fact> = Vec::new();
    for t in &n.tests {
        let Some(d) = Domain::of_check(&event.fields[t.field].ty, &t.check) else { continue };
        let narrowed = fact.fields[t.field].subtract(&d);
        if !narrowed.is_empty() {
            let mut f = fact.clone();
            f.fields[t.field] = narrowed;
            ways.push(f);
        }
    }
    if n.run_length > fact.run.0 {
        ways.push(Fact { run: (fact.run.0, fact.run.1.min(n.run_length - 1)), ..fact.clone() });
    }
    if let Some(w) = n.within {
        if w < fact.age.1 {
            ways.push(Fact { age: (fact.age.0.max(w + 1), fact.age.1), ..fact.clone() });
        }
    }
    for way in ways {
        let mut next = agents.clone();
        next.insert(agent, AgentReq::Fact(way));
        if propagate(model, &mut next, equal).is_err() {
            continue;
        }
        if let Some(found) = escape(model, next, rest, equal, budget) {
            return Some(found);
        }
    }
    None
}

/// One concrete working memory, for people and tools.
#[derive(Debug, Clone, PartialEq)]
pub struct Witness {
    pub state: StateId,
    /// Per agent with a required fact: event, payload, run length, age.
    pub json: Json,
    /// The memory is only a candidate: some condition was beyond exact checking.
    pub widened: bool,
}

impl Witness {
    fn new(model: &Model, states: &BTreeSet<StateId>, agents: &BTreeMap<AgentId, AgentReq>, widened: bool) -> Witness {
        let state = *states.iter().next().expect("a satisfiable situation has a state");
        let mut facts = Vec::new();
        let mut stale = Vec::new();
        for (agent, req) in agents {
            match req {
                AgentReq::Fact(f) => {
                    let event = model.event(f.event);
                    let payload: serde_json::Map<String, Json> = event
                        .fields
                        .iter()
                        .zip(&f.fields)
                        .map(|(field, d)| (field.name.clone(), d.sample(&field.ty).unwrap_or(Json::Null)))
                        .collect();
                    facts.push(json!({
                        "agent": model.agent(*agent).name,
                        "event": event.name,
                        "payload": payload,
                        "run": f.run.0.max(1),
                        "age_ns": f.age.0,
                    }));
                }
                AgentReq::Stale => stale.push(json!(model.agent(*agent).name)),
                AgentReq::Free | AgentReq::Fresh => {}
            }
        }
        let json = json!({ "state": model.state(state).name, "facts": facts, "stale": stale });
        Witness { state, json, widened }
    }

    /// The events of the memory, written as a person would post them.
    pub fn describe(&self) -> String {
        let facts = self.json["facts"].as_array().cloned().unwrap_or_default();
        let mut parts: Vec<String> = facts
            .iter()
            .map(|f| {
                let payload = f["payload"].as_object().cloned().unwrap_or_default();
                let args: Vec<String> = payload.iter().map(|(k, v)| format!("{k}: {}", show(v))).collect();
                let mut s = f["event"].as_str().unwrap_or("?").to_string();
                if !args.is_empty() {
                    s.push_str(&format!("({})", args.join(", ")));
                }
                if f["run"].as_u64().unwrap_or(1) > 1 {
                    s.push_str(&format!(" x{}", f["run"]));
                }
                s
            })
            .collect();
        for s in self.json["stale"].as_array().cloned().unwrap_or_default() {
            parts.push(format!("{} stale", s.as_str().unwrap_or("?")));
        }
        let state = self.json["state"].as_str().unwrap_or("?");
        if parts.is_empty() {
            format!("state {state}")
        } else {
            format!("state {state} with {}", parts.join(", "))
        }
    }
}

fn show(v: &Json) -> String {
    match v {
        Json::String(s) => s.clone(),
        Json::Number(n) if n.is_f64() => {
            let f = n.as_f64().unwrap_or(0.0);
            if f.fract() == 0.0 && f.abs() < 1e15 {
                format!("{f:.1}")
            } else {
                format!("{f}")
            }
        }
        other => other.to_string(),
    }
}
