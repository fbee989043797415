//! Builds the Rete network of a checked model (the format is
//! [`situ_bundle::Network`], documented there).
//!
//! Each rule becomes one chain of beta nodes, in this order:
//! 1. a join on the state fact (its guards' intersection minus its target);
//! 2. a join per positive pattern, in source order;
//! 3. a join per `stale A`, a negative node per `not stale A`;
//! 4. a negative node per `not P` (last, so that every variable is bound).
//!
//! Tests on one fact alone go to the pattern's alpha node; comparisons with
//! a variable bound in another pattern go to the beta node of whichever of
//! the two patterns comes later in the chain (flipping the comparison when
//! it is the variable's pattern). Identical alpha nodes, and identical beta
//! nodes under the same parent, are built once.

use crate::model::{self, FieldCheck, Model, Pattern, Rule, VarId};
use situ_bundle::{
    self as bundle, AlphaNode, BetaKind, BetaNode, Check, Cmp, Network, NetworkStats, Operand, Terminal, Test,
};
use situ_grammar::ast::CmpOp;
use std::collections::HashMap;

/// The network of every rule of `model`, in rule order.
pub fn build(model: &Model) -> Network {
    let mut b = Builder::default();
    for (i, rule) in model.rules.iter().enumerate() {
        let beta = b.rule(model, rule);
        b.terminals.push(Terminal { rule: i as u32, beta });
    }
    let stats = NetworkStats {
        alpha_unshared: b.alpha_unshared,
        alpha: b.alpha.len() as u32,
        beta_unshared: b.beta_unshared,
        beta: b.beta.len() as u32,
        terminals: b.terminals.len() as u32,
    };
    Network { alpha: b.alpha, beta: b.beta, terminals: b.terminals, stats }
}

#[derive(Default)]
struct Builder {
    alpha: Vec<AlphaNode>,
    alpha_index: HashMap<String, u32>,
    beta: Vec<BetaNode>,
    beta_index: HashMap<String, u32>,
    terminals: Vec<Terminal>,
    alpha_unshared: u32,
    beta_unshared: u32,
}

/// One side of a comparison: a field of the fact of a condition of the
/// rule's chain (positive patterns are conditions `0..n`), or a constant.
#[derive(Clone, Copy)]
enum Term {
    Field { cond: usize, field: u32 },
    Value(bundle::Value),
}

/// `lhs op rhs`.
struct Comparison {
    lhs: Term,
    op: Cmp,
    rhs: Term,
}

impl Builder {
    fn alpha(&mut self, node: AlphaNode) -> u32 {
        self.alpha_unshared += 1;
        let key = serde_json::to_string(&node).expect("alpha nodes serialize");
        let next = self.alpha.len() as u32;
        *self.alpha_index.entry(key).or_insert_with(|| {
            self.alpha.push(node);
            next
        })
    }

    fn beta(&mut self, node: BetaNode) -> u32 {
        self.beta_unshared += 1;
        let key = serde_json::to_string(&node).expect("beta nodes serialize");
        let next = self.beta.len() as u32;
        *self.beta_index.entry(key).or_insert_with(|| {
            self.beta.push(node);
            next
        })
    }

    /// Builds a rule's chain; returns its last beta node.
    fn rule(&mut self, model: &Model, rule: &Rule) -> u32 {
        let agent_of = |p: &Pattern| model.event(p.event).agent.0;
        let mut states: Vec<u32> = match rule.allowed_states() {
            Some(s) => s.into_iter().map(|s| s.0).collect(),
            None => (0..model.states.len() as u32).collect(),
        };
        states.retain(|&s| s != rule.target.0);
        let state = self.alpha(AlphaNode::State { states });
        let mut parent = self.beta(BetaNode { parent: None, kind: BetaKind::Join, alpha: state, tests: vec![] });

        // Where each of the rule's variables is bound: (positive pattern, field).
        let mut sites: HashMap<VarId, (usize, u32)> = HashMap::new();
        for (i, p) in rule.patterns.iter().enumerate() {
            for t in &p.tests {
                if let FieldCheck::Bind(v) = t.check {
                    sites.entry(v).or_insert((i, t.field as u32));
                }
            }
        }
        // Positive patterns: alpha tests, and beta tests placed at the later
        // of the two patterns they compare.
        let n = rule.patterns.len();
        let mut alpha_tests: Vec<Vec<Test>> = vec![Vec::new(); n];
        let mut beta_tests: Vec<Vec<Test>> = vec![Vec::new(); n];
        for (i, p) in rule.patterns.iter().enumerate() {
            for c in comparisons(p, i, &|v| sites.get(&v).copied()) {
                place(c, i, &mut alpha_tests, &mut beta_tests, &|cond| agent_of(&rule.patterns[cond]));
            }
            alpha_tests[i].extend(ranges(p));
        }
        for (i, p) in rule.patterns.iter().enumerate() {
            let alpha = self.alpha(AlphaNode::Event {
                event: p.event.0,
                tests: std::mem::take(&mut alpha_tests[i]),
                min_run: p.run_length,
                within_ns: p.within,
            });
            let tests = std::mem::take(&mut beta_tests[i]);
            parent = self.beta(BetaNode { parent: Some(parent), kind: BetaKind::Join, alpha, tests });
        }
        for s in &rule.stale {
            let alpha = self.alpha(AlphaNode::Stale { agent: s.agent.0 });
            let kind = if s.negated { BetaKind::Negative } else { BetaKind::Join };
            parent = self.beta(BetaNode { parent: Some(parent), kind, alpha, tests: vec![] });
        }
        // Negations: the rule's variables (bound in positive patterns) are
        // beta tests; variables first bound inside `not` are local (alpha).
        let outer = rule.variables.len();
        for neg in &rule.negations {
            let mut local: HashMap<VarId, (usize, u32)> = HashMap::new();
            for t in &neg.tests {
                if let FieldCheck::Bind(v) = t.check {
                    local.entry(v).or_insert((n, t.field as u32));
                }
            }
            let site = |v: VarId| if v < outer { sites.get(&v).copied() } else { local.get(&v).copied() };
            let mut alpha_t: Vec<Vec<Test>> = vec![Vec::new(); n + 1];
            let mut beta_t: Vec<Vec<Test>> = vec![Vec::new(); n + 1];
            for c in comparisons(neg, n, &site) {
                place(c, n, &mut alpha_t, &mut beta_t, &|cond| {
                    if cond == n {
                        agent_of(neg)
                    } else {
                        agent_of(&rule.patterns[cond])
                    }
                });
            }
            let mut tests = std::mem::take(&mut alpha_t[n]);
            tests.extend(ranges(neg));
            let alpha = self.alpha(AlphaNode::Event {
                event: neg.event.0,
                tests,
                min_run: neg.run_length,
                within_ns: neg.within,
            });
            let tests = std::mem::take(&mut beta_t[n]);
            parent = self.beta(BetaNode { parent: Some(parent), kind: BetaKind::Negative, alpha, tests });
        }
        parent
    }
}

/// Places a comparison: on one fact, an alpha test of that condition; on
/// two, a beta test of the later one, written from its side.
fn place(c: Comparison, own: usize, alpha: &mut [Vec<Test>], beta: &mut [Vec<Test>], agent_of: &dyn Fn(usize) -> u32) {
    let (lhs_cond, lhs_field) = match c.lhs {
        Term::Field { cond, field } => (cond, field),
        Term::Value(_) => unreachable!("the left side of a comparison is the pattern's own field"),
    };
    debug_assert_eq!(lhs_cond, own);
    match c.rhs {
        Term::Value(v) => {
            alpha[own].push(Test { field: lhs_field, check: Check::Compare { op: c.op, rhs: Operand::Value(v) } })
        }
        Term::Field { cond, field } if cond == own => {
            alpha[own].push(Test { field: lhs_field, check: Check::Compare { op: c.op, rhs: Operand::Own { field } } })
        }
        Term::Field { cond, field } if cond < own => beta[own].push(Test {
            field: lhs_field,
            check: Check::Compare { op: c.op, rhs: Operand::Fact { agent: agent_of(cond), field } },
        }),
        Term::Field { cond, field } => beta[cond].push(Test {
            field,
            check: Check::Compare { op: flip(c.op), rhs: Operand::Fact { agent: agent_of(own), field: lhs_field } },
        }),
    }
}

/// The comparisons of a pattern (condition `cond`), with variables resolved
/// to the fields they are bound to; ranges with a variable end are split in
/// two comparisons. Constant ranges are left to [`ranges`].
fn comparisons(p: &Pattern, cond: usize, site: &dyn Fn(VarId) -> Option<(usize, u32)>) -> Vec<Comparison> {
    let term = |o: &model::Operand| match o {
        model::Operand::Value(v) => Some(Term::Value(value(*v))),
        model::Operand::Var(v) => site(*v).map(|(cond, field)| Term::Field { cond, field }),
    };
    let mut out = Vec::new();
    for t in &p.tests {
        let lhs = Term::Field { cond, field: t.field as u32 };
        match &t.check {
            FieldCheck::Bind(_) => {}
            FieldCheck::Compare { op, rhs } => {
                if let Some(rhs) = term(rhs) {
                    out.push(Comparison { lhs, op: cmp(*op), rhs });
                }
            }
            FieldCheck::Range { lo, hi, inclusive } => {
                let constant = matches!((lo, hi), (model::Operand::Value(_), model::Operand::Value(_)));
                if !constant {
                    if let (Some(lo), Some(hi)) = (term(lo), term(hi)) {
                        out.push(Comparison { lhs, op: Cmp::Ge, rhs: lo });
                        out.push(Comparison { lhs, op: if *inclusive { Cmp::Le } else { Cmp::Lt }, rhs: hi });
                    }
                }
            }
        }
    }
    out
}

/// The constant ranges of a pattern, as alpha tests.
fn ranges(p: &Pattern) -> Vec<Test> {
    p.tests
        .iter()
        .filter_map(|t| match &t.check {
            FieldCheck::Range { lo: model::Operand::Value(lo), hi: model::Operand::Value(hi), inclusive } => {
                Some(Test {
                    field: t.field as u32,
                    check: Check::Range {
                        lo: Operand::Value(value(*lo)),
                        hi: Operand::Value(value(*hi)),
                        inclusive: *inclusive,
                    },
                })
            }
            _ => None,
        })
        .collect()
}

/// The tests of a pattern that stands alone (a property's event atom): its
/// variables are local, so every test is on its own fact (alpha tests).
pub fn pattern_alone(p: &Pattern) -> Vec<Test> {
    let mut sites: HashMap<VarId, (usize, u32)> = HashMap::new();
    for t in &p.tests {
        if let FieldCheck::Bind(v) = t.check {
            sites.entry(v).or_insert((0, t.field as u32));
        }
    }
    let mut alpha = vec![Vec::new()];
    let mut beta = vec![Vec::new()];
    for c in comparisons(p, 0, &|v| sites.get(&v).copied()) {
        place(c, 0, &mut alpha, &mut beta, &|_| 0);
    }
    let mut tests = std::mem::take(&mut alpha[0]);
    tests.extend(ranges(p));
    tests
}

/// `a op b` is `b flip(op) a`.
fn flip(op: Cmp) -> Cmp {
    match op {
        Cmp::Lt => Cmp::Gt,
        Cmp::Le => Cmp::Ge,
        Cmp::Gt => Cmp::Lt,
        Cmp::Ge => Cmp::Le,
        other => other,
    }
}

pub(crate) fn cmp(op: CmpOp) -> Cmp {
    match op {
        CmpOp::Eq => Cmp::Eq,
        CmpOp::Ne => Cmp::Ne,
        CmpOp::Lt => Cmp::Lt,
        CmpOp::Le => Cmp::Le,
        CmpOp::Gt => Cmp::Gt,
        CmpOp::Ge => Cmp::Ge,
    }
}

pub(crate) fn value(v: model::Value) -> bundle::Value {
    match v {
        model::Value::F64(f) => bundle::Value::F64(f),
        model::Value::I64(i) => bundle::Value::I64(i),
        model::Value::Bool(b) => bundle::Value::Bool(b),
        model::Value::Symbol(s) => bundle::Value::Symbol(s),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_source;

    const STACK: &str = "states { IT initial RS RO EM }
        agent LADAR sensor { stale after 300ms event LAOBS { distance: f64, height: f64 } event LAOBN }
        agent STCCD sensor { event STOBS { distance: f64 } event STOBN }
        agent Hinder processing { event HINDER { influence: f64 } }
    ";

    fn network(rules: &str) -> Network {
        let c = check_source("t.situ", &format!("{STACK}{rules}"));
        // Only the front end matters here: unreachable states are fine.
        let errors: Vec<_> = c.diagnostics.iter().filter(|d| d.code < "E0300").collect();
        assert!(errors.is_empty(), "{errors:?}");
        build(&c.model)
    }

    #[test]
    fn identical_tests_and_prefixes_are_shared() {
        let net = network(
            "rule a salience 10 { when state in {RS, IT} and LAOBS(distance < 30.0) then RO }
             rule b salience 10 { when state in {RS, IT} and LAOBS(distance < 30.0) and STOBS then RO }
             rule c { when state == RO and LAOBN x3 then RS }",
        );
        // a and b share the state join and the LAOBS join; b adds one node.
        assert_eq!(net.stats.beta_unshared, 2 + 3 + 2);
        assert_eq!(net.stats.beta, 2 + 1 + 2);
        assert_eq!(net.stats.alpha_unshared, 2 + 3 + 2);
        assert_eq!(net.stats.alpha, 2 + 1 + 2);
        assert_eq!(net.stats.saved(), 4);
        let (ta, tb) = (&net.terminals[0], &net.terminals[1]);
        assert_eq!(net.beta[tb.beta as usize].parent, Some(ta.beta));
    }

    #[test]
    fn the_state_join_excludes_the_target() {
        let net = network("rule a { when LAOBS then RO }");
        assert_eq!(net.alpha[0], AlphaNode::State { states: vec![0, 1, 3] });
    }

    #[test]
    fn a_variable_bound_later_is_tested_at_its_binding_pattern() {
        let net = network("rule a { when STOBS(distance <= ?r) and HINDER(influence: ?r) then RO }");
        let last = &net.beta[net.terminals[0].beta as usize];
        assert_eq!(
            last.tests,
            vec![Test { field: 0, check: Check::Compare { op: Cmp::Ge, rhs: Operand::Fact { agent: 1, field: 0 } } }]
        );
    }

    #[test]
    fn negations_stale_and_local_variables() {
        let net = network(
            "rule a { when LAOBS(distance: ?d) and not STOBS(distance: ?d) and not stale LADAR then RO }
             rule b { when LAOBN and not LAOBS(distance: ?x, height == ?x) then RO }",
        );
        let chain = |t: &Terminal| {
            let mut out = Vec::new();
            let mut at = Some(t.beta);
            while let Some(b) = at {
                out.push(net.beta[b as usize].clone());
                at = net.beta[b as usize].parent;
            }
            out.reverse();
            out
        };
        let a = chain(&net.terminals[0]);
        let kinds: Vec<BetaKind> = a.iter().map(|b| b.kind).collect();
        assert_eq!(kinds, [BetaKind::Join, BetaKind::Join, BetaKind::Negative, BetaKind::Negative]);
        assert_eq!(net.alpha[a[2].alpha as usize], AlphaNode::Stale { agent: 0 });
        assert_eq!(
            a[3].tests,
            vec![Test { field: 0, check: Check::Compare { op: Cmp::Eq, rhs: Operand::Fact { agent: 0, field: 0 } } }]
        );
        let b = chain(&net.terminals[1]);
        let AlphaNode::Event { tests, .. } = &net.alpha[b[2].alpha as usize] else { panic!("an event node") };
        assert_eq!(
            tests,
            &vec![Test { field: 1, check: Check::Compare { op: Cmp::Eq, rhs: Operand::Own { field: 0 } } }]
        );
        assert!(b[2].tests.is_empty());
    }
}
