//! The acceptance rule (language reference §10.4, §10.7): whether the
//! engine takes an event — its payload against the schema, its time
//! against its agent's latest accepted event and against the clock it
//! arrived at — and the clocks it keeps for that.

use super::net::Kind;
use super::{Engine, PostError, StepError};
use situ_bundle::Value;

impl Engine {
    /// How far ahead of the clock it arrives at an event may be stamped
    /// (ns; default [`DEFAULT_MAX_SKEW`]).
    pub fn max_skew(&self) -> u64 {
        self.max_skew
    }

    pub fn set_max_skew(&mut self, ns: u64) {
        self.max_skew = ns;
    }

    /// The stamp of the agent's latest accepted event (0 before its first):
    /// an event of the agent stamped earlier is refused.
    pub fn agent_time(&self, agent: u32) -> u64 {
        self.agents.get(agent as usize).map_or(0, |r| r.last)
    }

    /// Moves the agent's clock forward to `time` (a carried-over clock, at
    /// hot swap): its events stamped earlier are refused from then on.
    pub fn advance_agent_time(&mut self, agent: u32, time: u64) {
        if let Some(r) = self.agents.get_mut(agent as usize) {
            r.last = r.last.max(time);
        }
    }

    /// The Bulletinboard's clock when the next events arrive (`None`: each
    /// arrives at its stamp, as in a stream without clocks, a test or a
    /// search). The running stack sets it to its clock (the wall clock, or
    /// simulated time) before it takes the events of a drain; a stream line
    /// `@CLOCK` sets it for its event. Against it [`admit`](Self::admit)
    /// refuses events from the future.
    pub fn set_clock(&mut self, clock: Option<u64>) {
        self.clock = clock;
    }

    pub fn clock(&self) -> Option<u64> {
        self.clock
    }

    /// **The acceptance rule** (language reference §10.4), the one place
    /// where situ decides whether an event is taken: the engine's
    /// [`step`](Self::step) and [`post`](Self::post), hence `situ bench`,
    /// `situ test` and the running stack's Bulletinboard, all go through it.
    /// An event is refused when
    /// - its payload does not fit its event's fields ([`validate`](Self::validate));
    /// - it is stamped before its agent's latest accepted event (out of
    ///   order; the same time is accepted);
    /// - it is stamped more than [`max_skew`](Self::max_skew) ahead of the
    ///   [`clock`](Self::set_clock) it arrived at (from the future). Without
    ///   a clock an event arrives at its stamp, and none is from the future.
    ///
    /// NaN and the infinities are accepted: §10.3 says what they match.
    /// A refused event changes nothing, not even now.
    #[inline]
    pub fn admit(&self, event: u32, time: u64, payload: &[Value]) -> Result<(), PostError> {
        self.admitted(event, time, payload).map_err(|e| self.post_error(e))
    }

    /// [`admit`](Self::admit), its refusal in short.
    #[inline(always)]
    pub(super) fn admitted(&self, event: u32, time: u64, payload: &[Value]) -> Result<(), StepError> {
        let agent = self.validated(event, payload)?;
        self.admitted_time(event, agent, time)
    }

    /// The part of [`admitted`](Self::admitted) after the payload check:
    /// the time of `event` of agent `agent` against the agent's clock and
    /// the clock it arrived at.
    #[inline(always)]
    pub(super) fn admitted_time(&self, event: u32, agent: u32, time: u64) -> Result<(), StepError> {
        // SAFETY: an event's agent is an agent: `Net::new` reads each
        // event's agent's `stale after` from a table of one entry per
        // agent, and `agents` has one record per agent (native code: its
        // digest, checked by `Engine::with_native`).
        let last = unsafe { self.agents.get_unchecked(agent as usize) }.last;
        if time < last {
            return Err(StepError::OutOfOrder { event, time, last });
        }
        if let Some(clock) = self.clock {
            if time > clock.saturating_add(self.max_skew) {
                return Err(StepError::FromTheFuture { event, time, clock, max_skew: self.max_skew });
            }
        }
        Ok(())
    }

    /// The end of a mission (§10.12): if the state at rest is `final`, back
    /// to the initial state with no facts ([`reset`](Self::reset)) and
    /// true. `situ bench` and its stream generator call it after each event
    /// (after both rests), unless told not to.
    #[inline]
    pub fn reset_if_final(&mut self) -> bool {
        debug_assert!((self.state as usize) < self.net.final_state.len());
        // SAFETY: `Net::new` gives `final_state` an entry for every state
        // the engine can be in: the initial one, a rule's target, one
        // `force_state` checked.
        let fin = unsafe { *self.net.final_state.get_unchecked(self.state as usize) };
        if fin {
            self.reset();
        }
        fin
    }

    /// Checks an event against the bundle's schema (a part of
    /// [`admit`](Self::admit), which also checks its time).
    pub fn validate(&self, event: u32, payload: &[Value]) -> Result<(), PostError> {
        self.validated(event, payload).map(|_| ()).map_err(|e| self.post_error(e))
    }

    /// [`validate`](Self::validate), giving the event's agent.
    #[inline(always)]
    fn validated(&self, event: u32, payload: &[Value]) -> Result<u32, StepError> {
        let Some(ev) = self.net.event.get(event as usize) else {
            return Err(StepError::UnknownEvent { event });
        };
        let (s, e) = (ev.kinds.0 as usize, ev.kinds.1 as usize);
        let n = e.wrapping_sub(s);
        if n != payload.len() {
            return Err(StepError::Arity { event, expected: n, found: payload.len() });
        }
        let mut i = 0;
        while i < n {
            // SAFETY: `Net::new` builds each event's range of kinds inside
            // `kinds` (`s <= e <= kinds.len()`), and `payload` has `n` values.
            let (k, v) = unsafe { (*self.net.kinds.get_unchecked(s + i), *payload.get_unchecked(i)) };
            let fits = match (k, v) {
                (Kind::F64, Value::F64(_)) | (Kind::I64, Value::I64(_)) | (Kind::Bool, Value::Bool(_)) => true,
                (Kind::Symbol(n), Value::Symbol(x)) => x < n,
                _ => false,
            };
            if !fits {
                return Err(StepError::Type { event, field: i as u32 });
            }
            i += 1;
        }
        Ok(ev.agent)
    }
}
