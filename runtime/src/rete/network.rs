//! The interpreter's network at work: the alpha nodes of an event, a
//! state or a staleness re-evaluated against the working memory, the beta
//! nodes marked below them and re-evaluated in topological order, the
//! activated rules kept as they change (the fast path, `fast.rs`, uses
//! none of it).

use super::eval::{compare, in_range};
use super::net::{self, AlphaKind, OperandRt, TestKind, TestRt, NONE};
use super::Engine;
use situ_bundle::Value;

impl Engine {
    // ─── Alpha network ─────────────────────────────────────────────────

    pub(super) fn clear_event_alpha(&mut self, event: u32) {
        let (s, e) = self.net.event[event as usize].alpha;
        for i in s..e {
            let a = self.net.event_alpha[i as usize] as usize;
            if self.alpha_mem[a] {
                self.alpha_mem[a] = false;
                self.mark_succ(a);
            }
        }
    }

    /// Re-evaluates the alpha nodes of `event` against its agent's new fact:
    /// successors are marked where the result changes, and where it stays
    /// true but join tests below read the replaced fact's values.
    #[inline]
    pub(super) fn eval_event_alpha(&mut self, (s, e): (u32, u32)) {
        for i in s as usize..e as usize {
            let a = self.net.event_alpha[i] as usize;
            let pass = self.event_alpha_passes(&self.net.alpha[a]);
            if pass != self.alpha_mem[a] || (pass && self.net.alpha[a].refresh) {
                self.alpha_mem[a] = pass;
                self.mark_succ(a);
            }
        }
    }

    /// Re-evaluates the alpha nodes of an agent's current event (windows,
    /// forced run lengths); marks successors only where the result changes.
    pub(super) fn refresh_alpha(&mut self, agent: u32) {
        let event = self.agents[agent as usize].slot.event;
        if event == NONE {
            return;
        }
        let (s, e) = self.net.event[event as usize].alpha;
        for i in s..e {
            let a = self.net.event_alpha[i as usize] as usize;
            let pass = self.alpha_passes(a);
            if pass != self.alpha_mem[a] {
                self.alpha_mem[a] = pass;
                self.mark_succ(a);
            }
        }
    }

    pub(super) fn set_stale_alpha(&mut self, agent: u32, stale: bool) {
        let a = self.net.stale_alpha[agent as usize];
        if a != NONE && self.alpha_mem[a as usize] != stale {
            self.alpha_mem[a as usize] = stale;
            self.mark_succ(a as usize);
        }
    }

    pub(super) fn alpha_passes(&self, a: usize) -> bool {
        let node = &self.net.alpha[a];
        match node.kind {
            AlphaKind::State => self.net.state_in(node, self.state),
            AlphaKind::Stale => self.agents[node.agent as usize].stale,
            AlphaKind::Event => self.event_alpha_passes(node),
        }
    }

    /// An event alpha node's test of its agent's fact: the event, the run
    /// length, the window, the payload tests.
    #[inline]
    pub(super) fn event_alpha_passes(&self, node: &net::AlphaRt) -> bool {
        let slot = &self.agents[node.agent as usize].slot;
        if slot.event != node.key || slot.run < node.min_run {
            return false;
        }
        if node.within_ns != u64::MAX && self.now.saturating_sub(slot.time) > node.within_ns {
            return false;
        }
        let (s, e) = node.tests;
        s == e || self.net.alpha_tests[s as usize..e as usize].iter().all(|t| self.test(t, node.at as usize))
    }

    #[inline]
    pub(super) fn operand(&self, o: OperandRt, own: usize) -> Value {
        match o {
            OperandRt::Value(v) => v,
            OperandRt::Own(f) => self.payload[own + f as usize],
            OperandRt::Fact { agent, field } => {
                let a = agent as usize;
                if field < self.net.stride[a] {
                    self.payload[self.net.payload_at[a] as usize + field as usize]
                } else {
                    // Cannot happen in a valid token; a value that matches nothing.
                    Value::F64(f64::NAN)
                }
            }
        }
    }

    #[inline]
    pub(super) fn test(&self, t: &TestRt, own: usize) -> bool {
        let x = self.payload[own + t.field as usize];
        match t.kind {
            TestKind::Compare { op, rhs } => compare(op, x, self.operand(rhs, own)),
            TestKind::Range { lo, hi, inclusive } => {
                in_range(x, self.operand(lo, own), self.operand(hi, own), inclusive)
            }
        }
    }

    // ─── Beta network ──────────────────────────────────────────────────

    #[inline(always)]
    pub(super) fn mark(&mut self, b: usize) {
        let w = b / 64;
        self.dirty[w] |= 1 << (b % 64);
        self.dirty_lo = self.dirty_lo.min(w);
        self.dirty_hi = self.dirty_hi.max(w);
    }

    /// No `#[inline]`: with it, inlined into `insert`'s alpha loop, a step
    /// cost 29 instructions more (`bench/instructions.sh`: 602 against 573
    /// per event: the loop's set-up loaded its tables on every event);
    /// `#[inline(never)]` cost 4 more than the compiler's choice.
    pub(super) fn mark_succ(&mut self, a: usize) {
        let (s, e) = self.net.alpha[a].succ;
        for i in s..e {
            let b = self.net.succ[i as usize] as usize;
            self.mark(b);
        }
    }

    /// Re-evaluates the marked beta nodes, parents before children.
    pub(super) fn propagate(&mut self) {
        if self.dirty_lo == usize::MAX {
            return;
        }
        let mut w = self.dirty_lo;
        while w <= self.dirty_hi {
            let bits = self.dirty[w];
            if bits == 0 {
                w += 1;
                continue;
            }
            let bit = bits.trailing_zeros() as usize;
            self.dirty[w] &= !(1u64 << bit);
            self.eval_beta(w * 64 + bit);
        }
        self.dirty_lo = usize::MAX;
        self.dirty_hi = 0;
    }

    pub(super) fn eval_beta(&mut self, b: usize) {
        let node = &self.net.beta[b];
        let parent_ok = node.parent == NONE || self.beta_tok[node.parent as usize];
        let tok = parent_ok && {
            let right = self.alpha_mem[node.alpha as usize] && self.join_tests(node);
            right != node.negative
        };
        let was = self.beta_tok[b];
        self.beta_tok[b] = tok;
        if tok != was || (tok && node.refresh) {
            // New, gone, or refreshed with join tests below that read the
            // facts: the children re-evaluate.
            let (s, e) = node.children;
            for &c in &self.net.children[s as usize..e as usize] {
                let c = c as usize;
                let w = c / 64;
                self.dirty[w] |= 1 << (c % 64);
                self.dirty_hi = self.dirty_hi.max(w);
            }
        }
        if tok != was {
            let (s, e) = node.terminals;
            for i in s..e {
                let r = self.net.terminal_rules[i as usize];
                self.set_active(r, tok);
            }
        }
    }

    #[inline]
    pub(super) fn join_tests(&self, node: &net::BetaRt) -> bool {
        let (s, e) = node.tests;
        if s == e {
            return true;
        }
        let own = node.at as usize;
        self.net.beta_tests[s as usize..e as usize].iter().all(|t| self.test(t, own))
    }

    pub(super) fn set_active(&mut self, rule: u32, on: bool) {
        let r = rule as usize;
        if on && self.active_pos[r] == NONE {
            self.active_pos[r] = self.active.len() as u32;
            self.active.push(rule);
        } else if !on && self.active_pos[r] != NONE {
            let pos = self.active_pos[r] as usize;
            self.active.swap_remove(pos);
            if let Some(&moved) = self.active.get(pos) {
                self.active_pos[moved as usize] = pos as u32;
            }
            self.active_pos[r] = NONE;
        }
    }

    /// Every memory from scratch (construction, reset, hot swap).
    pub(super) fn recompute(&mut self) {
        for a in 0..self.net.alpha.len() {
            self.alpha_mem[a] = self.alpha_passes(a);
        }
        for r in std::mem::take(&mut self.active) {
            self.active_pos[r as usize] = NONE;
        }
        self.beta_tok.fill(false);
        self.dirty.fill(0);
        for b in 0..self.net.beta.len() {
            self.mark(b);
        }
        self.propagate();
    }
}
