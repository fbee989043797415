//! The reactive layer's way out of a local minimum: a detour in the manner
//! of the Bug algorithms (Lumelsky & Stepanov), kept as small as a reactive
//! layer's memory should be.
//!
//! A layer that only reacts to the scan and the direction to its goal stops
//! in front of an obstacle square across that direction: every case there
//! says "turn towards the goal", and the goal is behind the obstacle. DLA's
//! answer is the route, but while the route is computed (and with no route
//! at all) the reactive layer must still get away. So it remembers two
//! things: the closest it has been to its target, and when.
//! - Caught: no progress of [`PROGRESS`] towards the target for [`STUCK`]
//!   seconds. The detour starts, to the side with the more room.
//! - On the detour the cases are asked for the open direction nearest the
//!   target on that side, at least one sector off it: the robot goes round
//!   the obstacle instead of facing it.
//! - Left when the robot is [`PROGRESS`] closer to the target than where it
//!   was caught and the way to the target is open; or when the target moves
//!   (a new subgoal).
//! - A detour that gets nowhere (less than [`PROGRESS`] moved in [`STUCK`]
//!   seconds) turns to the other side.

use super::cases::Situation;
use situ_sim::geom::{wrap_angle, Pose, Vec2};
use std::f64::consts::PI;

/// Seconds without progress after which the robot is caught.
pub const STUCK: f64 = 8.0;
/// Progress towards the target (m) that counts.
pub const PROGRESS: f64 = 0.3;
/// A direction is open when its sector's nearest reading is this far (m).
pub const OPEN: f64 = 1.2;
/// How far the target may move (m) and still be the same target.
pub const SAME_TARGET: f64 = 1.0;

/// The memory of the detour: where it heads and how it has gone.
#[derive(Debug, Clone, Default)]
pub struct Detour {
    /// The target tracked, the closest the robot has come to it (m) and
    /// when (s).
    target: Option<Vec2>,
    best: f64,
    since: f64,
    /// The detour under way, if any.
    round: Option<Round>,
}

/// A detour under way.
#[derive(Debug, Clone, Copy)]
struct Round {
    /// 1 to the left of the target's direction, −1 to the right.
    side: f64,
    /// The distance to the target (m) when the robot was caught.
    caught: f64,
    /// Where the robot was and when (s), to see whether it moves at all.
    mark: (Vec2, f64),
}

impl Detour {
    /// Whether a detour is under way.
    pub fn active(&self) -> bool {
        self.round.is_some()
    }

    /// Forgets the target: the next call to [`Detour::aim`] starts afresh.
    pub fn reset(&mut self) {
        *self = Detour::default();
    }

    /// The direction (rad, robot frame) the reactive layer should head for
    /// at time `now` (s) from `pose`, its target at `target`, with the
    /// nearest reading of each sector in `ranges` (sector 0 ahead).
    pub fn aim(&mut self, now: f64, pose: &Pose, target: Vec2, ranges: &[f64]) -> f64 {
        let to = target - pose.pos();
        let d = to.norm();
        let towards = wrap_angle(to.y.atan2(to.x) - pose.theta);
        if self.target.is_none_or(|t| (t - target).norm() > SAME_TARGET) {
            *self = Detour { target: Some(target), best: d, since: now, round: None };
        }
        if d < self.best - PROGRESS {
            self.best = d;
            self.since = now;
        }
        let n = ranges.len();
        if n == 0 {
            return towards;
        }
        let range = |a: f64| ranges[Situation::sector_of(a, n)];
        if let Some(round) = self.round {
            if d < round.caught - PROGRESS && range(towards) >= OPEN.min(d) {
                self.round = None;
                self.best = d;
                self.since = now;
                return towards;
            }
        } else if now - self.since >= STUCK {
            let room = |side: f64| (1..n / 2).map(|k| range(side * k as f64 * 2.0 * PI / n as f64)).sum::<f64>();
            let side = if room(1.0) >= room(-1.0) { 1.0 } else { -1.0 };
            self.round = Some(Round { side, caught: d, mark: (pose.pos(), now) });
        } else {
            return towards;
        }
        let Some(round) = self.round.as_mut() else { return towards };
        if now - round.mark.1 >= STUCK {
            if (pose.pos() - round.mark.0).norm() < PROGRESS {
                round.side = -round.side;
            }
            round.mark = (pose.pos(), now);
        }
        // The open direction nearest the target on the detour's side, one
        // sector off it at least; none open: a quarter turn off it.
        let width = 2.0 * PI / n as f64;
        (1..n / 2)
            .map(|k| wrap_angle(towards + round.side * k as f64 * width))
            .find(|&a| range(a) >= OPEN)
            .unwrap_or(wrap_angle(towards + round.side * PI / 2.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use situ_sim::geom::v2;

    /// Eight sectors, all open but those listed.
    fn ranges(blocked: &[usize]) -> Vec<f64> {
        (0..8).map(|i| if blocked.contains(&i) { 0.5 } else { 5.0 }).collect()
    }

    #[test]
    fn heads_for_the_target_until_caught_then_goes_round_and_leaves_when_past() {
        let mut detour = Detour::default();
        let here = Pose::new(0.0, 0.0, 0.0);
        let goal = v2(10.0, 0.0);
        // Blocked ahead (and a little to the right): no progress.
        let blocked = ranges(&[0, 7]);
        for t in 0..8 {
            assert_eq!(detour.aim(t as f64, &here, goal, &blocked), 0.0, "at {t} s");
            assert!(!detour.active());
        }
        // Caught: the open direction nearest the goal on the freer side
        // (the left: the right's first sector is blocked).
        let a = detour.aim(STUCK, &here, goal, &blocked);
        assert!(detour.active());
        assert!((a - PI / 4.0).abs() < 1e-9, "{a}");
        // Gone round: closer than where caught, the way open: left.
        let past = Pose::new(1.0, 1.0, 0.0);
        let a = detour.aim(STUCK + 3.0, &past, goal, &ranges(&[]));
        assert!(!detour.active());
        assert!((a - (-1.0f64).atan2(9.0)).abs() < 1e-9, "{a}");
    }

    #[test]
    fn a_detour_that_gets_nowhere_turns_to_the_other_side_and_a_new_target_ends_it() {
        let mut detour = Detour::default();
        let here = Pose::new(0.0, 0.0, 0.0);
        let goal = v2(10.0, 0.0);
        let blocked = ranges(&[0]);
        detour.aim(0.0, &here, goal, &blocked);
        let first = detour.aim(STUCK, &here, goal, &blocked);
        assert!(detour.active());
        let second = detour.aim(2.0 * STUCK, &here, goal, &blocked);
        assert!((first + second).abs() < 1e-9, "{first} then {second}: the other side");
        // A subgoal elsewhere is a new target.
        detour.aim(2.0 * STUCK + 0.1, &here, v2(0.0, 10.0), &blocked);
        assert!(!detour.active());
    }
}
