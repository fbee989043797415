//! The metric layer of DLA: a probabilistic occupancy grid (Poncela et al.
//! 2002), updated from range readings.
//!
//! Each cell holds the log-odds of being occupied; a cell never observed
//! holds 0, that is p = 0.5 ("unknown"). A beam lowers the log-odds of the
//! cells it crosses (they are freer) and raises that of the cell where it
//! hit (more occupied); the cells are found by an exact grid traversal
//! (Amanatides & Woo's DDA). Log-odds are clamped so that the grid can
//! change its mind when the world changes.
//!
//! Cell `(x, y)` covers `[origin.x + x·cell, origin.x + (x+1)·cell) ×
//! [origin.y + y·cell, origin.y + (y+1)·cell)`; its index is `y·width + x`.

use situ_sim::geom::{v2, Pose, Vec2};

/// One range reading: a direction in the robot's frame, the range measured
/// and the sensor's maximum range (metres). A range at or beyond the maximum
/// means "nothing seen": the beam frees cells and marks no hit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Beam {
    /// Direction of the beam relative to the robot's heading (rad).
    pub angle: f64,
    /// Range measured (m).
    pub range: f64,
    /// Maximum range of the sensor (m).
    pub max_range: f64,
}

/// The increments and thresholds of a grid.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GridParams {
    /// Log-odds added to a cell a beam crossed (negative: freer).
    pub l_free: f32,
    /// Log-odds added to the cell a beam hit (positive: more occupied).
    pub l_occupied: f32,
    /// Lowest log-odds a cell can hold.
    pub l_min: f32,
    /// Highest log-odds a cell can hold.
    pub l_max: f32,
    /// A cell is free when its probability is below this.
    pub free_below: f64,
    /// A cell is occupied when its probability is above this.
    pub occupied_above: f64,
}

impl Default for GridParams {
    fn default() -> Self {
        GridParams { l_free: -0.4, l_occupied: 0.85, l_min: -4.0, l_max: 4.0, free_below: 0.3, occupied_above: 0.7 }
    }
}

/// What a cell is taken to be, by the thresholds of [`GridParams`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum CellClass {
    /// Probability below `free_below`.
    Free,
    /// Probability above `occupied_above`.
    Occupied,
    /// Anything between: never observed, or observed both ways.
    Unknown,
}

/// A probabilistic occupancy grid.
#[derive(Debug, Clone, PartialEq)]
pub struct OccupancyGrid {
    width: usize,
    height: usize,
    cell: f64,
    origin: Vec2,
    params: GridParams,
    logodds: Vec<f32>,
    /// The smallest log-odds that is not free, and the smallest that is
    /// occupied, by [`OccupancyGrid::classify`]: a cell's class from its
    /// log-odds without an exponential, and the same class.
    not_free_from: f32,
    occupied_from: f32,
}

/// The smallest `f32` log-odds (within ±1000) for which `holds`, a
/// property that once true stays true as the log-odds grow; by bisection
/// over the floats in order.
fn first_where(holds: impl Fn(f32) -> bool) -> f32 {
    // Floats in order as integers: negative ones reversed.
    let key = |x: f32| -> i64 {
        let b = x.to_bits() as i32;
        i64::from(if b < 0 { i32::MIN - b } else { b })
    };
    let float = |k: i64| -> f32 {
        let k = k as i32;
        f32::from_bits(if k < 0 { (i32::MIN - k) as u32 } else { k as u32 })
    };
    let (mut lo, mut hi) = (key(-1000.0), key(1000.0));
    if holds(float(lo)) {
        return f32::NEG_INFINITY;
    }
    if !holds(float(hi)) {
        return f32::INFINITY;
    }
    // holds(lo) is false, holds(hi) true.
    while hi - lo > 1 {
        let mid = lo + (hi - lo) / 2;
        if holds(float(mid)) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    float(hi)
}

/// The log-odds of a probability (clamped away from 0 and 1).
pub fn logodds(p: f64) -> f32 {
    let p = p.clamp(1e-6, 1.0 - 1e-6);
    (p / (1.0 - p)).ln() as f32
}

/// The class of a probability by `params`' thresholds.
fn classify(params: &GridParams, p: f64) -> CellClass {
    if p < params.free_below {
        CellClass::Free
    } else if p > params.occupied_above {
        CellClass::Occupied
    } else {
        CellClass::Unknown
    }
}

/// The probability of a log-odds.
pub fn probability(l: f32) -> f64 {
    1.0 / (1.0 + (-(l as f64)).exp())
}

impl OccupancyGrid {
    /// A grid of `width × height` unknown cells of side `cell` metres whose
    /// corner of lowest coordinates is at `origin`.
    ///
    /// # Panics
    /// If a dimension is zero or the cell size is not positive and finite.
    pub fn new(width: usize, height: usize, cell: f64, origin: Vec2, params: GridParams) -> Self {
        assert!(width > 0 && height > 0, "a grid has at least one cell");
        assert!(cell.is_finite() && cell > 0.0, "the cell size is positive");
        let class = |l: f32| classify(&params, probability(l));
        let not_free_from = first_where(|l| class(l) != CellClass::Free);
        let occupied_from = first_where(|l| class(l) == CellClass::Occupied);
        OccupancyGrid {
            width,
            height,
            cell,
            origin,
            params,
            logodds: vec![0.0; width * height],
            not_free_from,
            occupied_from,
        }
    }

    /// Number of columns.
    pub fn width(&self) -> usize {
        self.width
    }
    /// Number of rows.
    pub fn height(&self) -> usize {
        self.height
    }
    /// Side of a cell (m).
    pub fn cell_size(&self) -> f64 {
        self.cell
    }
    /// Corner of lowest coordinates (m).
    pub fn origin(&self) -> Vec2 {
        self.origin
    }
    /// The increments and thresholds.
    pub fn params(&self) -> &GridParams {
        &self.params
    }
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.logodds.len()
    }
    /// Whether the grid has no cell (never: kept for the convention).
    pub fn is_empty(&self) -> bool {
        self.logodds.is_empty()
    }
    /// The index of cell `(x, y)`.
    pub fn index(&self, x: usize, y: usize) -> usize {
        y * self.width + x
    }
    /// The cell `(x, y)` of an index.
    pub fn coords(&self, index: usize) -> (usize, usize) {
        (index % self.width, index / self.width)
    }
    /// The cell containing a point, if inside the grid.
    pub fn cell_of(&self, p: Vec2) -> Option<(usize, usize)> {
        let fx = ((p.x - self.origin.x) / self.cell).floor();
        let fy = ((p.y - self.origin.y) / self.cell).floor();
        if fx >= 0.0 && fy >= 0.0 && fx < self.width as f64 && fy < self.height as f64 {
            Some((fx as usize, fy as usize))
        } else {
            None
        }
    }
    /// The centre of cell `(x, y)` (m).
    pub fn center(&self, x: usize, y: usize) -> Vec2 {
        v2(self.origin.x + (x as f64 + 0.5) * self.cell, self.origin.y + (y as f64 + 0.5) * self.cell)
    }

    /// The log-odds of every cell, by index.
    pub fn logodds_cells(&self) -> &[f32] {
        &self.logodds
    }
    /// The log-odds of cell `(x, y)`.
    pub fn logodds_at(&self, x: usize, y: usize) -> f32 {
        self.logodds[self.index(x, y)]
    }
    /// Sets the probability of cell `(x, y)` (for maps made by hand).
    pub fn set_probability(&mut self, x: usize, y: usize, p: f64) {
        let i = self.index(x, y);
        self.logodds[i] = logodds(p).clamp(self.params.l_min, self.params.l_max);
    }
    /// Sets the probability of every cell of the rectangle `[x0, x1) × [y0, y1)`
    /// (clipped to the grid).
    pub fn fill(&mut self, x0: usize, y0: usize, x1: usize, y1: usize, p: f64) {
        let l = logodds(p).clamp(self.params.l_min, self.params.l_max);
        for y in y0..y1.min(self.height) {
            for x in x0..x1.min(self.width) {
                let i = self.index(x, y);
                self.logodds[i] = l;
            }
        }
    }

    /// The probability that cell `(x, y)` is occupied.
    pub fn probability(&self, x: usize, y: usize) -> f64 {
        probability(self.logodds_at(x, y))
    }
    /// The probability that the cell at index `i` is occupied.
    pub fn probability_index(&self, i: usize) -> f64 {
        probability(self.logodds[i])
    }
    /// The probability that the cell containing `p` is occupied; 0.5 outside.
    pub fn probability_at(&self, p: Vec2) -> f64 {
        self.cell_of(p).map_or(0.5, |(x, y)| self.probability(x, y))
    }
    /// The class of a probability by this grid's thresholds.
    pub fn classify(&self, p: f64) -> CellClass {
        classify(&self.params, p)
    }
    /// The class of a log-odds: that of its probability.
    pub fn class_of_logodds(&self, l: f32) -> CellClass {
        if l < self.not_free_from {
            CellClass::Free
        } else if l >= self.occupied_from {
            CellClass::Occupied
        } else {
            CellClass::Unknown
        }
    }
    /// The class of cell `(x, y)`.
    pub fn class(&self, x: usize, y: usize) -> CellClass {
        self.class_of_logodds(self.logodds_at(x, y))
    }
    /// The class of the cell at index `i`.
    pub fn class_index(&self, i: usize) -> CellClass {
        self.class_of_logodds(self.logodds[i])
    }
    /// Whether cell `(x, y)` is free.
    pub fn is_free(&self, x: usize, y: usize) -> bool {
        self.class(x, y) == CellClass::Free
    }
    /// Whether cell `(x, y)` is occupied.
    pub fn is_occupied(&self, x: usize, y: usize) -> bool {
        self.class(x, y) == CellClass::Occupied
    }
    /// Whether cell `(x, y)` is neither free nor occupied.
    pub fn is_unknown(&self, x: usize, y: usize) -> bool {
        self.class(x, y) == CellClass::Unknown
    }

    /// Adds `delta` to the log-odds of the cell at index `i`, clamped;
    /// whether the cell changed class.
    fn add(&mut self, i: usize, delta: f32) -> bool {
        let before = self.logodds[i];
        let after = (before + delta).clamp(self.params.l_min, self.params.l_max);
        self.logodds[i] = after;
        before.to_bits() != after.to_bits() && self.class_of_logodds(before) != self.class_of_logodds(after)
    }

    /// Updates the grid with one scan taken at `pose`: for each beam, the
    /// cells it crossed become freer and, when it hit something before its
    /// maximum range, the cell of the hit more occupied. Beams with a
    /// non-finite or negative range are ignored. Returns how many cell
    /// updates changed a cell's class (free, occupied, unknown): 0 when the
    /// classes are as they were.
    pub fn update(&mut self, pose: &Pose, beams: &[Beam]) -> usize {
        let mut changed = 0;
        let mut cells = Vec::new();
        for beam in beams {
            if !(beam.range.is_finite() && beam.max_range.is_finite() && beam.range >= 0.0) {
                continue;
            }
            let hit = beam.range < beam.max_range;
            let length = beam.range.min(beam.max_range);
            let a = pose.theta + beam.angle;
            let end = pose.pos() + v2(a.cos(), a.sin()) * length;
            cells.clear();
            self.traverse(pose.pos(), end, &mut cells);
            let hit_cell = if hit { self.cell_of(end).map(|(x, y)| self.index(x, y)) } else { None };
            for &i in &cells {
                if Some(i) != hit_cell {
                    changed += usize::from(self.add(i, self.params.l_free));
                }
            }
            if let Some(i) = hit_cell {
                changed += usize::from(self.add(i, self.params.l_occupied));
            }
        }
        changed
    }

    /// The indices of the cells the segment `a → b` crosses, in order, from
    /// the cell of `a` to that of `b`, clipped to the grid (the traversal
    /// stops when the segment leaves it; a segment starting outside gives
    /// nothing). Appended to `out`.
    pub fn traverse(&self, a: Vec2, b: Vec2, out: &mut Vec<usize>) {
        let Some((mut x, mut y)) = self.cell_of(a) else { return };
        let end = self.cell_of(b);
        let d = b - a;
        let step_x: i64 = if d.x > 0.0 { 1 } else { -1 };
        let step_y: i64 = if d.y > 0.0 { 1 } else { -1 };
        let next_boundary = |c: usize, step: i64, o: f64| {
            let k = if step > 0 { c as f64 + 1.0 } else { c as f64 };
            o + k * self.cell
        };
        let mut t_max_x =
            if d.x != 0.0 { (next_boundary(x, step_x, self.origin.x) - a.x) / d.x } else { f64::INFINITY };
        let mut t_max_y =
            if d.y != 0.0 { (next_boundary(y, step_y, self.origin.y) - a.y) / d.y } else { f64::INFINITY };
        let t_dx = if d.x != 0.0 { self.cell / d.x.abs() } else { f64::INFINITY };
        let t_dy = if d.y != 0.0 { self.cell / d.y.abs() } else { f64::INFINITY };
        // A bound on the steps: the Manhattan length in cells, plus slack.
        let limit = (d.x.abs() / self.cell + d.y.abs() / self.cell) as usize + 4;
        for _ in 0..limit {
            out.push(self.index(x, y));
            if Some((x, y)) == end || (t_max_x > 1.0 && t_max_y > 1.0) {
                return;
            }
            if t_max_x < t_max_y {
                let nx = x as i64 + step_x;
                if nx < 0 || nx >= self.width as i64 {
                    return;
                }
                x = nx as usize;
                t_max_x += t_dx;
            } else {
                let ny = y as i64 + step_y;
                if ny < 0 || ny >= self.height as i64 {
                    return;
                }
                y = ny as usize;
                t_max_y += t_dy;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_class_of_a_logodds_is_that_of_its_probability() {
        for params in [
            GridParams::default(),
            GridParams { free_below: 0.5, occupied_above: 0.5, ..GridParams::default() },
            GridParams { free_below: 0.01, occupied_above: 0.999, ..GridParams::default() },
        ] {
            let g = OccupancyGrid::new(1, 1, 0.1, v2(0.0, 0.0), params);
            let slow = |l: f32| g.classify(probability(l));
            // A sweep, and every float within 2,000 of each boundary.
            let mut ls: Vec<f32> = (-6000..=6000).map(|k| k as f32 * 1e-3).collect();
            for b in [g.not_free_from, g.occupied_from] {
                let mut up = b;
                let mut down = b;
                for _ in 0..2000 {
                    ls.extend([up, down]);
                    up = f32::from_bits(up.to_bits().wrapping_add(if up >= 0.0 { 1 } else { u32::MAX }));
                    down = f32::from_bits(down.to_bits().wrapping_add(if down > 0.0 { u32::MAX } else { 1 }));
                }
            }
            for l in ls {
                assert_eq!(g.class_of_logodds(l), slow(l), "log-odds {l} ({:#x}), {params:?}", l.to_bits());
            }
            assert!(g.not_free_from <= g.occupied_from);
        }
    }
}
