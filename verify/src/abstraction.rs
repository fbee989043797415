//! The finite abstraction that [`explore`](super::explore) searches.
//!
//! **Payloads.** The constants each field is compared with, in the rules
//! (the network's tests) and in the properties, cut its domain into classes:
//! two values are in one class when every such comparison gives the same
//! answer for both (the signature). The candidates — each constant, a round
//! value inside each open interval between two consecutive constants, one
//! below the smallest and one above the largest, and NaN — meet every
//! signature there is, so one representative per class (a round one, NaN
//! only when nothing else has its signature) is exact for comparisons with
//! constants. A field compared with a variable (another field) is not cut
//! by signature: it takes the merged constants of every field it is linked
//! to and two values inside each open interval, so that each order between
//! two linked fields occurs (exact for two fields; a sample for chains of
//! three or more, which the verdict then says).
//!
//! **Letters.** An event with one representative per field; the alphabet
//! is every event with every combination.
//!
//! **Time.** Between two events the time advances by a gap of 0 or D + 1 ns
//! for each duration D of the program (`stale after`, `within`, and the
//! `eventually … within D` of the properties): every threshold can be
//! crossed, alone or in sums. Other gaps (a difference of two durations,
//! say) are not explored, so when the program or the property has a
//! duration the exhaustive answer is "for every run with these gaps".
//!
//! **The abstract state** (the [`key`](Alphabet::key)): the state; each FSM's
//! state; per agent nothing, stale, or its latest event's letter with its
//! run length capped at the largest `xN` on that agent's events and its age
//! capped just past the largest duration that concerns it (`stale after`,
//! windows on its events); and, only for agents read by two rules that may
//! tie (same salience, same specificity, different targets, overlapping
//! states, no agent on which they need different events), the order of
//! their latest reports (recency). The static checks make such ties errors
//! (E0302) unless they are undecided (W0319), so this is usually empty.

use super::System;
use situ_compiler::bundle::{AlphaNode, BetaKind, Check, Content, FieldType, Operand, Test, Value};
use situ_compiler::spec::{Bound, Consequent, Pred, PropertySpec};
use std::collections::{BTreeMap, BTreeSet};

/// A field's classes: the representatives, and how a value finds its class.
#[derive(Debug, Clone)]
struct FieldClasses {
    reps: Vec<Value>,
    /// The constant comparisons on the field (empty for linked fields).
    checks: Vec<Check>,
    /// Compared with another field: classes are values, not signatures.
    linked: bool,
}

/// An event with a representative payload.
#[derive(Debug, Clone, PartialEq)]
pub struct Letter {
    pub event: u32,
    pub payload: Vec<Value>,
}

/// The abstraction of a program and a set of properties.
#[derive(Debug, Clone)]
pub struct Alphabet {
    fields: Vec<Vec<FieldClasses>>,
    pub letters: Vec<Letter>,
    /// The gaps between events: 0 first, then D + 1 ns for each duration D.
    pub gaps: Vec<u64>,
    /// Per agent: the run length beyond which runs are alike.
    run_cap: Vec<u64>,
    /// Per agent: the age beyond which ages are alike (0: age never matters).
    age_cap: Vec<u64>,
    /// Agents whose order of reports can decide which rule fires.
    recency: Vec<u32>,
    /// What the abstraction samples rather than covers (empty: exact).
    pub samples: Vec<String>,
}

/// The most gaps (an edge stores its gap's index in a byte).
const MAX_GAPS: usize = 255;

/// The most letters one event may have; more are cut (and said).
const MAX_LETTERS_PER_EVENT: usize = 512;

impl Alphabet {
    pub fn new(c: &Content, properties: &[&PropertySpec]) -> Alphabet {
        let n_agents = c.agents.len();
        // Constant comparisons per (event, field), and links between fields.
        let mut checks: Vec<Vec<Vec<Check>>> = c.events.iter().map(|e| vec![Vec::new(); e.fields.len()]).collect();
        let mut links: Vec<((u32, u32), (u32, u32))> = Vec::new();
        // `bound`: the events that earlier joins of the test's chain matched,
        // per agent: there the agent's fact is of that event.
        let mut add_test = |event: u32, t: &Test, bound: &[(u32, u32)], links: &mut Vec<_>| {
            let mut constant = true;
            let mut link = |o: &Operand| match o {
                Operand::Value(_) => {}
                Operand::Own { field } => {
                    constant = false;
                    links.push(((event, t.field), (event, *field)));
                }
                Operand::Fact { agent, field } => {
                    constant = false;
                    // The event its chain joined for that agent, else every
                    // event of the agent with this field index.
                    let events = match bound.iter().find(|(a, _)| a == agent) {
                        Some(&(_, e)) => vec![e],
                        None => c.agents[*agent as usize].events.clone(),
                    };
                    for e in events {
                        if (*field as usize) < c.events[e as usize].fields.len() {
                            links.push(((event, t.field), (e, *field)));
                        }
                    }
                }
            };
            match &t.check {
                Check::Compare { rhs, .. } => link(rhs),
                Check::Range { lo, hi, .. } => {
                    link(lo);
                    link(hi);
                }
            }
            if constant {
                checks[event as usize][t.field as usize].push(t.check.clone());
            }
        };
        let net = &c.network;
        let mut event_of_alpha: Vec<Option<u32>> = vec![None; net.alpha.len()];
        let mut run_cap = vec![1u64; n_agents];
        let mut thresholds: Vec<BTreeSet<u64>> = vec![BTreeSet::new(); n_agents];
        let mut durations: BTreeSet<u64> = BTreeSet::new();
        for (i, node) in net.alpha.iter().enumerate() {
            if let AlphaNode::Event { event, tests, min_run, within_ns } = node {
                event_of_alpha[i] = Some(*event);
                for t in tests {
                    add_test(*event, t, &[], &mut links);
                }
                let agent = c.events[*event as usize].agent as usize;
                run_cap[agent] = run_cap[agent].max(*min_run);
                if let Some(w) = within_ns {
                    thresholds[agent].insert(*w);
                    durations.insert(*w);
                }
            }
        }
        for b in &net.beta {
            if let Some(event) = event_of_alpha[b.alpha as usize] {
                let bound = joined_events(c, b.parent, &event_of_alpha);
                for t in &b.tests {
                    add_test(event, t, &bound, &mut links);
                }
            }
        }
        for p in properties {
            for pred in p.preds() {
                pred.visit(&mut |q| {
                    if let Pred::Event { event, tests, min_run } = q {
                        for t in tests {
                            add_test(*event, t, &[], &mut links);
                        }
                        let agent = c.events[*event as usize].agent as usize;
                        run_cap[agent] = run_cap[agent].max(*min_run);
                    }
                });
            }
            if let Consequent::Eventually { bound: Some(Bound::Nanos(d)), .. } = p.consequent {
                durations.insert(d);
            }
        }
        for (a, agent) in c.agents.iter().enumerate() {
            if let Some(d) = agent.stale_after_ns {
                thresholds[a].insert(d);
                durations.insert(d);
            }
        }
        let age_cap = thresholds.iter().map(|t| t.last().map_or(0, |m| m.saturating_add(1))).collect();
        let mut gaps = vec![0u64];
        gaps.extend(durations.iter().map(|d| d.saturating_add(1)));
        let mut samples = Vec::new();
        if gaps.len() > MAX_GAPS {
            gaps.truncate(MAX_GAPS);
            samples.push(format!("only the {MAX_GAPS} shortest gaps are explored"));
        }

        // Linked fields: groups by union-find, and their merged constants.
        let index: Vec<usize> = c
            .events
            .iter()
            .scan(0usize, |acc, e| {
                let at = *acc;
                *acc += e.fields.len();
                Some(at)
            })
            .collect();
        let total = index.last().map_or(0, |&i| i + c.events.last().map_or(0, |e| e.fields.len()));
        let mut parent: Vec<usize> = (0..total).collect();
        fn find(p: &mut [usize], x: usize) -> usize {
            let mut r = x;
            while p[r] != r {
                r = p[r];
            }
            p[x] = r;
            r
        }
        let mut linked = vec![false; total];
        for ((e1, f1), (e2, f2)) in &links {
            let (a, b) = (index[*e1 as usize] + *f1 as usize, index[*e2 as usize] + *f2 as usize);
            linked[a] = true;
            linked[b] = true;
            let (ra, rb) = (find(&mut parent, a), find(&mut parent, b));
            parent[ra] = rb;
        }
        let mut group_consts: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
        let mut group_size: BTreeMap<usize, usize> = BTreeMap::new();
        for (e, fs) in checks.iter().enumerate() {
            for (f, cs) in fs.iter().enumerate() {
                let i = index[e] + f;
                if linked[i] {
                    let root = find(&mut parent, i);
                    *group_size.entry(root).or_default() += 1;
                    group_consts.entry(root).or_default().extend(cs.iter().flat_map(constants));
                }
            }
        }
        if group_size.values().any(|&n| n > 2) {
            samples.push("values compared with variables are sampled".into());
        }

        let mut fields = Vec::new();
        for (e, event) in c.events.iter().enumerate() {
            let mut per_event = Vec::new();
            for (f, field) in event.fields.iter().enumerate() {
                let i = index[e] + f;
                let classes = if linked[i] {
                    let root = find(&mut parent, i);
                    let consts = group_consts.get(&root).cloned().unwrap_or_default();
                    FieldClasses { reps: candidates(&field.ty, &consts, true), checks: Vec::new(), linked: true }
                } else {
                    let cs = checks[e][f].clone();
                    let consts: Vec<f64> = cs.iter().flat_map(constants).collect();
                    let mut reps: Vec<Value> = Vec::new();
                    let mut seen: Vec<Vec<bool>> = Vec::new();
                    for v in candidates(&field.ty, &consts, false) {
                        let sig: Vec<bool> = cs.iter().map(|ch| check_value(ch, v)).collect();
                        if !seen.contains(&sig) {
                            seen.push(sig);
                            reps.push(v);
                        }
                    }
                    FieldClasses { reps, checks: cs, linked: false }
                };
                per_event.push(classes);
            }
            fields.push(per_event);
        }

        let mut letters = Vec::new();
        for (e, fs) in fields.iter().enumerate() {
            let mut combos: Vec<Vec<Value>> = vec![Vec::new()];
            for fc in fs {
                combos = combos
                    .iter()
                    .flat_map(|p| {
                        fc.reps.iter().map(move |v| {
                            let mut q = p.clone();
                            q.push(*v);
                            q
                        })
                    })
                    .take(MAX_LETTERS_PER_EVENT + 1)
                    .collect();
            }
            if combos.len() > MAX_LETTERS_PER_EVENT {
                combos.truncate(MAX_LETTERS_PER_EVENT);
                samples.push(format!("the payloads of `{}` are cut to {MAX_LETTERS_PER_EVENT}", c.events[e].name));
            }
            letters.extend(combos.into_iter().map(|payload| Letter { event: e as u32, payload }));
        }
        if gaps.len() > 1 {
            samples.push(format!(
                "time gaps of 0 or D + 1ns for D in {}",
                durations.iter().map(|d| super::show_duration(*d)).collect::<Vec<_>>().join(", ")
            ));
        }
        let recency = recency_agents(c);
        Alphabet { fields, letters, gaps, run_cap, age_cap, recency, samples }
    }

    /// Whether the abstraction is exact (nothing sampled).
    pub fn exact(&self) -> bool {
        self.samples.is_empty()
    }

    /// Per agent: the run length beyond which runs are alike (at least 1).
    pub fn run_cap(&self, agent: u32) -> u64 {
        self.run_cap[agent as usize].max(1)
    }

    /// Per agent: the age beyond which ages are alike (0: age never matters).
    pub fn age_cap(&self, agent: u32) -> u64 {
        self.age_cap[agent as usize]
    }

    /// The agents whose order of reports the abstract state keeps.
    pub fn recency(&self) -> &[u32] {
        &self.recency
    }

    /// The class of a value of a field: an index into its representatives.
    pub fn class_of(&self, event: u32, field: usize, v: Value) -> Option<usize> {
        let fc = self.fields.get(event as usize)?.get(field)?;
        if let Some(k) = fc.reps.iter().position(|r| same(*r, v)) {
            return Some(k);
        }
        if fc.linked {
            return None;
        }
        let sig: Vec<bool> = fc.checks.iter().map(|ch| check_value(ch, v)).collect();
        fc.reps.iter().position(|r| fc.checks.iter().map(|ch| check_value(ch, *r)).eq(sig.iter().copied()))
    }

    /// The representative of a value's class (the value itself when it has none).
    pub fn representative(&self, event: u32, field: usize, v: Value) -> Value {
        self.class_of(event, field, v).map_or(v, |k| self.fields[event as usize][field].reps[k])
    }

    /// The abstract state of a system, written into `out`.
    pub fn key(&self, sys: &System, out: &mut Vec<u64>) {
        out.clear();
        let e = &sys.engine;
        out.push(e.state() as u64);
        let c = sys.content();
        for a in 0..c.agents.len() as u32 {
            if let Some(f) = sys.org.fsm_state(a) {
                out.push(f as u64);
            }
            if e.is_stale(a) {
                out.push(u64::MAX);
                continue;
            }
            let Some(fact) = e.fact_view(a) else {
                out.push(u64::MAX - 1);
                continue;
            };
            out.push(fact.event as u64);
            for (i, v) in fact.payload.iter().enumerate() {
                out.push(self.class_of(fact.event, i, *v).map_or(u64::MAX, |k| k as u64));
            }
            out.push(fact.run.min(self.run_cap[a as usize]));
            out.push(e.now().saturating_sub(fact.time).min(self.age_cap[a as usize]));
        }
        if !self.recency.is_empty() {
            let mut order: Vec<(u64, u32)> =
                self.recency.iter().filter_map(|&a| e.fact_view(a).map(|f| (f.seq, a))).collect();
            order.sort_unstable();
            out.extend(order.iter().map(|&(_, a)| a as u64));
        }
    }

    /// The capped ages after a gap, for the agents with a fact: two gaps
    /// with the same signature lead to the same abstract successors.
    pub fn gap_signature(&self, sys: &System, gap: u64, out: &mut Vec<u64>) {
        out.clear();
        let e = &sys.engine;
        for a in 0..sys.content().agents.len() as u32 {
            let cap = self.age_cap[a as usize];
            if cap == 0 {
                continue;
            }
            if let Some(f) = e.fact_view(a) {
                out.push(e.now().saturating_sub(f.time).saturating_add(gap).min(cap));
            }
        }
    }
}

/// Agents read by rules that may tie on salience and specificity.
fn recency_agents(c: &Content) -> Vec<u32> {
    let net = &c.network;
    // Per rule: its allowed states (minus its target) and positive events.
    let mut info: Vec<(BTreeSet<u32>, BTreeMap<u32, u32>)> = Vec::new();
    for t in &net.terminals {
        let mut states = BTreeSet::new();
        let mut events = BTreeMap::new();
        let mut at = Some(t.beta);
        while let Some(b) = at {
            let node = &net.beta[b as usize];
            match &net.alpha[node.alpha as usize] {
                AlphaNode::State { states: s } => states.extend(s.iter().copied()),
                AlphaNode::Event { event, .. } if node.kind == BetaKind::Join => {
                    events.insert(c.events[*event as usize].agent, *event);
                }
                _ => {}
            }
            at = node.parent;
        }
        info.push((states, events));
    }
    let mut agents = BTreeSet::new();
    for (i, a) in c.rules.iter().enumerate() {
        for (j, b) in c.rules.iter().enumerate().skip(i + 1) {
            if a.salience != b.salience || a.specificity != b.specificity || a.target == b.target {
                continue;
            }
            let (sa, ea) = &info[i];
            let (sb, eb) = &info[j];
            // A rule without a state test may fire in every state.
            let in_a = |s: u32| sa.is_empty() || sa.contains(&s);
            let in_b = |s: u32| sb.is_empty() || sb.contains(&s);
            let overlap = (0..c.states.len() as u32).any(|s| in_a(s) && in_b(s) && s != a.target && s != b.target);
            let exclusive = ea.iter().any(|(agent, e)| eb.get(agent).is_some_and(|f| f != e));
            if overlap && !exclusive {
                agents.extend(a.matches.iter().chain(&b.matches).copied());
            }
        }
    }
    agents.into_iter().collect()
}

/// The constants of a check, as numbers (symbols and bools by index).
fn constants(ch: &Check) -> Vec<f64> {
    let num = |o: &Operand| match o {
        Operand::Value(Value::F64(f)) if !f.is_nan() => Some(*f),
        Operand::Value(Value::I64(i)) => Some(*i as f64),
        _ => None,
    };
    match ch {
        Check::Compare { rhs, .. } => num(rhs).into_iter().collect(),
        Check::Range { lo, hi, .. } => num(lo).into_iter().chain(num(hi)).collect(),
    }
}

fn check_value(ch: &Check, v: Value) -> bool {
    situ_runtime::rete::passes(&Test { field: 0, check: ch.clone() }, &[v])
}

fn same(a: Value, b: Value) -> bool {
    match (a, b) {
        (Value::F64(x), Value::F64(y)) => x.to_bits() == y.to_bits(),
        _ => a == b,
    }
}

/// Candidate values of a field: they meet every signature of comparisons
/// with `consts` (two inside each open interval when `two`).
/// Per agent, the event that a positive join above `parent` (in a rule's
/// chain) matched: wherever the chain's tests run, that agent's fact is of
/// that event (one fact per agent). The nearest join wins.
fn joined_events(c: &Content, mut parent: Option<u32>, event_of_alpha: &[Option<u32>]) -> Vec<(u32, u32)> {
    let mut out: Vec<(u32, u32)> = Vec::new();
    while let Some(p) = parent {
        let node = &c.network.beta[p as usize];
        if node.kind == BetaKind::Join {
            if let Some(e) = event_of_alpha[node.alpha as usize] {
                let agent = c.events[e as usize].agent;
                if !out.iter().any(|(a, _)| *a == agent) {
                    out.push((agent, e));
                }
            }
        }
        parent = node.parent;
    }
    out
}

fn candidates(ty: &FieldType, consts: &[f64], two: bool) -> Vec<Value> {
    let mut cs: Vec<f64> = consts.iter().copied().filter(|c| c.is_finite()).collect();
    cs.sort_by(f64::total_cmp);
    cs.dedup();
    match ty {
        FieldType::F64 => {
            let mut out = Vec::new();
            if cs.is_empty() {
                out.push(0.0);
                if two {
                    out.push(1.0);
                }
            } else {
                let (lo, hi) = (cs[0], cs[cs.len() - 1]);
                // Below the smallest constant: 0 when it is positive (most
                // quantities are), else the integer below.
                out.push(if lo > 0.0 { 0.0 } else { lo.floor() - 1.0 });
                if two {
                    out.push(lo.floor() - 2.0);
                }
                for w in cs.windows(2) {
                    if two {
                        if let Some(m) = between(w[0], w[1]) {
                            out.extend(between(w[0], m));
                            out.extend(between(m, w[1]));
                        }
                    } else {
                        out.extend(between(w[0], w[1]));
                    }
                }
                out.extend(cs.iter().copied());
                out.push(hi.ceil() + 1.0);
                if two {
                    out.push(hi.ceil() + 2.0);
                }
            }
            // The infinities compared with are values of their own.
            out.extend(consts.iter().copied().filter(|c| c.is_infinite()));
            out.push(f64::NAN);
            out.into_iter().map(Value::F64).collect()
        }
        FieldType::I64 => {
            let mut out: Vec<i64> = Vec::new();
            let is: Vec<i64> = cs.iter().map(|c| *c as i64).collect();
            if is.is_empty() {
                out.push(0);
                if two {
                    out.push(1);
                }
            }
            for (k, &c) in is.iter().enumerate() {
                out.extend([c.saturating_sub(1), c, c.saturating_add(1)]);
                if two {
                    out.extend([c.saturating_sub(2), c.saturating_add(2)]);
                }
                if let Some(&d) = is.get(k + 1) {
                    out.push(c + (d - c) / 2);
                }
            }
            out.sort_unstable();
            out.dedup();
            out.into_iter().map(Value::I64).collect()
        }
        FieldType::Bool => vec![Value::Bool(false), Value::Bool(true)],
        FieldType::Symbols(s) => (0..s.len() as u32).map(Value::Symbol).collect(),
    }
}

/// A round value strictly between `a` and `b`, if there is one.
fn between(a: f64, b: f64) -> Option<f64> {
    let mid = a + (b - a) / 2.0;
    for decimals in 0..10 {
        let scale = 10f64.powi(decimals);
        let m = (mid * scale).round() / scale;
        if a < m && m < b {
            return Some(m);
        }
    }
    (a < mid && mid < b).then_some(mid)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_values_between_constants() {
        assert_eq!(between(0.15, 0.3), Some(0.2));
        assert_eq!(between(5.0, 20.0), Some(13.0));
        assert_eq!(between(1.0, 1.0), None);
    }

    #[test]
    fn one_representative_per_signature() {
        let lt = |c: f64| Check::Compare { op: situ_compiler::bundle::Cmp::Lt, rhs: Operand::Value(Value::F64(c)) };
        let cs = [lt(5.0), lt(20.0), lt(30.0)];
        let mut sigs = BTreeSet::new();
        for v in candidates(&FieldType::F64, &[5.0, 20.0, 30.0], false) {
            sigs.insert(cs.iter().map(|ch| check_value(ch, v)).collect::<Vec<_>>());
        }
        // x < 5, 5 <= x < 20, 20 <= x < 30, x >= 30 or NaN.
        assert_eq!(sigs.len(), 4);
    }
}
