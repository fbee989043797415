//! The controllers of Dafflon et al. (2013): target reaching (eqs. 2–5),
//! obstacle avoidance by elliptic limit cycles (eqs. 6–11) and the single
//! Lyapunov control law (eqs. 12–15) that both feed.
//!
//! Every elementary controller produces a [`ControlInput`] (the paper's
//! ISP: posture errors and the target's velocity and curvature), and
//! [`control_law`] turns it into a [`Command`] (v, γ).
//!
//! Choices where the paper is silent (each is documented where it is used):
//! - **Regularisation of eq. (15).** The terms divided by sin eθ cos eθ are
//!   singular at eθ = 0 (their numerators need not vanish there). We replace
//!   1/(sin eθ cos eθ) by sc/(sc² + ε²) with sc = sin eθ cos eθ and
//!   ε = [`SINGULAR_EPS`]: equal to the original for |sc| ≫ ε, zero at
//!   sc = 0, bounded by 1/(2ε). 1/cos eθ is taken with |cos eθ| ≥ 0.1.
//! - **Scale of the limit cycle.** Eqs. (6)–(7) are written in metres, so
//!   the balance between the rotation and the attraction to the cycle
//!   depends on the ellipse's size (a 3 m ellipse is approached almost
//!   radially). We evaluate them in coordinates divided by √(a_lc b_lc):
//!   the orbit is the same ellipse, and every ellipse gets the spiral of the
//!   unit circle.
//! - **Feed-forward curvature.** For the limit cycle the target curvature
//!   1/r_cT of eq. (13) is the curvature of the limit cycle's flow line at
//!   the vehicle (by a finite difference of θd over 0.1 m along it).

use crate::geom::{unit, v2, wrap_angle, Pose, Vec2};
use crate::vehicle::{Command, VehicleParams};
use serde::Serialize;

/// The ε of the regularised 1/(sin eθ cos eθ) of eq. (15).
pub const SINGULAR_EPS: f64 = 0.2;
/// ξ of eq. (4): below this distance (m), θRT is θT.
pub const XI: f64 = 1e-3;

/// The designer's constants K = (Kd, Kl, Ko, Kx, KRT, Kθ) of eqs. (14)–(15).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Gains {
    /// Kd: weight of the position errors.
    pub kd: f64,
    /// Kl: weight of the distance to the target's line.
    pub kl: f64,
    /// Ko: weight of the orientation error.
    pub ko: f64,
    /// Kx: gain of the speed correction vb.
    pub kx: f64,
    /// KRT: weight of eRT.
    pub krt: f64,
    /// Kθ: orientation gain.
    pub ktheta: f64,
}

impl Gains {
    /// The gains of the urban UGV (2 m/s): CHOICE, tuned on the Dafflon scene
    /// by a sweep so that a static target 30 m away is reached to a few
    /// millimetres and its orientation to 0.01 rad from starts up to 5 m aside
    /// and 70° off.
    pub fn urban() -> Self {
        Gains { kd: 0.2, kl: 0.5, ko: 1.0, kx: 1.0, krt: 0.1, ktheta: 1.0 }
    }

    /// The gains for tracking a carrot `lookahead` metres ahead on a path
    /// (the outdoor Drive): CHOICE, Kd = Kl = 1/L² and Kθ = 1/L, which makes
    /// the law a pure pursuit (curvature 2e/L² for a lateral error e) plus a
    /// heading term.
    pub fn carrot(lookahead: f64) -> Self {
        let l = lookahead.max(1.0);
        Gains { kd: 1.0 / (l * l), kl: 1.0 / (l * l), ko: 1.0, kx: 0.3, krt: 0.05 / l, ktheta: 1.0 / l }
    }
}

/// A target posture with its velocity and curvature (Fig. 2 of the paper).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Target {
    /// (xT, yT, θT).
    pub pose: Pose,
    /// vT: the velocity wanted at the target (m/s).
    pub v: f64,
    /// 1/r_cT: the target's curvature (1/m, 0 for a static or straight target).
    pub curvature: f64,
}

/// The posture errors of eqs. (2)–(5).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Errors {
    /// ex: target ahead in the vehicle frame (m).
    pub ex: f64,
    /// ey: target to the left in the vehicle frame (m).
    pub ey: f64,
    /// eθ = θT − θ (rad).
    pub etheta: f64,
    /// d: distance to the target (m).
    pub d: f64,
    /// eRT = θT − θRT (rad).
    pub ert: f64,
}

/// The control inputs ISP of the control-law block.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ControlInput {
    /// Posture errors.
    pub errors: Errors,
    /// vT (m/s).
    pub v: f64,
    /// 1/r_cT (1/m).
    pub curvature: f64,
}

/// Eqs. (2)–(5): the errors between the vehicle and a target posture.
pub fn posture_errors(pose: &Pose, target: &Pose) -> Errors {
    let (dx, dy) = (target.x - pose.x, target.y - pose.y);
    let (s, c) = pose.theta.sin_cos();
    let ex = c * dx + s * dy;
    let ey = -s * dx + c * dy;
    let etheta = wrap_angle(target.theta - pose.theta);
    let d = dx.hypot(dy);
    let theta_rt = if d > XI { dy.atan2(dx) } else { target.theta };
    let ert = wrap_angle(target.theta - theta_rt);
    Errors { ex, ey, etheta, d, ert }
}

/// The target-reaching controller: the errors toward a (static or moving) target.
pub fn target_reaching(pose: &Pose, target: &Target) -> ControlInput {
    ControlInput { errors: posture_errors(pose, &target.pose), v: target.v, curvature: target.curvature }
}

/// Eqs. (12)–(15): the single Lyapunov control law, with the regularisation
/// of the module doc. The result is clamped to the vehicle's steering limit
/// and to speeds in [0, `v_max`].
pub fn control_law(input: &ControlInput, k: &Gains, params: &VehicleParams, v_max: f64) -> Command {
    let e = &input.errors;
    let (se, ce) = e.etheta.sin_cos();
    let (sr, cr) = e.ert.sin_cos();
    let sc = se * ce;
    let inv_sc = sc / (sc * sc + SINGULAR_EPS * SINGULAR_EPS);
    let ce_reg = if ce.abs() < 0.1 { 0.1f64.copysign(ce) } else { ce };
    let ct = input.curvature;
    // Eq. (15).
    let cc = e.d * e.d * k.kl * sr * cr * ct / k.ko * inv_sc
        + k.krt * sr * sr * inv_sc
        + (k.kd * e.ey - k.kl * e.d * sr * ce) / (k.ko * ce_reg)
        + k.ktheta * se / ce_reg;
    // Eq. (14).
    let vb = k.kx * (k.kd * e.ex + k.kl * e.d * sr * se + k.ko * se * cc);
    // Eqs. (12)–(13).
    let v = (input.v * ce + vb).clamp(0.0, v_max);
    let steer = (params.wheelbase * (ct / ce_reg + cc)).atan().clamp(-params.max_steer, params.max_steer);
    Command { v, steer }
}

/// An ellipse: centre, semi-axes and orientation Ω.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Ellipse {
    /// Centre (m).
    pub center: Vec2,
    /// Major semi-axis a (m).
    pub a: f64,
    /// Minor semi-axis b (m).
    pub b: f64,
    /// Orientation Ω of the major axis (rad).
    pub omega: f64,
}

impl Ellipse {
    /// The coefficients (A, B, C) of eqs. (8)–(10).
    pub fn coefficients(&self) -> (f64, f64, f64) {
        let (so, co) = self.omega.sin_cos();
        let a = (so / self.b).powi(2) + (co / self.a).powi(2);
        let b = (co / self.b).powi(2) + (so / self.a).powi(2);
        let c = (1.0 / (self.a * self.a) - 1.0 / (self.b * self.b)) * (2.0 * self.omega).sin();
        (a, b, c)
    }

    /// The level A x² + B y² + C x y of a point (1 on the ellipse, < 1 inside).
    pub fn level(&self, p: Vec2) -> f64 {
        let (a, b, c) = self.coefficients();
        let d = p - self.center;
        a * d.x * d.x + b * d.y * d.y + c * d.x * d.y
    }

    /// The same ellipse grown by `margin` on both semi-axes.
    pub fn grown(&self, margin: f64) -> Ellipse {
        Ellipse { a: self.a + margin, b: self.b + margin, ..*self }
    }

    /// An approximate distance from a point to the ellipse (0 inside):
    /// the distance to the centre less the radius in that direction.
    pub fn distance(&self, p: Vec2) -> f64 {
        let d = p - self.center;
        let r = d.norm();
        if r == 0.0 {
            return 0.0;
        }
        let lv = self.level(p);
        if lv <= 1.0 {
            return 0.0;
        }
        r - r / lv.sqrt()
    }

    /// The enclosing ellipse of a polygon: axes along its principal
    /// directions, the aspect ratio of its extents, scaled to hold every
    /// vertex (a circle's polygon gives its circle).
    pub fn enclosing(poly: &[Vec2]) -> Ellipse {
        let c = crate::geom::vertex_centroid(poly);
        let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
        for p in poly {
            let d = p - c;
            sxx += d.x * d.x;
            syy += d.y * d.y;
            sxy += d.x * d.y;
        }
        let omega = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let (u, w) = (unit(omega), unit(omega + std::f64::consts::FRAC_PI_2));
        let mut hx: f64 = 1e-3;
        let mut hy: f64 = 1e-3;
        for p in poly {
            let d = p - c;
            hx = hx.max(d.dot(&u).abs());
            hy = hy.max(d.dot(&w).abs());
        }
        let k = poly.iter().map(|p| ((p - c).dot(&u) / hx).hypot((p - c).dot(&w) / hy)).fold(1.0, f64::max);
        let (a, b, omega) =
            if hx >= hy { (k * hx, k * hy, omega) } else { (k * hy, k * hx, omega + std::f64::consts::FRAC_PI_2) };
        Ellipse { center: c, a, b, omega: wrap_angle(omega) }
    }
}

/// The avoidance direction: m = +1 clockwise, m = −1 counter-clockwise.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// m = +1.
    Clockwise,
    /// m = −1.
    CounterClockwise,
}

impl Direction {
    /// m of eqs. (6)–(7).
    pub fn m(self) -> f64 {
        match self {
            Direction::Clockwise => 1.0,
            Direction::CounterClockwise => -1.0,
        }
    }
}

/// Eqs. (6)–(7): the limit cycle's velocity field at `p`, in coordinates
/// scaled by √(a b) (see the module doc).
pub fn limit_cycle_field(ellipse: &Ellipse, dir: Direction, p: Vec2) -> Vec2 {
    let s = (ellipse.a * ellipse.b).sqrt();
    let (a, b, c) = ellipse.coefficients();
    let (a, b, c) = (a * s * s, b * s * s, c * s * s);
    let d = (p - ellipse.center) / s;
    let (x, y) = (d.x, d.y);
    let m = dir.m();
    let r = 1.0 - a * x * x - b * y * y - c * x * y;
    v2(m * (b * y + 0.5 * c * x) + x * r, -m * (a * x + 0.5 * c * y) + y * r)
}

/// Eq. (11): the desired orientation θd at `p`.
pub fn limit_cycle_heading(ellipse: &Ellipse, dir: Direction, p: Vec2) -> f64 {
    let f = limit_cycle_field(ellipse, dir, p);
    f.y.atan2(f.x)
}

/// The obstacle-avoidance controller: an orientation control (ex = ey = 0,
/// eθ = θd − θ) at vT, with the flow line's curvature as 1/r_cT.
pub fn limit_cycle(pose: &Pose, ellipse: &Ellipse, dir: Direction, v_t: f64) -> ControlInput {
    let p = pose.pos();
    let th = limit_cycle_heading(ellipse, dir, p);
    let step = 0.1;
    let th2 = limit_cycle_heading(ellipse, dir, p + unit(th) * step);
    let curvature = (wrap_angle(th2 - th) / step).clamp(-2.0, 2.0);
    ControlInput {
        errors: Errors { ex: 0.0, ey: 0.0, etheta: wrap_angle(th - pose.theta), d: 0.0, ert: 0.0 },
        v: v_t,
        curvature,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::circle_polygon;
    use crate::vehicle::Vehicle;

    #[test]
    fn errors_of_eqs_2_to_5() {
        let e = posture_errors(&Pose::new(0.0, 0.0, 0.0), &Pose::new(3.0, 4.0, 0.5));
        assert!((e.ex - 3.0).abs() < 1e-12 && (e.ey - 4.0).abs() < 1e-12);
        assert!((e.d - 5.0).abs() < 1e-12);
        assert!((e.etheta - 0.5).abs() < 1e-12);
        assert!((e.ert - (0.5 - 4f64.atan2(3.0))).abs() < 1e-12);
        let at = posture_errors(&Pose::new(1.0, 1.0, 0.0), &Pose::new(1.0, 1.0, 0.3));
        assert_eq!(at.ert, 0.0, "at the target θRT = θT");
    }

    #[test]
    fn target_is_reached() {
        let params = VehicleParams::urban();
        let gains = Gains::urban();
        for (x0, y0, th0) in [(0.0, 0.0, 0.0), (0.0, 4.0, -0.5), (2.0, -5.0, 1.0), (0.0, 0.0, 1.2)] {
            let mut veh = Vehicle::new(params, Pose::new(x0, y0, th0));
            let target = Target { pose: Pose::new(30.0, 2.0, 0.2), v: 0.3, curvature: 0.0 };
            let mut best = f64::INFINITY;
            for _ in 0..2000 {
                let cmd = control_law(&target_reaching(&veh.state.pose, &target), &gains, &params, params.max_speed);
                veh.step(cmd, 0.05);
                let e = posture_errors(&veh.state.pose, &target.pose);
                if e.d < best {
                    best = e.d;
                }
                if e.d < 0.2 {
                    assert!(e.etheta.abs() < 0.1, "with its orientation: eθ = {:.3}", e.etheta);
                    break;
                }
            }
            assert!(best < 0.2, "from ({x0}, {y0}, {th0}) the target is reached: closest {best:.2} m");
        }
    }

    #[test]
    fn enclosing_ellipse_of_circle_and_box() {
        let c = Ellipse::enclosing(&circle_polygon(v2(3.0, 4.0), 2.0, 16));
        assert!((c.center - v2(3.0, 4.0)).norm() < 1e-9);
        assert!((c.a - 2.0).abs() < 1e-6 && (c.b - 2.0).abs() < 1e-6);
        let r = Ellipse::enclosing(&crate::geom::rect_polygon(v2(0.0, 0.0), 4.0, 2.0, 0.3));
        assert!(r.a > r.b && (wrap_angle(2.0 * (r.omega - 0.3))).abs() < 1e-6);
        for p in crate::geom::rect_polygon(v2(0.0, 0.0), 4.0, 2.0, 0.3) {
            assert!(r.level(p) <= 1.0 + 1e-9);
        }
    }

    #[test]
    fn limit_cycle_directions() {
        let e = Ellipse { center: v2(0.0, 0.0), a: 2.0, b: 2.0, omega: 0.0 };
        // On the cycle at (2, 0): clockwise goes −y, counter-clockwise +y.
        let cw = limit_cycle_field(&e, Direction::Clockwise, v2(2.0, 0.0));
        let ccw = limit_cycle_field(&e, Direction::CounterClockwise, v2(2.0, 0.0));
        assert!(cw.y < 0.0 && cw.x.abs() < 1e-12);
        assert!(ccw.y > 0.0);
        // Outside, the field leads in; inside, out.
        assert!(limit_cycle_field(&e, Direction::Clockwise, v2(5.0, 0.0)).x < 0.0);
        assert!(limit_cycle_field(&e, Direction::Clockwise, v2(0.5, 0.0)).x > 0.0);
    }

    #[test]
    fn limit_cycle_circles_an_obstacle_without_touching_it() {
        let params = VehicleParams::urban();
        let gains = Gains::urban();
        let obstacle = circle_polygon(v2(10.0, 0.0), 1.0, 16);
        let enclosing = Ellipse::enclosing(&obstacle);
        let cycle = enclosing.grown(params.width / 2.0 + 1.5);
        for dir in [Direction::Clockwise, Direction::CounterClockwise] {
            let mut veh = Vehicle::new(params, Pose::new(4.0, 0.3, 0.0));
            veh.state.v = 1.0;
            let mut min_gap = f64::INFINITY;
            let mut swept = 0.0;
            let mut last =
                (veh.state.pose.pos() - enclosing.center).y.atan2((veh.state.pose.pos() - enclosing.center).x);
            for _ in 0..1600 {
                let input = limit_cycle(&veh.state.pose, &cycle, dir, params.max_speed / 2.0);
                let cmd = control_law(&input, &gains, &params, params.max_speed / 2.0);
                veh.step(cmd, 0.05);
                let fp = params.footprint(&veh.state.pose);
                min_gap = min_gap.min(crate::geom::polygon_distance(&fp, &obstacle));
                let rel = veh.state.pose.pos() - enclosing.center;
                let ang = rel.y.atan2(rel.x);
                swept += wrap_angle(ang - last);
                last = ang;
            }
            assert!(min_gap > 0.3, "{dir:?}: never closer than 0.3 m, was {min_gap:.2}");
            let expected_sign = -dir.m();
            assert!(
                swept * expected_sign > 2.0 * std::f64::consts::TAU,
                "{dir:?}: went round twice, swept {swept:.1} rad"
            );
        }
    }
}
