//! Inference (language reference §10.4): the state set with the state
//! alpha nodes it flips, the activated rule that fires first, and the rest:
//! firing until no rule is activated, each firing recorded with the facts
//! it matched (for explanations) in the buffers of the step.

use super::fast::at;
use super::net::Net;
use super::{AgentRec, Engine, FactRec, FiringRec, Record, StepError};
use situ_bundle::Value;

impl Engine {
    pub(super) fn set_state(&mut self, state: u32) {
        let old = self.state;
        if old == state {
            return;
        }
        self.state = state;
        // Only the state alpha nodes that contain one of the two states flip.
        for s in [old, state] {
            let (lo, hi) = self.net.state_alpha_at[s as usize];
            for i in lo..hi {
                let a = self.net.state_alpha[i as usize] as usize;
                let pass = self.net.state_in(&self.net.alpha[a], state);
                if pass != self.alpha_mem[a] {
                    self.alpha_mem[a] = pass;
                    self.mark_succ(a);
                }
            }
        }
        self.propagate();
    }

    /// The activated rule that fires first (§10.4), if any.
    pub(super) fn best(&self) -> Option<u32> {
        let mut best: Option<(u32, (i64, u32, u64))> = None;
        for &r in &self.active {
            let rule = &self.net.rules[r as usize];
            let (s, e) = rule.matches;
            let recency = self.net.rule_agents[s as usize..e as usize]
                .iter()
                .map(|&a| self.agents[a as usize].slot.seq)
                .max()
                .unwrap_or(0);
            let key = (rule.salience, rule.specificity, recency);
            // Ties: the rule declared first.
            let better = match best {
                None => true,
                Some((b, bk)) => key > bk || (key == bk && r < b),
            };
            if better {
                best = Some((r, key));
            }
        }
        best.map(|(r, _)| r)
    }

    /// Whether nothing waits to be propagated and no rule is activated.
    #[inline]
    pub(super) fn at_rest(&self) -> bool {
        self.dirty_lo == usize::MAX && self.active.is_empty()
    }

    /// Fires until no rule is activated; the bound counts the firings of
    /// the whole step.
    pub(super) fn rest(&mut self) -> Result<(), StepError> {
        self.propagate();
        while let Some(r) = self.best() {
            if self.record.firings.len() == self.cascade_limit {
                return Err(StepError::Cascade { limit: self.cascade_limit });
            }
            let to = self.record_firing(r);
            self.set_state(to);
        }
        Ok(())
    }

    /// Records the firing of rule `r` in the current state, with the facts
    /// its positive patterns matched and the agents its `stale` tests found
    /// stale; returns its target (the caller sets the state). The
    /// interpreter and the fast path record through it alike.
    pub(super) fn record_firing(&mut self, r: u32) -> u32 {
        let rule = &self.content.rules[r as usize];
        let to = rule.target;
        let facts0 = self.record.facts.len() as u32;
        for &a in &rule.matches {
            let slot = self.agents[a as usize].slot;
            let n = self.net.event.get(slot.event as usize).map_or(0, |e| (e.kinds.1 - e.kinds.0) as usize);
            let at = self.net.payload_at[a as usize] as usize;
            let v0 = self.record.values.len() as u32;
            // One by one: the usual zero, one or two values without a call
            // to `memcpy`.
            for &v in &self.payload[at..at + n] {
                self.record.values.push(v);
            }
            let values = (v0, self.record.values.len() as u32);
            self.record.facts.push(FactRec { agent: a, event: slot.event, time: slot.time, run: slot.run, values });
        }
        let stale0 = self.record.stale.len() as u32;
        for &a in &rule.stale {
            if self.agents[a as usize].stale {
                self.record.stale.push(a);
            }
        }
        let rec = FiringRec {
            rule: r,
            from: self.state,
            to,
            time: self.now,
            facts: (facts0, self.record.facts.len() as u32),
            stale: (stale0, self.record.stale.len() as u32),
        };
        self.record.firings.push(rec);
        to
    }
}

impl Engine {
    /// [`record_firing`](Self::record_firing) on the fast path, from the
    /// program's per-rule tables (`fast::Fire`): the same records.
    #[inline(always)]
    pub(super) fn fast_record(&mut self, r: u32) -> u32 {
        let p = &*self.fp;
        // SAFETY (`fast::at`): `r` is a rule of the program's lists, and
        // `fires` has one entry per rule; a firing's agents are in
        // `agents` (`Program::check`).
        let f = unsafe { *at(&p.fires, r as usize) };
        let (matches, stale) = unsafe {
            (
                p.agents.get_unchecked(f.matches.0 as usize..f.matches.1 as usize),
                p.agents.get_unchecked(f.stale.0 as usize..f.stale.1 as usize),
            )
        };
        let at = Recording {
            agents: &self.agents,
            payload: &self.payload,
            net: &self.net,
            state: self.state,
            now: self.now,
        };
        at.record(&mut self.record, r, f.target, matches, stale)
    }

    /// [`fast_record`](Self::fast_record) of a rule whose target and
    /// agents are given (native code).
    #[inline(always)]
    pub(super) fn record_with(&mut self, r: u32, target: u32, matches: &[u32], stale: &[u32]) -> u32 {
        let at = Recording {
            agents: &self.agents,
            payload: &self.payload,
            net: &self.net,
            state: self.state,
            now: self.now,
        };
        at.record(&mut self.record, r, target, matches, stale)
    }
}

/// The working memory a firing is recorded from.
struct Recording<'a> {
    agents: &'a [AgentRec],
    payload: &'a [Value],
    net: &'a Net,
    state: u32,
    now: u64,
}

impl Recording<'_> {
    /// Records the firing of rule `r` (to `target`) with the facts of the
    /// agents its positive patterns match (`matches`) and those of
    /// `stale` that are stale, as the interpreter's `record_firing`;
    /// returns `target`. The one recording of the fast path and of native
    /// code.
    #[inline(always)]
    fn record(&self, rec: &mut Record, r: u32, target: u32, matches: &[u32], stale: &[u32]) -> u32 {
        let facts0 = rec.facts.len() as u32;
        for &a in matches {
            // SAFETY (`fast::at`): a firing's agents are agents
            // (`Program::check`; native code: its digest), and `agents`
            // has one record per agent.
            let slot = unsafe { at(self.agents, a as usize) }.slot;
            // An agent's fact is one of its events, whose place and fields
            // fit in the arena (`Program::check`): the interpreter's
            // `payload_at[a]` and field count.
            let (s, n) = self
                .net
                .event
                .get(slot.event as usize)
                .map_or((0, 0), |e| (e.payload_at as usize, e.kinds.1.wrapping_sub(e.kinds.0) as usize));
            let v0 = rec.values.len() as u32;
            for j in s..s + n {
                rec.values.push(unsafe { *at(self.payload, j) });
            }
            let values = (v0, rec.values.len() as u32);
            rec.facts.push(FactRec { agent: a, event: slot.event, time: slot.time, run: slot.run, values });
        }
        let stale0 = rec.stale.len() as u32;
        for &a in stale {
            if unsafe { at(self.agents, a as usize) }.stale {
                rec.stale.push(a);
            }
        }
        let facts = (facts0, rec.facts.len() as u32);
        let stale = (stale0, rec.stale.len() as u32);
        rec.firings.push(FiringRec { rule: r, from: self.state, to: target, time: self.now, facts, stale });
        target
    }
}
