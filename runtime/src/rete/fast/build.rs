//! The fast path's program built from a bundle (`Program::new`), and the
//! check of its indexes under which the engine reads it unchecked
//! (`Program::check`).

use super::{bit, Arg, Check2, Cond, Fire, Program, Rule, Test, MAX_LIST_ENTRIES, MAX_RUN_BIT, STALE};
use crate::rete::net::{Net, NONE};
use situ_bundle::{AlphaNode, BetaKind, Check, Content, Operand, Value};

impl Program {
    /// The program of a validated bundle, or why the fast path declines it.
    // The lists are built per state and agent, the tables indexed per rule.
    #[allow(clippy::needless_range_loop)]
    pub(in crate::rete) fn new(c: &Content, net: &Net) -> Result<Program, &'static str> {
        let ns = c.states.len();
        let ne = c.events.len();
        let na = c.agents.len();
        let n = &c.network;
        let stale_bit: Vec<u64> = (0..na).map(|a| if ne + a < 64 { 1 << (ne + a) } else { 0 }).collect();
        let mut p = Program { ne, na, stale_bit: stale_bit.clone(), ..Program::default() };
        // The run-length thresholds that get a bit.
        let mut pairs: Vec<(u32, u64)> = n
            .alpha
            .iter()
            .filter_map(|a| match a {
                AlphaNode::Event { event, min_run, .. } if *min_run > 1 && (*event as usize) < ne => {
                    Some((*event, *min_run))
                }
                _ => None,
            })
            .collect();
        pairs.sort_unstable();
        pairs.dedup();
        let mut run_bit = std::collections::HashMap::new();
        let mut next = ne + na;
        for e in 0..ne as u32 {
            let mine: Vec<(u64, u64)> = pairs
                .iter()
                .filter(|&&(pe, k)| pe == e && k <= MAX_RUN_BIT && bit(e) != 0)
                .filter_map(|&(_, k)| {
                    let b = if next < 64 { 1u64 << next } else { 0 };
                    next += 1;
                    (b != 0).then(|| {
                        run_bit.insert((e, k), b);
                        (k, b)
                    })
                })
                .collect();
            let cap = mine.iter().map(|&(k, _)| k).max().unwrap_or(0);
            let first = p.runs.len() as u32;
            for run in 0..=cap {
                p.runs.push(mine.iter().filter(|&&(k, _)| run >= k).fold(bit(e), |m, &(_, b)| m | b));
            }
            p.run_at.push((first, cap as u32));
        }
        let arg = |o: &Operand, own: u32| -> Result<Arg, &'static str> {
            Ok(match *o {
                Operand::Value(v) => Arg::Value(v),
                Operand::Own { field } => Arg::At(place(net, own, field)?),
                Operand::Fact { agent, field } => {
                    let a = agent as usize;
                    if a >= na {
                        return Err("a test reads an agent out of range");
                    }
                    if field < net.stride[a] {
                        Arg::At(net.payload_at[a] + field)
                    } else {
                        // As the interpreter: a value that matches nothing.
                        Arg::Value(Value::F64(f64::NAN))
                    }
                }
            })
        };
        // Per rule: the states it can be activated in, the agents it reads.
        let mut ok_states: Vec<Vec<bool>> = Vec::with_capacity(c.rules.len());
        let mut reads: Vec<Vec<bool>> = Vec::with_capacity(c.rules.len());
        // Per rule, all its conditions (those the bits decide too).
        let mut full: Vec<Vec<Cond>> = Vec::with_capacity(c.rules.len());
        let mut terminal = vec![NONE; c.rules.len()];
        for t in &n.terminals {
            terminal[t.rule as usize] = t.beta;
        }
        for (r, rule) in c.rules.iter().enumerate() {
            let mut chain = Vec::new();
            let mut b = terminal[r];
            while b != NONE {
                if chain.len() > n.beta.len() {
                    return Err("a chain of beta nodes loops");
                }
                chain.push(b);
                b = n.beta[b as usize].parent.unwrap_or(NONE);
            }
            if chain.is_empty() {
                return Err("a rule without a terminal");
            }
            chain.reverse();
            let mut ok = vec![true; ns];
            let mut read = vec![false; na];
            let c0 = p.conds.len();
            for &b in &chain {
                let beta = &n.beta[b as usize];
                let negative = beta.kind == BetaKind::Negative;
                match &n.alpha[beta.alpha as usize] {
                    AlphaNode::State { states } => {
                        if !beta.tests.is_empty() {
                            return Err("join tests on a state node");
                        }
                        for (s, o) in ok.iter_mut().enumerate() {
                            *o &= states.contains(&(s as u32)) != negative;
                        }
                    }
                    AlphaNode::Stale { agent } => {
                        if !beta.tests.is_empty() {
                            return Err("join tests on a staleness node");
                        }
                        read[*agent as usize] = true;
                        p.conds.push(Cond {
                            agent: *agent,
                            event: STALE,
                            negative,
                            min_run: 0,
                            within: u64::MAX,
                            tests: (0, 0),
                        });
                    }
                    AlphaNode::Event { event, tests, min_run, within_ns } => {
                        let agent = c.events[*event as usize].agent;
                        read[agent as usize] = true;
                        let own = net.payload_at[agent as usize];
                        let t0 = p.tests.len() as u32;
                        for t in tests.iter().chain(&beta.tests) {
                            let x = place(net, own, t.field)?;
                            let float = c.events[*event as usize]
                                .fields
                                .get(t.field as usize)
                                .is_some_and(|f| f.ty == situ_bundle::FieldType::F64);
                            let test = match &t.check {
                                Check::Compare { op, rhs: Operand::Value(Value::F64(c)) } if float => {
                                    Test::F64 { x, op: *op, c: *c }
                                }
                                Check::Range {
                                    lo: Operand::Value(Value::F64(lo)),
                                    hi: Operand::Value(Value::F64(hi)),
                                    inclusive,
                                } if float => Test::F64Range { x, lo: *lo, hi: *hi, inclusive: *inclusive },
                                Check::Compare { op, rhs } => {
                                    Test::Any { x, check: Check2::Compare { op: *op, rhs: arg(rhs, own)? } }
                                }
                                Check::Range { lo, hi, inclusive } => Test::Any {
                                    x,
                                    check: Check2::Range {
                                        lo: arg(lo, own)?,
                                        hi: arg(hi, own)?,
                                        inclusive: *inclusive,
                                    },
                                },
                            };
                            for o in operands(&t.check) {
                                if let Operand::Fact { agent, .. } = o {
                                    read[*agent as usize] = true;
                                }
                            }
                            p.tests.push(test);
                        }
                        p.conds.push(Cond {
                            agent,
                            event: *event,
                            negative,
                            min_run: *min_run,
                            within: within_ns.unwrap_or(u64::MAX),
                            tests: (t0, p.tests.len() as u32),
                        });
                    }
                }
            }
            let m0 = p.agents.len() as u32;
            p.agents.extend_from_slice(&rule.matches);
            let s0 = p.agents.len() as u32;
            p.agents.extend_from_slice(&rule.stale);
            p.fires.push(Fire { target: rule.target, matches: (m0, s0), stale: (s0, p.agents.len() as u32) });
            // The bits: a positive condition's in `need` (kept as a
            // condition unless the bit decides it whole: no window, no
            // tests, and no run length above 1 without a threshold's bit),
            // a negated one decided whole by its bit in `mask` alone,
            // unless a positive condition needs the same bit (the rule
            // never holds: its conditions say so).
            // A run length above 1 is decided by its threshold's bit, if it
            // has one (else the event's bit is only needed).
            let threshold_bit = |c: &Cond| run_bit.get(&(c.event, c.min_run)).copied();
            let cond_bit = |c: &Cond| {
                if c.event == STALE {
                    stale_bit[c.agent as usize]
                } else if c.min_run > 1 {
                    threshold_bit(c).unwrap_or(bit(c.event))
                } else {
                    bit(c.event)
                }
            };
            let whole = |c: &Cond, b: u64| {
                b != 0
                    && (c.min_run <= 1 || c.event == STALE || threshold_bit(c).is_some())
                    && c.within == u64::MAX
                    && c.tests.0 == c.tests.1
            };
            let need = p.conds[c0..].iter().filter(|c| !c.negative).fold(0, |m, c| m | cond_bit(c));
            let (mut mask, mut kept) = (need, Vec::new());
            for c in &p.conds[c0..] {
                let b = cond_bit(c);
                if whole(c, b) && (!c.negative || need & b == 0) {
                    mask |= b;
                } else {
                    kept.push(*c);
                }
            }
            full.push(p.conds.split_off(c0));
            p.conds.extend(kept);
            p.rules.push(Rule { conds: (c0 as u32, p.conds.len() as u32), group: 0, need, mask });
            ok_states.push(ok);
            reads.push(read);
        }

        // The rules in the order they fire in, all else equal, and the rank
        // of each one's (salience, specificity).
        let prio = |r: u32| (c.rules[r as usize].salience, c.rules[r as usize].specificity);
        let mut order: Vec<u32> = (0..c.rules.len() as u32).collect();
        order.sort_by_key(|&r| (std::cmp::Reverse(prio(r)), r));
        let mut groups: Vec<(i64, u32)> = order.iter().map(|&r| prio(r)).collect();
        groups.dedup();
        for r in 0..c.rules.len() {
            let rank = groups.len() - 1 - groups.iter().position(|&g| g == prio(r as u32)).unwrap_or(0);
            p.rules[r].group = rank as u32;
        }
        // Whether `e` (of agent `a`) makes a condition of `r` on `a` false
        // (any of its conditions, those the bits decide too).
        let excluded =
            |r: u32, a: u32, e: u32| full[r as usize].iter().any(|c| c.agent == a && !c.negative && c.event != e);
        let push = |p: &mut Program, keep: &dyn Fn(u32) -> bool| -> Result<(u32, u32), &'static str> {
            let s = p.lists.len();
            for &r in &order {
                if keep(r) {
                    p.lists.push(r);
                }
            }
            if p.lists.len() > MAX_LIST_ENTRIES {
                return Err("its candidate lists are too large");
            }
            Ok((s as u32, p.lists.len() as u32))
        };
        for s in 0..ns {
            let l = push(&mut p, &|r| ok_states[r as usize][s])?;
            p.by_state.push(l);
            for a in 0..na {
                let l = push(&mut p, &|r| ok_states[r as usize][s] && reads[r as usize][a])?;
                p.by_agent.push(l);
            }
            for e in 0..ne {
                let a = c.events[e].agent;
                let l = push(&mut p, &|r| {
                    ok_states[r as usize][s] && reads[r as usize][a as usize] && !excluded(r, a, e as u32)
                })?;
                p.by_event.push(l);
            }
        }
        p.check(ns, net)?;
        Ok(p)
    }

    /// Checks every index of the program against the tables it indexes:
    /// the invariant under which the engine reads them unchecked ([`at`]).
    fn check(&self, ns: usize, net: &Net) -> Result<(), &'static str> {
        let payload_len = net.payload_len;
        // The events' agents, their places and windows (`fast_insert`).
        let events = net.event.len() == self.ne
            && net.timed_agents.iter().all(|&a| (a as usize) < self.na)
            && net.event.iter().all(|e| {
                (e.agent as usize) < self.na
                    && e.payload_at as usize + (e.kinds.1 - e.kinds.0) as usize <= payload_len
                    && e.windows.0 <= e.windows.1
                    && e.windows.1 as usize <= net.windows.len()
            });
        let range = |(s, e): (u32, u32), len: usize| s <= e && e as usize <= len;
        let lists = self.by_state.len() == ns
            && self.by_agent.len() == ns * self.na
            && self.by_event.len() == ns * self.ne
            && self.by_state.iter().chain(&self.by_agent).chain(&self.by_event).all(|&l| range(l, self.lists.len()))
            && self.lists.iter().all(|&r| (r as usize) < self.rules.len());
        let rules = self.rules.iter().all(|r| range(r.conds, self.conds.len()))
            && self.fires.len() == self.rules.len()
            && self.fires.iter().all(|f| range(f.matches, self.agents.len()) && range(f.stale, self.agents.len()))
            && self.agents.iter().all(|&a| (a as usize) < self.na);
        let conds = self.stale_bit.len() == self.na
            && self.run_at.len() == self.ne
            && self.run_at.iter().all(|&(s, cap)| (s as usize + cap as usize) < self.runs.len())
            && self.conds.iter().all(|c| (c.agent as usize) < self.na && range(c.tests, self.tests.len()));
        let place = |i: u32| (i as usize) < payload_len;
        let arg = |a: Arg| match a {
            Arg::Value(_) => true,
            Arg::At(i) => place(i),
        };
        let tests = self.tests.iter().all(|t| match *t {
            Test::F64 { x, .. } | Test::F64Range { x, .. } => place(x),
            Test::Any { x, check: Check2::Compare { rhs, .. } } => place(x) && arg(rhs),
            Test::Any { x, check: Check2::Range { lo, hi, .. } } => place(x) && arg(lo) && arg(hi),
        });
        if events && lists && rules && conds && tests {
            Ok(())
        } else {
            Err("an index of the program out of its table")
        }
    }
}

/// The place in the arena of field `field` of the agent whose payload starts
/// at `own`, if the arena has it (the interpreter reads the same place).
fn place(net: &Net, own: u32, field: u32) -> Result<u32, &'static str> {
    let x = own as usize + field as usize;
    if x < net.payload_len {
        Ok(x as u32)
    } else {
        Err("a test reads a field out of the payload arena")
    }
}

fn operands(c: &Check) -> Vec<&Operand> {
    match c {
        Check::Compare { rhs, .. } => vec![rhs],
        Check::Range { lo, hi, .. } => vec![lo, hi],
    }
}
