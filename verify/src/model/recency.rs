//! The order of the latest reports, for rules that tie on salience and
//! specificity (§10.4: the rule whose newest matched fact was posted last).

use super::Slot;
use crate::aig::{not, Aig, Lit, FALSE, TRUE};

/// The order of the latest reports of some agents: for each pair (a, b),
/// a < b, a latch that holds when a reported after b.
#[derive(Debug, Clone)]
pub(super) struct Recency {
    pub(super) agents: Vec<u32>,
    pub(super) newer: Vec<Lit>,
}

impl Recency {
    pub(super) fn latches(aig: &mut Aig, agents: &[u32]) -> Recency {
        let mut newer = Vec::new();
        for (i, a) in agents.iter().enumerate() {
            for b in &agents[i + 1..] {
                newer.push(aig.latch(&format!("newer{a}_{b}")));
            }
        }
        Recency { agents: agents.to_vec(), newer }
    }

    fn pair(&self, a: u32, b: u32) -> Option<usize> {
        let i = self.agents.iter().position(|&x| x == a)?;
        let j = self.agents.iter().position(|&x| x == b)?;
        let (i, j) = (i.min(j), i.max(j));
        let k = self.agents.len();
        Some(i * k - i * (i + 1) / 2 + (j - i - 1))
    }

    /// Whether `a` reported after `b` (both in the order).
    pub(super) fn newer(&self, a: u32, b: u32) -> Lit {
        let ia = self.agents.iter().position(|&x| x == a);
        let ib = self.agents.iter().position(|&x| x == b);
        match (self.pair(a, b), ia < ib) {
            (Some(p), true) => self.newer[p],
            (Some(p), false) => not(self.newer[p]),
            (None, _) => FALSE,
        }
    }

    /// The order after the chosen letter's agent reported.
    pub(super) fn after(&self, aig: &mut Aig, slots: &[Slot], lsel: &[Lit]) -> Recency {
        let reports: Vec<Lit> =
            self.agents.iter().map(|&a| aig.or_all(slots[a as usize].letters.iter().map(|&l| lsel[l]))).collect();
        let mut newer = Vec::new();
        for i in 0..self.agents.len() {
            for j in i + 1..self.agents.len() {
                let old = self.newer[newer.len()];
                // a_i reports: it is newer; a_j reports: it is; else unchanged.
                let x = aig.mux(reports[j], FALSE, old);
                newer.push(aig.mux(reports[i], TRUE, x));
            }
        }
        Recency { agents: self.agents.clone(), newer }
    }

    /// Whether rule x (matching the agents `mx`) beats rule y (`my`) of the
    /// same salience and specificity: the newest report among both is only
    /// x's (rules matching no fact come last), or neither's alone and x is
    /// declared first.
    pub(super) fn beats(&self, aig: &mut Aig, mx: &[u32], my: &[u32], first: bool) -> Lit {
        let all: Vec<u32> = mx.iter().chain(my).copied().collect();
        let tracked = all.iter().all(|a| self.agents.contains(a));
        if !tracked {
            // These two never tie on recency (see `Alphabet::recency`).
            return if first { TRUE } else { FALSE };
        }
        let newest_only = |aig: &mut Aig, own: &[u32], other: &[u32]| {
            let cands: Vec<Lit> = own
                .iter()
                .filter(|a| !other.contains(a))
                .map(|&a| {
                    let ls: Vec<Lit> = all.iter().filter(|&&b| b != a).map(|&b| self.newer(a, b)).collect();
                    aig.and_all(ls)
                })
                .collect();
            aig.or_all(cands)
        };
        let x_wins = newest_only(aig, mx, my);
        let y_wins = newest_only(aig, my, mx);
        let tie = aig.and(not(x_wins), not(y_wins));
        let by_order = if first { tie } else { FALSE };
        aig.or(x_wins, by_order)
    }
}
