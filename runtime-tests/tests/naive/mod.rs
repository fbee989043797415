//! A naive reference evaluator of situation rules, written from the
//! language reference (§10.2–10.4) and nothing else: after every change it
//! re-evaluates every rule against the whole working memory, straight from
//! the checked model's conditions. Slow and obviously right; the Rete engine
//! must agree with it on every stream.

use situ_compiler::bundle::Value;
use situ_compiler::model::{self, FieldCheck, Model, Operand, Pattern, Rule, StateId};
use std::collections::HashMap;

#[derive(Debug, Clone)]
struct Fact {
    event: usize,
    payload: Vec<Value>,
    time: u64,
    run: u64,
    seq: u64,
}

pub struct Naive<'m> {
    model: &'m Model,
    pub state: StateId,
    facts: Vec<Option<Fact>>,
    now: u64,
    seq: u64,
    /// Per agent, the stamp of its latest accepted event.
    last: Vec<u64>,
}

/// The rules fired while processing one event, in order; `Err` when the
/// cascade bound (64 per event) was hit.
pub type Fired = Result<Vec<usize>, Vec<usize>>;

impl<'m> Naive<'m> {
    pub fn new(model: &'m Model) -> Self {
        Naive {
            model,
            state: model.initial.expect("an initial state"),
            facts: vec![None; model.agents.len()],
            now: 0,
            seq: 0,
            last: vec![0; model.agents.len()],
        }
    }

    pub fn reset(&mut self) {
        self.state = self.model.initial.expect("an initial state");
        self.facts.fill(None);
    }

    /// Processes one event (§10.4); `None` when it is refused: stamped
    /// before its agent's latest accepted event (no arrival clock here, so
    /// nothing is from the future).
    pub fn post(&mut self, event: usize, time: u64, payload: &[Value]) -> Option<Fired> {
        let agent = self.model.events[event].agent.index();
        if time < self.last[agent] {
            return None;
        }
        self.last[agent] = time;
        Some(self.process(event, agent, time, payload))
    }

    fn process(&mut self, event: usize, agent: usize, time: u64, payload: &[Value]) -> Fired {
        self.now = self.now.max(time);
        let mut fired = Vec::new();
        self.rest(&mut fired)?;
        let run = match &self.facts[agent] {
            Some(f) if self.live(agent, f) && f.event == event => f.run + 1,
            _ => 1,
        };
        self.seq += 1;
        self.facts[agent] = Some(Fact { event, payload: payload.to_vec(), time, run, seq: self.seq });
        self.rest(&mut fired)?;
        Ok(fired)
    }

    fn rest(&mut self, fired: &mut Vec<usize>) -> Result<(), Vec<usize>> {
        loop {
            let activated: Vec<usize> =
                (0..self.model.rules.len()).filter(|&r| self.holds(&self.model.rules[r])).collect();
            let Some(best) = activated.into_iter().max_by_key(|&r| {
                let rule = &self.model.rules[r];
                (rule.salience, rule.specificity(), self.recency(rule), std::cmp::Reverse(r))
            }) else {
                return Ok(());
            };
            if fired.len() == 64 {
                return Err(std::mem::take(fired));
            }
            fired.push(best);
            self.state = self.model.rules[best].target;
        }
    }

    fn live(&self, agent: usize, f: &Fact) -> bool {
        match self.model.agents[agent].stale_after {
            Some(d) => self.now.saturating_sub(f.time) <= d,
            None => true,
        }
    }

    fn stale(&self, agent: usize) -> bool {
        self.facts[agent].as_ref().is_some_and(|f| !self.live(agent, f))
    }

    fn recency(&self, rule: &Rule) -> u64 {
        rule.patterns
            .iter()
            .filter_map(|p| self.facts[self.model.events[p.event.index()].agent.index()].as_ref().map(|f| f.seq))
            .max()
            .unwrap_or(0)
    }

    fn holds(&self, rule: &Rule) -> bool {
        if self.state == rule.target || !rule.allowed_states().is_none_or(|s| s.contains(&self.state)) {
            return false;
        }
        if !rule.stale.iter().all(|s| self.stale(s.agent.index()) != s.negated) {
            return false;
        }
        // Bind the rule's variables from their binding sites first: a
        // comparison may come before the binding in the source.
        let mut vars: HashMap<usize, Value> = HashMap::new();
        for p in &rule.patterns {
            let Some(f) = self.matching_fact(p) else { return false };
            for t in &p.tests {
                if let FieldCheck::Bind(v) = t.check {
                    vars.entry(v).or_insert(f.payload[t.field]);
                }
            }
        }
        rule.patterns.iter().all(|p| self.matches(p, &vars)) && !rule.negations.iter().any(|n| self.matches(n, &vars))
    }

    /// The agent's live fact of the pattern's event with run and window ok.
    fn matching_fact(&self, p: &Pattern) -> Option<&Fact> {
        let agent = self.model.events[p.event.index()].agent.index();
        let f = self.facts[agent].as_ref()?;
        let ok = self.live(agent, f)
            && f.event == p.event.index()
            && f.run >= p.run_length
            && p.within.is_none_or(|w| self.now.saturating_sub(f.time) <= w);
        ok.then_some(f)
    }

    fn matches(&self, p: &Pattern, outer: &HashMap<usize, Value>) -> bool {
        let Some(f) = self.matching_fact(p) else { return false };
        let mut vars = outer.clone();
        for t in &p.tests {
            if let FieldCheck::Bind(v) = t.check {
                vars.entry(v).or_insert(f.payload[t.field]);
            }
        }
        p.tests.iter().all(|t| {
            let x = f.payload[t.field];
            let get = |o: &Operand| match o {
                Operand::Value(v) => Some(value(*v)),
                Operand::Var(v) => vars.get(v).copied(),
            };
            match &t.check {
                FieldCheck::Bind(_) => true,
                FieldCheck::Compare { op, rhs } => get(rhs).is_some_and(|y| cmp(*op, x, y)),
                FieldCheck::Range { lo, hi, inclusive } => match (get(lo), get(hi)) {
                    (Some(lo), Some(hi)) => {
                        use situ_grammar::ast::CmpOp::*;
                        cmp(Ge, x, lo) && cmp(if *inclusive { Le } else { Lt }, x, hi)
                    }
                    _ => false,
                },
            }
        })
    }
}

fn value(v: model::Value) -> Value {
    match v {
        model::Value::F64(f) => Value::F64(f),
        model::Value::I64(i) => Value::I64(i),
        model::Value::Bool(b) => Value::Bool(b),
        model::Value::Symbol(s) => Value::Symbol(s),
    }
}

/// `x op y` as §10.3 says; numbers compare as f64 (the streams of these
/// tests stay far below 2^53, where that is exact).
fn cmp(op: situ_grammar::ast::CmpOp, x: Value, y: Value) -> bool {
    use situ_grammar::ast::CmpOp::*;
    let num = |v: Value| match v {
        Value::F64(f) => Some(f),
        Value::I64(i) => Some(i as f64),
        _ => None,
    };
    if let (Some(a), Some(b)) = (num(x), num(y)) {
        if a.is_nan() || b.is_nan() {
            return false;
        }
        return match op {
            Eq => a == b,
            Ne => a != b,
            Lt => a < b,
            Le => a <= b,
            Gt => a > b,
            Ge => a >= b,
        };
    }
    let equal = match (x, y) {
        (Value::Bool(a), Value::Bool(b)) => a == b,
        (Value::Symbol(a), Value::Symbol(b)) => a == b,
        _ => return false,
    };
    match op {
        Eq => equal,
        Ne => !equal,
        _ => false,
    }
}
