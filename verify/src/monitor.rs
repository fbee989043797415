//! The logic of properties (language reference §10.10), as a monitor that
//! reads a run point by point.
//!
//! A property is `always F` or `never F`; F is `Q`, `P -> Q`, `P -> next Q`
//! or `P -> eventually Q [within N events | D]` (`Q` alone is `true -> Q`).
//! At each point i of a run (0: the start; i: after event i) F is true,
//! false, or undecided because the run ends too soon:
//!
//! - `P -> Q`: ¬P(i) ∨ Q(i).
//! - `P -> next Q`: ¬P(i) ∨ Q(i+1); undecided at the last point when P(i).
//! - `P -> eventually Q within N events`: ¬P(i) ∨ Q(j) for some j in i..=i+N.
//! - `P -> eventually Q within D`: ¬P(i) ∨ Q(j) for some j ≥ i with
//!   t(j) − t(i) ≤ D (t: the time of the point's event, 0 at the start).
//! - `P -> eventually Q` (no bound): ¬P(i) ∨ Q(j) for some j ≥ i. On a
//!   finite run it is undecided while Q has not come; the exhaustive checker
//!   decides it on infinite runs: a counterexample is a run that reaches a
//!   cycle of the abstraction along which Q never holds (a lasso).
//!
//! `always F` fails at a point where F is false; `never F` at a point where
//! F is true. Undecided points fail neither.
//!
//! The monitor keeps one pending obligation: for `always`, the oldest (it
//! expires first, and a Q discharges all of them); for `never`, the
//! youngest (it lasts longest). Its state counts the points and nanoseconds
//! since the obligation began, capped just past the bound, so that it is
//! finite and can be part of an abstract state.

use situ_compiler::spec::{Bound, Consequent, PropertySpec};

/// How the consequent is bound in time.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Now,
    Next,
    Eventually { events: Option<u64>, nanos: Option<u64> },
}

/// The monitor of one property.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Monitor {
    pub never: bool,
    pub kind: Kind,
}

/// What the monitor remembers between points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub struct MonitorState {
    pub pending: bool,
    /// Points since the pending obligation began.
    pub events: u64,
    /// Nanoseconds since it began.
    pub nanos: u64,
}

impl Monitor {
    pub fn new(p: &PropertySpec) -> Monitor {
        let kind = match &p.consequent {
            Consequent::Now(_) => Kind::Now,
            Consequent::Next(_) => Kind::Next,
            Consequent::Eventually { bound, .. } => match bound {
                None => Kind::Eventually { events: None, nanos: None },
                Some(Bound::Events(n)) => Kind::Eventually { events: Some(*n), nanos: None },
                Some(Bound::Nanos(d)) => Kind::Eventually { events: None, nanos: Some(*d) },
            },
        };
        Monitor { never: p.never, kind }
    }

    /// An unbounded `eventually`: decided only on infinite runs.
    pub fn is_liveness(&self) -> bool {
        matches!(self.kind, Kind::Eventually { events: None, nanos: None })
    }

    /// The time bound of the consequent, if any.
    pub fn nanos_bound(&self) -> Option<u64> {
        match self.kind {
            Kind::Eventually { nanos, .. } => nanos,
            _ => None,
        }
    }

    /// Reads one point: the premise and the consequent's predicate there,
    /// and the time since the previous point. Returns why the property
    /// fails at this point, if it does.
    pub fn step(&self, st: &mut MonitorState, p: bool, q: bool, gap: u64) -> Option<String> {
        match (self.kind, self.never) {
            (Kind::Now, false) => (p && !q).then(|| "the premise holds and the consequent does not".into()),
            (Kind::Now, true) => (!p || q).then(|| "it holds here (a `never` property must hold at no point)".into()),
            (Kind::Next, never) => {
                let mut out = None;
                if st.pending {
                    st.pending = false;
                    if q == never {
                        out = Some(if never {
                            "the premise held at the previous point and the consequent holds now".into()
                        } else {
                            "the premise held at the previous point and the consequent does not hold now".into()
                        });
                    }
                }
                if never && !p && out.is_none() {
                    out = Some("the premise does not hold, so the implication holds here".into());
                }
                st.pending = p;
                out
            }
            (Kind::Eventually { events, nanos }, false) => {
                if st.pending {
                    self.advance(st, gap);
                    if nanos.is_some_and(|d| st.nanos > d) {
                        *st = MonitorState::default();
                        return Some(format!(
                            "the consequent did not hold within {} of the premise",
                            super::show_duration(nanos.unwrap_or(0))
                        ));
                    }
                    if q {
                        *st = MonitorState::default();
                    } else if let Some(n) = events.filter(|&n| st.events >= n) {
                        *st = MonitorState::default();
                        return Some(format!("the consequent did not hold within {n} events of the premise"));
                    }
                }
                if !st.pending && p && !q {
                    *st = MonitorState { pending: true, events: 0, nanos: 0 };
                }
                None
            }
            (Kind::Eventually { events, nanos }, true) => {
                if st.pending {
                    self.advance(st, gap);
                    let expired = nanos.is_some_and(|d| st.nanos > d) || events.is_some_and(|n| st.events > n);
                    if expired {
                        *st = MonitorState::default();
                    } else if q {
                        return Some("the consequent holds within the bound of an earlier premise".into());
                    }
                }
                if !p {
                    return Some("the premise does not hold, so the implication holds here".into());
                }
                if q {
                    return Some("the premise and the consequent hold together".into());
                }
                *st = MonitorState { pending: true, events: 0, nanos: 0 };
                None
            }
        }
    }

    fn advance(&self, st: &mut MonitorState, gap: u64) {
        let (events, nanos) = match self.kind {
            Kind::Eventually { events, nanos } => (events, nanos),
            _ => (None, None),
        };
        st.events = (st.events + 1).min(events.map_or(0, |n| n + 1));
        st.nanos = st.nanos.saturating_add(gap).min(nanos.map_or(0, |d| d.saturating_add(1)));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(m: Monitor, points: &[(bool, bool, u64)]) -> Option<usize> {
        let mut st = MonitorState::default();
        points.iter().position(|&(p, q, gap)| m.step(&mut st, p, q, gap).is_some())
    }

    const ALWAYS: bool = false;

    #[test]
    fn next_is_checked_at_the_following_point() {
        let m = Monitor { never: ALWAYS, kind: Kind::Next };
        assert_eq!(run(m, &[(true, false, 0), (false, true, 0), (true, true, 0), (false, false, 0)]), Some(3));
        assert_eq!(run(m, &[(false, false, 0), (true, false, 0)]), None, "undecided at the end");
    }

    #[test]
    fn eventually_within_events_counts_the_premise_point() {
        let m = Monitor { never: ALWAYS, kind: Kind::Eventually { events: Some(1), nanos: None } };
        assert_eq!(run(m, &[(true, false, 0), (false, true, 0)]), None);
        assert_eq!(run(m, &[(true, false, 0), (false, false, 0)]), Some(1));
        assert_eq!(run(m, &[(true, true, 0), (false, false, 0)]), None);
    }

    #[test]
    fn eventually_within_time_ignores_late_points() {
        let ms = 1_000_000;
        let m = Monitor { never: ALWAYS, kind: Kind::Eventually { events: None, nanos: Some(100 * ms) } };
        assert_eq!(run(m, &[(true, false, 0), (false, false, 50 * ms), (false, true, 50 * ms)]), None);
        assert_eq!(run(m, &[(true, false, 0), (false, false, 60 * ms), (false, true, 50 * ms)]), Some(2));
        assert_eq!(run(m, &[(true, false, 0), (false, false, 60 * ms)]), None, "undecided");
    }

    #[test]
    fn never_fails_where_the_formula_holds() {
        let now = Monitor { never: true, kind: Kind::Now };
        assert_eq!(run(now, &[(true, false, 0), (true, true, 0)]), Some(1));
        let next = Monitor { never: true, kind: Kind::Next };
        assert_eq!(run(next, &[(true, false, 0), (true, true, 0)]), Some(1));
    }
}
