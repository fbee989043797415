//! Speed of the DLA building blocks: building the split-and-merge pyramid
//! of a 512 × 512 occupancy grid (rooms, doors, obstacles, unexplored
//! parts, built from simulated scans), and retrieving the nearest case
//! among 100,000 random cases.
//!
//! `cargo run --release -p situ-sim --example dla_speed`
//! Targets: pyramid < 20 ms, retrieval < 5 µs per query.

use situ_sim::dla::cases::{Case, CaseBase, Command, Situation};
use situ_sim::dla::grid::{Beam, GridParams, OccupancyGrid};
use situ_sim::dla::pyramid::{Pyramid, PyramidParams};
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
    let mut noise = Noise::new(7, 0);
    let truth = truth(&mut noise);
    let grid = scanned_grid(&truth, &mut noise);
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
    let free_regions = p.regions().iter().filter(|r| r.class == situ_sim::dla::pyramid::RegionClass::Free).count();
    println!(
        "pyramid: {} levels, {} orphan blocks, {} regions ({} free); median of 15 builds: {ms:.2} ms (target < 20 ms)",
        p.levels(),
        p.blocks().len(),
        p.regions().len(),
        free_regions,
    );

    let max_range = 4.0;
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
    retrieval::<6>("random", &mut noise, &random);
    retrieval::<8>("random", &mut noise, &random);
    retrieval::<10>("random", &mut noise, &random);
    retrieval::<8>("scanned in the map", &mut noise, &scanned);
    retrieval::<10>("scanned in the map", &mut noise, &scanned);
}

/// Builds a base of 100,000 cases of `D − 2` sectors drawn by `draw` and
/// prints the mean time of a retrieval over 100,000 queries drawn alike
/// (median of 5 runs).
fn retrieval<const D: usize>(what: &str, noise: &mut Noise, draw: &dyn Fn(&mut Noise, usize) -> Situation) {
    const CASES: usize = 100_000;
    const QUERIES: usize = 100_000;
    let sectors = CaseBase::<D>::SECTORS;
    let mut base: CaseBase<D> = CaseBase::new(4.0, 0.0);
    let t = Instant::now();
    while base.len() < CASES {
        let situation = draw(noise, sectors);
        let command = Command { speed: noise.uniform(), turn_rate: noise.uniform() - 0.5 };
        base.insert(Case { situation, command }).expect("valid case");
    }
    let build = t.elapsed();
    let queries: Vec<Situation> = (0..QUERIES).map(|_| draw(noise, sectors)).collect();
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
    let us = median(per_query).as_secs_f64() * 1e6;
    println!(
        "cases ({what}, {sectors} sectors): {CASES} inserted in {:.0} ms; nearest case: {us:.2} µs per query (target < 5 µs)",
        build.as_secs_f64() * 1e3
    );
}
