//! Per-agent limits on the events that come in from other processes, so
//! that one agent that floods its events (or a process that floods on its
//! key) cannot starve the Bulletinboard, its heartbeat and status, or the
//! other agents: each agent has a token bucket filled at a rate derived
//! from its declared `rate`, and an event that finds its bucket empty is
//! refused (counted and recorded by the bus).
//!
//! An agent stepped at `rate` Hz reports its events once per step; the
//! limit allows [`EVENTS_PER_STEP`] events per period on average, and a
//! burst of one second's worth (at least [`MIN_BURST`]). An agent without
//! `rate` is stepped on input, which comes no faster than the stack's
//! fastest agent: it gets the limit of the fastest declared rate (10 Hz if
//! none is declared). The clock is the wall clock of the receiving
//! process: the events' own stamps are the sender's word.

use situ_compiler::bundle::Content;
use std::time::Instant;

/// Events an agent may report per period of its rate, on average.
pub const EVENTS_PER_STEP: f64 = 4.0;

/// The smallest burst an agent may send at once.
pub const MIN_BURST: f64 = 16.0;

/// The rate assumed when no agent of the bundle declares one (Hz).
const DEFAULT_HZ: f64 = 10.0;

#[derive(Debug, Clone)]
struct Bucket {
    tokens: f64,
    per_s: f64,
    burst: f64,
    last: Instant,
}

/// The buckets of every agent of a bundle.
#[derive(Debug)]
pub struct EventLimits {
    buckets: Vec<Bucket>,
}

impl EventLimits {
    pub fn new(content: &Content) -> EventLimits {
        let valid = |h: &f64| situ_compiler::bundle::rate_in_range(*h);
        let fastest = content
            .agents
            .iter()
            .filter_map(|a| a.rate_hz)
            .filter(valid)
            .fold(None, |m: Option<f64>, h| Some(m.map_or(h, |m| m.max(h))));
        let now = Instant::now();
        let buckets = content
            .agents
            .iter()
            .map(|a| {
                let hz = a.rate_hz.filter(valid).or(fastest).unwrap_or(DEFAULT_HZ);
                let per_s = EVENTS_PER_STEP * hz;
                let burst = per_s.max(MIN_BURST);
                Bucket { tokens: burst, per_s, burst, last: now }
            })
            .collect();
        EventLimits { buckets }
    }

    /// The sustained limit of `agent` (events per second).
    pub fn per_second(&self, agent: u32) -> f64 {
        self.buckets.get(agent as usize).map_or(0.0, |b| b.per_s)
    }

    /// Whether one more event of `agent` may pass at `now` (and takes its
    /// token if so).
    pub fn take(&mut self, agent: u32, now: Instant) -> bool {
        let Some(b) = self.buckets.get_mut(agent as usize) else { return false };
        let dt = now.saturating_duration_since(b.last).as_secs_f64();
        b.last = b.last.max(now);
        b.tokens = (b.tokens + dt * b.per_s).min(b.burst);
        if b.tokens >= 1.0 {
            b.tokens -= 1.0;
            true
        } else {
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn content(src: &str) -> Content {
        let c = situ_compiler::check_source("t.situ", src);
        assert_eq!(c.errors(), 0);
        situ_compiler::bundle::build(&c)
    }

    #[test]
    fn limits_follow_the_declared_rates() {
        let c = content(
            "states { A initial B }
             agent Fast sensor { rate 50Hz event F }
             agent Slow sensor { rate 1Hz event S }
             agent OnInput processing { event I }
             rule r { when state == A and F and S and I then B }",
        );
        let mut l = EventLimits::new(&c);
        assert_eq!(l.per_second(0), 200.0);
        assert_eq!(l.per_second(1), 4.0);
        assert_eq!(l.per_second(2), 200.0, "without a rate: the fastest rate");
        // A burst of one second's worth (at least 16), then nothing more at
        // the same instant; the other agents keep their own.
        let t = Instant::now() + Duration::from_secs(1);
        let passed = (0..1000).filter(|_| l.take(1, t)).count();
        assert_eq!(passed, 16);
        assert!(l.take(0, t));
        // A second later, a second's worth again.
        let t2 = t + Duration::from_secs(1);
        let passed = (0..1000).filter(|_| l.take(1, t2)).count();
        assert_eq!(passed, 4);
        assert!(!l.take(99, t2), "an agent that does not exist");
    }
}
