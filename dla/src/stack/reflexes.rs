//! The reactive layer's reflexes: what it does to the command its case (or
//! the teacher) chose, given the scan's readings, so that the body never
//! touches anything and is never left where it can do nothing.
//!
//! The body is 0.4 m × 0.36 m, the laser at its centre, and the tricycle
//! turns "on the spot" by crawling on full lock about a centre
//! [`TURN_RADIUS`] to the side. In order:
//! - a standing command becomes a creep when the strip ahead is clear;
//! - a turn on the spot is checked against the disc it sweeps about that
//!   centre ([`TURN_SWEEP`]): it turns the other way if that disc is
//!   clear, creeps straight on if the strip ahead is, turns within the
//!   tighter disc ([`TURN_TIGHT`]) if that is all it can do, else stops;
//! - the body's sweep over the next [`SWEEP_TIME`] (the command held, as the
//!   Base applies it) must keep [`SWEEP_MARGIN`] from every reading, and
//!   must not take a robot that can turn where it is to a place where it
//!   cannot; otherwise the command becomes a turn on the spot, or a stop.

use super::driver;
use crate::cases::Command as CaseCommand;
use crate::grid::Beam;
use situ_sim::geom::{v2, Pose, Vec2};
use situ_sim::vehicle::{integrate, VehicleParams};

/// How far to the side of the laser (the robot's centre) a turn on the
/// spot turns about (m): the indoor robot on full lock, 0.2 m / tan 1.2.
pub const TURN_RADIUS: f64 = 0.078;
/// The disc a turn on the spot sweeps about its centre (m): the far
/// corners of the 0.4 m × 0.36 m body, √(0.2² + (0.18 + 0.078)²) = 0.33,
/// and 0.03 to spare.
pub const TURN_SWEEP: f64 = 0.36;
/// The same disc with 0.014 to spare (m): a turn on the spot is allowed
/// this close only when neither a full-margin turn nor a creep is, so that
/// the robot is never left where it can do nothing at all.
pub const TURN_TIGHT: f64 = 0.34;
/// How far ahead the body must be clear for the reactive layer to creep
/// straight on when it can turn neither way (m).
pub const CREEP: f64 = 0.15;
/// Below this turn rate (rad/s) a command slower than a crawl is a stop.
pub const STILL_TURN: f64 = 0.05;
/// The slowest the Base rolls while it turns (m/s).
pub const CRAWL: f64 = 0.03;

/// The reactive layer's reflexes on the command it chose, given the scan's
/// readings as `points` in the robot's frame and the nearest sector range.
pub(super) fn reflexes(
    command: CaseCommand,
    points: &[Vec2],
    nearest_all: f64,
    vehicle: &VehicleParams,
) -> CaseCommand {
    // Never standing still where the body could creep straight on.
    let command = if standstill(&command) && ahead_clear(points, CREEP) {
        CaseCommand { speed: CRAWL, turn_rate: 0.0 }
    } else {
        command
    };
    // Turning "in place" sweeps a disc about a centre to the side it
    // turns to: that way if nothing is within the disc, else the other
    // way if nothing is within that one, else straight on at a crawl if
    // nothing is in the body's way, else within the tighter disc, else not
    // at all.
    let command = if command.speed < CRAWL && nearest_all < TURN_RADIUS + TURN_SWEEP {
        let side = if command.turn_rate < 0.0 { -1.0 } else { 1.0 };
        if let Some(side) = turn_side(points, side, TURN_SWEEP) {
            CaseCommand { speed: command.speed, turn_rate: side * command.turn_rate.abs() }
        } else if ahead_clear(points, CREEP) {
            CaseCommand { speed: CRAWL, turn_rate: 0.0 }
        } else if let Some(side) = turn_side(points, side, TURN_TIGHT) {
            // Hemmed in: the turn within the tighter disc rather than none.
            CaseCommand { speed: command.speed, turn_rate: side * command.turn_rate.abs() }
        } else {
            CaseCommand { speed: 0.0, turn_rate: 0.0 }
        }
    } else {
        command
    };
    // Last, the body's sweep over the next half second: a command that
    // would bring a reading within it becomes a turn on the spot (the
    // way it turned, else the other), or a stop.
    if sweep_clear(points, &command, vehicle) {
        command
    } else {
        let side = if command.turn_rate < 0.0 { -1.0 } else { 1.0 };
        let turn = driver().max_turn_rate;
        match turn_side(points, side, TURN_SWEEP).or_else(|| turn_side(points, side, TURN_TIGHT)) {
            Some(side) => CaseCommand { speed: 0.0, turn_rate: side * turn },
            None => CaseCommand { speed: 0.0, turn_rate: 0.0 },
        }
    }
}

/// Whether the Base stops on a command: slower than a crawl and turning
/// less than [`STILL_TURN`].
pub(super) fn standstill(c: &CaseCommand) -> bool {
    c.speed < CRAWL && c.turn_rate.abs() < STILL_TURN
}

/// The readings of a scan as points in the robot's frame (m).
pub(super) fn scan_points(beams: &[Beam]) -> impl Iterator<Item = Vec2> + '_ {
    beams
        .iter()
        .filter(|b| b.range.is_finite() && b.range < b.max_range)
        .map(|b| v2(b.range * b.angle.cos(), b.range * b.angle.sin()))
}

/// Whether a turn on the spot to `side` (1 left, −1 right) from `pose`
/// (in the frame of `points`) keeps the body clear of them: nothing within
/// [`TURN_SWEEP`] of the centre it turns about, [`TURN_RADIUS`] to that side.
fn turn_clear_at(points: &[Vec2], pose: &Pose, side: f64) -> bool {
    turn_clear_within(points, pose, side, TURN_SWEEP)
}

/// [`turn_clear_at`] with the disc's radius `sweep` (m).
fn turn_clear_within(points: &[Vec2], pose: &Pose, side: f64, sweep: f64) -> bool {
    points.iter().all(|&p| (pose.to_local(p) - v2(0.0, side * TURN_RADIUS)).norm() > sweep)
}

/// The side (1 left, −1 right) a turn on the spot from where the robot is
/// may take with the disc `sweep` clear: `side` if it can, else the other.
fn turn_side(points: &[Vec2], side: f64, sweep: f64) -> Option<f64> {
    let here = Pose::new(0.0, 0.0, 0.0);
    [side, -side].into_iter().find(|&s| turn_clear_within(points, &here, s, sweep))
}

/// How far ahead (s) `sweep_clear` follows a command.
pub const SWEEP_TIME: f64 = 0.5;
/// What the body keeps from every reading in `sweep_clear` (m).
pub const SWEEP_MARGIN: f64 = 0.04;

/// Whether the Base driving `c` (as [`Base`] turns it into a speed and a
/// steering angle, held) for [`SWEEP_TIME`] keeps the body, grown by
/// [`SWEEP_MARGIN`], clear of every reading of the scan, and, when the
/// robot could turn on the spot where it is, leaves it where it still can
/// (so it never drives into a corner it cannot turn out of).
fn sweep_clear(points: &[Vec2], c: &CaseCommand, vehicle: &VehicleParams) -> bool {
    if standstill(c) {
        return true;
    }
    let v = c.speed.clamp(CRAWL, vehicle.max_speed);
    let steer = (c.turn_rate * vehicle.wheelbase / v).atan().clamp(-vehicle.max_steer, vehicle.max_steer);
    let kappa = steer.tan() / vehicle.wheelbase;
    let body = vehicle.front.max(vehicle.rear).hypot(vehicle.width / 2.0) + SWEEP_MARGIN;
    let reach = v * SWEEP_TIME + body.max(TURN_RADIUS + TURN_SWEEP);
    let points: Vec<Vec2> = points.iter().copied().filter(|p| p.norm() <= reach).collect();
    let (front, rear, half) =
        (vehicle.front + SWEEP_MARGIN, vehicle.rear + SWEEP_MARGIN, vehicle.width / 2.0 + SWEEP_MARGIN);
    let here = Pose::new(0.0, 0.0, 0.0);
    let poses: Vec<Pose> = (1..=5).map(|k| integrate(here, v, kappa, SWEEP_TIME * k as f64 / 5.0)).collect();
    let body_clear = poses.iter().all(|pose| {
        points.iter().all(|&p| {
            let q = pose.to_local(p);
            !(q.x <= front && q.x >= -rear && q.y.abs() <= half)
        })
    });
    let can_turn = |pose: &Pose| turn_clear_at(&points, pose, 1.0) || turn_clear_at(&points, pose, -1.0);
    let last = poses.last().copied().unwrap_or(here);
    body_clear && (!can_turn(&here) || can_turn(&last))
}

/// Whether moving straight ahead by `reach` (m) keeps the body clear: no
/// reading in the strip the body sweeps (0.2 m ahead of the centre, 0.18 m
/// to each side, and 0.02 m to spare).
fn ahead_clear(points: &[Vec2], reach: f64) -> bool {
    points.iter().all(|p| !(p.x > 0.0 && p.x < 0.22 + reach && p.y.abs() < 0.2))
}

#[cfg(test)]
mod tests {
    use super::*;
    use situ_sim::vehicle::VehicleParams;

    /// A flat wall `x` metres ahead, readings every 2 cm across 1.2 m.
    fn wall(x: f64) -> Vec<Vec2> {
        (-30..=30).map(|i| v2(x, i as f64 * 0.02)).collect()
    }

    fn nearest(points: &[Vec2]) -> f64 {
        points.iter().map(|p| p.norm()).fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn a_robot_too_close_to_turn_with_the_full_margin_turns_within_the_tight_disc_rather_than_freeze_its_turn() {
        let vehicle = VehicleParams::indoor();
        // 0.35 m from the wall: neither full disc is clear, nor the strip
        // ahead; the body's own sweep (0.327 m) is.
        let points = wall(0.35);
        assert_eq!(turn_side(&points, 1.0, TURN_SWEEP), None);
        assert!(!ahead_clear(&points, CREEP));
        let c = reflexes(CaseCommand { speed: 0.0, turn_rate: -1.0 }, &points, nearest(&points), &vehicle);
        assert_eq!((c.speed, c.turn_rate), (0.0, -1.0), "frozen where it can turn");
        // The reflexes do not invent a motion: a command to stand stands
        // (the detour changes what the cases are asked).
        let c = reflexes(CaseCommand { speed: 0.0, turn_rate: 0.0 }, &points, nearest(&points), &vehicle);
        assert!(standstill(&c), "{c:?}");
        // Closer than the body's sweep: nothing is safe, it stops.
        let points = wall(0.3);
        let c = reflexes(CaseCommand { speed: 0.0, turn_rate: 1.0 }, &points, nearest(&points), &vehicle);
        assert!(standstill(&c), "{c:?}");
        // Far enough: the full margin turn, the way it was asked.
        let points = wall(0.6);
        let c = reflexes(CaseCommand { speed: 0.0, turn_rate: -1.0 }, &points, nearest(&points), &vehicle);
        assert!(c.turn_rate < 0.0, "{c:?}");
    }

    #[test]
    fn a_command_that_would_drive_the_body_into_a_reading_is_turned_or_stopped() {
        let vehicle = VehicleParams::indoor();
        let points = wall(0.4);
        let c = reflexes(CaseCommand { speed: 0.5, turn_rate: 0.0 }, &points, nearest(&points), &vehicle);
        assert!(c.speed < CRAWL, "{c:?}: drove on into the wall");
        // Nothing near: the command as chosen.
        let c = reflexes(CaseCommand { speed: 0.5, turn_rate: 0.2 }, &[], f64::INFINITY, &vehicle);
        assert_eq!((c.speed, c.turn_rate), (0.5, 0.2));
    }
}
