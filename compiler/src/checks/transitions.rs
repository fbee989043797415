//! The state transition graph of a model: an edge `s -> t` for every rule
//! with target `t` whose conditions can hold in state `s` (`s != t`), with a
//! witness memory. Reachability and path witnesses come from here.

use super::situation::{Situation, Unsat, Witness};
use crate::model::*;
use std::collections::{BTreeSet, VecDeque};

/// One possible firing.
#[derive(Debug, Clone)]
pub struct Edge {
    pub from: StateId,
    pub to: StateId,
    pub rule: RuleId,
    pub witness: Witness,
}

/// The graph, and for each rule its situation or why it has none.
#[derive(Debug, Clone)]
pub struct Transitions {
    pub edges: Vec<Edge>,
    pub situations: Vec<Result<Situation, Unsat>>,
}

impl Transitions {
    pub fn build(model: &Model) -> Transitions {
        let mut edges = Vec::new();
        let mut situations = Vec::new();
        for (i, rule) in model.rules.iter().enumerate() {
            let sit = Situation::of_rule(model, rule);
            let sit = sit.and_then(|s| s.witness(model).map(|_| s));
            if let Ok(s) = &sit {
                for &from in s.states.iter().filter(|&&st| st != rule.target) {
                    let mut at = s.clone();
                    at.states = BTreeSet::from([from]);
                    if let Ok(witness) = at.witness(model) {
                        edges.push(Edge { from, to: rule.target, rule: RuleId(i as u32), witness });
                    }
                }
            }
            situations.push(sit);
        }
        Transitions { edges, situations }
    }

    /// For every state, the edge by which a shortest path from `start`
    /// reaches it (`None` for `start` and for unreachable states), and
    /// whether it is reachable.
    pub fn shortest_paths(&self, model: &Model, start: StateId) -> Vec<Option<Option<usize>>> {
        let mut pred: Vec<Option<Option<usize>>> = vec![None; model.states.len()];
        pred[start.index()] = Some(None);
        let mut queue = VecDeque::from([start]);
        while let Some(s) = queue.pop_front() {
            for (i, e) in self.edges.iter().enumerate().filter(|(_, e)| e.from == s) {
                if pred[e.to.index()].is_none() {
                    pred[e.to.index()] = Some(Some(i));
                    queue.push_back(e.to);
                }
            }
        }
        pred
    }

    /// The edges of a shortest path to `target`, in order.
    pub fn path(&self, pred: &[Option<Option<usize>>], target: StateId) -> Option<Vec<&Edge>> {
        let mut path = Vec::new();
        let mut at = target;
        loop {
            match pred[at.index()]? {
                None => break,
                Some(e) => {
                    path.push(&self.edges[e]);
                    at = self.edges[e].from;
                }
            }
        }
        path.reverse();
        Some(path)
    }
}
