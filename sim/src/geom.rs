//! Plane geometry: points, poses, polygons, and the two road pieces (a
//! straight segment and a circular arc) with arc-length parametrisation.
//!
//! Angles are in radians, counter-clockwise from the x axis; lengths in
//! metres. "Left" is the side of positive lateral offset when travelling along
//! a piece.

use nalgebra::Vector2;
use serde::Serialize;
use std::f64::consts::{PI, TAU};

/// A point or a vector of the plane (metres).
pub type Vec2 = Vector2<f64>;

/// Shorthand for [`Vec2::new`].
pub fn v2(x: f64, y: f64) -> Vec2 {
    Vec2::new(x, y)
}

/// Wraps an angle to (-π, π].
pub fn wrap_angle(a: f64) -> f64 {
    let mut r = (a + PI).rem_euclid(TAU) - PI;
    if r <= -PI {
        r += TAU;
    }
    r
}

/// The z component of the cross product of two plane vectors.
pub fn cross(a: Vec2, b: Vec2) -> f64 {
    a.x * b.y - a.y * b.x
}

/// The unit vector at angle `a`.
pub fn unit(a: f64) -> Vec2 {
    v2(a.cos(), a.sin())
}

/// A posture of the vehicle: the position of the rear-axle centre and the
/// heading θ (eq. 1 of Dafflon et al.).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Pose {
    /// x in the global frame (m).
    pub x: f64,
    /// y in the global frame (m).
    pub y: f64,
    /// Heading θ (rad).
    pub theta: f64,
}

impl Pose {
    /// A pose from its three coordinates.
    pub fn new(x: f64, y: f64, theta: f64) -> Self {
        Pose { x, y, theta }
    }
    /// The position as a vector.
    pub fn pos(&self) -> Vec2 {
        v2(self.x, self.y)
    }
    /// A point given in this pose's frame (x forward, y left), in the global frame.
    pub fn to_world(&self, local: Vec2) -> Vec2 {
        let (s, c) = self.theta.sin_cos();
        v2(self.x + c * local.x - s * local.y, self.y + s * local.x + c * local.y)
    }
    /// A global point in this pose's frame (x forward, y left).
    pub fn to_local(&self, world: Vec2) -> Vec2 {
        let (s, c) = self.theta.sin_cos();
        let d = world - self.pos();
        v2(c * d.x + s * d.y, -s * d.x + c * d.y)
    }
}

/// The distance from `p` to the segment `a`–`b`.
pub fn dist_point_segment(p: Vec2, a: Vec2, b: Vec2) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 { ((p - a).dot(&ab) / l2).clamp(0.0, 1.0) } else { 0.0 };
    (a + ab * t - p).norm()
}

/// Whether `p` is inside the polygon (even-odd rule; the boundary counts as
/// inside only by chance, callers use [`dist_point_polygon`] for margins).
pub fn contains(poly: &[Vec2], p: Vec2) -> bool {
    let n = poly.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (poly[i], poly[j]);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
        j = i;
    }
    inside
}

/// The distance from `p` to the polygon: 0 inside, else to the nearest edge.
pub fn dist_point_polygon(poly: &[Vec2], p: Vec2) -> f64 {
    if contains(poly, p) {
        return 0.0;
    }
    edges(poly).map(|(a, b)| dist_point_segment(p, a, b)).fold(f64::INFINITY, f64::min)
}

/// The closed polygon's edges as pairs of points.
pub fn edges(poly: &[Vec2]) -> impl Iterator<Item = (Vec2, Vec2)> + '_ {
    (0..poly.len()).map(move |i| (poly[i], poly[(i + 1) % poly.len()]))
}

/// Whether the segments `a`–`b` and `c`–`d` intersect (touching counts).
pub fn segments_intersect(a: Vec2, b: Vec2, c: Vec2, d: Vec2) -> bool {
    let d1 = cross(b - a, c - a);
    let d2 = cross(b - a, d - a);
    let d3 = cross(d - c, a - c);
    let d4 = cross(d - c, b - c);
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0)) && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0)) {
        return true;
    }
    let on = |p: Vec2, q: Vec2, r: Vec2, d: f64| {
        d == 0.0 && r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    on(a, b, c, d1) || on(a, b, d, d2) || on(c, d, a, d3) || on(c, d, b, d4)
}

/// Whether two polygons overlap (an edge crossing or one inside the other).
pub fn polygons_intersect(p: &[Vec2], q: &[Vec2]) -> bool {
    if p.is_empty() || q.is_empty() {
        return false;
    }
    for (a, b) in edges(p) {
        for (c, d) in edges(q) {
            if segments_intersect(a, b, c, d) {
                return true;
            }
        }
    }
    contains(p, q[0]) || contains(q, p[0])
}

/// The smallest distance between two polygons (0 when they overlap).
pub fn polygon_distance(p: &[Vec2], q: &[Vec2]) -> f64 {
    if polygons_intersect(p, q) {
        return 0.0;
    }
    let mut best = f64::INFINITY;
    for &v in p {
        for (c, d) in edges(q) {
            best = best.min(dist_point_segment(v, c, d));
        }
    }
    for &v in q {
        for (a, b) in edges(p) {
            best = best.min(dist_point_segment(v, a, b));
        }
    }
    best
}

/// The convex hull of a point set, counter-clockwise (Andrew's monotone
/// chain); the points are sorted first, so the result does not depend on
/// their order.
pub fn convex_hull(points: &[Vec2]) -> Vec<Vec2> {
    let mut pts: Vec<Vec2> = points.iter().copied().filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let mut hull: Vec<Vec2> = Vec::with_capacity(pts.len() * 2);
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &Vec2>> =
            if pass == 0 { Box::new(pts.iter()) } else { Box::new(pts.iter().rev()) };
        for &p in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 1] - hull[hull.len() - 2], p - hull[hull.len() - 2]) <= 0.0
            {
                hull.pop();
            }
            hull.push(p);
        }
        hull.pop();
    }
    hull
}

/// The signed area of a polygon (positive counter-clockwise).
pub fn signed_area(poly: &[Vec2]) -> f64 {
    edges(poly).map(|(a, b)| cross(a, b)).sum::<f64>() / 2.0
}

/// The centroid of a polygon's vertices.
pub fn vertex_centroid(poly: &[Vec2]) -> Vec2 {
    if poly.is_empty() {
        return Vec2::zeros();
    }
    poly.iter().fold(Vec2::zeros(), |acc, p| acc + p) / poly.len() as f64
}

/// A regular polygon approximating a circle.
pub fn circle_polygon(center: Vec2, radius: f64, sides: usize) -> Vec<Vec2> {
    let n = sides.max(3);
    (0..n).map(|i| center + unit(TAU * i as f64 / n as f64) * radius).collect()
}

/// A rectangle centred on `center`, `length` along `heading`, `width` across.
pub fn rect_polygon(center: Vec2, length: f64, width: f64, heading: f64) -> Vec<Vec2> {
    let f = unit(heading) * (length / 2.0);
    let l = unit(heading + PI / 2.0) * (width / 2.0);
    vec![center - f - l, center + f - l, center + f + l, center - f + l]
}

/// Points along the polygon's boundary no further than `step` apart (the
/// vertices included), for sampled distance queries.
pub fn densify(poly: &[Vec2], step: f64, out: &mut Vec<Vec2>) {
    out.clear();
    for (a, b) in edges(poly) {
        let n = ((b - a).norm() / step).ceil().max(1.0) as usize;
        for k in 0..n {
            out.push(a + (b - a) * (k as f64 / n as f64));
        }
    }
}

/// One piece of road or track geometry, oriented (it has a start and an end).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Piece {
    /// The straight segment from `a` to `b`.
    Line {
        /// Start point.
        a: Vec2,
        /// End point.
        b: Vec2,
    },
    /// A circular arc.
    Arc {
        /// Centre of the circle.
        center: Vec2,
        /// Radius (m), positive.
        radius: f64,
        /// Angle of the start point seen from the centre (rad).
        start: f64,
        /// Signed swept angle: positive turns left (counter-clockwise).
        sweep: f64,
    },
}

/// Where a point lies relative to a piece.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    /// Arc length of the nearest point of the piece, clamped to [0, length].
    pub s: f64,
    /// Signed lateral offset (positive on the left), measured to the piece's
    /// supporting line or circle.
    pub lateral: f64,
    /// The distance to the nearest point of the piece.
    pub distance: f64,
}

impl Piece {
    /// The arc from `a` to `b` of the given radius, turning left or right
    /// (the minor arc). `None` when the radius is shorter than half the chord.
    pub fn arc_between(a: Vec2, b: Vec2, radius: f64, left: bool) -> Option<Piece> {
        let chord = b - a;
        let c = chord.norm();
        if radius.is_nan() || radius <= 0.0 || c == 0.0 || radius < c / 2.0 - 1e-9 {
            return None;
        }
        let h = (radius * radius - c * c / 4.0).max(0.0).sqrt();
        let mid = (a + b) / 2.0;
        let n = v2(-chord.y, chord.x) / c;
        let center = if left { mid + n * h } else { mid - n * h };
        let start = (a.y - center.y).atan2(a.x - center.x);
        let end = (b.y - center.y).atan2(b.x - center.x);
        let mut sweep = wrap_angle(end - start);
        if left && sweep < 0.0 {
            sweep += TAU;
        }
        if !left && sweep > 0.0 {
            sweep -= TAU;
        }
        Some(Piece::Arc { center, radius, start, sweep })
    }

    /// The length (m).
    pub fn length(&self) -> f64 {
        match *self {
            Piece::Line { a, b } => (b - a).norm(),
            Piece::Arc { radius, sweep, .. } => radius * sweep.abs(),
        }
    }

    /// The point at arc length `s` (clamped to the piece).
    pub fn point(&self, s: f64) -> Vec2 {
        let s = s.clamp(0.0, self.length());
        match *self {
            Piece::Line { a, b } => {
                let l = (b - a).norm();
                if l == 0.0 {
                    a
                } else {
                    a + (b - a) * (s / l)
                }
            }
            Piece::Arc { center, radius, start, sweep } => center + unit(start + sweep.signum() * s / radius) * radius,
        }
    }

    /// The heading of travel at arc length `s`.
    pub fn heading(&self, s: f64) -> f64 {
        match *self {
            Piece::Line { a, b } => (b.y - a.y).atan2(b.x - a.x),
            Piece::Arc { radius, start, sweep, .. } => {
                let s = s.clamp(0.0, self.length());
                wrap_angle(start + sweep.signum() * s / radius + sweep.signum() * PI / 2.0)
            }
        }
    }

    /// The signed curvature (1/m, positive turning left).
    pub fn curvature(&self) -> f64 {
        match *self {
            Piece::Line { .. } => 0.0,
            Piece::Arc { radius, sweep, .. } => sweep.signum() / radius,
        }
    }

    /// The start point.
    pub fn start_point(&self) -> Vec2 {
        self.point(0.0)
    }

    /// The end point.
    pub fn end_point(&self) -> Vec2 {
        self.point(self.length())
    }

    /// The same geometry travelled the other way.
    pub fn reversed(&self) -> Piece {
        match *self {
            Piece::Line { a, b } => Piece::Line { a: b, b: a },
            Piece::Arc { center, radius, start, sweep } => {
                Piece::Arc { center, radius, start: start + sweep, sweep: -sweep }
            }
        }
    }

    /// The part between arc lengths `s0` and `s1` (clamped, `s0 ≤ s1`).
    pub fn sub(&self, s0: f64, s1: f64) -> Piece {
        let l = self.length();
        let (s0, s1) = (s0.clamp(0.0, l), s1.clamp(0.0, l).max(s0.clamp(0.0, l)));
        match *self {
            Piece::Line { .. } => Piece::Line { a: self.point(s0), b: self.point(s1) },
            Piece::Arc { center, radius, start, sweep } => Piece::Arc {
                center,
                radius,
                start: start + sweep.signum() * s0 / radius,
                sweep: sweep.signum() * (s1 - s0) / radius,
            },
        }
    }

    /// Projects a point onto the piece.
    pub fn project(&self, p: Vec2) -> Projection {
        match *self {
            Piece::Line { a, b } => {
                let ab = b - a;
                let l = ab.norm();
                if l == 0.0 {
                    return Projection { s: 0.0, lateral: 0.0, distance: (p - a).norm() };
                }
                let u = ab / l;
                let s = (p - a).dot(&u).clamp(0.0, l);
                let lateral = cross(u, p - a);
                Projection { s, lateral, distance: (a + u * s - p).norm() }
            }
            Piece::Arc { center, radius, start, sweep } => {
                let d = p - center;
                let r = d.norm();
                let phi = d.y.atan2(d.x);
                let delta = (sweep.signum() * (phi - start)).rem_euclid(TAU);
                let len = sweep.abs();
                let delta = if delta <= len {
                    delta
                } else if delta - len < TAU - delta {
                    len
                } else {
                    0.0
                };
                let s = delta * radius;
                let lateral = sweep.signum() * (radius - r);
                Projection { s, lateral, distance: (self.point(s) - p).norm() }
            }
        }
    }

    /// Points along the piece no further than `step` apart, both ends included.
    pub fn sample(&self, step: f64) -> Vec<Vec2> {
        let l = self.length();
        let n = (l / step).ceil().max(1.0) as usize;
        (0..=n).map(|k| self.point(l * k as f64 / n as f64)).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64, tol: f64) -> bool {
        (a - b).abs() <= tol
    }

    #[test]
    fn wrap_is_in_range() {
        for k in -20..20 {
            let a = wrap_angle(k as f64 * 0.7);
            assert!(a > -PI && a <= PI);
        }
        assert!(close(wrap_angle(3.0 * PI), PI, 1e-12));
    }

    #[test]
    fn pose_frames_round_trip() {
        let p = Pose::new(3.0, -2.0, 0.7);
        let w = v2(10.0, 4.0);
        let back = p.to_world(p.to_local(w));
        assert!((back - w).norm() < 1e-12);
        assert!((p.to_local(p.to_world(v2(1.0, 0.0))) - v2(1.0, 0.0)).norm() < 1e-12);
    }

    #[test]
    fn polygon_queries() {
        let sq = rect_polygon(v2(0.0, 0.0), 2.0, 2.0, 0.0);
        assert!(contains(&sq, v2(0.5, 0.5)));
        assert!(!contains(&sq, v2(1.5, 0.5)));
        assert!(close(dist_point_polygon(&sq, v2(3.0, 0.0)), 2.0, 1e-12));
        let far = rect_polygon(v2(5.0, 0.0), 2.0, 2.0, 0.0);
        assert!(close(polygon_distance(&sq, &far), 3.0, 1e-12));
        let over = rect_polygon(v2(1.5, 0.0), 2.0, 2.0, 0.3);
        assert!(polygons_intersect(&sq, &over));
        let inner = rect_polygon(v2(0.0, 0.0), 0.5, 0.5, 0.0);
        assert!(polygons_intersect(&sq, &inner));
        assert!(close(signed_area(&sq), 4.0, 1e-12));
    }

    #[test]
    fn hull_of_square_with_inside_points() {
        let pts = vec![v2(0.0, 0.0), v2(1.0, 1.0), v2(2.0, 0.0), v2(2.0, 2.0), v2(0.0, 2.0), v2(0.5, 1.5)];
        let h = convex_hull(&pts);
        assert_eq!(h.len(), 4);
        assert!(close(signed_area(&h), 4.0, 1e-12));
    }

    #[test]
    fn arc_between_and_projection() {
        // A quarter circle of radius 10 turning left from (0,0) heading east.
        let a = v2(0.0, 0.0);
        let b = v2(10.0, 10.0);
        let arc = Piece::arc_between(a, b, 10.0, true).expect("arc");
        assert!(close(arc.length(), 10.0 * PI / 2.0, 1e-9));
        assert!(close(arc.heading(0.0), 0.0, 1e-9));
        assert!(close(arc.heading(arc.length()), PI / 2.0, 1e-9));
        assert!(close(arc.curvature(), 0.1, 1e-12));
        assert!((arc.end_point() - b).norm() < 1e-9);
        let mid = arc.point(arc.length() / 2.0);
        let pr = arc.project(mid + (v2(0.0, 10.0) - mid).normalize() * 1.0);
        assert!(close(pr.s, arc.length() / 2.0, 1e-9));
        assert!(close(pr.lateral, 1.0, 1e-9), "toward the centre is left: {}", pr.lateral);
        let rev = arc.reversed();
        assert!((rev.start_point() - b).norm() < 1e-9);
        assert!(close(rev.curvature(), -0.1, 1e-12));
        let sub = arc.sub(1.0, 3.0);
        assert!(close(sub.length(), 2.0, 1e-9));
        assert!((sub.start_point() - arc.point(1.0)).norm() < 1e-9);
        assert!(Piece::arc_between(a, b, 5.0, true).is_none());
    }

    #[test]
    fn line_projection_sign() {
        let l = Piece::Line { a: v2(0.0, 0.0), b: v2(10.0, 0.0) };
        let p = l.project(v2(4.0, -2.0));
        assert!(close(p.s, 4.0, 1e-12) && close(p.lateral, -2.0, 1e-12) && close(p.distance, 2.0, 1e-12));
        let beyond = l.project(v2(13.0, 4.0));
        assert!(close(beyond.s, 10.0, 1e-12) && close(beyond.distance, 5.0, 1e-12));
    }
}
