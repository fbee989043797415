//! Drive, the actuator agent: tracks LPL's local target with the single
//! Lyapunov control law of eqs. (12)–(15) (`track()`), or brakes (`halt()`,
//! `estop()`).
//!
//! The target is a carrot on the offset path a lookahead ahead, with the
//! path's heading and curvature; the gains are [`Gains::carrot`] of that
//! lookahead, and the speed is clamped to the plan's limit (the law's vb
//! term, positive while the carrot leads, would otherwise push above it).

use crate::control::{control_law, target_reaching, Gains};
use crate::geom::Pose;
use crate::lpl::LocalPlan;
use crate::vehicle::{Command, VehicleParams};

/// The Drive agent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Drive {
    /// The vehicle it drives.
    pub params: VehicleParams,
}

impl Drive {
    /// Drive for a vehicle.
    pub fn new(params: VehicleParams) -> Self {
        Drive { params }
    }

    /// `track()`: steering and speed toward LPL's target.
    pub fn track(&self, pose: &Pose, plan: &LocalPlan) -> Command {
        let input = target_reaching(pose, &plan.target);
        control_law(&input, &Gains::carrot(plan.lookahead), &self.params, plan.speed)
    }

    /// `halt()`: brake to standstill (at the vehicle's braking limit) and
    /// hold the wheel where it is.
    pub fn halt(&self, steer: f64) -> Command {
        Command { v: 0.0, steer }
    }

    /// `estop()`: emergency braking (the same command: the vehicle model
    /// brakes at its limit), wheel straight.
    pub fn estop(&self) -> Command {
        Command { v: 0.0, steer: 0.0 }
    }
}
