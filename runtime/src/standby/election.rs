//! Which board leads. Pure: every time is given, in nanoseconds of one
//! monotonic clock, so the rules are tested without waiting.
//!
//! - A board starts as a follower. It leads when it has heard no leader
//!   for its lease (plus `stagger` per rank, so that two followers do not
//!   take over at once); at start, when it has heard none for the join
//!   time (a lease from its first link to another process, [`linked`]:
//!   a board that comes back hears the leader first), one lease more per
//!   rank (the first listed leads when all start together, even if it
//!   started a little later).
//!
//! [`linked`]: Election::linked
//! - Its epoch is above every epoch it has seen and above the wall clock in
//!   milliseconds, times 256, plus its rank: epochs grow across restarts
//!   and two boards never pick the same one.
//! - A leader that hears a higher epoch steps down: it follows again.
//! - A follower whose log lacks a decision the agents were told (not
//!   `ready`) does not lead at its deadline: leading from an older state
//!   would take that decision back. It waits `give_up` more for a board
//!   that has it; then it leads from the rules' initial state
//!   ([`Decision::LeadFromStart`]), as a single board that restarts.

use super::StandbyConfig;

/// What the board must do.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Decision {
    /// Lead at this epoch.
    Lead(u64),
    /// Lead at this epoch from the rules' initial state: no board that
    /// holds the decisions the agents were told led within `give_up`.
    LeadFromStart(u64),
    /// A higher epoch leads: follow it.
    StepDown { higher: u64 },
}

#[derive(Debug, Clone)]
pub struct Election {
    rank: u32,
    lease: u64,
    stagger: u64,
    join: u64,
    give_up: u64,
    started: u64,
    /// Since when the deadline has passed while this follower was not
    /// ready.
    waiting: Option<u64>,
    /// This board's epoch while it leads.
    leading: Option<u64>,
    /// The highest epoch seen, this board's included.
    highest: u64,
    /// When the highest epoch's leader was last heard.
    last_heard: Option<u64>,
}

impl Election {
    /// A board starting at `now`, having seen epochs up to `known` (its
    /// journal's, or 0).
    pub fn new(config: &StandbyConfig, now: u64, known: u64) -> Election {
        let lease = config.lease.as_nanos() as u64;
        Election {
            rank: config.rank,
            lease,
            stagger: config.stagger.as_nanos() as u64,
            join: lease,
            give_up: config.give_up.as_nanos() as u64,
            started: now,
            waiting: None,
            leading: None,
            highest: known,
            last_heard: None,
        }
    }

    /// The board's first link to another process came at `now`: its join
    /// time counts from here.
    pub fn linked(&mut self, now: u64) {
        self.started = now;
    }

    pub fn leading(&self) -> Option<u64> {
        self.leading
    }

    pub fn highest(&self) -> u64 {
        self.highest
    }

    /// Another board was heard at `at` with `epoch`.
    pub fn heard(&mut self, epoch: u64, at: u64) -> Option<Decision> {
        if epoch < self.highest {
            return None;
        }
        self.highest = epoch;
        if self.last_heard.is_none_or(|t| at > t) {
            // Something new was heard: the wait for a board that holds
            // the log starts again from it (the same beat told again, as a
            // transport's "last heard" is, changes nothing).
            self.last_heard = Some(at);
            self.waiting = None;
        }
        match self.leading {
            Some(mine) if epoch > mine => {
                self.leading = None;
                Some(Decision::StepDown { higher: epoch })
            }
            _ => None,
        }
    }

    /// How long this board waits without hearing a leader before it leads.
    fn patience(&self) -> u64 {
        self.lease.saturating_add(self.stagger.saturating_mul(self.rank as u64))
    }

    /// When this follower will lead if it hears nothing more.
    pub fn deadline(&self) -> Option<u64> {
        if self.leading.is_some() {
            return None;
        }
        Some(match self.last_heard {
            Some(t) => t.saturating_add(self.patience()),
            None => self.started.saturating_add(self.join).saturating_add(self.lease.saturating_mul(self.rank as u64)),
        })
    }

    /// Whether this follower's deadline passed while it was not ready
    /// (it waits for a board that holds the decisions it lacks).
    pub fn waiting(&self) -> bool {
        self.waiting.is_some()
    }

    /// At `now` (the wall clock reads `wall_ms`): whether this follower
    /// leads now, and with which epoch. `ready`: its log holds every
    /// decision the agents were told, as far as it heard.
    pub fn poll(&mut self, now: u64, wall_ms: u64, ready: bool) -> Option<Decision> {
        let deadline = self.deadline()?;
        if now < deadline {
            return None;
        }
        let afresh = if ready {
            false
        } else {
            let since = *self.waiting.get_or_insert(now);
            if now < since.saturating_add(self.give_up) {
                return None;
            }
            true
        };
        self.waiting = None;
        let counter = (self.highest >> 8).saturating_add(1).max(wall_ms);
        let epoch = (counter << 8) | (self.rank as u64 & 0xff);
        self.leading = Some(epoch);
        self.highest = epoch;
        Some(if afresh { Decision::LeadFromStart(epoch) } else { Decision::Lead(epoch) })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    const MS: u64 = 1_000_000;

    /// Lease 400 ms, 100 ms more per rank.
    fn config(rank: u32) -> StandbyConfig {
        let mut c = StandbyConfig::new("b", rank, Duration::from_millis(200));
        c.lease = Duration::from_millis(400);
        c.stagger = Duration::from_millis(100);
        c
    }

    #[test]
    fn the_first_board_leads_after_the_join_time_and_the_second_later() {
        let (mut a, mut b) = (Election::new(&config(0), 0, 0), Election::new(&config(1), 0, 0));
        assert_eq!(a.poll(399 * MS, 1000, true), None);
        let Some(Decision::Lead(e)) = a.poll(400 * MS, 1000, true) else { panic!("rank 0 leads at 400 ms") };
        assert_eq!(e, 1000 << 8);
        // The second heard it before its own, later, deadline.
        assert_eq!(b.heard(e, 405 * MS), None);
        assert_eq!(b.poll(500 * MS, 1000, true), None);
        assert_eq!(b.deadline(), Some((405 + 400 + 100) * MS));
        // Alone, the second would have led a lease after the first.
        let mut c = Election::new(&config(1), 0, 0);
        assert_eq!(c.poll(799 * MS, 1000, true), None);
        assert!(matches!(c.poll(800 * MS, 1000, true), Some(Decision::Lead(_))));
        // The join time counts from the first link.
        let mut d = Election::new(&config(0), 0, 0);
        d.linked(1000 * MS);
        assert_eq!(d.poll(1399 * MS, 1000, true), None);
        assert!(matches!(d.poll(1400 * MS, 1000, true), Some(Decision::Lead(_))));
    }

    #[test]
    fn a_follower_leads_with_a_higher_epoch_when_the_leader_falls_silent() {
        let mut b = Election::new(&config(1), 0, 0);
        let old = 5000 << 8;
        b.heard(old, 10 * MS);
        assert_eq!(b.poll(509 * MS, 1, true), None);
        let Some(Decision::Lead(e)) = b.poll(510 * MS, 1, true) else { panic!("leads after lease + stagger") };
        assert!(e > old, "{e} > {old}");
        assert_eq!(e & 0xff, 1, "the rank is in the epoch");
    }

    #[test]
    fn a_leader_steps_down_for_a_higher_epoch_only() {
        let mut a = Election::new(&config(0), 0, 0);
        let Some(Decision::Lead(e)) = a.poll(800 * MS, 7, true) else { panic!() };
        assert_eq!(a.heard(e - 1, 900 * MS), None, "a lower epoch is ignored");
        assert_eq!(a.leading(), Some(e));
        assert_eq!(a.heard(e + 1, 901 * MS), Some(Decision::StepDown { higher: e + 1 }));
        assert_eq!(a.leading(), None);
        // Following now: it leads again only after hearing nothing for its lease.
        assert_eq!(a.poll(1300 * MS, 7, true), None);
        let Some(Decision::Lead(again)) = a.poll(1301 * MS, 7, true) else { panic!() };
        assert!(again > e + 1);
    }

    #[test]
    fn a_follower_that_lacks_a_decision_does_not_lead_until_it_gives_up() {
        let mut c = config(1);
        c.give_up = Duration::from_millis(2000);
        let mut b = Election::new(&c, 0, 0);
        let old = 5000 << 8;
        b.heard(old, 10 * MS);
        // Its deadline (10 + 400 + 100 ms) passes while it is behind.
        assert_eq!(b.poll(600 * MS, 1, false), None);
        assert!(b.waiting());
        assert_eq!(b.poll(2599 * MS, 1, false), None);
        // Caught up meanwhile: it leads at once.
        let mut caught = b.clone();
        assert!(matches!(caught.poll(700 * MS, 1, true), Some(Decision::Lead(_))));
        // The same beat told again changes nothing.
        let mut again = b.clone();
        again.heard(old, 10 * MS);
        assert!(again.waiting());
        // Another board led meanwhile: the wait starts again from its beat.
        let mut other = b.clone();
        other.heard(old + 256, 1000 * MS);
        assert!(!other.waiting());
        assert_eq!(other.poll(2600 * MS, 1, false), None);
        // Nobody came: after give_up it leads, from the rules' start.
        let Some(Decision::LeadFromStart(e)) = b.poll(2600 * MS, 1, false) else {
            panic!("leads from the start after give_up")
        };
        assert!(e > old);
        assert!(!b.waiting());
    }

    #[test]
    fn epochs_grow_across_restarts_with_the_wall_clock_or_the_journal() {
        // Restarted with a journal whose epoch is ahead of the wall clock.
        let mut a = Election::new(&config(0), 0, (9000 << 8) | 1);
        let Some(Decision::Lead(e)) = a.poll(800 * MS, 10, true) else { panic!() };
        assert_eq!(e, 9001 << 8);
        // Restarted without one: the wall clock.
        let mut b = Election::new(&config(0), 0, 0);
        assert_eq!(b.poll(800 * MS, 12345, true), Some(Decision::Lead(12345 << 8)));
    }
}
