//! What the bridge asks of the ROS 2 lifecycle nodes, as a pure function:
//! from each node's known state and what its agent's table says now, the
//! next `change_state` request to send. The bridge sends one request at a
//! time and asks again after each answer, so the order below is the order
//! on the wire.
//!
//! A table's mode becomes a lifecycle state: `run` and `wait` → active (a
//! waiting agent's outputs are unlinked in the links the bridge publishes),
//! `sleep` → inactive. The order never leaves a reader active without its
//! writer:
//!
//! 1. **configurations** (unconfigured → inactive), which activate nothing;
//! 2. **activations**, writers before their readers (the links of the new
//!    situation), so that a node that becomes active finds its writers
//!    active, and a reader that stays active gets its new writer before…
//! 3. **deactivations**, readers before their writers (the links of the
//!    situations being left: a writer is deactivated only after every
//!    reader it fed that is deactivated too), …loses its old one.
//!
//! A cycle of links is broken at its node of lowest index. A node whose
//! state is unknown (it has not answered `get_state` yet) or that failed
//! its last request for the present target is left alone, and does not
//! hold the others back.

/// A lifecycle node's primary state (`lifecycle_msgs/msg/State`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum NodeState {
    /// Not known yet: the node has not answered.
    Unknown,
    Unconfigured,
    Inactive,
    Active,
    Finalized,
}

impl NodeState {
    /// The state of a `lifecycle_msgs/msg/State` id (primary states only;
    /// a transition state is not a resting state, so `Unknown`).
    pub fn from_id(id: u8) -> NodeState {
        match id {
            1 => NodeState::Unconfigured,
            2 => NodeState::Inactive,
            3 => NodeState::Active,
            4 => NodeState::Finalized,
            _ => NodeState::Unknown,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            NodeState::Unknown => "unknown",
            NodeState::Unconfigured => "unconfigured",
            NodeState::Inactive => "inactive",
            NodeState::Active => "active",
            NodeState::Finalized => "finalized",
        }
    }
}

/// What a node's agent's table asks for in the current situation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    Inactive,
    Active,
}

/// A `lifecycle_msgs/msg/Transition` the bridge requests.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transition {
    Configure,
    Activate,
    Deactivate,
}

impl Transition {
    /// Its id in `lifecycle_msgs/msg/Transition`.
    pub fn id(self) -> u8 {
        match self {
            Transition::Configure => 1,
            Transition::Activate => 3,
            Transition::Deactivate => 4,
        }
    }

    pub fn label(self) -> &'static str {
        match self {
            Transition::Configure => "configure",
            Transition::Activate => "activate",
            Transition::Deactivate => "deactivate",
        }
    }

    /// The state a node is in after it made this transition.
    pub fn goal(self) -> NodeState {
        match self {
            Transition::Configure | Transition::Deactivate => NodeState::Inactive,
            Transition::Activate => NodeState::Active,
        }
    }
}

/// One request: `transition` of node number `node`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Step {
    pub node: usize,
    pub transition: Transition,
}

/// One node as the planner sees it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Node {
    pub state: NodeState,
    pub target: Target,
    /// Its last request for this target failed or was not answered: the
    /// bridge does not insist until the target changes.
    pub held: bool,
}

/// The next request, or `None` when every node that can be driven is where
/// its table wants it. `left` are the links `(writer, reader)` between nodes
/// of the situation being left, `entered` those of the new one.
pub fn next_step(nodes: &[Node], left: &[(usize, usize)], entered: &[(usize, usize)]) -> Option<Step> {
    let free = |n: &Node| !n.held;
    if let Some(node) = nodes.iter().position(|n| free(n) && n.state == NodeState::Unconfigured) {
        return Some(Step { node, transition: Transition::Configure });
    }
    let to_activate: Vec<bool> =
        nodes.iter().map(|n| free(n) && n.state == NodeState::Inactive && n.target == Target::Active).collect();
    // A reader waits for its writers: the blocker of `r` is a writer `w`.
    if let Some(node) = first_unblocked(&to_activate, entered, |w, r| (r, w)) {
        return Some(Step { node, transition: Transition::Activate });
    }
    let to_deactivate: Vec<bool> =
        nodes.iter().map(|n| free(n) && n.state == NodeState::Active && n.target == Target::Inactive).collect();
    // A writer waits for its readers.
    first_unblocked(&to_deactivate, left, |w, r| (w, r)).map(|node| Step { node, transition: Transition::Deactivate })
}

/// The first pending node that no other pending node must precede; the
/// lowest pending one when every one is held back (a cycle). `orient`
/// turns a link `(writer, reader)` into `(node, the node that must go first)`.
fn first_unblocked(
    pending: &[bool],
    links: &[(usize, usize)],
    orient: fn(usize, usize) -> (usize, usize),
) -> Option<usize> {
    let blocked = |n: usize| {
        links.iter().any(|&(w, r)| {
            let (node, first) = orient(w, r);
            node == n && first != n && pending.get(first).copied().unwrap_or(false)
        })
    };
    let mut any = None;
    for (n, &p) in pending.iter().enumerate() {
        if p {
            if !blocked(n) {
                return Some(n);
            }
            any.get_or_insert(n);
        }
    }
    any
}

#[cfg(test)]
mod tests {
    use super::*;
    use NodeState::*;

    fn node(state: NodeState, target: Target) -> Node {
        Node { state, target, held: false }
    }

    /// Every request until none is left, applying each as if it succeeded.
    fn run(mut nodes: Vec<Node>, left: &[(usize, usize)], entered: &[(usize, usize)]) -> Vec<(usize, &'static str)> {
        let mut out = Vec::new();
        while let Some(s) = next_step(&nodes, left, entered) {
            assert!(out.len() < 3 * nodes.len(), "no end: {out:?}");
            nodes[s.node].state = s.transition.goal();
            out.push((s.node, s.transition.label()));
        }
        out
    }

    #[test]
    fn writers_activate_first_and_readers_deactivate_first() {
        // 0 → 1 → 2: a scanner feeds a planner that feeds a controller.
        let chain = [(0, 1), (1, 2)];
        let up = vec![node(Inactive, Target::Active); 3];
        assert_eq!(run(up, &[], &chain), [(0, "activate"), (1, "activate"), (2, "activate")]);
        // Declared in the other order, still writers first.
        let reversed = [(2, 1), (1, 0)];
        let up = vec![node(Inactive, Target::Active); 3];
        assert_eq!(run(up, &[], &reversed), [(2, "activate"), (1, "activate"), (0, "activate")]);
        let down = vec![node(Active, Target::Inactive); 3];
        assert_eq!(run(down, &chain, &[]), [(2, "deactivate"), (1, "deactivate"), (0, "deactivate")]);
    }

    #[test]
    fn unconfigured_nodes_are_configured_before_any_activation() {
        let nodes = vec![node(Unconfigured, Target::Active), node(Unconfigured, Target::Inactive)];
        assert_eq!(run(nodes, &[], &[(0, 1)]), [(0, "configure"), (1, "configure"), (0, "activate")]);
    }

    #[test]
    fn a_reader_that_stays_active_gets_its_new_writer_before_losing_the_old() {
        // A controller (0) read the planner (1); now it reads recovery (2).
        let nodes = vec![node(Active, Target::Active), node(Active, Target::Inactive), node(Inactive, Target::Active)];
        assert_eq!(run(nodes, &[(1, 0)], &[(2, 0)]), [(2, "activate"), (1, "deactivate")]);
    }

    #[test]
    fn cycles_break_at_the_lowest_node() {
        let nodes = vec![node(Inactive, Target::Active); 2];
        assert_eq!(run(nodes, &[], &[(0, 1), (1, 0)]), [(0, "activate"), (1, "activate")]);
    }

    #[test]
    fn unknown_held_and_finalized_nodes_are_left_alone_and_hold_nobody_back() {
        let nodes = vec![
            Node { state: Inactive, target: Target::Active, held: true },
            node(Unknown, Target::Active),
            node(Finalized, Target::Active),
            node(Inactive, Target::Active),
        ];
        assert_eq!(run(nodes, &[], &[(0, 3), (1, 3), (2, 3)]), [(3, "activate")]);
    }

    #[test]
    fn nodes_where_their_table_wants_them_get_no_request() {
        let nodes = vec![node(Active, Target::Active), node(Inactive, Target::Inactive)];
        assert_eq!(next_step(&nodes, &[(0, 1)], &[(0, 1)]), None);
    }
}
