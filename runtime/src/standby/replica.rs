//! A follower's bookkeeping. Pure: times are given (nanoseconds of one
//! monotonic clock).
//!
//! - **The log.** A batch applies when it starts right after what this
//!   board applied, or overlaps it with the same epochs; one that starts
//!   further on means entries were missed (ask the leader for them); one
//!   whose epochs differ from ours, or a leader whose log is shorter than
//!   ours, means this board applied entries the leader does not have (it
//!   led once, cut off): it starts again from the leader's log.
//! - **The events held.** Every board hears the agents' events; a follower
//!   holds each until the leader's log shows it (then forgets it). At a
//!   takeover, the events still held were never sequenced: the new leader
//!   takes them, in the order they arrived, once. An event that arrives
//!   after the log showed it (its path was slower) is recognised and
//!   dropped. Both are kept for `keep` at most.

use super::{same_event, Batch, LogStore, Logged};
use crate::bus::EventMsg;
use std::collections::VecDeque;

/// What to do with a batch.
#[derive(Debug, Clone, PartialEq)]
pub enum Offer {
    /// Apply these entries, the first right after what was applied.
    Apply(Vec<Logged>),
    /// Nothing new.
    Nothing,
    /// Entries were missed: ask for the log from this index.
    Behind { from: u64 },
    /// This board's log is not the leader's: start again from nothing.
    Diverged,
}

#[derive(Debug)]
pub struct Replica {
    keep: u64,
    held: VecDeque<(u64, EventMsg)>,
    taken: VecDeque<(u64, EventMsg)>,
    /// Events held longer than `keep` and dropped: the leader never had them.
    pub dropped: u64,
}

impl Replica {
    /// Holds events for `keep` nanoseconds at most.
    pub fn new(keep: u64) -> Replica {
        Replica { keep, held: VecDeque::new(), taken: VecDeque::new(), dropped: 0 }
    }

    /// What `batch` means for a board whose log is `log`.
    pub fn offer(&self, batch: &Batch, log: &LogStore) -> Offer {
        let applied = log.len();
        if batch.first > applied + 1 {
            return Offer::Behind { from: applied + 1 };
        }
        if log.epoch_at(batch.first - 1) != Some(batch.prev_epoch) {
            return Offer::Diverged;
        }
        let mut fresh = Vec::new();
        for (i, l) in batch.entries.iter().enumerate() {
            let index = batch.first + i as u64;
            if index <= applied {
                if log.epoch_at(index) != Some(l.epoch) {
                    return Offer::Diverged;
                }
            } else {
                fresh.push(l.clone());
            }
        }
        if fresh.is_empty() && batch.last() < applied && batch.entries.is_empty() {
            // A beat says the leader's log is shorter than ours. If the
            // entry after its end was written by this leader, the beat is
            // only older than what we applied since (it came late); if by
            // an older one, the leader never had it.
            if log.epoch_at(batch.last() + 1) != Some(batch.epoch) {
                return Offer::Diverged;
            }
        }
        if fresh.is_empty() {
            Offer::Nothing
        } else {
            Offer::Apply(fresh)
        }
    }

    /// An event heard from an agent at `now`.
    pub fn hold(&mut self, msg: EventMsg, now: u64) {
        self.expire(now);
        if let Some(i) = self.taken.iter().position(|(_, m)| same_event(m, &msg)) {
            self.taken.remove(i);
            return;
        }
        self.held.push_back((now, msg));
    }

    /// The leader's log showed `msg` (applied or refused) at `now`.
    pub fn sequenced(&mut self, msg: &EventMsg, now: u64) {
        if let Some(i) = self.held.iter().position(|(_, m)| same_event(m, msg)) {
            self.held.remove(i);
            return;
        }
        self.taken.push_back((now, msg.clone()));
    }

    /// The events never sequenced, in the order they arrived; forgets
    /// everything held (this board now leads).
    pub fn take_unsequenced(&mut self, now: u64) -> Vec<EventMsg> {
        self.expire(now);
        self.taken.clear();
        self.held.drain(..).map(|(_, m)| m).collect()
    }

    /// How many events are held now.
    pub fn held(&self) -> usize {
        self.held.len()
    }

    /// Forgets what is held and what was taken (a board that starts again).
    pub fn clear(&mut self) {
        self.held.clear();
        self.taken.clear();
    }

    fn expire(&mut self, now: u64) {
        let cut = now.saturating_sub(self.keep);
        while self.held.front().is_some_and(|(t, _)| *t < cut) {
            self.held.pop_front();
            self.dropped += 1;
        }
        while self.taken.front().is_some_and(|(t, _)| *t < cut) {
            self.taken.pop_front();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::standby::Entry;
    use situ_bundle::Value;

    fn ev(time: u64, x: f64) -> EventMsg {
        EventMsg { agent: 0, event: 0, time, payload: vec![Value::F64(x)], urgent: false }
    }

    fn logged(epoch: u64, time: u64) -> Logged {
        Logged { epoch, entry: Entry::Tick { time } }
    }

    fn log_of(epochs: &[u64]) -> LogStore {
        let mut l = LogStore::default();
        for (i, e) in epochs.iter().enumerate() {
            l.push(logged(*e, i as u64));
        }
        l
    }

    fn batch(first: u64, prev_epoch: u64, epochs: &[u64]) -> Batch {
        Batch {
            epoch: 9,
            board: "a".into(),
            first,
            prev_epoch,
            decided: 0,
            entries: epochs.iter().map(|e| logged(*e, 0)).collect(),
        }
    }

    #[test]
    fn a_batch_applies_after_what_was_applied_and_overlaps_are_skipped() {
        let r = Replica::new(1_000);
        let log = log_of(&[1, 1]);
        assert_eq!(r.offer(&batch(3, 1, &[1, 2]), &log), Offer::Apply(vec![logged(1, 0), logged(2, 0)]));
        assert_eq!(r.offer(&batch(2, 1, &[1, 2]), &log), Offer::Apply(vec![logged(2, 0)]));
        assert_eq!(r.offer(&batch(1, 0, &[1, 1]), &log), Offer::Nothing);
        assert_eq!(r.offer(&batch(5, 2, &[2]), &log), Offer::Behind { from: 3 });
    }

    #[test]
    fn a_log_that_is_not_the_leaders_is_diverged() {
        let r = Replica::new(1_000);
        // Entry 2 was written in epoch 1 here, in epoch 3 at the leader.
        assert_eq!(r.offer(&batch(3, 3, &[3]), &log_of(&[1, 1])), Offer::Diverged);
        assert_eq!(r.offer(&batch(2, 1, &[3]), &log_of(&[1, 1])), Offer::Diverged);
        // The leader (epoch 9)'s beat says its log has 1 entry; ours has 2,
        // the second written by epoch 1: the leader never had it.
        assert_eq!(r.offer(&batch(2, 1, &[]), &log_of(&[1, 1])), Offer::Diverged);
        // The second written by epoch 9: the beat is only late.
        assert_eq!(r.offer(&batch(2, 1, &[]), &log_of(&[1, 9])), Offer::Nothing);
        // A beat at our length is nothing new.
        assert_eq!(r.offer(&batch(3, 1, &[]), &log_of(&[1, 1])), Offer::Nothing);
    }

    #[test]
    fn held_events_are_forgotten_once_sequenced_even_when_they_arrive_late() {
        let mut r = Replica::new(1_000);
        r.hold(ev(1, 0.5), 10);
        r.hold(ev(2, f64::NAN), 11);
        r.sequenced(&ev(2, f64::NAN), 12); // the same NaN
        r.sequenced(&ev(3, 1.0), 13); // its own message comes after the log
        r.hold(ev(3, 1.0), 14);
        r.hold(ev(4, 1.0), 15);
        assert_eq!(r.take_unsequenced(16), vec![ev(1, 0.5), ev(4, 1.0)]);
        assert_eq!(r.held(), 0);
    }

    #[test]
    fn events_held_too_long_are_dropped_and_counted() {
        let mut r = Replica::new(100);
        r.hold(ev(1, 0.0), 0);
        r.hold(ev(2, 0.0), 150);
        assert_eq!(r.take_unsequenced(150), vec![ev(2, 0.0)]);
        assert_eq!(r.dropped, 1);
    }
}
