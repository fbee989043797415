//! Which FSM states an FSM agent can be in while the system is in a given
//! state, over-approximated from the bundle alone, so that the wiring of a
//! state draws only the links of the FSM states that can be active there.
//!
//! The rule (docs/language.md §10.12): an FSM starts in its initial state
//! with the system in its initial state. Its inputs are (a) any of its own
//! events, at any time, and (b) the state at rest becoming another state
//! that some rule targets (any rule, from any state: the guards are not
//! looked at, which is what makes this an over-approximation). Each input
//! fires the first matching transition, as at runtime. The pairs (system
//! state, FSM state) reachable that way are the ones drawn.

use crate::bundle::{Behaviour, Content, Fsm, Trigger};

/// `possible[s][q]`: the FSM `f` may be in its state `q` while the system
/// is in state `s`.
pub fn possible(c: &Content, agent: u32, f: &Fsm) -> Vec<Vec<bool>> {
    let (n, m) = (c.states.len(), f.states.len());
    let mut seen = vec![vec![false; m]; n];
    if n == 0 || m == 0 || c.initial as usize >= n || f.initial as usize >= m {
        return seen;
    }
    let mut targets: Vec<u32> = c.rules.iter().map(|r| r.target).filter(|&t| (t as usize) < n).collect();
    targets.sort_unstable();
    targets.dedup();
    let events: Vec<u32> =
        c.events.iter().enumerate().filter(|(_, e)| e.agent == agent).map(|(i, _)| i as u32).collect();
    let first = |q: u32, fires: &dyn Fn(&Trigger) -> bool| {
        f.transitions.iter().find(|t| t.from == q && fires(&t.trigger)).map_or(q, |t| t.to)
    };
    let mut stack = vec![(c.initial, f.initial)];
    seen[c.initial as usize][f.initial as usize] = true;
    while let Some((s, q)) = stack.pop() {
        let mut next: Vec<(u32, u32)> = Vec::new();
        for &e in &events {
            next.push((s, first(q, &|t| matches!(t, Trigger::Event(x) if *x == e))));
        }
        for &t in targets.iter().filter(|&&t| t != s) {
            next.push((t, first(q, &|tr| matches!(tr, Trigger::States(v) if v.contains(&t)))));
        }
        for (s2, q2) in next {
            if (q2 as usize) < m && !seen[s2 as usize][q2 as usize] {
                seen[s2 as usize][q2 as usize] = true;
                stack.push((s2, q2));
            }
        }
    }
    seen
}

/// Per agent (`None` for agents without an FSM), [`possible`].
pub fn all_possible(c: &Content) -> Vec<Option<Vec<Vec<bool>>>> {
    c.agents
        .iter()
        .enumerate()
        .map(|(i, a)| match &a.behaviour {
            Behaviour::Fsm(f) => Some(possible(c, i as u32, f)),
            _ => None,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::check_source;

    const SRC: &str = "states { Landed initial Survey Home }
        agent Link sensor { event GO event BACK event DOWN }
        agent Gimbal actuator {
            event LOCKED
            function aim function film
            fsm {
                Stowed initial => sleep
                Aiming => run aim() from Link
                Recording => run film() to Link
                Stowed -> Aiming on state == Survey
                Aiming -> Recording on LOCKED
                Aiming -> Stowed on state in {Landed, Home}
                Recording -> Stowed on state in {Landed, Home}
            }
        }
        rule go { when state == Landed and GO then Survey }
        rule back { when state == Survey and BACK then Home }
        rule down { when state == Home and DOWN then Landed }";

    #[test]
    fn a_gimbal_stowed_on_the_ground_is_only_stowed_there() {
        let c = crate::bundle::build(&check_source("t.situ", SRC));
        let g = c.agent_id("Gimbal").unwrap();
        let Behaviour::Fsm(f) = &c.agents[g as usize].behaviour else { panic!("an FSM") };
        let p = possible(&c, g, f);
        let at = |s: &str| -> Vec<&str> {
            let s = c.state_id(s).unwrap() as usize;
            (0..f.states.len()).filter(|&q| p[s][q]).map(|q| f.states[q].name.as_str()).collect()
        };
        assert_eq!(at("Landed"), ["Stowed"]);
        assert_eq!(at("Home"), ["Stowed"]);
        assert_eq!(at("Survey"), ["Aiming", "Recording"]);
    }
}
