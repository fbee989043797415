//! The network of a bundle in the dense form the interpreter runs: flat
//! arrays indexed by node, with the successor lists precomputed, so that an
//! event touches only the nodes of its own event and the chains below them.

use situ_bundle::{AlphaNode, BetaKind, Check, Cmp, Content, Operand, Value};

/// No node, no event.
pub const NONE: u32 = u32::MAX;

/// A test on one field of the node's fact.
#[derive(Debug, Clone, Copy)]
pub struct TestRt {
    pub field: u32,
    pub kind: TestKind,
}

#[derive(Debug, Clone, Copy)]
pub enum TestKind {
    Compare { op: Cmp, rhs: OperandRt },
    Range { lo: OperandRt, hi: OperandRt, inclusive: bool },
}

#[derive(Debug, Clone, Copy)]
pub enum OperandRt {
    Value(Value),
    Own(u32),
    /// A field of an agent's fact (its payload offset is looked up at run time).
    Fact {
        agent: u32,
        field: u32,
    },
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AlphaKind {
    /// Index into `state_sets`.
    State,
    Event,
    Stale,
}

#[derive(Debug, Clone, Copy)]
pub struct AlphaRt {
    pub kind: AlphaKind,
    /// The event (Event), the agent (Stale), the state set's word offset (State).
    pub key: u32,
    /// The agent whose fact it tests (Event, Stale).
    pub agent: u32,
    pub tests: (u32, u32),
    pub min_run: u64,
    pub within_ns: u64,
    /// Its successors: beta nodes with it as right input, in `succ`.
    pub succ: (u32, u32),
    /// Whether a join test below it reads fact values: only then does a
    /// replaced fact that still passes need its successors re-evaluated.
    pub refresh: bool,
    /// Its agent's payload offset (Event; 0 otherwise).
    pub at: u32,
}

#[derive(Debug, Clone, Copy)]
pub struct BetaRt {
    pub parent: u32,
    pub negative: bool,
    pub alpha: u32,
    pub tests: (u32, u32),
    pub children: (u32, u32),
    /// The rules it activates (rules with identical chains share it), in
    /// `terminal_rules`.
    pub terminals: (u32, u32),
    /// Whether a join test below it reads fact values (see [`AlphaRt::refresh`]).
    pub refresh: bool,
    /// The payload offset of its right fact's agent (0 without one).
    pub at: u32,
}

/// What a step needs of an event, in one place: one look-up per event on
/// the hot path instead of one per table.
#[derive(Debug, Clone, Copy)]
pub struct EventRt {
    pub agent: u32,
    /// Its agent's payload offset.
    pub payload_at: u32,
    /// Its fields' kinds, in `kinds` (always inside it: `Net::new`
    /// builds them so, and the payload check reads them unchecked).
    pub kinds: (u32, u32),
    /// Its alpha nodes, in `event_alpha`.
    pub alpha: (u32, u32),
    /// Its windows, in `windows`.
    pub windows: (u32, u32),
    /// Its agent's `stale after`, ns (`u64::MAX`: never).
    pub stale_after: u64,
    /// Its bit in the fast path's `Engine::have` (`fast::bit`).
    pub bit: u64,
}

#[derive(Debug, Clone)]
pub struct RuleRt {
    pub salience: i64,
    pub specificity: u32,
    /// The agents whose facts its positive patterns match, in `rule_agents`.
    pub matches: (u32, u32),
}

/// The dense network.
#[derive(Debug, Clone)]
pub struct Net {
    pub alpha: Vec<AlphaRt>,
    pub alpha_tests: Vec<TestRt>,
    pub succ: Vec<u32>,
    pub beta: Vec<BetaRt>,
    pub beta_tests: Vec<TestRt>,
    pub children: Vec<u32>,
    pub terminal_rules: Vec<u32>,
    pub rules: Vec<RuleRt>,
    pub rule_agents: Vec<u32>,
    /// The alpha nodes of each event ([`EventRt::alpha`]).
    pub event_alpha: Vec<u32>,
    /// The distinct windows of each event's alpha nodes, ascending
    /// ([`EventRt::windows`]).
    pub windows: Vec<u64>,
    /// Per agent: its stale alpha node, or `NONE`.
    pub stale_alpha: Vec<u32>,
    /// State sets of the state alpha nodes: one bit per state, as many u64
    /// words per node as the states need.
    pub state_sets: Vec<u64>,
    /// Per state: the state alpha nodes that contain it, in `state_alpha`.
    pub state_alpha_at: Vec<(u32, u32)>,
    pub state_alpha: Vec<u32>,
    /// Per agent: the offset of its payload in the payload arena, and its
    /// stride (the most fields of any of its events).
    pub payload_at: Vec<u32>,
    pub stride: Vec<u32>,
    pub payload_len: usize,
    /// Agents with a staleness or a window to watch.
    pub timed_agents: Vec<u32>,
    /// The fields' kinds of each event ([`EventRt::kinds`]).
    pub kinds: Vec<Kind>,
    /// Per event, what a step needs of it (the tables above, gathered).
    pub event: Vec<EventRt>,
    /// Per state: whether it is final (and `false` for any other state a
    /// bundle that was not validated names: see `Net::new`).
    pub final_state: Vec<bool>,
}

/// A field's type, flat, for checking payloads fast.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    F64,
    I64,
    Bool,
    /// A symbol of a set of this many.
    Symbol(u32),
}

fn range(start: usize, end: usize) -> (u32, u32) {
    (start as u32, end as u32)
}

impl Net {
    /// The dense form of a validated bundle (see
    /// `situ_bundle::codec::validate`: every index is in range).
    pub fn new(c: &Content) -> Net {
        let na = c.agents.len();
        let ne = c.events.len();
        let ns = c.states.len();
        let words = ns.div_ceil(64).max(1);
        let net = &c.network;

        // Payload layout.
        let mut payload_at = Vec::with_capacity(na);
        let mut stride = Vec::with_capacity(na);
        let mut at = 0u32;
        for a in &c.agents {
            let s = a.events.iter().map(|&e| c.events[e as usize].fields.len()).max().unwrap_or(0) as u32;
            payload_at.push(at);
            stride.push(s);
            at += s;
        }

        // Successors of alpha nodes, children of beta nodes.
        let mut succ_lists: Vec<Vec<u32>> = vec![Vec::new(); net.alpha.len()];
        let mut child_lists: Vec<Vec<u32>> = vec![Vec::new(); net.beta.len()];
        for (i, b) in net.beta.iter().enumerate() {
            succ_lists[b.alpha as usize].push(i as u32);
            if let Some(p) = b.parent {
                child_lists[p as usize].push(i as u32);
            }
        }
        let mut succ = Vec::new();
        let mut state_sets = Vec::new();
        let mut alpha_tests = Vec::new();
        let mut alpha = Vec::with_capacity(net.alpha.len());
        let mut event_lists: Vec<Vec<u32>> = vec![Vec::new(); ne];
        let mut window_lists: Vec<Vec<u64>> = vec![Vec::new(); ne];
        let mut stale_alpha = vec![NONE; na];
        let mut state_lists: Vec<Vec<u32>> = vec![Vec::new(); ns];
        for (i, node) in net.alpha.iter().enumerate() {
            let s0 = succ.len();
            succ.extend_from_slice(&succ_lists[i]);
            let succ_range = range(s0, succ.len());
            let t0 = alpha_tests.len();
            let rt = match node {
                AlphaNode::State { states } => {
                    let off = state_sets.len();
                    state_sets.resize(off + words, 0);
                    for &s in states {
                        state_sets[off + s as usize / 64] |= 1 << (s % 64);
                        state_lists[s as usize].push(i as u32);
                    }
                    AlphaRt {
                        kind: AlphaKind::State,
                        key: off as u32,
                        agent: NONE,
                        tests: (0, 0),
                        min_run: 0,
                        within_ns: u64::MAX,
                        succ: succ_range,
                        refresh: false,
                        at: 0,
                    }
                }
                AlphaNode::Event { event, tests, min_run, within_ns } => {
                    alpha_tests.extend(tests.iter().map(test));
                    event_lists[*event as usize].push(i as u32);
                    if let Some(w) = within_ns {
                        window_lists[*event as usize].push(*w);
                    }
                    AlphaRt {
                        kind: AlphaKind::Event,
                        key: *event,
                        agent: c.events[*event as usize].agent,
                        tests: range(t0, alpha_tests.len()),
                        min_run: *min_run,
                        within_ns: within_ns.unwrap_or(u64::MAX),
                        succ: succ_range,
                        refresh: false,
                        at: payload_at[c.events[*event as usize].agent as usize],
                    }
                }
                AlphaNode::Stale { agent } => {
                    stale_alpha[*agent as usize] = i as u32;
                    AlphaRt {
                        kind: AlphaKind::Stale,
                        key: *agent,
                        agent: *agent,
                        tests: (0, 0),
                        min_run: 0,
                        within_ns: u64::MAX,
                        succ: succ_range,
                        refresh: false,
                        at: 0,
                    }
                }
            };
            alpha.push(rt);
        }

        let mut terminal_lists: Vec<Vec<u32>> = vec![Vec::new(); net.beta.len()];
        for t in &net.terminals {
            terminal_lists[t.beta as usize].push(t.rule);
        }
        let mut terminal_rules = Vec::new();
        let mut beta = Vec::with_capacity(net.beta.len());
        let mut beta_tests = Vec::new();
        let mut children = Vec::new();
        for (i, b) in net.beta.iter().enumerate() {
            let t0 = beta_tests.len();
            beta_tests.extend(b.tests.iter().map(test));
            let c0 = children.len();
            children.extend_from_slice(&child_lists[i]);
            let a = &alpha[b.alpha as usize];
            let r0 = terminal_rules.len();
            terminal_rules.extend_from_slice(&terminal_lists[i]);
            beta.push(BetaRt {
                parent: b.parent.unwrap_or(NONE),
                negative: b.kind == BetaKind::Negative,
                alpha: b.alpha,
                tests: range(t0, beta_tests.len()),
                children: range(c0, children.len()),
                terminals: range(r0, terminal_rules.len()),
                refresh: false,
                at: if a.kind == AlphaKind::Event { a.at } else { 0 },
            });
        }
        // Bottom up (children come after their parents): whether a subtree
        // has join tests.
        let mut tested = vec![false; beta.len()];
        for b in (0..beta.len()).rev() {
            let (s, e) = beta[b].children;
            let below = children[s as usize..e as usize].iter().any(|&c| tested[c as usize]);
            beta[b].refresh = below;
            tested[b] = below || beta[b].tests.0 != beta[b].tests.1;
        }
        for a in &mut alpha {
            let (s, e) = a.succ;
            a.refresh = succ[s as usize..e as usize].iter().any(|&b| tested[b as usize]);
        }

        let mut rule_agents = Vec::new();
        let rules = c
            .rules
            .iter()
            .map(|r| {
                let m0 = rule_agents.len();
                rule_agents.extend_from_slice(&r.matches);
                RuleRt { salience: r.salience, specificity: r.specificity, matches: range(m0, rule_agents.len()) }
            })
            .collect();

        let flatten = |lists: Vec<Vec<u32>>| {
            let mut at = Vec::with_capacity(lists.len());
            let mut flat = Vec::new();
            for l in lists {
                let s = flat.len();
                flat.extend(l);
                at.push(range(s, flat.len()));
            }
            (at, flat)
        };
        let (event_alpha_at, event_alpha) = flatten(event_lists);
        let (state_alpha_at, state_alpha) = flatten(state_lists);
        let mut event_windows_at = Vec::with_capacity(ne);
        let mut windows = Vec::new();
        for mut w in window_lists {
            w.sort_unstable();
            w.dedup();
            let s = windows.len();
            windows.extend(w);
            event_windows_at.push(range(s, windows.len()));
        }
        let stale_after: Vec<u64> = c.agents.iter().map(|a| a.stale_after_ns.unwrap_or(u64::MAX)).collect();
        let timed_agents = (0..na as u32)
            .filter(|&a| {
                stale_after[a as usize] != u64::MAX
                    || c.agents[a as usize].events.iter().any(|&e| {
                        let (s, t) = event_windows_at[e as usize];
                        s != t
                    })
            })
            .collect();
        let event_agent: Vec<u32> = c.events.iter().map(|e| e.agent).collect();
        let mut kinds = Vec::new();
        let mut event_kinds = Vec::with_capacity(ne);
        for e in &c.events {
            let s = kinds.len();
            kinds.extend(e.fields.iter().map(|f| match &f.ty {
                situ_bundle::FieldType::F64 => Kind::F64,
                situ_bundle::FieldType::I64 => Kind::I64,
                situ_bundle::FieldType::Bool => Kind::Bool,
                situ_bundle::FieldType::Symbols(s) => Kind::Symbol(s.len() as u32),
            }));
            event_kinds.push(range(s, kinds.len()));
        }
        let event = (0..ne)
            .map(|e| {
                let agent = event_agent[e];
                EventRt {
                    agent,
                    payload_at: payload_at[agent as usize],
                    kinds: event_kinds[e],
                    alpha: event_alpha_at[e],
                    windows: event_windows_at[e],
                    stale_after: stale_after[agent as usize],
                    bit: super::fast::bit(e as u32),
                }
            })
            .collect();
        let mut final_state: Vec<bool> = c.states.iter().map(|s| s.is_final).collect();
        // An entry for every state the engine can be in (the initial one,
        // a rule's target, one `force_state` checked), which
        // `reset_if_final` reads unchecked: a bundle that was not validated
        // may name others, which are not final.
        let top = c.rules.iter().map(|r| r.target).chain([c.initial]).max().map_or(0, |s| s as usize + 1);
        if final_state.len() < top {
            final_state.resize(top, false);
        }
        Net {
            event,
            final_state,
            kinds,
            alpha,
            alpha_tests,
            succ,
            beta,
            beta_tests,
            children,
            terminal_rules,
            rules,
            rule_agents,
            event_alpha,
            windows,
            stale_alpha,
            state_sets,
            state_alpha_at,
            state_alpha,
            payload_at,
            stride,
            payload_len: at as usize,
            timed_agents,
        }
    }

    #[inline]
    pub fn state_in(&self, alpha: &AlphaRt, state: u32) -> bool {
        let off = alpha.key as usize + state as usize / 64;
        self.state_sets[off] & (1 << (state % 64)) != 0
    }
}

fn operand(o: &Operand) -> OperandRt {
    match *o {
        Operand::Value(v) => OperandRt::Value(v),
        Operand::Own { field } => OperandRt::Own(field),
        Operand::Fact { agent, field } => OperandRt::Fact { agent, field },
    }
}

fn test(t: &situ_bundle::Test) -> TestRt {
    let kind = match &t.check {
        Check::Compare { op, rhs } => TestKind::Compare { op: *op, rhs: operand(rhs) },
        Check::Range { lo, hi, inclusive } => {
            TestKind::Range { lo: operand(lo), hi: operand(hi), inclusive: *inclusive }
        }
    };
    TestRt { field: t.field, kind }
}
