//! The DLA building blocks: occupancy grid, split-and-merge pyramid and
//! topological map, route and potential-field path planners, case base.

use situ_dla::cases::{drive, Case, CaseBase, CaseError, Command, DriverParams, Situation};
use situ_dla::grid::{Beam, CellClass, GridParams, OccupancyGrid};
use situ_dla::pyramid::{Pyramid, PyramidParams, RegionClass};
use situ_dla::route::{plan_path, plan_route, PathParams, RouteParams};
use situ_sim::geom::{v2, Pose, Vec2};
use situ_sim::noise::Noise;
use std::path::PathBuf;

const FREE: f64 = 0.1;
const OCC: f64 = 0.9;

fn empty(w: usize, h: usize) -> OccupancyGrid {
    OccupancyGrid::new(w, h, 0.1, v2(0.0, 0.0), GridParams::default())
}

#[test]
fn grid_update_marks_free_occupied_and_unknown() {
    let mut g = empty(40, 40);
    let pose = Pose::new(0.55, 2.05, 0.0);
    let beams = [
        Beam { angle: 0.0, range: 2.0, max_range: 3.0 },
        // Nothing seen up to the maximum range: frees cells, marks no hit.
        Beam { angle: std::f64::consts::FRAC_PI_2, range: 3.0, max_range: 3.0 },
    ];
    for _ in 0..3 {
        g.update(&pose, &beams);
    }
    // Along the first beam, the cells before the hit are free; the hit
    // (x = 2.55 m, cell 25) is occupied; beyond it nothing is known.
    for x in 5..25 {
        assert!(g.is_free(x, 20), "cell ({x}, 20) p = {}", g.probability(x, 20));
    }
    assert!(g.is_occupied(25, 20));
    assert!(g.is_unknown(26, 20));
    assert_eq!(g.probability(26, 20), 0.5);
    // The second beam leaves the grid at y = 4 m: free to the edge, no hit.
    for y in 21..40 {
        assert!(g.is_free(5, y), "cell (5, {y})");
    }
    assert!((0..40).all(|y| !g.is_occupied(5, y)));
    // Never observed: exactly 0.5.
    assert_eq!(g.probability(30, 5), 0.5);
    assert_eq!(g.class(30, 5), CellClass::Unknown);
    // The point queries agree with the cells.
    assert!(g.probability_at(v2(2.55, 2.05)) > 0.7);
    assert_eq!(g.probability_at(v2(-1.0, 0.0)), 0.5);
    // Repeated evidence is clamped, and can be overturned.
    for _ in 0..100 {
        g.update(&pose, &beams[..1]);
    }
    assert!(g.logodds_at(25, 20) <= g.params().l_max);
    let far = [Beam { angle: 0.0, range: 3.0, max_range: 3.0 }];
    for _ in 0..100 {
        g.update(&pose, &far);
    }
    assert!(g.is_free(25, 20));
}

/// Two rooms (x 1..=14 and 16..=30) in walls, a door of two cells in the
/// wall between them (x = 15, y 7..=8), unexplored beyond the right wall.
fn two_rooms(door_open: bool) -> OccupancyGrid {
    let mut g = empty(40, 16);
    g.fill(0, 0, 32, 16, OCC);
    g.fill(1, 1, 15, 15, FREE);
    g.fill(16, 1, 31, 15, FREE);
    if door_open {
        g.fill(15, 7, 16, 9, FREE);
    }
    g
}

fn params(max_extent: usize) -> PyramidParams {
    PyramidParams { max_extent, ..PyramidParams::default() }
}

fn cell_center(g: &OccupancyGrid, x: usize, y: usize) -> Vec2 {
    g.center(x, y)
}

#[test]
fn pyramid_regions_partition_the_cells_with_the_right_classes() {
    for door in [true, false] {
        let g = two_rooms(door);
        let p = Pyramid::build(&g, &params(16));
        let mut seen = vec![0u32; g.len()];
        let mut total = 0;
        for r in p.regions() {
            assert_eq!(r.size, p.cells(r.id).len());
            total += r.size;
            for &c in p.cells(r.id) {
                let c = c as usize;
                seen[c] += 1;
                assert_eq!(p.region_of_index(c), r.id);
                let (x, y) = g.coords(c);
                assert!(r.bbox.contains(x, y));
                assert_eq!(RegionClass::from(g.class(x, y)), r.class, "cell ({x}, {y})");
            }
            // The blocks linked into the region are exactly its cells.
            let in_blocks: usize = r.blocks.iter().map(|&b| (p.blocks()[b].w * p.blocks()[b].h) as usize).sum();
            assert_eq!(in_blocks, r.size);
            let expected = match r.class {
                RegionClass::Free => FREE,
                RegionClass::Occupied => OCC,
                RegionClass::Unexplored => 0.5,
            };
            assert!((r.mean_occupancy - expected).abs() < 1e-3);
        }
        assert_eq!(total, g.len());
        assert!(seen.iter().all(|&n| n == 1), "every cell in exactly one region");
        let room_a = p.region_of(5, 5);
        let room_b = p.region_of(25, 10);
        assert_eq!(p.region(room_a).class, RegionClass::Free);
        assert_eq!(p.region(room_b).class, RegionClass::Free);
        assert_ne!(room_a, room_b);
        assert_eq!(p.region(p.region_of(0, 0)).class, RegionClass::Occupied);
        assert_eq!(p.region(p.region_of(15, 3)).class, RegionClass::Occupied);
        assert_eq!(p.region(p.region_of(35, 5)).class, RegionClass::Unexplored);
        // Each room is one region (it fits the extent), the centroid inside.
        for (room, x0, x1) in [(room_a, 1, 14), (room_b, 16, 30)] {
            for y in 1..15 {
                for x in x0..=x1 {
                    assert_eq!(p.region_of(x, y), room);
                }
            }
            let c = p.region(room).centroid;
            assert!(c.x > x0 as f64 * 0.1 && c.x < (x1 + 1) as f64 * 0.1);
        }
        assert_eq!(p.region_at(&g, v2(0.55, 0.55)), Some(room_a));
        assert_eq!(p.region_at(&g, v2(-0.1, 0.55)), None);
    }
}

#[test]
fn pyramid_adjacency_is_sharing_an_edge_of_cells() {
    for door in [true, false] {
        let g = two_rooms(door);
        let p = Pyramid::build(&g, &params(16));
        let (w, h) = (g.width(), g.height());
        let n = p.regions().len();
        let mut brute = vec![vec![false; n]; n];
        for y in 0..h {
            for x in 0..w {
                let r = p.region_of(x, y);
                if x + 1 < w && p.region_of(x + 1, y) != r {
                    brute[r][p.region_of(x + 1, y)] = true;
                    brute[p.region_of(x + 1, y)][r] = true;
                }
                if y + 1 < h && p.region_of(x, y + 1) != r {
                    brute[r][p.region_of(x, y + 1)] = true;
                    brute[p.region_of(x, y + 1)][r] = true;
                }
            }
        }
        for (a, row) in brute.iter().enumerate() {
            for (b, &adj) in row.iter().enumerate() {
                assert_eq!(p.adjacent(a, b), adj, "regions {a} and {b}");
            }
        }
        let (room_a, room_b) = (p.region_of(5, 5), p.region_of(25, 10));
        let wall = p.region_of(15, 3);
        assert!(p.adjacent(room_a, wall) || p.adjacent(room_b, wall));
        // The rooms touch only through the door.
        let through_door = p.adjacent(room_a, room_b)
            || p.neighbours(room_a).iter().any(|&d| p.adjacent(d, room_b) && p.region(d).class == RegionClass::Free);
        assert_eq!(through_door, door);
    }
}

#[test]
fn route_goes_through_the_door_and_none_when_it_is_closed() {
    let g = two_rooms(true);
    let p = Pyramid::build(&g, &params(16));
    let (start, goal) = (cell_center(&g, 3, 3), cell_center(&g, 27, 12));
    let route = plan_route(&p, &g, start, goal, &RouteParams::default()).expect("a route");
    assert_eq!(route[0], p.region_of(3, 3));
    assert_eq!(*route.last().unwrap(), p.region_of(27, 12));
    assert!(route.len() >= 2);
    for pair in route.windows(2) {
        assert!(p.adjacent(pair[0], pair[1]));
    }
    assert!(route.iter().all(|&r| p.region(r).class == RegionClass::Free));
    // The route crosses the door's cells.
    assert!(route.contains(&p.region_of(15, 7)));
    // Same region: a route of one.
    assert_eq!(
        plan_route(&p, &g, start, cell_center(&g, 10, 10), &RouteParams::default()),
        Some(vec![p.region_of(3, 3)])
    );
    // Into a wall or off the grid: none.
    assert_eq!(plan_route(&p, &g, start, cell_center(&g, 15, 3), &RouteParams::default()), None);
    assert_eq!(plan_route(&p, &g, start, v2(100.0, 0.0), &RouteParams::default()), None);

    let closed = two_rooms(false);
    let p = Pyramid::build(&closed, &params(16));
    assert_eq!(plan_route(&p, &closed, start, goal, &RouteParams::default()), None);
}

#[test]
fn route_crosses_unexplored_regions_only_when_allowed() {
    // A free corridor cut by an unexplored stretch.
    let mut g = empty(30, 5);
    g.fill(0, 0, 30, 5, OCC);
    g.fill(1, 1, 29, 4, FREE);
    g.fill(12, 1, 18, 4, 0.5);
    let p = Pyramid::build(&g, &params(16));
    let (start, goal) = (cell_center(&g, 2, 2), cell_center(&g, 27, 2));
    assert_eq!(plan_route(&p, &g, start, goal, &RouteParams::default()), None);
    let allow = RouteParams { allow_unexplored: true, ..RouteParams::default() };
    let route = plan_route(&p, &g, start, goal, &allow).expect("a route");
    assert!(route.iter().any(|&r| p.region(r).class == RegionClass::Unexplored));
}

/// Checks that a path starts and ends where asked, moves one cell at a
/// time, and never enters an occupied cell.
fn check_path(g: &OccupancyGrid, path: &[Vec2], start: Vec2, goal: Vec2) {
    assert_eq!(path[0], start);
    assert_eq!(*path.last().unwrap(), goal);
    let cells: Vec<(usize, usize)> = path.iter().map(|&q| g.cell_of(q).expect("on the grid")).collect();
    for &(x, y) in &cells {
        assert!(!g.is_occupied(x, y), "the path enters occupied cell ({x}, {y})");
    }
    for pair in cells.windows(2) {
        let (dx, dy) = (pair[0].0.abs_diff(pair[1].0), pair[0].1.abs_diff(pair[1].1));
        assert!(dx <= 1 && dy <= 1, "a jump from {:?} to {:?}", pair[0], pair[1]);
        if dx == 1 && dy == 1 {
            // No corner cutting.
            assert!(!g.is_occupied(pair[0].0, pair[1].1) && !g.is_occupied(pair[1].0, pair[0].1));
        }
    }
}

#[test]
fn potential_field_path_goes_through_the_door() {
    let g = two_rooms(true);
    let p = Pyramid::build(&g, &params(16));
    let (start, goal) = (cell_center(&g, 3, 3), cell_center(&g, 27, 12));
    let route = plan_route(&p, &g, start, goal, &RouteParams::default()).unwrap();
    let path = plan_path(&g, &p, &route, start, goal, &PathParams::default()).expect("a path");
    check_path(&g, &path, start, goal);
    assert_eq!(p.region_at(&g, *path.last().unwrap()), Some(*route.last().unwrap()));
    assert!(path.iter().any(|&q| g.cell_of(q) == Some((15, 7)) || g.cell_of(q) == Some((15, 8))));
    // A start outside the route's first region is refused.
    assert_eq!(plan_path(&g, &p, &route, goal, start, &PathParams::default()), None);
}

#[test]
fn potential_field_path_escapes_a_u_shaped_trap() {
    let mut g = empty(40, 40);
    g.fill(0, 0, 40, 40, OCC);
    g.fill(1, 1, 39, 39, FREE);
    // A U open towards the start: its bottom at x = 25, arms to x = 15.
    g.fill(25, 10, 26, 31, OCC);
    g.fill(15, 10, 26, 11, OCC);
    g.fill(15, 30, 26, 31, OCC);
    let p = Pyramid::build(&g, &PyramidParams::default());
    let (start, goal) = (cell_center(&g, 8, 20), cell_center(&g, 35, 20));
    let route = plan_route(&p, &g, start, goal, &RouteParams::default()).expect("a route");
    let path = plan_path(&g, &p, &route, start, goal, &PathParams::default()).expect("a path");
    check_path(&g, &path, start, goal);
    assert_eq!(p.region_at(&g, goal), Some(*route.last().unwrap()));
    // The descent went into the U (the trap: a local minimum at its
    // bottom), and the path escaped it around an arm.
    let inside = |q: &Vec2| q.x > 1.6 && q.x < 2.5 && q.y > 1.1 && q.y < 3.0;
    assert!(path.iter().any(inside), "the descent did not meet the trap");
    assert!(path.iter().any(|q| q.y < 1.0 || q.y > 3.1));
}

fn random_situation(noise: &mut Noise, sectors: usize, max_range: f64) -> Situation {
    let ranges = (0..sectors).map(|_| noise.uniform() * max_range * 1.1).collect();
    Situation::new(ranges, (noise.uniform() * 2.0 - 1.0) * std::f64::consts::PI)
}

fn random_case(noise: &mut Noise, sectors: usize) -> Case {
    Case {
        situation: random_situation(noise, sectors, 4.0),
        command: Command { speed: noise.uniform(), turn_rate: noise.uniform() - 0.5 },
    }
}

#[test]
fn nearest_case_equals_brute_force() {
    for seed in 0..4 {
        let mut noise = Noise::new(seed, 1);
        let mut base: CaseBase<10> = CaseBase::new(4.0, 0.0);
        for _ in 0..(500 + 1500 * seed as usize) {
            assert!(base.insert(random_case(&mut noise, 8)).unwrap());
        }
        let keys: Vec<[f64; 10]> = base.cases().iter().map(|c| base.key(&c.situation).unwrap()).collect();
        for _ in 0..300 {
            let q = random_situation(&mut noise, 8, 4.0);
            let k = base.key(&q).unwrap();
            let brute = keys
                .iter()
                .map(|c| c.iter().zip(&k).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt())
                .fold(f64::INFINITY, f64::min);
            let (i, d) = base.nearest(&q).unwrap().unwrap();
            assert!((d - brute).abs() < 1e-5, "seed {seed}: {d} vs {brute}");
            assert_eq!(base.command(&q).unwrap(), Some(base.cases()[i].command));
        }
        // A case is its own nearest.
        let c = base.cases()[17].clone();
        assert_eq!(base.nearest(&c.situation).unwrap(), Some((17, 0.0)));
        assert!(!base.insert(c).unwrap(), "an identical case is not added twice");
    }
    let base: CaseBase<10> = CaseBase::new(4.0, 0.0);
    assert_eq!(base.nearest(&Situation::new(vec![1.0; 8], 0.0)).unwrap(), None);
    assert!(matches!(
        base.nearest(&Situation::new(vec![1.0; 7], 0.0)),
        Err(CaseError::SectorCount { expected: 8, found: 7 })
    ));
    assert!(matches!(base.nearest(&Situation::new(vec![f64::NAN; 8], 0.0)), Err(CaseError::NotFinite)));
}

/// The nearest case by brute force: its distance (double precision).
fn brute_nearest<const D: usize>(keys: &[[f64; D]], k: &[f64; D]) -> f64 {
    keys.iter()
        .map(|c| c.iter().zip(k).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt())
        .fold(f64::INFINITY, f64::min)
}

/// A situation with its ranges on a coarse grid (many equal coordinates,
/// ranges beyond the maximum) and its goal in one of 16 directions.
fn coarse_situation(noise: &mut Noise) -> Situation {
    let ranges = (0..8).map(|_| (noise.uniform() * 4.4 / 0.5).round() * 0.5).collect();
    let goal = ((noise.uniform() * 16.0).floor() - 8.0) * std::f64::consts::PI / 8.0;
    Situation::new(ranges, goal)
}

#[test]
fn nearest_case_stays_exact_while_cases_are_added() {
    // Cases added one at a time, queries between the additions: the
    // answer must stay the brute-force nearest case across the index's
    // rebuilds (latest cases scanned, then made trees, trees merged).
    let mut noise = Noise::new(11, 3);
    let mut base: CaseBase<10> = CaseBase::new(4.0, 0.0);
    let mut keys: Vec<[f64; 10]> = Vec::new();
    let mut snapshot = None;
    for step in 0..3000 {
        let case = if step % 3 == 0 {
            random_case(&mut noise, 8)
        } else {
            Case { situation: coarse_situation(&mut noise), command: Command { speed: 0.1, turn_rate: 0.0 } }
        };
        let k = base.key(&case.situation).unwrap();
        let before = brute_nearest(&keys, &k);
        let situation = case.situation.clone();
        if base.insert(case).unwrap() {
            keys.push(k);
            // The case just added is its own nearest.
            assert_eq!(base.nearest(&situation).unwrap(), Some((keys.len() - 1, 0.0)), "step {step}");
        } else {
            assert_eq!(before, 0.0, "step {step}: a case was refused as a repeat of none");
        }
        let q = if step % 2 == 0 { random_situation(&mut noise, 8, 4.0) } else { coarse_situation(&mut noise) };
        let k = base.key(&q).unwrap();
        let (i, d) = base.nearest(&q).unwrap().unwrap();
        let brute = brute_nearest(&keys, &k);
        assert!((d - brute).abs() < 1e-5, "step {step}: {d} vs {brute}");
        assert!((brute_nearest(&keys[i..=i], &k) - d).abs() < 1e-12);
        if step == 1234 {
            snapshot = Some((base.clone(), keys.len()));
        }
    }
    assert!(keys.len() > 2000, "only {} distinct cases", keys.len());
    // A clone answers on its own cases, not on those added since.
    let (clone, n) = snapshot.unwrap();
    assert_eq!(clone.len(), n);
    // The base read back from its file (all in one tree) gives the same answers.
    let read = CaseBase::<10>::from_text(&base.to_text()).unwrap();
    for _ in 0..300 {
        let q = random_situation(&mut noise, 8, 4.0);
        let k = base.key(&q).unwrap();
        let (i, d) = clone.nearest(&q).unwrap().unwrap();
        assert!(i < n && (d - brute_nearest(&keys[..n], &k)).abs() < 1e-5);
        let (i, d) = read.nearest(&q).unwrap().unwrap();
        assert!((d - brute_nearest(&keys, &k)).abs() < 1e-5);
        assert_eq!(read.cases()[i], base.cases()[i]);
    }
}

#[test]
fn learning_adds_only_novel_cases() {
    let mut base: CaseBase<6> = CaseBase::new(4.0, 0.1);
    let cmd = Command { speed: 0.3, turn_rate: 0.0 };
    let a = Case { situation: Situation::new(vec![2.0, 2.0, 2.0, 2.0], 0.0), command: cmd };
    assert!(base.learn(a.clone()).unwrap());
    assert!(!base.learn(a).unwrap());
    // 0.2 m on one sector of a 4 m range: 0.05 away, not novel.
    let near = Case { situation: Situation::new(vec![2.2, 2.0, 2.0, 2.0], 0.0), command: cmd };
    assert!(!base.learn(near).unwrap());
    // 1 m: 0.25 away, novel.
    let far = Case { situation: Situation::new(vec![3.0, 2.0, 2.0, 2.0], 0.0), command: cmd };
    assert!(base.learn(far).unwrap());
    // Another subgoal direction is novel too.
    let turned = Case { situation: Situation::new(vec![2.0, 2.0, 2.0, 2.0], 1.0), command: cmd };
    assert!(base.learn(turned).unwrap());
    assert_eq!(base.len(), 3);
}

/// A fresh directory for one test.
fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("situ-dla-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn files(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    v.sort();
    v
}

#[test]
fn case_base_file_round_trip_is_atomic() {
    let dir = scratch("round-trip");
    let path = dir.join("robot.cases");
    let mut noise = Noise::new(3, 3);
    let mut base: CaseBase<10> = CaseBase::new(4.5, 0.05);
    for _ in 0..300 {
        base.insert(random_case(&mut noise, 8)).unwrap();
    }
    base.write(&path).unwrap();
    let back = CaseBase::<10>::read(&path).unwrap();
    assert_eq!(back.cases(), base.cases());
    assert_eq!(back.max_range(), 4.5);
    assert_eq!(back.novelty(), 0.05);
    assert_eq!(back.to_text(), base.to_text());
    // Writing over it replaces it whole and leaves no temporary file.
    let mut other: CaseBase<10> = CaseBase::new(4.5, 0.05);
    other.insert(random_case(&mut noise, 8)).unwrap();
    other.write(&path).unwrap();
    assert_eq!(CaseBase::<10>::read(&path).unwrap().cases(), other.cases());
    assert_eq!(files(&dir), vec!["robot.cases".to_string()]);
    // An empty base too.
    let empty: CaseBase<10> = CaseBase::new(4.0, 0.0);
    empty.write(&path).unwrap();
    assert!(CaseBase::<10>::read(&path).unwrap().is_empty());
    // A write that cannot happen leaves the file as it was.
    let before = std::fs::read(&path).unwrap();
    assert!(base.write(&dir.join("missing-dir").join("robot.cases")).is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(files(&dir), vec!["robot.cases".to_string()]);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn damaged_or_foreign_case_files_are_errors_and_left_untouched() {
    let dir = scratch("damaged");
    let mut noise = Noise::new(4, 4);
    let mut base: CaseBase<10> = CaseBase::new(4.0, 0.05);
    for _ in 0..50 {
        base.insert(random_case(&mut noise, 8)).unwrap();
    }
    let text = base.to_text();
    let read_back = |name: &str, bytes: &[u8]| {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        let result = CaseBase::<10>::read(&path);
        assert_eq!(std::fs::read(&path).unwrap(), bytes, "{name} was modified");
        result.err().unwrap_or_else(|| panic!("{name} was read"))
    };
    // Cut in the middle.
    let cut = read_back("cut", &text.as_bytes()[..text.len() / 2]);
    assert!(matches!(cut, CaseError::Damaged { .. }), "{cut}");
    // Cut after a whole line: the checksum line is missing.
    let lines: Vec<&str> = text.lines().collect();
    let short = lines[..lines.len() - 3].join("\n") + "\n";
    assert!(matches!(read_back("short", short.as_bytes()), CaseError::Damaged { .. }));
    // One digit changed.
    let pos = text.find("\nc ").unwrap() + 4;
    let mut flipped = text.clone().into_bytes();
    flipped[pos] = if flipped[pos] == b'1' { b'2' } else { b'1' };
    let e = read_back("flipped", &flipped);
    assert!(matches!(e, CaseError::Checksum | CaseError::Damaged { .. }), "{e}");
    // A number that is not one.
    let garbled = text.replacen("\nc ", "\nc x", 1);
    assert!(matches!(read_back("garbled", garbled.as_bytes()), CaseError::Damaged { .. }));
    // Not a case base, not text, another version.
    assert!(matches!(read_back("other", b"hello\n"), CaseError::NotACaseBase));
    assert!(matches!(read_back("empty", b""), CaseError::NotACaseBase));
    assert!(matches!(read_back("binary", &[0xff, 0xfe, 0x00]), CaseError::Damaged { .. }));
    let v2text = text.replacen("situ-casebase 1", "situ-casebase 2", 1);
    assert!(matches!(read_back("version", v2text.as_bytes()), CaseError::UnsupportedVersion(2)));
    // Text after the checksum.
    let extra = format!("{text}c 1\n");
    assert!(matches!(read_back("extra", extra.as_bytes()), CaseError::Damaged { .. }));
    // Of another robot: 4 sectors, not 8.
    let mut four: CaseBase<6> = CaseBase::new(4.0, 0.05);
    four.insert(random_case(&mut noise, 4)).unwrap();
    let e = read_back("four", four.to_text().as_bytes());
    assert!(matches!(e, CaseError::OtherRobot { expected: 8, found: 4 }), "{e}");
    assert!(e.to_string().contains("another robot"));
    // A directory is not a case base.
    assert!(matches!(CaseBase::<10>::read(&dir), Err(CaseError::Io(_))));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn scripted_driver_steers_to_free_space_and_slows_near_obstacles() {
    let p = DriverParams::default();
    // All clear, subgoal ahead: full speed, straight.
    let c = drive(&Situation::new(vec![4.0; 8], 0.0), 4.0, &p);
    assert_eq!(c.speed, p.max_speed);
    assert_eq!(c.turn_rate, 0.0);
    // Subgoal on the left: turn left.
    let c = drive(&Situation::new(vec![4.0; 8], 1.2), 4.0, &p);
    assert!(c.turn_rate > 0.0);
    // Obstacle close ahead, subgoal ahead: stop and turn away, to the freer side.
    let mut ranges = vec![4.0; 8];
    ranges[0] = 0.2;
    ranges[1] = 0.5;
    let c = drive(&Situation::new(ranges, 0.0), 4.0, &p);
    assert_eq!(c.speed, 0.0);
    assert!(c.turn_rate < 0.0, "{c:?}");
    // Obstacle at 0.6 m ahead, subgoal ahead but sector clear elsewhere: slower.
    let mut ranges = vec![4.0; 8];
    ranges[0] = 0.6;
    let c = drive(&Situation::new(ranges, 0.0), 4.0, &p);
    assert!(c.speed < p.max_speed && c.turn_rate != 0.0);
    // Boxed in: turn in place.
    let c = drive(&Situation::new(vec![0.1; 8], 0.0), 4.0, &p);
    assert_eq!(c.speed, 0.0);
    assert!(c.turn_rate.abs() > 0.0);
    // Learnt cases reproduce the driver on the situations they saw.
    let mut noise = Noise::new(9, 9);
    let mut base: CaseBase<10> = CaseBase::new(4.0, 0.0);
    let seen: Vec<Situation> = (0..200).map(|_| random_situation(&mut noise, 8, 4.0)).collect();
    for s in &seen {
        base.learn(Case { situation: s.clone(), command: drive(s, 4.0, &p) }).unwrap();
    }
    for s in &seen {
        assert_eq!(base.command(s).unwrap(), Some(drive(s, 4.0, &p)));
    }
}

#[test]
fn sectors_of_a_scan() {
    let beams: Vec<Beam> = (0..8)
        .map(|k| Beam { angle: k as f64 * std::f64::consts::FRAC_PI_4, range: 1.0 + k as f64, max_range: 5.0 })
        .collect();
    let s = Situation::from_scan(&beams, 4, 5.0, 0.0);
    // Four sectors of 90°: sector 0 spans [-45°, 45°), so it holds the
    // beams at 0° and 315° (1 m and 8 m, capped at 5 m); 45° goes to sector 1.
    assert_eq!(s.ranges.len(), 4);
    assert_eq!(s.ranges[0], 1.0);
    assert_eq!(s.ranges[1], 2.0);
    assert_eq!(Situation::sector_of(-0.1, 4), 0);
    assert_eq!(Situation::sector_of(std::f64::consts::PI, 4), 2);
    assert!((Situation::sector_angle(3, 4) + std::f64::consts::FRAC_PI_2).abs() < 1e-12);
}

#[test]
fn traversal_is_a_chain_of_cells_from_start_to_end() {
    let g = empty(37, 23);
    let mut noise = Noise::new(11, 0);
    let mut cells = Vec::new();
    for _ in 0..2000 {
        let a = v2(noise.uniform() * 3.7, noise.uniform() * 2.3);
        let b = v2(noise.uniform() * 3.7, noise.uniform() * 2.3);
        cells.clear();
        g.traverse(a, b, &mut cells);
        let (ca, cb) = (g.cell_of(a).unwrap(), g.cell_of(b).unwrap());
        assert_eq!(g.coords(cells[0]), ca);
        assert_eq!(g.coords(*cells.last().unwrap()), cb, "{a:?} -> {b:?}");
        for pair in cells.windows(2) {
            let (p, q) = (g.coords(pair[0]), g.coords(pair[1]));
            assert_eq!(p.0.abs_diff(q.0) + p.1.abs_diff(q.1), 1, "a step of one cell");
        }
    }
}

/// The region of every cell is 4-connected.
fn connected(p: &Pyramid, w: usize, r: usize) -> bool {
    let cells = p.cells(r);
    let mut seen = std::collections::HashSet::from([cells[0] as usize]);
    let mut stack = vec![cells[0] as usize];
    while let Some(c) = stack.pop() {
        let (x, y) = (c % w, c / w);
        let mut next = vec![];
        if x > 0 {
            next.push(c - 1);
        }
        if x + 1 < w {
            next.push(c + 1);
        }
        if y > 0 {
            next.push(c - w);
        }
        if c + w < p.cell_regions().len() {
            next.push(c + w);
        }
        for n in next {
            if p.region_of_index(n) == r && seen.insert(n) {
                stack.push(n);
            }
        }
    }
    seen.len() == cells.len()
}

#[test]
fn pyramid_of_random_grids_is_a_partition_into_homogeneous_connected_regions() {
    let mut noise = Noise::new(5, 5);
    for _ in 0..40 {
        let w = 1 + (noise.uniform() * 70.0) as usize;
        let h = 1 + (noise.uniform() * 70.0) as usize;
        let mut g = empty(w, h);
        for _ in 0..12 {
            let (x, y) = ((noise.uniform() * w as f64) as usize, (noise.uniform() * h as f64) as usize);
            let (rw, rh) = (1 + (noise.uniform() * 20.0) as usize, 1 + (noise.uniform() * 20.0) as usize);
            let p = [0.05, 0.15, 0.25, 0.5, 0.8, 0.95][(noise.uniform() * 6.0) as usize];
            g.fill(x, y, x + rw, y + rh, p);
        }
        let params = PyramidParams { max_extent: 1 + (noise.uniform() * 40.0) as usize, ..PyramidParams::default() };
        let p = Pyramid::build(&g, &params);
        let mut seen = vec![0; g.len()];
        for b in p.blocks() {
            let mut lo: f64 = 1.0;
            let mut hi: f64 = 0.0;
            for y in b.y..b.y + b.h {
                for x in b.x..b.x + b.w {
                    let (x, y) = (x as usize, y as usize);
                    seen[g.index(x, y)] += 1;
                    assert_eq!(RegionClass::from(g.class(x, y)), b.class);
                    lo = lo.min(g.probability(x, y));
                    hi = hi.max(g.probability(x, y));
                }
            }
            assert!(hi - lo <= params.spread + 1e-6, "a block is homogeneous");
        }
        assert!(seen.iter().all(|&n| n == 1), "the blocks partition the grid");
        let mut total = 0;
        for r in p.regions() {
            total += r.size;
            assert!(connected(&p, w, r.id), "region {} is connected", r.id);
            assert!(r.bbox.x1 - r.bbox.x0 < params.max_extent.max(1 << (p.levels() - 1)));
            for &c in p.cells(r.id) {
                assert_eq!(RegionClass::from(g.class_index(c as usize)), r.class);
            }
        }
        assert_eq!(total, g.len());
    }
}

/// The `points` attribute of the polyline of class `class` in `svg`.
fn polyline_points<'a>(svg: &'a str, class: &str) -> &'a str {
    let at = svg.find(&format!(r#"<polyline class="{class}""#)).expect("the polyline");
    let rest = &svg[at..];
    let from = rest.find(r#"points=""#).expect("points") + r#"points=""#.len();
    let to = rest[from..].find('"').expect("closing quote");
    &rest[from..from + to]
}

/// A well-formedness check short of an XML parser: one root `<svg>`,
/// balanced groups, every element closed.
fn check_svg(svg: &str) {
    assert!(svg.starts_with("<svg "), "starts with <svg");
    assert!(svg.trim_end().ends_with("</svg>"), "ends with </svg>");
    assert_eq!(svg.matches("<svg").count(), 1);
    assert_eq!(svg.matches("<g ").count() + svg.matches("<g>").count(), svg.matches("</g>").count());
    assert_eq!(svg.matches("<text").count(), svg.matches("</text>").count());
    assert_eq!(svg.matches('<').count(), svg.matches('>').count());
    // Every opened tag is closed, in order.
    let mut stack: Vec<&str> = Vec::new();
    for tag in svg.split('<').skip(1) {
        let tag = &tag[..tag.find('>').expect("a tag is closed")];
        let name = tag.trim_start_matches('/').split([' ', '\n']).next().unwrap();
        if tag.starts_with('/') {
            assert_eq!(stack.pop(), Some(name), "closing </{name}>");
        } else if !tag.ends_with('/') {
            stack.push(name);
        }
    }
    assert!(stack.is_empty(), "unclosed {stack:?}");
}

#[test]
fn drawing_of_two_rooms_shows_route_labels_and_path() {
    use situ_dla::draw::draw;
    let g = two_rooms(true);
    let p = Pyramid::build(&g, &params(16));
    let (start, goal) = (cell_center(&g, 3, 3), cell_center(&g, 27, 12));
    let route = plan_route(&p, &g, start, goal, &RouteParams::default()).unwrap();
    let path = plan_path(&g, &p, &route, start, goal, &PathParams::default()).unwrap();
    let trajectory: Vec<(f64, f64)> = path.iter().map(|q| (q.x + 0.02, q.y - 0.01)).collect();
    let svg =
        draw(&g, Some(&p), &route, &path, &trajectory, (start.x, start.y), (goal.x, goal.y), "two <rooms> & a door");
    check_svg(&svg);
    assert!(svg.contains("two &lt;rooms&gt; &amp; a door"));
    // One label per route region, numbered in order.
    assert_eq!(svg.matches(r#"class="route-label""#).count(), route.len());
    for (k, r) in route.iter().enumerate() {
        assert!(svg.contains(&format!(r#"class="route-label" data-region="{r}""#)), "label of region {r}");
        assert!(svg.contains(&format!(">{}</text>", k + 1)));
    }
    // Every region outlined.
    for r in p.regions() {
        assert!(svg.contains(&format!(r#"<path data-region="{}" "#, r.id)), "outline of region {}", r.id);
    }
    // The path's points, in metres, in order.
    let expected: Vec<String> = path.iter().map(|q| format!("{:.3},{:.3}", q.x, q.y)).collect();
    assert_eq!(polyline_points(&svg, "path"), expected.join(" "));
    let expected: Vec<String> = trajectory.iter().map(|q| format!("{:.3},{:.3}", q.0, q.1)).collect();
    assert_eq!(polyline_points(&svg, "trajectory"), expected.join(" "));
    assert!(svg.contains(r#"<circle class="start""#) && svg.contains(r#"<polygon class="goal""#));
    // Deterministic.
    let again =
        draw(&g, Some(&p), &route, &path, &trajectory, (start.x, start.y), (goal.x, goal.y), "two <rooms> & a door");
    assert_eq!(svg, again);
    // Without a pyramid: the grid, the path, no region, no label.
    let bare = draw(&g, None, &route, &path, &[], (start.x, start.y), (goal.x, goal.y), "grid only");
    check_svg(&bare);
    assert!(!bare.contains("route-label") && !bare.contains("data-region") && !bare.contains(r#"class="trajectory""#));
    assert_eq!(polyline_points(&bare, "path"), polyline_points(&svg, "path"));
}

#[test]
fn drawing_of_a_200_by_200_grid_stays_small() {
    use situ_dla::draw::draw;
    // Two rooms of 10 × 20 m in walls, a door, boxes, an unexplored strip,
    // and some noise on the free cells' probabilities.
    let mut g = empty(200, 200);
    g.fill(0, 0, 200, 200, OCC);
    g.fill(2, 2, 99, 198, FREE);
    g.fill(101, 2, 198, 198, FREE);
    g.fill(99, 90, 101, 110, FREE);
    g.fill(160, 2, 198, 198, 0.5);
    for (x, y, w, h) in [(20, 30, 10, 15), (60, 120, 20, 8), (120, 40, 12, 12), (130, 150, 6, 25)] {
        g.fill(x, y, x + w, y + h, OCC);
    }
    let mut noise = Noise::new(3, 0);
    for y in 2..198 {
        for x in 2..160 {
            if g.is_free(x, y) && noise.uniform() < 0.01 {
                g.set_probability(x, y, 0.2);
            }
        }
    }
    let p = Pyramid::build(&g, &PyramidParams::default());
    let (start, goal) = (g.center(10, 10), g.center(150, 180));
    let route = plan_route(&p, &g, start, goal, &RouteParams::default()).expect("a route");
    let path = plan_path(&g, &p, &route, start, goal, &PathParams::default()).expect("a path");
    let svg = draw(&g, Some(&p), &route, &path, &[], (start.x, start.y), (goal.x, goal.y), "200 x 200");
    check_svg(&svg);
    assert_eq!(svg.matches(r#"class="route-label""#).count(), route.len());
    assert!(svg.len() < 200_000, "{} bytes", svg.len());
    assert!(svg.matches("<rect").count() < 2_000, "{} rects", svg.matches("<rect").count());
    assert_eq!(svg, draw(&g, Some(&p), &route, &path, &[], (start.x, start.y), (goal.x, goal.y), "200 x 200"));
}
