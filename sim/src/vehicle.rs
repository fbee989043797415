//! The vehicle: the tricycle kinematic model of eq. (1) of Dafflon et al.,
//!
//! ```text
//! ẋ = v cos θ,   ẏ = v sin θ,   θ̇ = v tan(γ) / lb
//! ```
//!
//! with actuator limits, integrated with a fixed step.
//!
//! **Integrator.** Over one step `dt` the inputs are held (zero-order hold)
//! and the model is integrated *exactly*: with κ = tan(γ)/lb the vehicle
//! moves along a circular arc of curvature κ (a straight segment when κ = 0),
//! so a constant-steering run is a circle of radius lb/tan γ to rounding,
//! whatever the step. Before the step, the commanded speed and steering are
//! rate-limited (acceleration, braking and steering-rate limits) and clamped
//! (speed and steering limits); the limited values are the ones held.

use crate::geom::{v2, wrap_angle, Pose, Vec2};
use serde::{Deserialize, Serialize};

/// The vehicle's geometry and limits.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct VehicleParams {
    /// Wheelbase lb: rear axle to the (virtual) front wheel (m).
    pub wheelbase: f64,
    /// Overall width (m).
    pub width: f64,
    /// Rear axle to the front bumper (m).
    pub front: f64,
    /// Rear axle to the rear bumper (m).
    pub rear: f64,
    /// Steering limit |γ| (rad).
    pub max_steer: f64,
    /// Steering rate limit |γ̇| (rad/s).
    pub max_steer_rate: f64,
    /// Speed limit of the vehicle (m/s); plans may impose lower ones.
    pub max_speed: f64,
    /// Acceleration limit (m/s²).
    pub max_accel: f64,
    /// Braking limit (m/s², positive).
    pub max_decel: f64,
    /// Ground clearance: obstacles no higher than this are driven over (m).
    pub clearance: f64,
}

impl VehicleParams {
    /// The outdoor vehicle of Zhang & Zhu, a refurbished automobile: 2.7 m
    /// wheelbase, 1.8 m wide, 10 m/s on open road (rules/outdoor.situ).
    pub fn outdoor() -> Self {
        VehicleParams {
            wheelbase: 2.7,
            width: 1.8,
            front: 3.6,
            rear: 0.9,
            max_steer: 0.55,
            max_steer_rate: 0.8,
            max_speed: 10.0,
            max_accel: 2.0,
            max_decel: 4.0,
            clearance: 0.15,
        }
    }

    /// The urban UGV of Dafflon et al.: a small electric car (Cycab-like,
    /// 1.2 m wheelbase), vmax = 2 m/s.
    pub fn urban() -> Self {
        VehicleParams {
            wheelbase: 1.2,
            width: 1.2,
            front: 1.6,
            rear: 0.3,
            max_steer: 0.4,
            max_steer_rate: 1.5,
            max_speed: 2.0,
            max_accel: 1.0,
            max_decel: 3.0,
            clearance: 0.1,
        }
    }

    /// DLA's small indoor robot (Pérez 2006 ran a Pioneer-like platform):
    /// 0.4 m square, 0.6 m/s, its pose (and its laser) at its centre; a
    /// tricycle with a short wheelbase and a wide steering range turns
    /// nearly on the spot.
    pub fn indoor() -> Self {
        VehicleParams {
            wheelbase: 0.2,
            width: 0.36,
            front: 0.2,
            rear: 0.2,
            max_steer: 1.2,
            max_steer_rate: 4.0,
            max_speed: 0.6,
            max_accel: 0.8,
            max_decel: 1.5,
            clearance: 0.02,
        }
    }

    /// The footprint rectangle at a pose, counter-clockwise.
    pub fn footprint(&self, pose: &Pose) -> Vec<Vec2> {
        let h = self.width / 2.0;
        [v2(-self.rear, -h), v2(self.front, -h), v2(self.front, h), v2(-self.rear, h)]
            .iter()
            .map(|p| pose.to_world(*p))
            .collect()
    }

    /// The minimum turning radius lb / tan(γmax) (m).
    pub fn min_turn_radius(&self) -> f64 {
        self.wheelbase / self.max_steer.tan()
    }
}

/// A command to the vehicle: speed and front-wheel angle.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Command {
    /// Linear velocity v (m/s).
    pub v: f64,
    /// Front-wheel orientation γ (rad, positive left).
    pub steer: f64,
}

/// The vehicle's state: posture and the actuators' current values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct VehicleState {
    /// Posture (rear-axle centre, heading).
    pub pose: Pose,
    /// Current speed (m/s).
    pub v: f64,
    /// Current front-wheel angle (rad).
    pub steer: f64,
}

impl VehicleState {
    /// At rest at a pose.
    pub fn at(pose: Pose) -> Self {
        VehicleState { pose, v: 0.0, steer: 0.0 }
    }

    /// The path curvature tan(γ)/lb (1/m).
    pub fn curvature(&self, params: &VehicleParams) -> f64 {
        self.steer.tan() / params.wheelbase
    }
}

/// The tricycle model with its parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Vehicle {
    /// Geometry and limits.
    pub params: VehicleParams,
    /// Current state.
    pub state: VehicleState,
}

impl Vehicle {
    /// A vehicle at rest at a pose.
    pub fn new(params: VehicleParams, pose: Pose) -> Self {
        Vehicle { params, state: VehicleState::at(pose) }
    }

    /// Applies a command for `dt` seconds (see the module doc for the limits
    /// and the integrator).
    pub fn step(&mut self, cmd: Command, dt: f64) {
        let p = &self.params;
        let s = &mut self.state;
        let v_target = cmd.v.clamp(0.0, p.max_speed);
        let dv = (v_target - s.v).clamp(-p.max_decel * dt, p.max_accel * dt);
        s.v = (s.v + dv).clamp(0.0, p.max_speed);
        let g_target = cmd.steer.clamp(-p.max_steer, p.max_steer);
        let dg = (g_target - s.steer).clamp(-p.max_steer_rate * dt, p.max_steer_rate * dt);
        s.steer = (s.steer + dg).clamp(-p.max_steer, p.max_steer);
        s.pose = integrate(s.pose, s.v, s.steer.tan() / p.wheelbase, dt);
    }
}

/// Exact integration of eq. (1) over `dt` with speed `v` and curvature `kappa` held.
pub fn integrate(pose: Pose, v: f64, kappa: f64, dt: f64) -> Pose {
    let ds = v * dt;
    let dth = kappa * ds;
    let (x, y) = if dth.abs() < 1e-9 {
        let mid = pose.theta + dth / 2.0;
        (pose.x + ds * mid.cos(), pose.y + ds * mid.sin())
    } else {
        let r = 1.0 / kappa;
        let th1 = pose.theta + dth;
        (pose.x + r * (th1.sin() - pose.theta.sin()), pose.y - r * (th1.cos() - pose.theta.cos()))
    };
    Pose::new(x, y, wrap_angle(pose.theta + dth))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_drive() {
        let mut veh = Vehicle::new(VehicleParams::urban(), Pose::new(1.0, 2.0, 0.5));
        veh.state.v = 2.0;
        for _ in 0..100 {
            veh.step(Command { v: 2.0, steer: 0.0 }, 0.05);
        }
        // 5 s at 2 m/s along heading 0.5.
        let p = veh.state.pose;
        assert!((p.x - (1.0 + 10.0 * 0.5f64.cos())).abs() < 1e-9);
        assert!((p.y - (2.0 + 10.0 * 0.5f64.sin())).abs() < 1e-9);
        assert!((p.theta - 0.5).abs() < 1e-12);
    }

    #[test]
    fn constant_curvature_circle() {
        let params = VehicleParams::urban();
        let gamma: f64 = 0.3;
        let radius = params.wheelbase / gamma.tan();
        let mut veh = Vehicle::new(params, Pose::new(0.0, 0.0, 0.0));
        veh.state.v = 1.5;
        veh.state.steer = gamma;
        let centre = v2(0.0, radius);
        let mut max_err: f64 = 0.0;
        let mut turned = 0.0;
        for _ in 0..2000 {
            veh.step(Command { v: 1.5, steer: gamma }, 0.02);
            turned += 1.5 * 0.02 / radius;
            max_err = max_err.max(((veh.state.pose.pos() - centre).norm() - radius).abs());
        }
        assert!(turned > 6.3, "went round at least once");
        assert!(max_err < 1e-9, "stays on the circle of radius lb/tan γ = {radius}: error {max_err}");
    }

    #[test]
    fn limits_hold() {
        let params = VehicleParams::outdoor();
        let mut veh = Vehicle::new(params, Pose::new(0.0, 0.0, 0.0));
        veh.step(Command { v: 50.0, steer: 2.0 }, 0.1);
        assert!((veh.state.v - params.max_accel * 0.1).abs() < 1e-12);
        assert!((veh.state.steer - params.max_steer_rate * 0.1).abs() < 1e-12);
        for _ in 0..200 {
            veh.step(Command { v: 50.0, steer: 2.0 }, 0.1);
        }
        assert_eq!(veh.state.v, params.max_speed);
        assert_eq!(veh.state.steer, params.max_steer);
        let fp = params.footprint(&Pose::new(0.0, 0.0, 0.0));
        assert_eq!(fp.len(), 4);
    }
}
