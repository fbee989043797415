//! Speed of the DLA building blocks: building the split-and-merge pyramid
//! of a 512 × 512 occupancy grid (rooms, doors, obstacles, unexplored
//! parts, built from simulated scans), and retrieving the nearest case
//! among 100,000 cases.
//!
//! Two kinds of case base are measured, and both are reported:
//! - *uniform*: situations drawn uniformly at random (every range uniform
//!   in [0, 4] m, the goal in any direction), the worst case for an exact
//!   k-d tree in this many dimensions;
//! - *obstacle fields*: situations as a robot meets them — random fields of
//!   discs and boxes in a walled 20 × 20 m area, random poses in free
//!   space, the sector minima of a simulated 360-beam range scan (ray cast
//!   against the obstacles, maximum range 4 m, 1 cm noise) and the direction
//!   to a random goal, with the scripted driver's command; the queries are
//!   fresh situations of other fields, generated the same way.
//!
//! The retrieval is also measured at 10,000 cases to show how it scales.
//!
//! On-line learning is measured too: a base growing to 2,000 cases by
//! [`CaseBase::learn`] over obstacle-field situations, one learn and one
//! retrieval per step, as the running stack does.
//!
//! `cargo run --release -p situ-dla --example dla_speed`
//! `cargo run --release -p situ-dla --example dla_speed -- --retrieval`
//! (only the 8-sector retrieval and the on-line learning: no pyramid, no
//! 4- and 6-sector runs; ~1/3 of the time); `--kiddo` also measures
//! kiddo 5's incremental and immutable k-d trees on the same cases.
//! Targets: pyramid < 20 ms, retrieval < 5 µs per query.

use situ_dla::cases::{drive, Case, CaseBase, Command, DriverParams, Situation};
use situ_dla::grid::{Beam, GridParams, OccupancyGrid};
use situ_dla::pyramid::{Pyramid, PyramidParams};
use situ_sim::geom::{v2, Pose};
use situ_sim::noise::Noise;
use std::hint::black_box;
use std::time::{Duration, Instant};

const N: usize = 512;
const CELL: f64 = 0.05;

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v[v.len() / 2]
}

/// The ground truth: outer walls, 4 × 4 rooms with a door in each inner
/// wall, and random boxes.
fn truth(noise: &mut Noise) -> Vec<bool> {
    let mut occ = vec![false; N * N];
    let mut set = |x0: usize, y0: usize, x1: usize, y1: usize, v: bool| {
        for y in y0..y1.min(N) {
            for x in x0..x1.min(N) {
                occ[y * N + x] = v;
            }
        }
    };
    set(0, 0, N, 4, true);
    set(0, N - 4, N, N, true);
    set(0, 0, 4, N, true);
    set(N - 4, 0, N, N, true);
    let room = N / 4;
    for k in 1..4 {
        set(k * room - 2, 0, k * room + 2, N, true);
        set(0, k * room - 2, N, k * room + 2, true);
        for j in 0..4 {
            // A door 20 cells (1 m) wide in each piece of wall.
            let d = j * room + room / 2 - 10 + (noise.uniform() * 40.0) as usize - 20;
            set(k * room - 2, d, k * room + 2, d + 20, false);
            set(d, k * room - 2, d + 20, k * room + 2, false);
        }
    }
    for _ in 0..60 {
        let x = 8 + (noise.uniform() * (N - 40) as f64) as usize;
        let y = 8 + (noise.uniform() * (N - 40) as f64) as usize;
        let w = 4 + (noise.uniform() * 20.0) as usize;
        let h = 4 + (noise.uniform() * 20.0) as usize;
        set(x, y, x + w, y + h, true);
    }
    occ
}

/// A grid built from scans of `truth` taken at random free places of the
/// explored part (x < 3/4 of the map): the rest stays unknown.
fn scanned_grid(truth: &[bool], noise: &mut Noise) -> OccupancyGrid {
    let mut grid = OccupancyGrid::new(N, N, CELL, v2(0.0, 0.0), GridParams::default());
    let max_range = 6.0;
    let mut poses = 0;
    while poses < 80 {
        let x = noise.uniform() * (N as f64 * 0.75) * CELL;
        let y = noise.uniform() * N as f64 * CELL;
        let (cx, cy) = ((x / CELL) as usize, (y / CELL) as usize);
        if truth[cy * N + cx] {
            continue;
        }
        poses += 1;
        let pose = Pose::new(x, y, 0.0);
        let beams: Vec<Beam> = (0..360)
            .map(|k| {
                let a = (k as f64).to_radians();
                let (dx, dy) = (a.cos(), a.sin());
                let mut r = 0.0;
                while r < max_range {
                    let (px, py) = (x + dx * r, y + dy * r);
                    if px < 0.0 || py < 0.0 || px >= N as f64 * CELL || py >= N as f64 * CELL {
                        r = max_range;
                        break;
                    }
                    if truth[(py / CELL) as usize * N + (px / CELL) as usize] {
                        break;
                    }
                    r += CELL * 0.5;
                }
                let range = (r + noise.normal(0.01)).max(0.0);
                Beam { angle: a, range: if r >= max_range { max_range } else { range }, max_range }
            })
            .collect();
        grid.update(&pose, &beams);
    }
    grid
}

fn main() {
    let retrieval_only = std::env::args().skip(1).any(|a| a == "--retrieval");
    KIDDO.store(std::env::args().skip(1).any(|a| a == "--kiddo"), std::sync::atomic::Ordering::Relaxed);
    let mut noise = Noise::new(7, 0);
    let truth = truth(&mut noise);
    if !retrieval_only {
        pyramid(&truth, &mut noise);
    }
    cases(&truth, retrieval_only);
}

/// Builds the grid scanned in `truth` and measures its pyramid.
fn pyramid(truth: &[bool], noise: &mut Noise) {
    let grid = scanned_grid(truth, noise);
    let (mut free, mut occupied, mut unknown) = (0, 0, 0);
    for y in 0..N {
        for x in 0..N {
            match (grid.is_free(x, y), grid.is_occupied(x, y)) {
                (true, _) => free += 1,
                (_, true) => occupied += 1,
                _ => unknown += 1,
            }
        }
    }
    println!("grid {N} x {N}: {free} free, {occupied} occupied, {unknown} unknown cells");

    let params = PyramidParams::default();
    let mut times = Vec::new();
    let mut last = None;
    for _ in 0..15 {
        let t = Instant::now();
        let p = Pyramid::build(black_box(&grid), &params);
        times.push(t.elapsed());
        last = Some(p);
    }
    let p = last.expect("built");
    let ms = median(times).as_secs_f64() * 1e3;
    let free_regions = p.regions().iter().filter(|r| r.class == situ_dla::pyramid::RegionClass::Free).count();
    println!(
        "pyramid: {} levels, {} orphan blocks, {} regions ({} free); median of 15 builds: {ms:.2} ms (target < 20 ms)",
        p.levels(),
        p.blocks().len(),
        p.regions().len(),
        free_regions,
    );
}

/// Measures the retrieval of the nearest case and the on-line learning;
/// `short`: only the 8-sector retrievals.
fn cases(truth: &[bool], short: bool) {
    // Its own generator: the same cases with and without the pyramid.
    let mut noise = Noise::new(7, 1);
    let max_range = MAX_RANGE;
    let random = |noise: &mut Noise, sectors: usize| {
        let ranges = (0..sectors).map(|_| noise.uniform() * max_range).collect();
        Situation::new(ranges, (noise.uniform() * 2.0 - 1.0) * std::f64::consts::PI)
    };
    // Situations seen in the map: scans from random free places of the
    // ground truth, towards a random subgoal.
    let scanned = |noise: &mut Noise, sectors: usize| loop {
        let (x, y) = (noise.uniform() * N as f64 * CELL, noise.uniform() * N as f64 * CELL);
        if truth[(y / CELL) as usize * N + (x / CELL) as usize] {
            continue;
        }
        let theta = noise.uniform() * std::f64::consts::TAU;
        let beams: Vec<Beam> = (0..sectors * 3)
            .map(|k| {
                let a = (k as f64 - 1.0) * std::f64::consts::TAU / (sectors * 3) as f64;
                let (dx, dy) = ((theta + a).cos(), (theta + a).sin());
                let mut r = 0.0;
                while r < max_range {
                    let (px, py) = (x + dx * r, y + dy * r);
                    if px < 0.0 || py < 0.0 || px >= N as f64 * CELL || py >= N as f64 * CELL {
                        break;
                    }
                    if truth[(py / CELL) as usize * N + (px / CELL) as usize] {
                        break;
                    }
                    r += CELL * 0.5;
                }
                Beam { angle: a, range: r.min(max_range), max_range }
            })
            .collect();
        let goal = (noise.uniform() * 2.0 - 1.0) * std::f64::consts::PI;
        break Situation::from_scan(&beams, sectors, max_range, goal);
    };
    let mut summary = Vec::new();
    let random_case = |noise: &mut Noise, sectors: usize| {
        let situation = random(noise, sectors);
        Case { situation, command: Command { speed: noise.uniform(), turn_rate: noise.uniform() - 0.5 } }
    };
    let scanned_case = |noise: &mut Noise, sectors: usize| {
        let situation = scanned(noise, sectors);
        Case { situation, command: Command { speed: noise.uniform(), turn_rate: noise.uniform() - 0.5 } }
    };
    println!("uniform situations (worst case for an exact k-d tree), random commands:");
    for cases in [10_000, 100_000] {
        summary.push(retrieval::<10>("uniform", cases, &mut noise, &mut { random_case }, &mut { random }));
    }
    if !short {
        retrieval::<6>("uniform", 100_000, &mut noise, &mut { random_case }, &mut { random });
        retrieval::<8>("uniform", 100_000, &mut noise, &mut { random_case }, &mut { random });
    }
    println!("situations scanned in the 512 x 512 map above, random commands:");
    if !short {
        retrieval::<8>("scanned in the map", 100_000, &mut noise, &mut { scanned_case }, &mut { scanned });
    }
    summary.push(retrieval::<10>("scanned in the map", 100_000, &mut noise, &mut { scanned_case }, &mut { scanned }));

    println!("situations met in random obstacle fields, the scripted driver's commands:");
    for cases in [10_000, 100_000] {
        // Separate generators: the queries come from other fields than the cases.
        let mut train = Fields::new(FIELD_SITUATIONS);
        let mut test = Fields::new(FIELD_SITUATIONS);
        let driver = DriverParams::default();
        summary.push(retrieval::<10>(
            "obstacle fields",
            cases,
            &mut noise,
            &mut |noise, sectors| {
                let situation = train.situation(noise, sectors);
                let command = drive(&situation, MAX_RANGE, &driver);
                Case { situation, command }
            },
            &mut |noise, sectors| test.situation(noise, sectors),
        ));
    }
    println!();
    println!("nearest case, 8 sectors (D = 10), mean over 100,000 queries, median of 5 runs (target < 5 µs):");
    println!(
        "  {:<20} {:>9} {:>10} {:>12} {:>14} {:>10}",
        "case base", "cases", "µs/query", "read: µs/q", "mean distance", "insert ms"
    );
    for r in &summary {
        println!(
            "  {:<20} {:>9} {:>10.2} {:>12.2} {:>14.3} {:>10.0}",
            r.what, r.cases, r.us, r.loaded_us, r.mean_distance, r.insert_ms
        );
    }
    learning();
}

/// On-line learning as the running stack does it: per step the nearest
/// case to a situation (obstacle fields, 8 sectors), then
/// [`CaseBase::learn`] of the situation with the scripted driver's command
/// (novelty 0.05), from an empty base until it holds 2,000 cases. Prints the
/// mean and the largest time of a step (median of 5 runs), and the mean over
/// the steps from 1,500 cases on.
fn learning() {
    const TARGET: usize = 2_000;
    let mut noise = Noise::new(7, 2);
    let mut fields = Fields::new(FIELD_SITUATIONS);
    let driver = DriverParams::default();
    let cases: Vec<Case> = (0..4 * TARGET)
        .map(|_| {
            let situation = fields.situation(&mut noise, 8);
            let command = drive(&situation, MAX_RANGE, &driver);
            Case { situation, command }
        })
        .collect();
    let (mut means, mut maxima, mut lates, mut steps) = (Vec::new(), Vec::new(), Vec::new(), 0);
    for _ in 0..5 {
        let run = cases.clone();
        let mut base: CaseBase<10> = CaseBase::new(MAX_RANGE, 0.05);
        let mut times = Vec::with_capacity(run.len());
        let mut late = Vec::new();
        let mut acc = 0usize;
        for c in run {
            if base.len() >= TARGET {
                break;
            }
            let t = Instant::now();
            acc += base.nearest(black_box(&c.situation)).expect("valid").map_or(0, |(i, _)| i);
            let big = base.len() >= 1_500;
            base.learn(c).expect("valid");
            let dt = t.elapsed();
            times.push(dt);
            if big {
                late.push(dt);
            }
        }
        black_box(acc);
        assert_eq!(base.len(), TARGET, "the base reached its size");
        steps = times.len();
        means.push(times.iter().sum::<Duration>() / times.len() as u32);
        maxima.push(*times.iter().max().expect("steps"));
        lates.push(late.iter().sum::<Duration>() / late.len() as u32);
    }
    println!(
        "on-line learning, 8 sectors, novelty 0.05, empty to {TARGET} cases in {steps} steps (nearest + learn), \
         median of 5 runs: {:.2} µs per step, {:.2} µs from 1,500 cases on, largest step {:.0} µs",
        median(means).as_secs_f64() * 1e6,
        median(lates).as_secs_f64() * 1e6,
        median(maxima).as_secs_f64() * 1e6,
    );
}

/// The figures of one retrieval measurement.
struct Retrieval {
    what: &'static str,
    cases: usize,
    us: f64,
    loaded_us: f64,
    mean_distance: f64,
    insert_ms: f64,
}

/// Builds a base of `cases` cases of `D − 2` sectors drawn by `case`
/// (inserted one by one with [`CaseBase::insert`], the insertion alone
/// timed: duplicates are refused and counted, drawing goes on until `cases`
/// went in) and prints the mean time of a retrieval over 100,000 queries
/// drawn by `query` (median of 5 runs), and the mean distance from a query
/// to its nearest case; then the same for the base written and read back
/// (its index then one tree, not the few trees and the buffer that
/// insertion one by one leaves). A sample of the queries is checked
/// against a brute-force search.
fn retrieval<const D: usize>(
    what: &'static str,
    cases: usize,
    noise: &mut Noise,
    case: &mut dyn FnMut(&mut Noise, usize) -> Case,
    query: &mut dyn FnMut(&mut Noise, usize) -> Situation,
) -> Retrieval {
    const QUERIES: usize = 100_000;
    let sectors = CaseBase::<D>::SECTORS;
    let mut base: CaseBase<D> = CaseBase::new(MAX_RANGE, 0.0);
    // Drawn first, so that the insertion alone is timed.
    let first: Vec<Case> = (0..cases).map(|_| case(noise, sectors)).collect();
    let t = Instant::now();
    for c in first {
        base.insert(c).expect("valid case");
    }
    let build = t.elapsed();
    let mut drawn = cases;
    while base.len() < cases {
        drawn += 1;
        base.insert(case(noise, sectors)).expect("valid case");
    }
    let queries: Vec<Situation> = (0..QUERIES).map(|_| query(noise, sectors)).collect();
    // The median over 5 runs of the queries, per query (µs).
    let time_queries = |base: &CaseBase<D>| {
        let mut per_query = Vec::new();
        for _ in 0..5 {
            let t = Instant::now();
            let mut acc = 0usize;
            for q in &queries {
                acc += base.nearest(black_box(q)).expect("valid").expect("not empty").0;
            }
            black_box(acc);
            per_query.push(t.elapsed() / QUERIES as u32);
        }
        median(per_query).as_secs_f64() * 1e6
    };
    let us = time_queries(&base);
    // The same base read from its file: all its cases in one tree.
    let t = Instant::now();
    let loaded: CaseBase<D> = CaseBase::from_text(&base.to_text()).expect("its own text");
    let load = t.elapsed();
    let loaded_us = time_queries(&loaded);
    for q in queries.iter().step_by(QUERIES / 50) {
        assert_eq!(loaded.nearest(q).expect("valid"), base.nearest(q).expect("valid"), "the same nearest case");
    }
    let mean_distance =
        queries.iter().map(|q| base.nearest(q).expect("valid").expect("not empty").1).sum::<f64>() / QUERIES as f64;
    // The k-d tree's answer is the nearest case (to single precision).
    let keys: Vec<[f64; D]> = base.cases().iter().map(|c| base.key(&c.situation).expect("valid")).collect();
    for q in queries.iter().step_by(QUERIES / 50) {
        let k = base.key(q).expect("valid");
        let brute = keys
            .iter()
            .map(|c| c.iter().zip(&k).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt())
            .fold(f64::INFINITY, f64::min);
        let (_, d) = base.nearest(q).expect("valid").expect("not empty");
        assert!(d <= brute + 1e-5, "the k-d tree missed the nearest case: {d} > {brute}");
    }
    if KIDDO.load(std::sync::atomic::Ordering::Relaxed) {
        kiddo_reference(&keys, &queries.iter().map(|q| base.key(q).expect("valid")).collect::<Vec<_>>());
    }
    println!(
        "  cases ({what}, {sectors} sectors): {} inserted of {drawn} drawn ({} duplicates refused) in {:.0} ms; \
         nearest case: {us:.2} µs per query (target < 5 µs), mean distance {mean_distance:.3}; \
         written and read back (one tree) in {:.0} ms: {loaded_us:.2} µs per query",
        base.len(),
        drawn - base.len(),
        build.as_secs_f64() * 1e3,
        load.as_secs_f64() * 1e3
    );
    Retrieval { what, cases, us, loaded_us, mean_distance, insert_ms: build.as_secs_f64() * 1e3 }
}

/// Whether to measure kiddo's k-d trees on the same cases (`--kiddo`).
static KIDDO: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// The reference of `--kiddo`: kiddo 5's incremental k-d tree (what the
/// case base used before, buckets of 64) and its immutable one (buckets of
/// 32), single precision, over the same keys and queries: build time and
/// time per query (median of 3 runs).
fn kiddo_reference<const D: usize>(keys: &[[f64; D]], queries: &[[f64; D]]) {
    use kiddo::immutable::float::kdtree::ImmutableKdTree;
    use kiddo::SquaredEuclidean;
    let narrow = |k: &[f64; D]| -> [f32; D] { std::array::from_fn(|i| k[i] as f32) };
    let points: Vec<[f32; D]> = keys.iter().map(narrow).collect();
    let qs: Vec<[f32; D]> = queries.iter().map(narrow).collect();
    let t = Instant::now();
    let mut mutable: kiddo::float::kdtree::KdTree<f32, u64, D, 64, u32> = kiddo::float::kdtree::KdTree::new();
    for (i, p) in points.iter().enumerate() {
        mutable.add(p, i as u64);
    }
    let mutable_build = t.elapsed();
    let t = Instant::now();
    let immutable: ImmutableKdTree<f32, u64, D, 32> = ImmutableKdTree::new_from_slice(&points);
    let immutable_build = t.elapsed();
    let time = |f: &dyn Fn(&[f32; D]) -> u64| {
        let mut runs = Vec::new();
        for _ in 0..3 {
            let t = Instant::now();
            let mut acc = 0u64;
            for q in &qs {
                acc = acc.wrapping_add(f(black_box(q)));
            }
            black_box(acc);
            runs.push(t.elapsed() / qs.len() as u32);
        }
        median(runs).as_secs_f64() * 1e6
    };
    let m = time(&|q| mutable.nearest_one::<SquaredEuclidean>(q).item);
    let i = time(&|q| immutable.nearest_one::<SquaredEuclidean>(q).item);
    println!(
        "    kiddo KdTree (B 64): built in {:.0} ms, {m:.2} µs per query; \
         kiddo ImmutableKdTree (B 32): built in {:.0} ms, {i:.2} µs per query",
        mutable_build.as_secs_f64() * 1e3,
        immutable_build.as_secs_f64() * 1e3
    );
}

/// The maximum range of the simulated sensor (m).
const MAX_RANGE: f64 = 4.0;
/// Side of the walled square area of an obstacle field (m).
const FIELD: f64 = 20.0;
/// Beams of the simulated range scan (one per degree).
const BEAMS: usize = 360;
/// Situations drawn in one obstacle field before a new field is made.
const FIELD_SITUATIONS: usize = 50;
/// The clearance (m) of a pose from the obstacles: the robot's radius.
const CLEARANCE: f64 = 0.25;

/// An obstacle of a field.
#[derive(Clone, Copy)]
enum Obstacle {
    /// Centre and radius (m).
    Disc { x: f64, y: f64, r: f64 },
    /// Corners (m), `x0 < x1`, `y0 < y1`.
    Box { x0: f64, y0: f64, x1: f64, y1: f64 },
}

impl Obstacle {
    /// The centre and radius of a circle around the obstacle.
    fn bounds(&self) -> (f64, f64, f64) {
        match *self {
            Obstacle::Disc { x, y, r } => (x, y, r),
            Obstacle::Box { x0, y0, x1, y1 } => ((x0 + x1) / 2.0, (y0 + y1) / 2.0, (x1 - x0).hypot(y1 - y0) / 2.0),
        }
    }
    /// The distance from point `(px, py)` to the obstacle (0 inside).
    fn distance(&self, px: f64, py: f64) -> f64 {
        match *self {
            Obstacle::Disc { x, y, r } => ((px - x).hypot(py - y) - r).max(0.0),
            Obstacle::Box { x0, y0, x1, y1 } => {
                let dx = (x0 - px).max(px - x1).max(0.0);
                let dy = (y0 - py).max(py - y1).max(0.0);
                dx.hypot(dy)
            }
        }
    }
    /// The distance along the ray from `(px, py)` in unit direction
    /// `(dx, dy)` to the obstacle, if it is hit.
    fn ray(&self, px: f64, py: f64, dx: f64, dy: f64) -> Option<f64> {
        match *self {
            Obstacle::Disc { x, y, r } => {
                let (mx, my) = (px - x, py - y);
                let b = mx * dx + my * dy;
                let c = mx * mx + my * my - r * r;
                if c > 0.0 && b > 0.0 {
                    return None;
                }
                let disc = b * b - c;
                (disc >= 0.0).then(|| (-b - disc.sqrt()).max(0.0))
            }
            Obstacle::Box { x0, y0, x1, y1 } => {
                let (mut near, mut far) = (0.0f64, f64::INFINITY);
                for (p, d, lo, hi) in [(px, dx, x0, x1), (py, dy, y0, y1)] {
                    if d.abs() < 1e-12 {
                        if p < lo || p > hi {
                            return None;
                        }
                    } else {
                        let (a, b) = ((lo - p) / d, (hi - p) / d);
                        near = near.max(a.min(b));
                        far = far.min(a.max(b));
                    }
                }
                (near <= far).then_some(near)
            }
        }
    }
}

/// Random obstacle fields, a new one every `per_field` situations, and the
/// situations a robot meets in them.
struct Fields {
    per_field: usize,
    left: usize,
    obstacles: Vec<Obstacle>,
}

impl Fields {
    fn new(per_field: usize) -> Self {
        Fields { per_field, left: 0, obstacles: Vec::new() }
    }

    /// A new field: 5 to 30 discs (radius 0.15–0.8 m) and 5 to 30 boxes
    /// (sides 0.3–3 m), anywhere in the area.
    fn renew(&mut self, noise: &mut Noise) {
        self.obstacles.clear();
        let discs = 5 + (noise.uniform() * 26.0) as usize;
        let boxes = 5 + (noise.uniform() * 26.0) as usize;
        for _ in 0..discs {
            let (x, y) = (noise.uniform() * FIELD, noise.uniform() * FIELD);
            self.obstacles.push(Obstacle::Disc { x, y, r: 0.15 + noise.uniform() * 0.65 });
        }
        for _ in 0..boxes {
            let (x, y) = (noise.uniform() * FIELD, noise.uniform() * FIELD);
            let (w, h) = (0.3 + noise.uniform() * 2.7, 0.3 + noise.uniform() * 2.7);
            self.obstacles.push(Obstacle::Box { x0: x, y0: y, x1: x + w, y1: y + h });
        }
        self.left = self.per_field;
    }

    /// A situation: a random pose at least [`CLEARANCE`] from the obstacles
    /// and walls, the sector minima of a scan from it, a random goal.
    fn situation(&mut self, noise: &mut Noise, sectors: usize) -> Situation {
        if self.left == 0 {
            self.renew(noise);
        }
        self.left -= 1;
        let (x, y) = loop {
            let x = CLEARANCE + noise.uniform() * (FIELD - 2.0 * CLEARANCE);
            let y = CLEARANCE + noise.uniform() * (FIELD - 2.0 * CLEARANCE);
            if self.obstacles.iter().all(|o| o.distance(x, y) >= CLEARANCE) {
                break (x, y);
            }
        };
        let theta = noise.uniform() * std::f64::consts::TAU;
        // Only the obstacles within reach.
        let near: Vec<Obstacle> = self
            .obstacles
            .iter()
            .filter(|o| {
                let (cx, cy, r) = o.bounds();
                (cx - x).hypot(cy - y) <= MAX_RANGE + r
            })
            .copied()
            .collect();
        let beams: Vec<Beam> = (0..BEAMS)
            .map(|k| {
                let a = (k as f64 + 0.5) * std::f64::consts::TAU / BEAMS as f64 - std::f64::consts::PI;
                let (dx, dy) = ((theta + a).cos(), (theta + a).sin());
                // The walls of the area.
                let wall = |p: f64, d: f64| match d {
                    d if d > 1e-12 => (FIELD - p) / d,
                    d if d < -1e-12 => -p / d,
                    _ => f64::INFINITY,
                };
                let mut r = wall(x, dx).min(wall(y, dy));
                for o in &near {
                    if let Some(t) = o.ray(x, y, dx, dy) {
                        r = r.min(t);
                    }
                }
                let range = if r >= MAX_RANGE { MAX_RANGE } else { (r + noise.normal(0.01)).clamp(0.0, MAX_RANGE) };
                Beam { angle: a, range, max_range: MAX_RANGE }
            })
            .collect();
        let (gx, gy) = (noise.uniform() * FIELD, noise.uniform() * FIELD);
        let goal = (gy - y).atan2(gx - x) - theta;
        Situation::from_scan(&beams, sectors, MAX_RANGE, goal)
    }
}
